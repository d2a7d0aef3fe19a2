"""Kinematics of one couple of two moving patches (Sect. 5 and 7 of the paper), generic over
curve-curve ("CC"), curve-surface ("CS"), point-curve ("PC") and point-surface ("PS") pairs;
plain numpy.

Patch 1 is a curve on Body 1; patch 2 a curve (CC) or a surface (CS) on Body 2. Each body frame
F_i has the world pose (R_i, p_i) and twist (w_i, v_i), v_i the velocity of its origin. A point
of patch i is P_i = p_i + R_i r_i(u_i), its tangents T_i = R_i dr_i/du_i, its second derivatives
K_i = R_i d2r_i/du_i2, and d = P_1 - P_2.

Closest-point conditions F(u) = 0, the paper's contact form (Eq. 37-38), which stays regular
when the gap is zero (the gradient of |d|^2 does not: at a tangent curve-surface touch it is
degenerate):

    CC:  F = [t1 . d,  t2 . d]
    CS:  F = [s_u . d,  s_v . d,  t1 . N],   N = s_u x s_v
    PC:  F = [t2 . d]                  (patch 1 a point p, `Point`; u = (s,) of the curve)

Where the gap is not zero they are the conditions of minimal distance (d parallel to the normal,
perpendicular to the curve tangents). Their Jacobian Fu = dF/du is the paper's J of Eq. (40);
Eq. (47) follows from dF/dt = 0 along the motion: u' = -Fu^-1 (dF/dt at fixed u).

Contact frame (Definition 2): n = sigma N/|N| (CS) or sigma (t1 x t2)/|t1 x t2| (CC), sigma = +-1
fixed when the pair becomes potential so that n points from Body 2 to Body 1 (docs/model.md);
tangents ta = s_u/|s_u| (CS) or t2/|t2| (CC), tb = n x ta. Signed gap g = n . d.

Point-curve ("PC", a petal corner against a ring's inside circle): patch 1 is a point p (a
sphere of radius r, `drake_dock.core.patches.Point`), d = p - c(s); n = sigma d/|d|,
g = sigma |d| - r, ta = t2/|t2|; the contact system takes sigma = +1 (`hybrid.couple_sigma`:
n along d, also while the sphere overlaps the curve, g < 0).
Its Jacobian is the scalar Fu = k2 . d - t2 . t2 (for a circle of radius R, -R rho_p with
rho_p the distance of p from the axis: singular on the axis, where every s is closest); its
conditioning is |Fu| / (t2 . t2 + |k2| |d|). d = 0 (the corner on the curve, r deeper than a
touch) has no normal: `SingularCoupleError`. A point-curve couple is a potential contact only
with the point on the concave side of the curve (`point_curve_side`; docs/model.md, "The petal
corner").

Point-surface ("PS", a petal corner against a guide surface): patch 1 a point p (a sphere of
radius r), u = (u, v) of the surface, d = p - s(u); F = [s_u . d, s_v . d] (Eq. 38 without its
tangency row), n = sigma N/|N| as for C-S, g = n . d - r, ta = s_u/|s_u|. Its Jacobian is
[[s_uu . d - s_u . s_u, s_uv . d - s_u . s_v], [.., s_vv . d - s_v . s_v]], regular at d = 0 (the
point on the surface): singular only at a centre of curvature of the surface.

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

# One couple is evaluated in plain floats (3-tuples); its frame and the frame's rates by the
# compiled code the couple kernels share (`drake_dock.core.kernels.frames`).
from drake_dock.core.kernels.frames import frame_rates_cc, frame_rates_cs, frame_rates_pc
from drake_dock.core.vec3 import add as _add, axpy as _axpy, cross as _cr, dot as _dot, \
    mul as _mul, rot as _rot, sub as _sub
from drake_dock.errors import SingularCoupleError


def _solve(A, b):
    """A x = b for n = 2, 3 by Cramer's rule (lists of floats; the callers have checked the
    conditioning of A, `_conditioning`, so that no pivoting is needed at these sizes)."""
    if len(b) == 2:
        (a, c), (d, e) = A
        det = a * e - c * d
        return [(b[0] * e - c * b[1]) / det, (a * b[1] - b[0] * d) / det]
    r0, r1, r2 = A
    c0 = _cr(r1, r2)
    det = _dot(r0, c0)
    c1, c2 = _cr(r2, r0), _cr(r0, r1)
    # x = adj(A) b / det, the columns of adj(A) being the cross products of the rows.
    return [(c0[0] * b[0] + c1[0] * b[1] + c2[0] * b[2]) / det,
            (c0[1] * b[0] + c1[1] * b[1] + c2[1] * b[2]) / det,
            (c0[2] * b[0] + c1[2] * b[1] + c2[2] * b[2]) / det]


def _det(A):
    if len(A) == 2:
        return A[0][0] * A[1][1] - A[0][1] * A[1][0]
    return _dot(A[0], _cr(A[1], A[2]))


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
    """World-oriented jet (R r, R T, R K) of a patch at u (R as nested lists)."""
    r, T, K = patch.jet(u)
    return (_rot(R, r), [_rot(R, t) for t in T],
            [[_rot(R, k) for k in row] for row in K])


def _residual(kind, d, T1, K1, T2, K2):
    if kind == "PC":
        # The analogue of Eq. (37) for a point: d (p - c(s)) . t2 = 0; d/ds = k2 . d - t2 . t2.
        t2, k2 = T2[0], K2[0][0]
        return [_dot(t2, d)], [[_dot(k2, d) - _dot(t2, t2)]]
    if kind == "PS":
        # Eq. (38) for a point: su . d = sv . d = 0; d/du of su . d is suu . d - su . su.
        su, sv = T2
        (suu, suv), (_, svv) = K2
        susv = _dot(su, sv)
        return ([_dot(su, d), _dot(sv, d)],
                [[_dot(suu, d) - _dot(su, su), _dot(suv, d) - susv],
                 [_dot(suv, d) - susv, _dot(svv, d) - _dot(sv, sv)]])
    t1, k1 = T1[0], K1[0][0]
    if kind == "CC":
        t2, k2 = T2[0], K2[0][0]
        t12 = _dot(t1, t2)
        return ([_dot(t1, d), _dot(t2, d)],
                [[_dot(k1, d) + _dot(t1, t1), -t12], [t12, _dot(k2, d) - _dot(t2, t2)]])
    su, sv = T2
    (suu, suv), (_, svv) = K2
    N = _cr(su, sv)
    susv = _dot(su, sv)
    return ([_dot(su, d), _dot(sv, d), _dot(t1, N)],
            [[_dot(su, t1), _dot(suu, d) - _dot(su, su), _dot(suv, d) - susv],
             [_dot(sv, t1), _dot(suv, d) - susv, _dot(svv, d) - _dot(sv, sv)],
             [_dot(k1, N), _dot(t1, _add(_cr(suu, sv), _cr(su, suv))),
              _dot(t1, _add(_cr(suv, sv), _cr(su, svv)))]])


def _conditioning(Fu, T1, T2):
    """|det| / product of row norms of Fu with its columns scaled by the parameters' tangent
    lengths (invariant to how the patches are parametrised): sin^2 / (1 + cos^2) of the angle
    between the curves of a C-C couple at contact; 0 when Eq. (39) fails."""
    scale = [math.sqrt(_dot(t, t)) for t in (*T1, *T2)]
    if min(scale) > 0.0:
        Fu = [[f / c for f, c in zip(row, scale)] for row in Fu]
    den = 1.0
    for row in Fu:
        den *= math.hypot(*row)
    return abs(_det(Fu)) / den if den > 0 else 0.0


def _pc_conditioning(Fu, d, T2, K2):
    """|Fu| / (t2 . t2 + |k2| |d|) in [0, 1] of a point-curve couple: 1 with p on the curve, 0
    with p on a circle's axis (the couple is not isolated)."""
    t2, k2 = T2[0], K2[0][0]
    den = _dot(t2, t2) + math.sqrt(_dot(k2, k2) * _dot(d, d))
    return abs(Fu[0][0]) / den if den > 0 else 0.0


def point_curve_side(patch2, R2, s, n) -> float:
    """The cosine between a point-curve couple's normal n (world) and the curve's curvature
    direction c''(s) (its frame turned by R2): positive while the point lies on the concave
    side of the curve, inside a circle's passage (1 where the curve is straight)."""
    k = _rot(float_pose((R2, (0.0, 0.0, 0.0)))[0], patch2.jet([float(s)])[2][0][0])
    nk = math.sqrt(_dot(k, k))
    return _dot(float_vec(n), k) / nk if nk > 0.0 else 1.0


def float_pose(X):
    """A pose (R, p) as (rows of R as lists, p as a tuple) of floats, the form the couple
    evaluation works in; a pose already in that form is returned as is."""
    R, p = X
    return R.tolist() if hasattr(R, "tolist") else R, float_vec(p)


def float_vec(a):
    """A 3-vector as a tuple of floats (unchanged if it is one)."""
    if type(a) is tuple:
        return a
    return tuple(a.tolist()) if hasattr(a, "tolist") else tuple(float(c) for c in a)


_pose = float_pose


def closest_point_conditions(kind, patch1, X1, patch2, X2, u, *, conditioning=False):
    """F(u) and Fu of the contact form for body poses X_i = (R_i, p_i) (and the conditioning
    of Fu if asked)."""
    n1 = patch1.dim
    u = [float(a) for a in u]
    (R1, p1), (R2, p2) = _pose(X1), _pose(X2)
    r1, T1, K1 = _geometry(patch1, R1, u[:n1])
    r2, T2, K2 = _geometry(patch2, R2, u[n1:])
    d = _sub(_add(r1, p1), _add(r2, p2))
    F, Fu = _residual(kind, d, T1, K1, T2, K2)
    if conditioning:
        cond = (_pc_conditioning(Fu, d, T2, K2) if kind == "PC"
                else _conditioning(Fu, T1, T2))
        return np.array(F), np.array(Fu), cond
    return np.array(F), np.array(Fu)


def evaluate_couple(kind, patch1, X1, V1, patch2, X2, V2, u_state, sigma, *,
                    project=True) -> CoupleEval:
    """Evaluates the couple whose state is ``u_state`` for body poses X_i = (R_i, p_i) and
    twists V_i = (w_i, v_i). With ``project`` one Newton step on F(u) = 0 corrects the drift of
    the integrated couple before anything else is computed (its size is returned)."""
    if kind == "PC":
        return _evaluate_point_curve(patch1, X1, V1, patch2, X2, V2, u_state, sigma, project)
    if kind == "PS":
        return _evaluate_point_surface(patch1, X1, V1, patch2, X2, V2, u_state, sigma, project)
    n1 = patch1.dim
    (R1, p1o), (R2, p2o) = _pose(X1), _pose(X2)
    w1, v1 = (float_vec(x) for x in V1)
    w2, v2 = (float_vec(x) for x in V2)
    u0 = [float(a) for a in u_state]
    u = u0
    r1, T1, K1 = _geometry(patch1, R1, u[:n1])
    r2, T2, K2 = _geometry(patch2, R2, u[n1:])
    d = _sub(_add(r1, p1o), _add(r2, p2o))
    F, Fu = _residual(kind, d, T1, K1, T2, K2)
    residual = math.sqrt(sum(f * f for f in F))
    cond = _conditioning(Fu, T1, T2)
    du = [0.0] * len(u)
    if project and residual > 0.0 and cond > 1e-14:
        du = [-a for a in _solve(Fu, F)]
        u = [a + b for a, b in zip(u, du)]
        if max(abs(a) for a in du) > 1e-9 * (1.0 + max(abs(a) for a in u)):
            r1, T1, K1 = _geometry(patch1, R1, u[:n1])
            r2, T2, K2 = _geometry(patch2, R2, u[n1:])
            d = _sub(_add(r1, p1o), _add(r2, p2o))
            F, Fu = _residual(kind, d, T1, K1, T2, K2)
            cond = _conditioning(Fu, T1, T2)
        else:
            # A round-off-sized correction: the points move along their tangents (exact to
            # O(du^2) < 1e-18); tangents and curvatures are kept.
            for t, a in zip(T1, du[:n1]):
                r1 = _axpy(a, t, r1)
            for t, a in zip(T2, du[n1:]):
                r2 = _axpy(a, t, r2)
            d = _sub(_add(r1, p1o), _add(r2, p2o))
    P1, P2 = _add(r1, p1o), _add(r2, p2o)
    v_rel = _sub(_add(v1, _cr(w1, r1)), _add(v2, _cr(w2, r2)))
    t1, k1 = T1[0], K1[0][0]
    w1t1 = _cr(w1, t1)
    if kind == "CC":
        t2, k2 = T2[0], K2[0][0]
        w2t2 = _cr(w2, t2)
        Ft = [_dot(w1t1, d) + _dot(t1, v_rel), _dot(w2t2, d) + _dot(t2, v_rel)]
    else:
        su, sv = T2
        N = _cr(su, sv)
        w2su, w2sv = _cr(w2, su), _cr(w2, sv)
        Ft = [_dot(w2su, d) + _dot(su, v_rel), _dot(w2sv, d) + _dot(sv, v_rel),
              _dot(w1t1, N) + _dot(t1, _cr(w2, N))]
    # Eq. (47): u' = -J^-1 dF/dt (J = Fu, Eq. 40). A singular J is reported by `conditioning`
    # and handled by the caller's rule; here it gives zeros, never a NaN.
    udot = _solve(Fu, [-f for f in Ft]) if cond > 1e-14 else [0.0] * len(u)
    u1d, u2d = udot[:n1], udot[n1:]
    # Rates of the world tangents along the couple: w x T + K u'.
    t1dot = _axpy(u1d[0], k1, w1t1)
    if kind == "CC":
        t2dot = _axpy(u2d[0], k2, w2t2)
        n, ndot, ta, tadot, conv = frame_rates_cc(
            *map(tuple, (t1, t2, t1dot, t2dot, w1, w2)), u1d[0], u2d[0], float(sigma))
    else:
        (suu, suv), (_, svv) = K2
        sudot = _axpy(u2d[1], suv, _axpy(u2d[0], suu, w2su))
        svdot = _axpy(u2d[1], svv, _axpy(u2d[0], suv, w2sv))
        n, ndot, ta, tadot, conv = frame_rates_cs(
            *map(tuple, (t1, su, sv, sudot, svdot, N, w1, w2)), u1d[0], u2d[0], u2d[1],
            float(sigma))
    tb = _cr(n, ta)
    tbdot = _add(_cr(ndot, ta), _cr(n, tadot))
    # Three arrays, the fields views of their rows (one numpy call each, not eleven).
    U = np.array((u, du, udot))
    V = np.array((P1, P2, n, ta, tb, v_rel))
    T = np.array(((_dot(ta, v_rel), _dot(tb, v_rel)),
                  (_dot(ta, conv) + _dot(tadot, v_rel), _dot(tb, conv) + _dot(tbdot, v_rel))))
    return CoupleEval(
        u=U[0], drift=U[1], residual=residual, udot=U[2], conditioning=cond, p1=V[0],
        p2=V[1], n=V[2], ta=V[3], tb=V[4], gap=_dot(n, d), v_rel=V[5],
        vn=_dot(n, v_rel), vt=T[0], bias_n=_dot(n, conv) + _dot(ndot, v_rel), bias_t=T[1])


def _point_setup(patch1, X1, V1, X2, V2):
    """(R2, p2, w1, v1, w2, v2, r1, P1) of a point couple: Body 2's pose, both twists in
    floats, the point's offset R1 p from its frame's origin and its world position."""
    (R1, p1o), (R2, p2o) = _pose(X1), _pose(X2)
    w1, v1 = (float_vec(x) for x in V1)
    w2, v2 = (float_vec(x) for x in V2)
    r1 = _rot(R1, patch1.jet(())[0])
    return R2, p2o, w1, v1, w2, v2, r1, _add(r1, p1o)


def _point_couple(U, cond, P1, P2, frame, v_rel, w1, radius, gap):
    """The `CoupleEval` of a point couple (kinds "PC", "PS") whose sphere of ``radius`` is
    centred at P1: U = (u, drift, udot, residual), frame = (n, n', ta, ta', conv, qhat,
    qhat'). The contact point is the sphere's point towards Body 2, q = -radius qhat from its
    centre: v_rel there, and its motion over the sphere, w1 x (q' - w1 x q), in the Eq. (52)
    term (the normal row's terms equal the centre's)."""
    u, du, udot, residual = U
    n, ndot, ta, tadot, conv, qhat, qhat_dot = frame
    q = _mul(qhat, -radius)
    qdot = _mul(qhat_dot, -radius)
    P1 = _add(P1, q)
    v_rel = _add(v_rel, _cr(w1, q))
    conv = _add(conv, _cr(w1, _sub(qdot, _cr(w1, q))))
    tb = _cr(n, ta)
    tbdot = _add(_cr(ndot, ta), _cr(n, tadot))
    return CoupleEval(
        u=np.array(u), drift=np.array(du), residual=residual, udot=np.array(udot),
        conditioning=cond, p1=np.array(P1), p2=np.array(P2), n=np.array(n), ta=np.array(ta),
        tb=np.array(tb), gap=gap, v_rel=np.array(v_rel),
        vn=_dot(n, v_rel), vt=np.array((_dot(ta, v_rel), _dot(tb, v_rel))),
        bias_n=_dot(n, conv) + _dot(ndot, v_rel),
        bias_t=np.array((_dot(ta, conv) + _dot(tadot, v_rel),
                         _dot(tb, conv) + _dot(tbdot, v_rel))))


def _evaluate_point_curve(patch1, X1, V1, patch2, X2, V2, u_state, sigma, project):
    """`evaluate_couple` for kind "PC" (module docstring): patch 1 a `Point`, patch 2 a curve,
    u = (s,). s' = -Ft / Fu (Eq. 47 with F = t2 . d); the frame and its rates from d' = v_rel -
    t2 s' and t2' = w2 x t2 + k2 s' (`frame_rates_pc`: n' = sigma (d' - dh (dh . d')) / |d|,
    dh = d / |d|; c = -(w2 x t2) s', Eq. 52); the contact point q = -r dh from the centre."""
    R2, p2o, w1, v1, w2, v2, r1, P1 = _point_setup(patch1, X1, V1, X2, V2)

    def at(s):
        r2, (t2,), ((k2,),) = _geometry(patch2, R2, [s])
        d = _sub(P1, _add(r2, p2o))
        (F,), ((Fu,),) = _residual("PC", d, None, None, (t2,), ((k2,),))
        return r2, t2, k2, d, F, Fu

    s = float(u_state[0])
    r2, t2, k2, d, F, Fu = at(s)
    residual = abs(F)
    cond = _pc_conditioning([[Fu]], d, (t2,), ((k2,),))
    ds = 0.0
    if project and residual > 0.0 and cond > 1e-14:
        ds = -F / Fu
        s += ds
        r2, t2, k2, d, F, Fu = at(s)
        cond = _pc_conditioning([[Fu]], d, (t2,), ((k2,),))
    dist = math.sqrt(_dot(d, d))
    if not dist > 0.0:
        raise SingularCoupleError("point-curve couple: the point lies on the curve (|d| = 0), "
                                  "its normal is undefined")
    v_rel = _sub(_add(v1, _cr(w1, r1)), _add(v2, _cr(w2, r2)))
    w2t2 = _cr(w2, t2)
    Ft = _dot(w2t2, d) + _dot(t2, v_rel)
    # Eq. (47); a singular Fu (p on a circle's axis) gives zero, reported by `conditioning`.
    sdot = -Ft / Fu if cond > 1e-14 else 0.0
    sig = float(sigma)
    n, ndot, ta, tadot, conv = frame_rates_pc(d, t2, _axpy(-sdot, t2, v_rel),
                                              _axpy(sdot, k2, w2t2), tuple(w2), sdot, sig)
    return _point_couple(([s], [ds], [sdot], residual), cond, P1, _add(r2, p2o),
                         (n, ndot, ta, tadot, conv, _mul(n, sig), _mul(ndot, sig)), v_rel, w1,
                         patch1.radius, sig * dist - patch1.radius)


def _evaluate_point_surface(patch1, X1, V1, patch2, X2, V2, u_state, sigma, project):
    """`evaluate_couple` for kind "PS" (module docstring): patch 1 a `Point`, patch 2 a
    surface, u = (u, v). u' = -Fu^-1 Ft (Eq. 47 with F = [s_u . d, s_v . d]); the frame and its
    rates as for C-S with no curve on Body 1 (`frame_rates_cs` with t1 = 0); the contact point
    is the sphere's point towards the surface, q = -r n from its centre."""
    R2, p2o, w1, v1, w2, v2, r1, P1 = _point_setup(patch1, X1, V1, X2, V2)

    def at(u):
        r2, T2, K2 = _geometry(patch2, R2, u)
        d = _sub(P1, _add(r2, p2o))
        F, Fu = _residual("PS", d, (), (), T2, K2)
        return r2, T2, K2, d, F, Fu, _conditioning(Fu, (), T2)

    u = [float(a) for a in u_state]
    r2, T2, K2, d, F, Fu, cond = at(u)
    residual = math.hypot(*F)
    du = [0.0, 0.0]
    if project and residual > 0.0 and cond > 1e-14:
        du = [-a for a in _solve(Fu, F)]
        u = [a + b for a, b in zip(u, du)]
        r2, T2, K2, d, F, Fu, cond = at(u)
    su, sv = T2
    (suu, suv), (_, svv) = K2
    w2su, w2sv = _cr(w2, su), _cr(w2, sv)
    v_rel = _sub(_add(v1, _cr(w1, r1)), _add(v2, _cr(w2, r2)))
    Ft = [_dot(w2su, d) + _dot(su, v_rel), _dot(w2sv, d) + _dot(sv, v_rel)]
    # Eq. (47); a singular Fu (p at a centre of curvature) gives zeros, reported by
    # `conditioning`.
    udot = _solve(Fu, [-f for f in Ft]) if cond > 1e-14 else [0.0, 0.0]
    sudot = _axpy(udot[1], suv, _axpy(udot[0], suu, w2su))
    svdot = _axpy(udot[1], svv, _axpy(udot[0], suv, w2sv))
    n, ndot, ta, tadot, conv = frame_rates_cs((0.0, 0.0, 0.0), *map(tuple, (
        su, sv, sudot, svdot, _cr(su, sv), w1, w2)), 0.0, udot[0], udot[1], float(sigma))
    return _point_couple((u, du, udot, residual), cond, P1, _add(r2, p2o),
                         (n, ndot, ta, tadot, conv, n, ndot), v_rel, w1, patch1.radius,
                         _dot(n, d) - patch1.radius)
