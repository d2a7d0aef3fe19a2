"""The direction of a start of sliding, compiled: friction opposes the tangential relative
acceleration it produces, so a couple starting to slide from rest slides along s with a_t along
s. The fixed point s = a_t/|a_t|, then, where it leaves a starting couple's a_t off its s, the
scan of one couple's direction or the grid and Newton's method for two (`slide_start` states
what each accepts)."""
from __future__ import annotations

import math
from typing import NamedTuple

import numpy as np
from numba import njit

from drake_dock.core import constraints as ref
from drake_dock.core.kernels.solve import (OK, SLIDE_START_ITER, Solution, accelerations,
                                           solve_modes)

#: a_t lies along s where its component across s is below this fraction of |a_t| (the fixed
#: point's test, and the grid's at a root where a_t is not below 1e-6 of the acceleration scale)
ALONG_RTOL = 1e-9


class Outputs(NamedTuple):
    """What a start of sliding writes: a mode solve's `solve.Solution` (v', lambda_n,
    lambda_t, the generalized contact force) and the couples' normal and tangential
    accelerations (`solve.accelerations`)."""

    solution: Solution
    gdd: np.ndarray
    at: np.ndarray


@njit(cache=True, inline="always")
def _solve(P, modes, dirs, omega, out):
    """`solve_modes` of the `solve.Problem` P under ``modes`` and ``dirs`` into the `Outputs` out,
    with the couples' accelerations; returns the status. Inlined where it is called (as a
    function of its own it would add about a tenth to the unit's compile)."""
    st, _c = solve_modes(P, modes, dirs, omega, out.solution)
    if st != OK:
        return st
    accelerations(P.W, P.bias, out.solution.vdot, out.gdd, out.at)
    return OK


@njit(cache=True, inline="always")
def slide_start(P, modes, dirs, starting, omega, out):
    """The start of sliding for the `solve.Problem` P: the sliding directions (in dirs) of the
    couples ``starting`` to slide, the solution in the `Outputs` out; returns (status,
    directions found). The fixed point s = a_t/|a_t| runs until it converges or for
    `SLIDE_START_ITER` iterations (none found where a starting couple's a_t is exactly 0);
    its directions are found when every starting couple's a_t then lies along its s (a
    positive component along it, and across it below `ALONG_RTOL` of |a_t|). Otherwise one
    starting couple's direction is scanned
    (`_slide_start_scan`: found at a bisected root with a_t.s > 0), two couples' by the grid
    and Newton's method (`_slide_start_grid`: found at a root with a_t along s, or a_t below
    1e-6 of the acceleration scale), and three or more are not found."""
    at = out.at
    for _ in range(SLIDE_START_ITER):
        st = _solve(P, modes, dirs, omega, out)
        if st != OK:
            return st, False
        change = 0.0
        for i in starting:
            na = math.hypot(at[i, 0], at[i, 1])
            if na == 0.0:
                return OK, False
            n0, n1 = at[i, 0] / na, at[i, 1] / na
            change = max(change, max(abs(n0 - dirs[i, 0]), abs(n1 - dirs[i, 1])))
            dirs[i, 0], dirs[i, 1] = n0, n1
        if change < 1e-13:
            break
    st = _solve(P, modes, dirs, omega, out)
    if st != OK:
        return st, False
    for i in starting:
        # Found where a_t lies along s (Eq. 50: the friction of a start of sliding opposes
        # the slip it starts): a positive component along s, across it below ALONG_RTOL |a_t|.
        a0_, a1 = at[i, 0], at[i, 1]
        d0, d1 = dirs[i, 0], dirs[i, 1]
        if not (a0_ * d0 + a1 * d1 > 0
                and abs(d0 * a1 - d1 * a0_) <= ALONG_RTOL * math.hypot(a0_, a1)):
            if len(starting) == 1:
                return _slide_start_scan(P, modes, dirs, i, omega, out)
            if len(starting) == 2:
                return _slide_start_grid(P, modes, dirs, starting, omega, out)
            return OK, False
    return OK, True


@njit(cache=True)
def _slip_residual(P, modes, dirs, i, th, omega, out):
    """`_slide_start_scan`'s residual: couple i sliding along theta; returns
    (status, the angle from its direction to its tangential acceleration)."""
    dirs[i, 0], dirs[i, 1] = math.cos(th), math.sin(th)
    st = _solve(P, modes, dirs, omega, out)
    if st != OK:
        return st, 0.0
    return OK, _slip_angle(dirs, out.at, i)


@njit(cache=True)
def _slip_angle(dirs, at, i):
    """The slip angle of couple i (`drake_dock.core.constraints.slip_angle`): the angle from
    its direction to its tangential acceleration."""
    s0, s1, a0_, a1 = dirs[i, 0], dirs[i, 1], at[i, 0], at[i, 1]
    return math.atan2(s0 * a1 - s1 * a0_, s0 * a0_ + s1 * a1)


@njit(cache=True)
def _slip_residuals(P, modes, dirs, starting, th, omega, out, r, angle):
    """`_slide_start_grid`'s residual into r (2,): the starting couples sliding
    along th (2,); the angles between their directions and accelerations if ``angle``, else
    s x a_t. Returns the status."""
    for c in range(2):
        dirs[starting[c], 0], dirs[starting[c], 1] = math.cos(th[c]), math.sin(th[c])
    st = _solve(P, modes, dirs, omega, out)
    if st != OK:
        return st
    at = out.at
    for c in range(2):
        i = starting[c]
        r[c] = (_slip_angle(dirs, at, i) if angle
                else dirs[i, 0] * at[i, 1] - dirs[i, 1] * at[i, 0])
    return OK


@njit(cache=True, inline="always")
def _slide_start_grid(P, modes, dirs, starting, omega, out):
    """The directions of two couples starting to slide where the fixed point leaves a couple's
    a_t off its s: where each couple's tangential acceleration lies along its direction. The
    point of a `SLIDE_START_GRID`^2 grid of the two angles around the fixed point's last
    directions with the least angles between directions and accelerations starts Newton's method
    on s x a_t (smooth where a_t vanishes, unlike the angle; forward-difference Jacobian, steps
    halved while it does not fall). Found (status, True) at a root with a_t along s, or with a_t
    below 1e-6 of the acceleration scale (both couples at the stick-slip transition: forces on
    the cones' edges), else (status, False)."""
    n = ref.SLIDE_START_GRID
    th0 = np.empty(2)
    for c in range(2):
        th0[c] = math.atan2(dirs[starting[c], 1], dirs[starting[c], 0])
    r, rn, t = np.empty(2), np.empty(2), np.empty(2)
    best, th = np.inf, th0.copy()
    for g0 in range(n):
        for g1 in range(n):
            t[0] = th0[0] + 2.0 * math.pi * (g0 / n - 0.5)
            t[1] = th0[1] + 2.0 * math.pi * (g1 / n - 0.5)
            st = _slip_residuals(P, modes, dirs, starting, t, omega, out, r, True)
            if st != OK:
                return st, False
            if abs(r[0]) + abs(r[1]) < best:
                best, th[0], th[1] = abs(r[0]) + abs(r[1]), t[0], t[1]
    st = _slip_residuals(P, modes, dirs, starting, th, omega, out, r, False)
    if st != OK:
        return st, False
    J = np.empty((2, 2))
    for _ in range(40):
        for c in range(2):
            t[0], t[1] = th[0], th[1]
            t[c] += 1e-7
            st = _slip_residuals(P, modes, dirs, starting, t, omega, out, rn, False)
            if st != OK:
                return st, False
            J[0, c], J[1, c] = (rn[0] - r[0]) / 1e-7, (rn[1] - r[1]) / 1e-7
        det = J[0, 0] * J[1, 1] - J[0, 1] * J[1, 0]
        if not (math.isfinite(det) and det != 0.0):
            break
        s0 = (J[0, 1] * r[1] - J[1, 1] * r[0]) / det
        s1 = (J[1, 0] * r[0] - J[0, 0] * r[1]) / det
        moved = False
        for _h in range(30):
            t[0], t[1] = th[0] + s0, th[1] + s1
            st = _slip_residuals(P, modes, dirs, starting, t, omega, out, rn, False)
            if st != OK:
                return st, False
            if abs(rn[0]) + abs(rn[1]) < abs(r[0]) + abs(r[1]):
                th[0], th[1], r[0], r[1], moved = t[0], t[1], rn[0], rn[1], True
                break
            s0, s1 = 0.5 * s0, 0.5 * s1
        if not moved:
            break
    st = _slip_residuals(P, modes, dirs, starting, th, omega, out, r, False)
    if st != OK:
        return st, False
    small = 1e-6 * (1.0 + np.abs(out.solution.vdot).max())
    at = out.at
    ok = True
    for c in range(2):
        i = starting[c]
        na = math.hypot(at[i, 0], at[i, 1])
        ok = ok and (na <= small or (abs(r[c]) <= ALONG_RTOL * na
                                     and at[i, 0] * dirs[i, 0] + at[i, 1] * dirs[i, 1] > 0))
    return OK, ok


@njit(cache=True)
def _nearest_bracket(ths, rs, th0, within_quarter):
    """The slide-start scan's bracket of one kind (`_slide_start_scan` bisects the first kind's,
    then the second's): the nearest th0 where the angle
    changes sign with both ends within 90 deg (``within_quarter``) or by less than 180 deg;
    -1 for none."""
    best, best_k = np.inf, -1
    for k in range(rs.shape[0] - 1):
        if not rs[k] * rs[k + 1] <= 0:
            continue
        if within_quarter:
            near = max(abs(rs[k]), abs(rs[k + 1])) < 0.5 * math.pi
        else:
            near = abs(rs[k] - rs[k + 1]) < math.pi
        if near:
            dist = abs(0.5 * (ths[k] + ths[k + 1]) - th0)
            if dist < best:
                best, best_k = dist, k
    return best_k


@njit(cache=True, inline="always")
def _slide_start_scan(P, modes, dirs, i, omega, out):
    """The direction of couple i starting to slide where the fixed point leaves its a_t off s: a
    direction s(theta) along which its tangential acceleration lies, bracketed on
    `SLIDE_START_SCAN` angles around the fixed point's last direction theta0 and bisected (the
    bracket nearest theta0 whose ends lie within 90 deg of s; failing that, the nearest where
    the angle crosses zero rather than +-180 deg, `_nearest_bracket`: next to the stick-slip
    transition a_t is small and turns fast with theta). Found (status, True), or (status, False)
    if there is none."""
    at = out.at
    th0 = math.atan2(dirs[i, 1], dirs[i, 0])
    n = ref.SLIDE_START_SCAN
    ths, rs = np.empty(n + 1), np.empty(n + 1)
    for k in range(n + 1):
        ths[k] = th0 + 2.0 * math.pi * (k / n - 0.5)
        st, rs[k] = _slip_residual(P, modes, dirs, i, ths[k], omega, out)
        if st != OK:
            return st, False
    first = _nearest_bracket(ths, rs, th0, True)
    second = _nearest_bracket(ths, rs, th0, False)
    tried = False
    for best_k in (first, second):
        if best_k < 0 or (best_k == first and tried):
            continue
        tried = True
        lo, hi, flo = ths[best_k], ths[best_k + 1], rs[best_k]
        for _ in range(60):
            mid = 0.5 * (lo + hi)
            st, fm = _slip_residual(P, modes, dirs, i, mid, omega, out)
            if st != OK:
                return st, False
            if fm * flo > 0:
                lo, flo = mid, fm
            else:
                hi = mid
        st, _r = _slip_residual(P, modes, dirs, i, 0.5 * (lo + hi), omega, out)
        if st != OK:
            return st, False
        if at[i, 0] * dirs[i, 0] + at[i, 1] * dirs[i, 1] > 0:
            return OK, True
    if not tried:
        st, _r = _slip_residual(P, modes, dirs, i, th0, omega, out)
        return st, False
    return OK, False

