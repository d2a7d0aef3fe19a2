"""The impact without collision (Genot and Brogliato 1999): where the contact set has no
consistent mode (the Painleve paradox: a sliding couple whose friction drives it into the
surface faster than its normal force can push it out), the rigid model's answer is an impulse
at zero approach speed, a tangential impact, after which the couples roll or stick and a mode
exists again.

`impact_without_collision` gives the plastic, sticking one: an impulse P = (P_n, P_t) of
every couple in the set that brings each couple's relative velocity to zero, W^T v+ = 0 with
v+ = v + M^-1 W P (the velocity-level impact law with restitution 0; Moreau's sweeping
process at an instant), admissible when every couple pushes (P_n >= 0) and its tangential
impulse lies inside the static friction cone (|P_t| <= mu_s P_n).

The impulses solving (W^T M^-1 W) P = -W^T v form an affine set, not a point, whenever the
rows are redundant: k >= 2 couples between two rigid bodies have 3k rows of a 6-dof relative
motion (rank 5 for k = 2, 6 for k >= 3). Every impulse of the set gives the same v+ (W P is
fixed): v+ is the M-orthogonal projection of v onto W^T v = 0, so the kinetic energy does not
increase. The minimum-norm impulse is taken when admissible; otherwise an admissible one is
sought in the set (`_admissible_in_set`). None when the set has none (the impulse of the
paradox is not a sticking one; the caller reports the paradox) or when the couples' velocity
cannot be brought to zero (a row set singular beyond its redundancy).
"""
from __future__ import annotations

import dataclasses
import math

import numpy as np
from scipy.optimize import linprog

RCOND = 1e-9        # singular values of M^-1/2 W below this fraction of the largest are zero
CONE_FACETS = 32    # facets of the polygon inscribed in each couple's friction cone
MARGIN_CAP = 1e-3   # largest margin sought inside the polygons, per unit of the impulse scale


@dataclasses.dataclass
class ImpactWithoutCollision:
    v_plus: np.ndarray          # generalized velocity after the impulse
    P_n: np.ndarray             # (k,) normal impulses (N s)
    P_t: np.ndarray             # (k, 2) tangential impulses (N s)
    energy_lost: float          # kinetic energy taken by the impulse (J), >= 0


def _admissible(P, mu_s, tol) -> bool:
    """Every couple pushes and its tangential impulse is inside the cone, to within tol (N s).
    P is (k, 3), rows (P_n, P_ta, P_tb)."""
    return not ((P[:, 0] < -tol).any()
                or (np.hypot(P[:, 1], P[:, 2]) > mu_s * P[:, 0] + tol).any())


def _cone_rows(k, mu_s):
    """G with G P <= 0 (P stacked per couple as (P_n, P_ta, P_tb)) for P_n >= 0 and P_t inside
    the regular CONE_FACETS-gon inscribed in the circle |P_t| = mu_s P_n: a point inside the
    polygon is inside the true cone."""
    a = 2.0 * math.pi * np.arange(CONE_FACETS) / CONE_FACETS
    facet = np.column_stack([np.full(CONE_FACETS, -mu_s * math.cos(math.pi / CONE_FACETS)),
                             np.cos(a), np.sin(a)])
    block = np.vstack([[-1.0, 0.0, 0.0], facet])
    G = np.zeros((k * len(block), 3 * k))
    for j in range(k):
        G[j * len(block):(j + 1) * len(block), 3 * j:3 * j + 3] = block
    return G


def _admissible_in_set(P0, N, mu_s):
    """An impulse P0 + N z inside the inscribed polygons (`_cone_rows`), P0 and N in units of
    the impulse scale, or None when there is none: a linear program (HiGHS) first for the
    largest common margin s <= MARGIN_CAP of every row, then, keeping half that margin, for the
    least |z|_1 (N's columns are orthonormal: an impulse near the minimum-norm one, with no
    squeeze between the couples beyond what admissibility asks). A margin below -1e-9 (no
    point of the set inside the polygons) gives None."""
    G = _cone_rows(len(P0) // 3, mu_s)
    nz = N.shape[1]
    GN, h = G @ N, -(G @ P0)
    ones = np.ones((len(G), 1))
    opts = {"primal_feasibility_tolerance": 1e-10, "dual_feasibility_tolerance": 1e-10}
    # 1. max s subject to G (P0 + N z) + s <= 0, s <= MARGIN_CAP (z free, s free below).
    c = np.zeros(nz + 1)
    c[-1] = -1.0
    r = linprog(c, A_ub=np.hstack([GN, ones]), b_ub=h, bounds=[(None, None)] * nz
                + [(None, MARGIN_CAP)], method="highs", options=opts)
    if r.status != 0 or not r.x[-1] >= -1e-9:
        return None
    s = 0.5 * r.x[-1]
    # 2. min sum(t), -t <= z <= t, subject to G (P0 + N z) <= -s.
    eye = np.eye(nz)
    A = np.vstack([np.hstack([GN, np.zeros((len(G), nz))]),
                   np.hstack([eye, -eye]), np.hstack([-eye, -eye])])
    b = np.concatenate([h - s, np.zeros(2 * nz)])
    r2 = linprog(np.concatenate([np.zeros(nz), np.ones(nz)]), A_ub=A, b_ub=b,
                 bounds=[(None, None)] * nz + [(0.0, None)] * nz, method="highs",
                 options=opts)
    z = r2.x[:nz] if r2.status == 0 else r.x[:nz]
    return P0 + N @ z


def impact_without_collision(M, Wn, Wt, v, mu_s, *, rtol=1e-9):
    """The sticking impulse of the couples whose rows are Wn (nv, k) and Wt (nv, 2k; couple j's
    columns 2j, 2j + 1) at velocity v (module docstring), or None when no impulse of the set
    is admissible to within ``rtol`` of the largest impulse, or when W^T v+ is not zero to
    within 1e-8 of the largest relative velocity |W^T v|. M is the mass matrix."""
    k = Wn.shape[1]
    W = np.empty((Wn.shape[0], 3 * k))
    W[:, 0::3] = Wn
    W[:, 1::3] = Wt[:, 0::2]
    W[:, 2::3] = Wt[:, 1::2]
    if not all(np.all(np.isfinite(a)) for a in (M, W, v)):
        return None
    try:
        L = np.linalg.cholesky(M)                   # M = L L^T
        B = np.linalg.solve(L, W)                   # W^T M^-1 W = B^T B
        U, S, Vt = np.linalg.svd(B)                 # Vt's rows past the rank span null(W)
    except np.linalg.LinAlgError:
        return None
    r = int((S > RCOND * S[0]).sum()) if S[0] > 0.0 else 0
    # Minimum-norm P = -pinv(B) L^T v; in w = L^T v the impulse projects w onto null(B^T).
    P = -(Vt[:r].T @ ((U[:, :r].T @ (L.T @ v)) / S[:r]))
    scale = float(np.abs(P).max()) if P.size else 0.0
    if scale > 0.0 and not _admissible(P.reshape(k, 3), mu_s, rtol * scale):
        if r == 3 * k:
            return None
        P = _admissible_in_set(P / scale, Vt[r:].T, mu_s)
        if P is None:
            return None
        P = scale * P
        if not _admissible(P.reshape(k, 3), mu_s, rtol * float(np.abs(P).max())):
            return None
    v_plus = v + np.linalg.solve(L.T, B @ P)
    if np.abs(W.T @ v_plus).max() > 1e-8 * np.abs(W.T @ v).max():
        return None
    P = P.reshape(k, 3)
    lost = 0.5 * float(v @ M @ v - v_plus @ M @ v_plus)
    return ImpactWithoutCollision(v_plus, P[:, 0].copy(), P[:, 1:].copy(), lost)
