"""The constraint solve of Eq. 48-52 compiled (`drake_dock.core.constraints` states the law):
the forces and accelerations of a contact set for given modes, over the packed rows of
`drake_dock.core.kernels.constraints`: the products in loops, LU with partial pivoting and the
SVD for the singular case (`small_linalg`), and the squeeze of two sticking couples
(`drake_dock.core.squeeze`)."""
from __future__ import annotations

import math
from typing import NamedTuple

import numpy as np
from numba import njit

from drake_dock.core import constraints as ref
from drake_dock.core.kernels import small_linalg as L
from drake_dock.core.squeeze import cones_hold, squeeze_along
from drake_dock.core.kernels.copies import copy1

STICK, SLIDE, DETACH = 0, 1, 2
CODE = {ref.STICK: STICK, ref.SLIDE: SLIDE, ref.DETACH: DETACH}
NAME = (ref.STICK, ref.SLIDE, ref.DETACH)
OK, SINGULAR, NONFINITE, NONE_CONSISTENT, INDETERMINATE = 0, 1, 2, 3, 4
SLIDE_START_ITER = ref.SLIDE_START_ITER


class Problem(NamedTuple):
    """The contact problem of a mode solve: M^-1 (nv, nv), the free acceleration a0 (nv,),
    the rows' W (k, nv, 3) and bias accelerations (k, 3), the couples' gaps, normal velocities
    and friction coefficients mu, mu_s (k,)."""

    Minv: np.ndarray
    a0: np.ndarray
    W: np.ndarray
    bias: np.ndarray
    gap: np.ndarray
    vn: np.ndarray
    mu: np.ndarray
    mu_s: np.ndarray


class Solution(NamedTuple):
    """What a mode solve writes: v' (nv,), lambda_n (k,), lambda_t (k, 2) and the generalized
    contact force (nv,)."""

    vdot: np.ndarray
    lam_n: np.ndarray
    lam_t: np.ndarray
    gf: np.ndarray



@njit(cache=True)
def stabilised(x, vn, gap, omega):
    """x + 2 omega g' + omega^2 g: the Baumgarte-stabilised normal row (Eq. 52), x = g'' or its
    velocity-product term bn."""
    return x + 2 * omega * vn + omega ** 2 * gap


@njit(cache=True)
def solve_modes(P, modes, dirs, omega, out):
    """The contact forces and accelerations of the `Problem` P under the mode codes ``modes`` and
    the sliding directions ``dirs`` (k, 2) into the `Solution` out; returns (status,
    cond(A)): SINGULAR when the constraint matrix is singular and the equations inconsistent,
    NONFINITE when they hold an inf or a nan."""
    Minv, a0, W, bias, gap, vn, mu, mu_s = P
    vdot, lam_n, lam_t, gf = out
    k, nv = W.shape[0], W.shape[1]
    m = 0
    for i in range(k):
        m += 3 if modes[i] == STICK else (1 if modes[i] == SLIDE else 0)
    lam_n[:] = 0.0
    lam_t[:] = 0.0
    if m == 0:
        copy1(vdot, a0)
        gf[:] = 0.0
        return OK, 0.0
    # C: the force directions (a sticking couple's W^3, W^1, W^2; a sliding one's
    # W^3 - mu W^t s), D: the constrained directions (W^3, W^1, W^2; W^3). C^T and D^T are
    # kept C-ordered.
    Ct = np.empty((m, nv))
    Dt = np.empty((m, nv))
    rhs = np.empty(m)
    soft = 0.0       # the Baumgarte terms' squared norm (the singular case below)
    j = 0
    for i in range(k):
        if modes[i] != DETACH:
            soft += (2 * omega * vn[i] + omega ** 2 * gap[i]) ** 2
        if modes[i] == STICK:
            for c in range(3):
                for a in range(nv):
                    Ct[j + c, a] = W[i, a, c]
                    Dt[j + c, a] = W[i, a, c]
            rhs[j] = stabilised(bias[i, 0], vn[i], gap[i], omega)
            rhs[j + 1] = bias[i, 1]
            rhs[j + 2] = bias[i, 2]
            j += 3
        elif modes[i] == SLIDE:
            s0, s1 = dirs[i, 0], dirs[i, 1]
            for a in range(nv):
                Ct[j, a] = W[i, a, 0] - mu[i] * (W[i, a, 1] * s0 + W[i, a, 2] * s1)
                Dt[j, a] = W[i, a, 0]
            rhs[j] = stabilised(bias[i, 0], vn[i], gap[i], omega)
            j += 1
    # MinvC = M^-1 C (nv, m), A = D^T M^-1 C, b = -(rhs + D^T a0).
    MinvC = np.empty((nv, m))
    for r in range(nv):
        for c in range(m):
            acc = 0.0
            for a in range(nv):
                acc += Minv[r, a] * Ct[c, a]
            MinvC[r, c] = acc
    A = np.empty((m, m))
    b = np.empty(m)
    for r in range(m):
        acc = 0.0
        for a in range(nv):
            acc += Dt[r, a] * a0[a]
        b[r] = -(rhs[r] + acc)
        for c in range(m):
            acc = 0.0
            for a in range(nv):
                acc += Dt[r, a] * MinvC[a, c]
            A[r, c] = acc
    if not (np.all(np.isfinite(A)) and np.all(np.isfinite(b))):
        return NONFINITE, np.nan
    # Singular (redundant or degenerate rows) when the Hadamard ratio |det A| / prod of its
    # row norms, a scale-free measure in [0, 1] that vanishes with the smallest singular value
    # of the row-scaled matrix, is below 1e-12 (an SVD per evaluation would cost more than the
    # rest of the solve).
    prod, positive = 1.0, True
    for r in range(m):
        s = 0.0
        for c in range(m):
            s += A[r, c] * A[r, c]
        rn = math.sqrt(s)
        positive = positive and rn > 0
        prod *= rn
    LU, piv, sign = L.lu(A)
    ratio = abs(L.lu_det(LU, sign)) / prod if positive and prod > 0 else 0.0
    cond = 0.0
    if np.isfinite(ratio) and ratio > 1e-12:
        lam = L.lu_solve(LU, piv, b)
    else:
        U, sv, V = L.svd(A)
        cond = sv[0] / sv[-1] if sv[-1] > 0.0 else math.inf
        # Redundant constraints (a body resting on several sticking couples is statically
        # indeterminate): the minimum-norm forces, if the equations are consistent. The
        # Baumgarte terms pull each couple's own drift to zero, so redundant rows disagree by
        # as much as those terms: a residual within them is consistent.
        lam = L.svd_solve(U, sv, V, b, 1e-10)
        if L.norm(L.matvec(A, lam) - b) > (1e-8 * (1.0 + L.norm(b)) + math.sqrt(soft)):
            return SINGULAR, cond
        ns = 0
        for i in range(k):
            ns += 1 if modes[i] == STICK else 0
        offsets, mus = np.empty(ns, np.int64), np.empty(ns)
        j, n = 0, 0
        for i in range(k):
            if modes[i] == STICK:
                offsets[n], mus[n] = j, mu_s[i]
                n += 1
            j += 3 if modes[i] == STICK else (1 if modes[i] == SLIDE else 0)
        if not cones_hold(lam, offsets, mus):     # `drake_dock.core.squeeze` (Eq. 51)
            z = V[:, m - 1].copy()
            C = Ct.T.copy()
            C_norm = 0.0
            for r in range(nv):
                for c in range(m):
                    C_norm += C[r, c] * C[r, c]
            lam = squeeze_along(lam, sv, z, L.norm(L.matvec(C, z)), math.sqrt(C_norm),
                                offsets, mus)
    for r in range(nv):
        acc, acc2 = 0.0, 0.0
        for c in range(m):
            acc += MinvC[r, c] * lam[c]
            acc2 += Ct[c, r] * lam[c]
        vdot[r] = a0[r] + acc
        gf[r] = acc2
    j = 0
    for i in range(k):
        if modes[i] == STICK:
            lam_n[i], lam_t[i, 0], lam_t[i, 1] = lam[j], lam[j + 1], lam[j + 2]
            j += 3
        elif modes[i] == SLIDE:
            lam_n[i] = lam[j]
            f = -mu[i] * lam[j]
            lam_t[i, 0], lam_t[i, 1] = f * dirs[i, 0], f * dirs[i, 1]
            j += 1
    return OK, cond


@njit(cache=True)
def accelerations(W, bias, vdot, gdd, at):
    """g'' (k,) and the tangential relative accelerations at (k, 2) at vdot."""
    for i in range(W.shape[0]):
        for c in range(3):
            s = 0.0
            for a in range(W.shape[1]):
                s += W[i, a, c] * vdot[a]
            if c == 0:
                gdd[i] = s + bias[i, 0]
            else:
                at[i, c - 1] = s + bias[i, c]



def warm():
    """Compiles or loads the solve: a free body (nv = 6) with one sticking and one sliding
    couple."""
    nv, k = 6, 2
    W = np.zeros((k, nv, 3))
    for i in range(k):
        W[i, :3] = np.eye(3)
        W[i, 3:, 0] = (1.0, 0.0, 0.0)
    solve_modes(Problem(np.eye(nv), np.zeros(nv), W, np.zeros((k, 3)), np.zeros(k),
                        np.zeros(k), np.full(k, 0.3), np.full(k, 0.3)),
                np.array([STICK, SLIDE], dtype=np.int64), np.array([[0.0, 0.0], [1.0, 0.0]]),
                20.0, Solution(np.empty(nv), np.empty(k), np.empty((k, 2)), np.empty(nv)))
