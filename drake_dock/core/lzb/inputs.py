"""Argument checks of `drake_dock.core.lzb.solve.solve_lzb`: a ValueError naming the argument
for degenerate input, before any integration."""
from __future__ import annotations

import numpy as np


def per_couple(name, value, s, *, positive=False, lo=None, hi=None):
    """``value`` as s floats (a scalar is broadcast), checked finite and within the bounds;
    ValueError naming ``name`` otherwise."""
    a = np.broadcast_to(np.asarray(value, dtype=float), (s,)).copy() if np.ndim(value) == 0 \
        else np.asarray(value, dtype=float)
    if a.shape != (s,):
        raise ValueError(f"{name}: expected a scalar or {s} values (one per couple), got shape "
                         f"{np.shape(value)}")
    if not np.all(np.isfinite(a)):
        raise ValueError(f"{name}: values must be finite, got {a}")
    if positive and np.any(a <= 0):
        raise ValueError(f"{name}: values must be > 0, got {a}")
    if lo is not None and np.any(a < lo):
        raise ValueError(f"{name}: values must be >= {lo}, got {a}")
    if hi is not None and np.any(a > hi):
        raise ValueError(f"{name}: values must be <= {hi}, got {a}")
    return a


def check_inputs(M, Wn, v_minus, Wt):
    """(M, its Cholesky factor L, Wn as (n, s), v_minus, Wt, n, s) after checking shapes,
    finiteness, symmetry and positive definiteness; ValueError naming the argument otherwise."""
    M = np.asarray(M, dtype=float)
    if M.ndim != 2 or M.shape[0] != M.shape[1]:
        raise ValueError(f"M: expected a square matrix, got shape {M.shape}")
    n = M.shape[0]
    if not np.all(np.isfinite(M)):
        raise ValueError("M: contains non-finite values")
    if not np.allclose(M, M.T, rtol=1e-12, atol=1e-12 * np.abs(M).max()):
        raise ValueError("M: not symmetric")
    try:
        L = np.linalg.cholesky(M)
    except np.linalg.LinAlgError:
        raise ValueError("M: not positive definite (Cholesky failed)") from None
    Wn = np.asarray(Wn, dtype=float)
    if Wn.ndim == 1:
        Wn = Wn[:, None]
    if Wn.ndim != 2 or Wn.shape[0] != n or Wn.shape[1] < 1:
        raise ValueError(f"Wn: expected shape ({n}, s) with s >= 1, got {Wn.shape}")
    if not np.all(np.isfinite(Wn)):
        raise ValueError("Wn: contains non-finite values")
    s = Wn.shape[1]
    if np.any(np.linalg.norm(Wn, axis=0) == 0):
        raise ValueError(f"Wn: column(s) {np.flatnonzero(np.linalg.norm(Wn, axis=0) == 0)} "
                         "are zero")
    v = np.asarray(v_minus, dtype=float)
    if v.shape != (n,):
        raise ValueError(f"v_minus: expected shape ({n},), got {v.shape}")
    if not np.all(np.isfinite(v)):
        raise ValueError("v_minus: contains non-finite values")
    if Wt is not None:
        Wt = np.asarray(Wt, dtype=float)
        if Wt.shape != (n, 2 * s):
            raise ValueError(f"Wt: expected shape ({n}, {2 * s}) (two tangent directions per "
                             f"couple), got {Wt.shape}")
        if not np.all(np.isfinite(Wt)):
            raise ValueError("Wt: contains non-finite values")
    return M, L, Wn, v, Wt, n, s
