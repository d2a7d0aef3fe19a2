"""The force split of redundant sticking couples (Eq. 51): two couples that stick between the
same two rigid bodies constrain only five of their six relative velocities (the rotation about
the line through the two contact points is free), so their six force components are fixed up
to one internal squeeze along that line. The minimum-norm forces of the solve may leave a
couple's static cone while a squeeze puts every couple inside it: a consistent stick that the
minimum-norm split would reject as a Painleve inconsistency.

The compiled solve (`drake_dock.core.kernels.solve`) takes the minimum-norm forces lam (m,) of
the solve, and where they leave a cone (`cones_hold`) calls `squeeze_along` with the solve's
matrix A (m, m) through its singular values and last right singular vector, its force
directions C (nv, m) through |C z| and |C|, and the modes' layout (each sticking couple's
offset in lam and its mu_s). Where the minimum-norm forces lie inside every sticking couple's
cone, or the
redundancy is not a single squeeze that does no work (A's null space of dimension 1 with
C z = 0), lam is returned as it is. Otherwise the squeeze s z nearest to lam is added that puts
every sticking couple inside its cone shrunk to ``SHRINK`` mu_s (so that the stick-slip witness
does not start at zero), or, if none does, inside the cone itself; if no squeeze does, lam as it
is (the mode is then inconsistent). The accelerations are those of lam either way (C z = 0).

Plain Python over floats and numpy arrays, marked `register_jitable`: the compiled solve
compiles them, and tests/core/test_squeeze.py calls `cone_interval` and `sorted_values` as
Python too.
"""
from __future__ import annotations

import math

import numpy as np
from numba.extending import register_jitable

SHRINK = 0.95
NULL_RTOL = 1e-10          # singular values below this of the largest span the null space
WORK_RTOL = 1e-9           # |C z| below this of |C| does no work


@register_jitable
def inside(a, b0, b1, mu):
    """Whether the force (normal a, tangential (b0, b1)) lies in the cone of mu."""
    return a >= 0.0 and math.sqrt(b0 * b0 + b1 * b1) <= mu * a


@register_jitable
def cone_interval(a, b, c0, c1, d0, d1, mu):
    """(lo, hi): the s with a + b s >= 0 and |(c0, c1) + s (d0, d1)| <= mu (a + b s), an
    interval (the cone is convex); lo > hi when empty, +-inf when unbounded."""
    p = mu * mu * b * b - (d0 * d0 + d1 * d1)
    q = mu * mu * a * b - (c0 * d0 + c1 * d1)
    r = mu * mu * a * a - (c0 * c0 + c1 * c1)
    cuts = np.full(5, np.nan)
    cuts[0], cuts[1] = -np.inf, np.inf
    if b != 0.0:
        cuts[2] = -a / b
    if p != 0.0:
        disc = q * q - p * r
        if disc >= 0.0:
            root = math.sqrt(disc)
            cuts[3], cuts[4] = (-q - root) / p, (-q + root) / p
    elif q != 0.0:
        cuts[3] = -r / (2.0 * q)
    cuts = sorted_values(cuts[~np.isnan(cuts)])
    lo, hi = np.inf, -np.inf
    for j in range(len(cuts) - 1):
        x0, x1 = cuts[j], cuts[j + 1]
        if x0 == -np.inf and x1 == np.inf:
            t = 0.0
        elif x0 == -np.inf:
            t = x1 - 1.0 - abs(x1)
        elif x1 == np.inf:
            t = x0 + 1.0 + abs(x0)
        else:
            t = 0.5 * (x0 + x1)
        if inside(a + b * t, c0 + d0 * t, c1 + d1 * t, mu):
            lo, hi = min(lo, x0), max(hi, x1)
    return lo, hi


@register_jitable
def sorted_values(x):
    """A copy of x in ascending order, by a stable insertion sort: the order numba's np.sort
    gives a handful of values. Not np.sort itself: the kernels argsort float arrays elsewhere
    (the SVD's singular values), and numba names the machine code of its quicksort per
    process, the sort's and the argsort's alike; a solve compiled in a process that loaded
    the SVD from the cache could then link one of the two in place of the other."""
    out = x.copy()
    for i in range(1, len(out)):
        v = out[i]
        j = i
        while j > 0 and v < out[j - 1]:
            out[j] = out[j - 1]
            j -= 1
        out[j] = v
    return out


@register_jitable
def squeeze_interval(lam, z, offsets, mus, shrink):
    """The s for which lam + s z puts every sticking couple (its offset in lam, its mu_s)
    inside its cone shrunk by ``shrink``: (lo, hi), lo > hi when none."""
    lo, hi = -np.inf, np.inf
    for j in range(len(offsets)):
        o = offsets[j]
        a, b = cone_interval(lam[o], z[o], lam[o + 1], lam[o + 2], z[o + 1], z[o + 2],
                             shrink * mus[j])
        lo, hi = max(lo, a), min(hi, b)
    return lo, hi


@register_jitable
def cones_hold(lam, offsets, mus):
    """Whether lam puts every sticking couple in its cone, or there are fewer than two (no
    squeeze)."""
    ok = True
    for j in range(len(offsets)):
        o = offsets[j]
        ok = ok and inside(lam[o], lam[o + 1], lam[o + 2], mus[j])
    return ok or len(offsets) < 2


@register_jitable
def squeeze_along(lam, S, z, Cz_norm, C_norm, offsets, mus):
    """lam, or lam plus the squeeze nearest to it that puts the sticking couples inside their
    cones (module docstring), from A's singular values S (descending) and the right singular
    vector z of the smallest, with |C z| and |C| (Frobenius): the squeeze along z when it is
    A's only null direction and does no work."""
    if S[-1] > NULL_RTOL * S[0] or (len(S) > 1 and S[-2] <= NULL_RTOL * S[0]):
        return lam
    if Cz_norm > WORK_RTOL * C_norm:
        return lam
    for shrink in (SHRINK, 1.0):
        lo, hi = squeeze_interval(lam, z, offsets, mus, shrink)
        if lo <= hi:
            return lam + min(max(0.0, lo), hi) * z
    return lam
