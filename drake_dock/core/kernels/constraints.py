"""The constraint solve and mode selection of Eq. 48-52 (Coulomb friction, the
Baumgarte-stabilised normal rows; `drake_dock.core.constraints` states the law, the modes and the
selection's rules and holds the records), compiled over plain arrays:

- `solve_given_modes` (the contact forces and accelerations for given modes) and
  `select_contact_modes` (the enumeration of the modes, the start of sliding, the consistency
  tests and the preferences), over `ContactRow`s, returning a `ContactSolution`; the tests check
  them against the modes' equations and inequalities and against closed forms
  (tests/core/test_kernels_constraints.py, test_constraints.py, test_squeeze.py);
- `solve_packed`, the solve on rows already packed as arrays (`pack_rows`), for the derivative
  evaluation.

A couple's row is packed as W (nv, 3), the columns W^3, W^1, W^2 of Eq. (11) (n, ta, tb), and
its velocity-product terms (bn, bt) as one 3-vector. The modes are codes `STICK`, `SLIDE`,
`DETACH`. The kernels return a status instead of raising; the wrappers raise the typed
errors (`raise_status`).
"""
from __future__ import annotations

import math

import numpy as np
from numba import njit

from drake_dock.core import constraints as ref
from drake_dock.core.kernels.copies import copy1
from drake_dock.core.kernels.slide_start import Outputs, slide_start
from drake_dock.core.kernels.solve import (CODE, DETACH, INDETERMINATE, NAME, NONE_CONSISTENT,
                                           NONFINITE, OK, SLIDE, STICK, Problem, Solution,
                                           accelerations, solve_modes, stabilised)
from drake_dock.errors import (NumericalError, PainleveError, PainleveInconsistency,
                               SingularContactError)


@njit(cache=True)
def _consistent(modes, lam_n, lam_t, gdd, vn, gap, mu_s, omega, tol_f, tol_a):
    """Complementarity on the stabilised normal row (lambda_n >= 0 in contact, Eq. 50-51;
    g'' + 2 omega g' + omega^2 g >= 0 detached, Eq. 52) and the static cone (Eq. 51), within
    tol_f (N) and tol_a (m/s^2)."""
    for i in range(modes.shape[0]):
        if modes[i] == DETACH:
            if stabilised(gdd[i], vn[i], gap[i], omega) < -tol_a:
                return False
        else:
            if lam_n[i] < -tol_f:
                return False
            if (modes[i] == STICK
                    and math.hypot(lam_t[i, 0], lam_t[i, 1]) > mu_s[i] * lam_n[i] + tol_f):
                return False
    return True


@njit(cache=True)
def _select(P, vt, avoid, v_slip, omega, rtol, tie_rtol):
    """`select_contact_modes` without its errors, for the `Problem` P and the
    couples' tangential velocities vt (k, 2): returns (status, modes (n, k), dirs
    (n, k, 2), vdot (n, nv), lam_n (n, k), lam_t (n, k, 2), gf (n, nv), best, other), with
    row ``best`` the choice, and for INDETERMINATE row ``other`` the second consistent
    choice."""
    Minv, a0, W, bias, gap, vn, mu, mu_s = P
    k, nv = W.shape[0], W.shape[1]
    nopt = np.empty(k, np.int64)
    moving = np.zeros((k, 2))
    has_dir = np.zeros(k, np.bool_)
    n = 1
    for i in range(k):
        speed = math.hypot(vt[i, 0], vt[i, 1])
        if speed > v_slip:
            nopt[i] = 2
            has_dir[i] = True
            moving[i, 0], moving[i, 1] = vt[i, 0] / speed, vt[i, 1] / speed
        else:
            nopt[i] = 3
        n *= nopt[i]
    # Force and acceleration scales (the free motion: every couple detached).
    gdd, at = np.empty(k), np.empty((k, 2))
    accelerations(W, bias, a0, gdd, at)
    free_at = at.copy()
    a_scale = 1.0 + np.abs(gdd).max() + np.abs(free_at).max()
    M_ = np.empty((n, k), np.int64)
    D_ = np.zeros((n, k, 2))
    V_ = np.empty((n, nv))
    LN = np.empty((n, k))
    LT = np.empty((n, k, 2))
    GF = np.empty((n, nv))
    key = np.empty(n, np.int64)
    level = np.empty(n, np.int64)       # 0 consistent at rtol, 1 within tie_rtol, 2 neither
    modes = np.empty(k, np.int64)
    gmodes = np.empty(k, np.int64)
    for c in range(n):
        # The c-th choice in itertools.product order (the last couple varies fastest).
        r = c
        for i in range(k - 1, -1, -1):
            o = r % nopt[i]
            r //= nopt[i]
            modes[i] = (SLIDE, DETACH)[o] if has_dir[i] else o
        copy1(M_[c], modes)
        level[c] = 2
        dirs = D_[c]
        nstart = 0
        for i in range(k):
            if modes[i] == SLIDE:
                if has_dir[i]:
                    copy1(dirs[i], moving[i])
                else:
                    nstart += 1
        starting = np.empty(nstart, np.int64)
        j = 0
        for i in range(k):
            if modes[i] == SLIDE and not has_dir[i]:
                starting[j] = i
                j += 1
        vdot, lam_n, lam_t, gf = V_[c], LN[c], LT[c], GF[c]
        if nstart:
            # Start from the direction opposite to the sticking force (or the free
            # tangential acceleration).
            for i in range(k):
                gmodes[i] = STICK if modes[i] == SLIDE and not has_dir[i] else modes[i]
            st, _c = solve_modes(P, gmodes, dirs, omega, Solution(vdot, lam_n, lam_t, gf))
            if st != OK:
                continue
            for i in starting:
                g0, g1 = -lam_t[i, 0], -lam_t[i, 1]
                if math.hypot(g0, g1) == 0.0:
                    g0, g1 = free_at[i, 0], free_at[i, 1]
                ng = math.hypot(g0, g1)
                if ng > 0:
                    dirs[i, 0], dirs[i, 1] = g0 / ng, g1 / ng
                else:
                    dirs[i, 0], dirs[i, 1] = 1.0, 0.0
            st, ok = slide_start(P, modes, dirs, starting, omega,
                                 Outputs(Solution(vdot, lam_n, lam_t, gf), gdd, at))
            if st != OK or not ok:
                continue
        else:
            st, _c = solve_modes(P, modes, dirs, omega, Solution(vdot, lam_n, lam_t, gf))
            if st != OK:
                continue
            accelerations(W, bias, vdot, gdd, at)
        f_scale = 1.0 + np.abs(lam_n).max()
        if _consistent(modes, lam_n, lam_t, gdd, vn, gap, mu_s, omega, rtol * f_scale,
                       rtol * a_scale):
            level[c] = 0
        elif _consistent(modes, lam_n, lam_t, gdd, vn, gap, mu_s, omega,
                         tie_rtol * f_scale, tie_rtol * a_scale):
            level[c] = 1
        # Preference: fewer modes being left, more sticking couples, more in contact.
        left, sticks, detached = 0, 0, 0
        for i in range(k):
            left += avoid[i, modes[i]]
            sticks += modes[i] == STICK
            detached += modes[i] == DETACH
        key[c] = (left * (k + 1) + (k - sticks)) * (k + 1) + detached
    lvl = 0 if (level == 0).any() else 1
    idx = np.flatnonzero(level == lvl)
    if idx.shape[0] == 0:
        return NONE_CONSISTENT, M_, D_, V_, LN, LT, GF, -1, -1
    idx = idx[np.argsort(key[idx], kind="mergesort")]
    best = idx[0]
    v_scale = 1.0 + np.abs(V_[best]).max()
    for o in idx[1:]:
        if np.abs(V_[o] - V_[best]).max() <= 1e-6 * v_scale:
            continue
        for i in range(k):
            if (M_[best, i] == DETACH) != (M_[o, i] == DETACH):
                return INDETERMINATE, M_, D_, V_, LN, LT, GF, best, o
    return OK, M_, D_, V_, LN, LT, GF, best, -1


def pack_rows(rows):
    """The `ContactRow` list as arrays: W (k, nv, 3), bias (k, 3), gap, vn (k,), vt (k, 2),
    mu, mu_s (k,)."""
    k = len(rows)
    nv = len(rows[0].Wn) if k else 0
    W, bias = np.empty((k, nv, 3)), np.empty((k, 3))
    for i, r in enumerate(rows):
        W[i, :, 0], W[i, :, 1:] = r.Wn, r.Wt
        bias[i, 0], bias[i, 1:] = r.bn, r.bt
    return (W, bias, np.array([r.gap for r in rows], dtype=float).reshape(k),
            np.array([r.vn for r in rows], dtype=float).reshape(k),
            np.array([r.vt for r in rows], dtype=float).reshape(k, 2),
            np.array([r.mu for r in rows], dtype=float).reshape(k),
            np.array([r.mu_s for r in rows], dtype=float).reshape(k))


def _dirs_array(modes, dirs):
    out = np.zeros((len(modes), 2))
    for i, (m, s) in enumerate(zip(modes, dirs)):
        if m == ref.SLIDE:
            out[i] = s
    return out


def solve_packed(P, modes, dirs, omega, *, time=None, names=()):
    """(vdot, lam_n (k,), lam_t (k, 2), generalized force) for the `Problem` P of the packed
    rows and the mode codes ``modes`` (int array), ``dirs`` (k, 2) the sliding directions;
    `SingularContactError` (naming ``names``)."""
    k, nv = P.W.shape[0], len(P.a0)
    vdot, lam_n, lam_t, gf = np.empty(nv), np.empty(k), np.empty((k, 2)), np.empty(nv)
    st, cond = solve_modes(P, modes, dirs, omega, Solution(vdot, lam_n, lam_t, gf))
    if st != OK:
        raise_status(st, cond, modes, names, time)
    return vdot, lam_n, lam_t, gf


def raise_status(status, cond, modes, names, time):
    """The typed error of a solve's status other than OK (NONFINITE or SINGULAR) for the mode
    codes ``modes`` of the couples ``names``."""
    if status == NONFINITE:
        raise NumericalError(f"contact constraint equations not finite for modes "
                             f"{tuple(NAME[m] for m in modes)}", time=time,
                             couples=[c for c, m in zip(names, modes) if m != DETACH])
    raise SingularContactError(
        f"contact constraint equations singular and inconsistent (cond = {cond:.3e}) for "
        f"modes {tuple(NAME[m] for m in modes)}", time=time,
        couples=[c for c, m in zip(names, modes) if m != DETACH])


def _problem(Minv, a0, rows):
    """(the `Problem` of the rows under M^-1 and a0, the rows' tangential velocities vt)."""
    W, bias, gap, vn, vt, mu, mu_s = pack_rows(rows)
    return Problem(np.ascontiguousarray(Minv, dtype=float), np.asarray(a0, dtype=float), W,
                   bias, gap, vn, mu, mu_s), vt


def solve_given_modes(Minv, a0, rows, modes, dirs, *, omega=0.0, time=None):
    """The contact forces and accelerations for the given modes (``dirs[i]`` the sliding
    direction of a sliding couple, None for the others) of the `ContactRow`s ``rows``, the
    inverse mass matrix ``Minv`` and the free acceleration ``a0``: a `ContactSolution`. Where
    the constraint matrix is singular (redundant rows) the minimum-norm forces, squeezed into
    the cones of two sticking couples where that helps (`drake_dock.core.squeeze`), if the
    equations are consistent within the Baumgarte terms; else it raises
    `SingularContactError` (with ``time`` and the couples). `NumericalError` if the equations
    are not finite."""
    codes = np.array([CODE[m] for m in modes], dtype=np.int64)
    vdot, lam_n, lam_t, gf = solve_packed(_problem(Minv, a0, rows)[0], codes,
                                          _dirs_array(modes, dirs), omega, time=time,
                                          names=[r.name for r in rows])
    return ref.ContactSolution(tuple(modes), list(dirs), vdot, lam_n, lam_t, gf, list(rows))


def select_contact_modes(Minv, a0, rows, *, v_slip=1e-6, omega=0.0, time=None, rtol=1e-9,
                         avoid=None):
    """One consistent choice of modes for the contact set (`drake_dock.core.constraints`
    states the rules), a `ContactSolution`. A couple whose sliding speed exceeds ``v_slip``
    slides in its direction of motion (or detaches); one at rest may stick, start to slide or
    detach. ``avoid[i]`` lists modes that couple i is leaving (its witness has just crossed
    zero): at a tie, where a mode it leaves is still consistent within round-off, another
    consistent mode is taken (a choice whose solve is singular or not finite is not
    consistent). Raises `PainleveInconsistency` (no consistent mode), `PainleveError`
    (several that differ in their normal modes) or, for more than `MAX_ENUMERATED` couples,
    `NumericalError`, with ``time`` and the couples."""
    k = len(rows)
    names = [r.name for r in rows]
    if k == 0:
        return solve_given_modes(Minv, a0, rows, (), [], omega=omega, time=time)
    if k > ref.MAX_ENUMERATED:
        raise NumericalError(f"{k} couples in contact at once; mode enumeration is limited to "
                             f"{ref.MAX_ENUMERATED}", time=time, couples=names)
    P, vt = _problem(Minv, a0, rows)
    av = np.zeros((k, 3), dtype=np.int64)
    for i, a in enumerate(avoid or [()] * k):
        for m in a:
            av[i, CODE[m]] = 1
    st, M_, D_, V_, LN, LT, GF, best, other = _select(
        P, vt, av, float(v_slip), float(omega), float(rtol), ref.TIE_RTOL)
    if st == NONE_CONSISTENT:
        raise PainleveInconsistency(
            "no consistent contact mode (Painleve inconsistency: the rigid model with this "
            "friction has no solution)", time=time, couples=names)
    modes = tuple(NAME[m] for m in M_[best])
    if st == INDETERMINATE:
        raise PainleveError(
            f"several consistent contact modes with different accelerations "
            f"({modes} and {tuple(NAME[m] for m in M_[other])}): Painleve indeterminacy",
            time=time, couples=names)
    dirs = [D_[best, i].copy() if m == ref.SLIDE else None for i, m in enumerate(modes)]
    return ref.ContactSolution(modes, dirs, V_[best].copy(), LN[best].copy(), LT[best].copy(),
                               GF[best].copy(), list(rows))


def warm():
    """Compiles (or loads) the kernels by one selection and one solve of a small scene."""
    nv = 6
    W = np.zeros((2, nv, 3))
    for i in range(2):
        for c in range(3):
            W[i, c, c] = 1.0
            W[i, 3 + c, c] = 0.5 * (i + 1)
    bias = np.zeros((2, 3))
    z, vt = np.zeros(2), np.array([[0.0, 0.0], [0.1, 0.0]])
    one = np.ones(2)
    P = Problem(np.eye(nv), -np.ones(nv), W, bias, z, z, 0.1 * one, 0.1 * one)
    _select(P, vt, np.zeros((2, 3), np.int64), 1e-6, 20.0, 1e-9, ref.TIE_RTOL)
    solve_packed(P, np.array([STICK, SLIDE], np.int64), np.array([[0.0, 0.0], [1.0, 0.0]]),
                 20.0)
