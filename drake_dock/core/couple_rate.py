"""Tracking a couple as its bodies move (Sect. 7.2, Eq. 43-47), for any pair of posed patches.

The couple u* = (u1*, u2*) satisfies the closest-point conditions F(u, t) = 0 in the paper's
contact form (`drake_dock.core.couple`). Differentiating along the motion (Eq. 43-45),

    u*' = -J^-1 dF/dt,     J = dF/du (Eq. 40),                                   (47)

where dF/dt collects the bodies' motion: a material point moves with v + w x (r - p) and a
tangent turns with w x T. J is singular when a curve-curve couple turns parallel (Eq. 39 fails)
or the couple is not isolated (a ring coaxial with a cone); then `SingularCoupleError` is raised
instead of a silent jump.
"""
from __future__ import annotations

import numpy as np

from drake_dock.core.couple import evaluate_couple
from drake_dock.core.relations import kind_of
from drake_dock.errors import SingularCoupleError


def couple_rate(P1, P2, u1, u2, twist1, twist2, *, kind=None, conditioning_min=1e-10,
                name=None, time=None):
    """Eq. (47): the rate u*' of the couple (u1, u2) of posed patches P1, P2 whose bodies move
    with world twists (w, v), v the velocity of the body frame's origin P.p.

    Raises `SingularCoupleError` when J's conditioning (|det J| / product of its row norms)
    falls below ``conditioning_min``."""
    kind = kind or kind_of(P1.patch.dim, P2.patch.dim)
    u = np.concatenate([np.atleast_1d(u1), np.atleast_1d(u2)]).astype(float)
    ev = evaluate_couple(kind, P1.patch, (P1.R, P1.p), twist1, P2.patch, (P2.R, P2.p), twist2,
                         u, 1.0, project=False)
    if not ev.conditioning > conditioning_min:
        raise SingularCoupleError(
            f"couple Jacobian (Eq. 40) singular, conditioning = {ev.conditioning:.3e}",
            time=time, couples=[name] if name else ())
    return ev.udot
