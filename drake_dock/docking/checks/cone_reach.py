"""Which points moving on straight segments can cross the petals' cone (Eq. 12) at a height
the petals span: on a translation, the only points that the interpenetration check
(`drake_dock.docking.checks.penetration.deepest_penetration`) must watch against the petals.

A point's signed cone distance s along its segment Y(f) = A + f D (0 <= f <= 1) is convex in f:
sin(alpha1) |A_xy + f D_xy| (a norm) plus a linear term. Its greatest value on an interval
is at an end, its least at an end or where s'(f) = 0, in closed form (`cone_extremes`)."""
from __future__ import annotations

import math

import numpy as np

# Below this |s| (m) a point counts as reaching the cone: far above the round-off of s.
REACH_TOL = 1e-7


def cone_distance(g, X):
    """Signed distance s of points X (M, 3) to the cone of Eq. (12), positive away from the
    axis: the same for the three petals."""
    return (np.hypot(X[:, 0], X[:, 1]) - g.Rp) * math.sin(g.alpha1) + X[:, 2] * math.cos(g.alpha1)


def cone_extremes(g, A, D, lo, hi):
    """Least and greatest cone distance s of the points A + f D (M, 3) over lo <= f <= hi (M,).
    With Q = D_xy and c = D_z cos(alpha1): s'(f) = sin(alpha1) Q.(A_xy + f Q) / |A_xy + f Q| + c
    vanishes at f = f0 + t, f0 = -A_xy.Q / |Q|^2 (the point nearest the axis, at distance h),
    t = -sign(c) |c| h / sqrt(|Q|^2 (sin^2(alpha1) |Q|^2 - c^2)); where sin^2(alpha1) |Q|^2
    <= c^2 the norm's slope cannot cancel c and s is monotone."""
    sa, ca = math.sin(g.alpha1), math.cos(g.alpha1)
    s_lo, s_hi = (cone_distance(g, A + f[:, None] * D) for f in (lo, hi))
    least = np.minimum(s_lo, s_hi)
    Q2 = (D[:, :2] ** 2).sum(axis=1)
    c = D[:, 2] * ca
    turn = np.flatnonzero(sa * sa * Q2 > c * c)
    if len(turn):
        A_t, D_t, Q2_t, c_t = A[turn], D[turn], Q2[turn], c[turn]
        f0 = -(A_t[:, :2] * D_t[:, :2]).sum(axis=1) / Q2_t
        h = np.hypot(*(A_t[:, :2] + f0[:, None] * D_t[:, :2]).T)
        t = -np.sign(c_t) * np.abs(c_t) * h / np.sqrt(Q2_t * (sa * sa * Q2_t - c_t * c_t))
        f = np.clip(f0 + t, lo[turn], hi[turn])
        least[turn] = np.minimum(least[turn], cone_distance(g, A_t + f[:, None] * D_t))
    return least, np.maximum(s_lo, s_hi)


def may_cross(g, A, D, margin, tol=REACH_TOL):
    """Whether each point A + f D (M, 3), 0 <= f <= 1, comes within ``tol`` of the cone, or
    crosses it, at a height -margin <= z <= H + margin."""
    z0, dz = A[:, 2], D[:, 2]
    moving = dz != 0.0
    with np.errstate(divide="ignore", invalid="ignore"):
        f_a, f_b = (-margin - z0) / dz, (g.H + margin - z0) / dz
    inside = (z0 >= -margin) & (z0 <= g.H + margin)
    lo = np.where(moving, np.maximum(0.0, np.minimum(f_a, f_b)), np.where(inside, 0.0, 2.0))
    hi = np.where(moving, np.minimum(1.0, np.maximum(f_a, f_b)), 1.0)
    keep = lo <= hi
    least, most = cone_extremes(g, A[keep], D[keep], lo[keep], hi[keep])
    keep[keep] = (least <= tol) & (most >= -tol)
    return keep


def watched_on_translation(g, XR, p, max_travel):
    """Which of the points XR (M, 3) of one APDS, posed in the other's frame at the samples n by
    the translations p[n] (N, 3), can cross a petal's plate between two sub-steps. A crossing
    is interpolated on the chord between two sub-steps at most ``max_travel`` apart, where the
    interpolated foot's height is the chord's; the path changes side of the cone on that
    chord, so the crossing's height lies within max_travel of a height where the path meets
    the cone (a point held exactly on the cone keeps its last place, and the sub-steps it is
    held at lie on the cone too). The band is widened by 2 max_travel."""
    keep = np.zeros(len(XR), dtype=bool)
    for n in range(1, len(p)):
        keep |= may_cross(g, XR + p[n - 1], np.broadcast_to(p[n] - p[n - 1], XR.shape).copy(),
                          2.0 * max_travel + 1e-6)
    return keep
