"""Tracking a couple as its bodies move (Sect. 7.2, Eq. 43-47), for any pair of patches.

The couple u* = (u1*, u2*) of two posed patches satisfies the closest-point conditions
    g(u, t) = J(u, t)^T d(u, t) = 0,    d = r1(u1) - r2(u2),   J = [dr1/du1, -dr2/du2],
which at contact (d = 0) are the paper's conditions (37)-(38). Differentiating along the motion
(Eq. 43-45),
    u*' = -H^-1 dg/dt,      H = dg/du = J^T J + blockdiag(d . r1_uu, -d . r2_uu),    (47)
where dg/dt collects the bodies' motion: a material point moves with v + w x (r - p) and a
tangent turns with w x T. H is the Jacobian J of Eq. (40) generalised to a non-zero gap; it is
singular when a curve-curve couple turns parallel (Eq. 39 fails) or a couple is degenerate, and
then `SingularCoupleError` is raised instead of a silent jump.
"""
from __future__ import annotations

import numpy as np

from drake_dock.errors import NumericalError


class SingularCoupleError(NumericalError):
    """The tracking Jacobian H of a couple is singular (Eq. 39 fails or the couple is not
    isolated): the couple must end, be handed over or be re-sought."""


def closest_point_residual(P1, P2, u1, u2):
    """g = J^T d (zero at the couple) and H = dg/du."""
    n1 = P1.patch.dim
    d = P1.position(u1) - P2.position(u2)
    J = np.concatenate([P1.first(u1), -P2.first(u2)], axis=1)
    H = J.T @ J
    H[:n1, :n1] += np.einsum("x,xab->ab", d, P1.second(u1))
    H[n1:, n1:] -= np.einsum("x,xab->ab", d, P2.second(u2))
    return J.T @ d, H, d, J


def couple_rate(P1, P2, u1, u2, twist1, twist2, *, cond_max=1e12, name=None, time=None):
    """Eq. (47): the rate u*' of the couple (u1, u2) of posed patches P1, P2 whose bodies move
    with world twists (w, v), v the velocity of the body frame's origin P.p.

    Raises `SingularCoupleError` when cond(H) exceeds ``cond_max``."""
    g, H, d, J = closest_point_residual(P1, P2, u1, u2)
    (w1, v1), (w2, v2) = twist1, twist2
    r1, r2 = P1.position(u1), P2.position(u2)
    dd = (v1 + np.cross(w1, r1 - P1.p)) - (v2 + np.cross(w2, r2 - P2.p))
    T1, T2 = P1.first(u1), P2.first(u2)
    dJ = np.concatenate([np.cross(w1, T1.T).T, -np.cross(w2, T2.T).T], axis=1)
    dg_dt = dJ.T @ d + J.T @ dd
    c = np.linalg.cond(H)
    if not np.isfinite(c) or c > cond_max:
        raise SingularCoupleError(f"couple Jacobian (Eq. 40) singular, cond = {c:.3e}",
                                  time=time, couples=[name] if name else ())
    return -np.linalg.solve(H, dg_dt)
