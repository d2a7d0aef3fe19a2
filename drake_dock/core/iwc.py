"""The impact without collision (Genot and Brogliato 1999): where the contact set has no
consistent mode (the Painleve paradox: a sliding couple whose friction drives it into the
surface faster than its normal force can push it out), the rigid model's answer is an impulse
at zero approach speed, a tangential impact, after which the couples roll or stick and a mode
exists again.

`impact_without_collision` gives the plastic, sticking one: the impulse P = (P_n, P_t) of
every couple in the set that brings each couple's relative velocity to zero, W^T v+ = 0 with
v+ = v + M^-1 W P (the velocity-level impact law with restitution 0; Moreau's sweeping
process at an instant), admissible when every couple pushes (P_n >= 0) and its tangential
impulse lies inside the static friction cone (|P_t| <= mu_s P_n). Otherwise it returns None:
the impulse of the paradox is not a sticking one, and the caller reports the paradox.
"""
from __future__ import annotations

import dataclasses

import numpy as np


@dataclasses.dataclass
class ImpactWithoutCollision:
    v_plus: np.ndarray          # generalized velocity after the impulse
    P_n: np.ndarray             # (k,) normal impulses (N s)
    P_t: np.ndarray             # (k, 2) tangential impulses (N s)
    energy_lost: float          # kinetic energy taken by the impulse (J), >= 0


def impact_without_collision(M, Wn, Wt, v, mu_s, *, rtol=1e-9):
    """The sticking impulse of the couples whose rows are Wn (nv, k) and Wt (nv, 2k; couple j's
    columns 2j, 2j + 1) at velocity v (module docstring), or None when it is not admissible
    (a couple would pull, or its impulse leaves the cone, beyond ``rtol`` of the largest
    impulse). M is the mass matrix."""
    k = Wn.shape[1]
    W = np.empty((Wn.shape[0], 3 * k))
    W[:, 0::3] = Wn
    W[:, 1::3] = Wt[:, 0::2]
    W[:, 2::3] = Wt[:, 1::2]
    MinvW = np.linalg.solve(M, W)
    try:
        P = np.linalg.solve(W.T @ MinvW, -(W.T @ v))
    except np.linalg.LinAlgError:
        return None
    P = P.reshape(k, 3)
    tol = rtol * (1.0 + float(np.abs(P).max()))
    P_n, P_t = P[:, 0], P[:, 1:]
    if (P_n < -tol).any() or (np.hypot(P_t[:, 0], P_t[:, 1]) > mu_s * P_n + tol).any():
        return None
    v_plus = v + MinvW @ P.ravel()
    lost = 0.5 * float(v @ M @ v - v_plus @ M @ v_plus)
    return ImpactWithoutCollision(v_plus, P_n.copy(), P_t.copy(), lost)
