"""Kinematics of one couple of two moving patches (Sect. 5 and 7 of the paper), generic over
curve-curve ("CC") and curve-surface ("CS") pairs; plain numpy.

Patch 1 is a curve on Body 1; patch 2 a curve (CC) or a surface (CS) on Body 2. Each body frame
F_i has the world pose (R_i, p_i) and twist (w_i, v_i), v_i the velocity of its origin. A point
of patch i is P_i = p_i + R_i r_i(u_i), its tangents T_i = R_i dr_i/du_i, its second derivatives
K_i = R_i d2r_i/du_i2, and d = P_1 - P_2.

Closest-point conditions F(u) = 0, the paper's contact form (Eq. 37-38), which stays regular
when the gap is zero (the gradient of |d|^2 does not: at a tangent curve-surface touch it is
degenerate):

    CC:  F = [t1 . d,  t2 . d]
    CS:  F = [s_u . d,  s_v . d,  t1 . N],   N = s_u x s_v

Where the gap is not zero they are the conditions of minimal distance (d parallel to the normal,
perpendicular to the curve tangents). Their Jacobian Fu = dF/du is the paper's J of Eq. (40);
Eq. (47) follows from dF/dt = 0 along the motion: u' = -Fu^-1 (dF/dt at fixed u).

Contact frame (Definition 2): n = sigma N/|N| (CS) or sigma (t1 x t2)/|t1 x t2| (CC), sigma = +-1
fixed when the pair becomes potential so that n points from Body 2 to Body 1 (model notes);
tangents ta = s_u/|s_u| (CS) or t2/|t2| (CC), tb = n x ta. Signed gap g = n . d.

Relative velocity (Eq. 23-25) of the material points at the couple, v_rel = v_1(P_1) - v_2(P_2);
g' = n . v_rel exactly at the couple (the points' own motion along the tangents is
perpendicular to n). Differentiating once more,

    g''   = n . (a_1(P_1) - a_2(P_2)) + n . c + n' . v_rel
    (t . v_rel)' = t . (a_1 - a_2) + t . c + t' . v_rel,   c = w1 x (T1 u1') - w2 x (T2 u2'),

where a_i(P_i) is the acceleration of the material point (J_i v' + J_i' v in the multibody
coordinates). `CoupleEval.bias_n` and `bias_t` hold the terms c and n', t' that do not depend
on the body accelerations; the caller adds n . (J1' v - J2' v) at the points (Eq. 52).
"""
from __future__ import annotations

import dataclasses
import math

import numpy as np


def cross(a, b):
    """3-vector cross product (np.cross costs ~10 us per call on small vectors)."""
    return np.array([a[1] * b[2] - a[2] * b[1], a[2] * b[0] - a[0] * b[2],
                     a[0] * b[1] - a[1] * b[0]])


def _unit(a):
    na = math.sqrt(a @ a)
    if na == 0.0:     # degenerate (parallel curves): reported by `conditioning`, no NaN
        return a, 1.0
    return a / na, na


def _perp_rate(unit, rate, norm):
    """d/dt (a/|a|) = (I - u u^T) a' / |a|."""
    return (rate - unit * (unit @ rate)) / norm


@dataclasses.dataclass
class CoupleEval:
    """One couple evaluated at a state (all vectors in world coordinates)."""

    u: np.ndarray          # projected couple (u1, u2) (Newton-corrected)
    drift: np.ndarray      # u - u_state (the correction applied)
    residual: float        # |F(u_state)|, the drift of the closest-point conditions
    udot: np.ndarray       # Eq. (47) at u
    conditioning: float    # |det Fu| / prod(row norms) in [0, 1]; 0 = singular (Eq. 39 fails)
    p1: np.ndarray
    p2: np.ndarray
    n: np.ndarray
    ta: np.ndarray
    tb: np.ndarray
    gap: float
    v_rel: np.ndarray      # relative velocity of the material points
    vn: float
    vt: np.ndarray         # (2,) components along ta, tb
    bias_n: float          # n . c + n' . v_rel
    bias_t: np.ndarray     # (2,) t . c + t' . v_rel

    @property
    def frame(self):
        """3x3 rotation whose columns are (ta, tb, n) (Definition 2)."""
        return np.column_stack([self.ta, self.tb, self.n])


def _geometry(patch, R, u):
    r = patch.position(u)
    T = R @ patch.first(u)
    K = (R @ patch.second(u).reshape(3, -1)).reshape(3, patch.dim, patch.dim)
    return R @ r, T, K


def _residual(kind, d, T1, K1, T2, K2):
    t1, k1 = T1[:, 0], K1[:, 0, 0]
    if kind == "CC":
        t2, k2 = T2[:, 0], K2[:, 0, 0]
        F = np.array([t1 @ d, t2 @ d])
        Fu = np.array([[k1 @ d + t1 @ t1, -(t1 @ t2)],
                       [t2 @ t1, k2 @ d - t2 @ t2]])
        return F, Fu
    su, sv = T2[:, 0], T2[:, 1]
    suu, suv, svv = K2[:, 0, 0], K2[:, 0, 1], K2[:, 1, 1]
    N = cross(su, sv)
    F = np.array([su @ d, sv @ d, t1 @ N])
    Fu = np.array([
        [su @ t1, suu @ d - su @ su, suv @ d - su @ sv],
        [sv @ t1, suv @ d - sv @ su, svv @ d - sv @ sv],
        [k1 @ N, t1 @ (cross(suu, sv) + cross(su, suv)), t1 @ (cross(suv, sv) + cross(su, svv))]])
    return F, Fu


def _conditioning(Fu, T1=None, T2=None):
    """|det| / product of row norms of Fu with its columns scaled by the parameters' tangent
    lengths (invariant to how the patches are parametrised): sin^2 / (1 + cos^2) of the angle
    between the curves of a C-C couple at contact; 0 when Eq. (39) fails."""
    if T1 is not None:
        scale = np.sqrt(np.concatenate([np.einsum("xi,xi->i", T1, T1),
                                        np.einsum("xi,xi->i", T2, T2)]))
        if np.all(scale > 0):
            Fu = Fu / scale
    rows = np.sqrt(np.einsum("ij,ij->i", Fu, Fu))
    den = float(np.prod(rows))
    return abs(float(np.linalg.det(Fu))) / den if den > 0 else 0.0


def closest_point_conditions(kind, patch1, X1, patch2, X2, u, *, conditioning=False):
    """F(u) and Fu of the contact form for body poses X_i = (R_i, p_i) (and the conditioning
    of Fu if asked)."""
    n1 = patch1.dim
    r1, T1, K1 = _geometry(patch1, X1[0], u[:n1])
    r2, T2, K2 = _geometry(patch2, X2[0], u[n1:])
    d = (r1 + X1[1]) - (r2 + X2[1])
    F, Fu = _residual(kind, d, T1, K1, T2, K2)
    if conditioning:
        return F, Fu, _conditioning(Fu, T1, T2)
    return F, Fu


def evaluate_couple(kind, patch1, X1, V1, patch2, X2, V2, u_state, sigma, *,
                    project=True) -> CoupleEval:
    """Evaluates the couple whose state is ``u_state`` for body poses X_i = (R_i, p_i) and
    twists V_i = (w_i, v_i). With ``project`` one Newton step on F(u) = 0 corrects the drift of
    the integrated couple before anything else is computed (its size is returned)."""
    n1 = patch1.dim
    R1, p1o = X1
    R2, p2o = X2
    w1, v1 = V1
    w2, v2 = V2
    u = np.asarray(u_state, dtype=float)
    r1, T1, K1 = _geometry(patch1, R1, u[:n1])
    r2, T2, K2 = _geometry(patch2, R2, u[n1:])
    d = (r1 + p1o) - (r2 + p2o)
    F, Fu = _residual(kind, d, T1, K1, T2, K2)
    residual = float(np.sqrt(F @ F))
    cond = _conditioning(Fu, T1, T2)
    du = np.zeros_like(u)
    if project and residual > 0.0 and cond > 1e-14:
        du = -np.linalg.solve(Fu, F)
        u = u + du
        if np.abs(du).max() > 1e-9 * (1.0 + np.abs(u).max()):
            r1, T1, K1 = _geometry(patch1, R1, u[:n1])
            r2, T2, K2 = _geometry(patch2, R2, u[n1:])
            d = (r1 + p1o) - (r2 + p2o)
            F, Fu = _residual(kind, d, T1, K1, T2, K2)
            cond = _conditioning(Fu, T1, T2)
        else:
            # A round-off-sized correction: the points move along their tangents (exact to
            # O(du^2) < 1e-18); tangents and curvatures are kept.
            r1 = r1 + T1 @ du[:n1]
            r2 = r2 + T2 @ du[n1:]
            d = (r1 + p1o) - (r2 + p2o)
    P1, P2 = r1 + p1o, r2 + p2o
    vm1 = v1 + cross(w1, r1)
    vm2 = v2 + cross(w2, r2)
    v_rel = vm1 - vm2
    t1, k1 = T1[:, 0], K1[:, 0, 0]
    w1t1 = cross(w1, t1)
    if kind == "CC":
        t2, k2 = T2[:, 0], K2[:, 0, 0]
        w2t2 = cross(w2, t2)
        Ft = np.array([w1t1 @ d + t1 @ v_rel, w2t2 @ d + t2 @ v_rel])
    else:
        su, sv = T2[:, 0], T2[:, 1]
        N = cross(su, sv)
        Ft = np.array([cross(w2, su) @ d + su @ v_rel, cross(w2, sv) @ d + sv @ v_rel,
                       w1t1 @ N + t1 @ cross(w2, N)])
    # Eq. (47): u' = -J^-1 dF/dt (J = Fu, Eq. 40). A singular J is reported by `conditioning`
    # and handled by the caller's rule; here it gives zeros, never a NaN.
    udot = np.linalg.solve(Fu, -Ft) if cond > 1e-14 else np.zeros_like(u)
    u1d, u2d = udot[:n1], udot[n1:]
    # Rates of the world tangents along the couple: w x T + K u'.
    t1dot = w1t1 + k1 * u1d[0]
    if kind == "CC":
        t2dot = w2t2 + k2 * u2d[0]
        c = cross(t1, t2)
        n_hat, c_norm = _unit(c)
        n = sigma * n_hat
        ndot = sigma * _perp_rate(n_hat, cross(t1dot, t2) + cross(t1, t2dot), c_norm)
        ta, t2_norm = _unit(t2)
        tadot = _perp_rate(ta, t2dot, t2_norm)
        conv = cross(w1, t1 * u1d[0]) - cross(w2, t2 * u2d[0])
    else:
        suu, suv, svv = K2[:, 0, 0], K2[:, 0, 1], K2[:, 1, 1]
        sudot = cross(w2, su) + suu * u2d[0] + suv * u2d[1]
        svdot = cross(w2, sv) + suv * u2d[0] + svv * u2d[1]
        N_hat, N_norm = _unit(N)
        n = sigma * N_hat
        ndot = sigma * _perp_rate(N_hat, cross(sudot, sv) + cross(su, svdot), N_norm)
        ta, su_norm = _unit(su)
        tadot = _perp_rate(ta, sudot, su_norm)
        conv = cross(w1, t1 * u1d[0]) - cross(w2, T2 @ u2d)
    tb = cross(n, ta)
    tbdot = cross(ndot, ta) + cross(n, tadot)
    return CoupleEval(
        u=u, drift=du, residual=residual, udot=udot, conditioning=cond, p1=P1, p2=P2, n=n,
        ta=ta, tb=tb, gap=float(n @ d), v_rel=v_rel, vn=float(n @ v_rel),
        vt=np.array([ta @ v_rel, tb @ v_rel]),
        bias_n=float(n @ conv + ndot @ v_rel),
        bias_t=np.array([ta @ conv + tadot @ v_rel, tb @ conv + tbdot @ v_rel]))


def orientation_sign(kind, patch1, X1, patch2, X2, u) -> float:
    """sigma of Definition 2 for a pair becoming potential: the sign that makes the gap of the
    couple u non-negative (n from Body 2 towards Body 1)."""
    ev = evaluate_couple(kind, patch1, X1, (np.zeros(3), np.zeros(3)), patch2, X2,
                         (np.zeros(3), np.zeros(3)), u, 1.0, project=False)
    return 1.0 if ev.gap >= 0.0 else -1.0
