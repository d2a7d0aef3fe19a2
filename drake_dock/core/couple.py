"""Kinematics of one couple of two moving patches (Sect. 5 and 7 of the paper), generic over
curve-curve ("CC"), curve-surface ("CS"), point-curve ("PC") and point-surface ("PS") pairs.
The compiled couple kernels (`drake_dock.core.kernels.couples`) evaluate it; the functions here
pack a pair's patches (`drake_dock.core.kernels.jets.patch_spec`), poses and twists for them,
read their row into a `CoupleEval` and raise the typed errors. A patch that no kernel describes
is refused with a ValueError naming its type.

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
g = sigma |d| - r, ta = t2/|t2|; the contact system takes sigma = +1 (`relations.Relation.sigma`:
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

from drake_dock.core.kernels import couples as K
from drake_dock.core.kernels.frames import frame
from drake_dock.core.kernels.jets import jet, patch_spec
from drake_dock.core.relations import relation
from drake_dock.errors import SingularCoupleError



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


def kernel_spec(patch):
    """(kind, parameters) of a patch for the kernels (`jets.patch_spec`), kept on the patch; a
    ValueError names the type of a patch that no kernel describes."""
    hit = patch.__dict__.get("_kernel_spec")
    if hit is None:
        hit = patch.__dict__["_kernel_spec"] = patch_spec(patch)
    if hit is None:
        raise ValueError(f"{type(patch).__name__} has no kernel description (`jets.patch_spec`): "
                         f"its couples cannot be evaluated")
    return hit


def _rotation(R):
    return np.ascontiguousarray(R, dtype=float)


def _vec(a):
    return float(a[0]), float(a[1]), float(a[2])


def _pair(kind, patch1, patch2):
    """(pair code, patch 1's kind and parameters, its point, patch 2's kind and parameters) of
    a pair of ``kind``, its patches checked against the kind."""
    rel = relation(kind)
    d1, d2 = rel.dims
    if patch1.dim != d1 or patch2.dim != d2:
        raise ValueError(f"a {kind} couple needs patches of dimensions {d1} and {d2}, not "
                         f"{type(patch1).__name__} ({patch1.dim}) and {type(patch2).__name__} "
                         f"({patch2.dim})")
    k2, q2 = kernel_spec(patch2)
    if rel.point:
        return rel.code, 0, q2, _vec(patch1.p), k2, q2
    k1, q1 = kernel_spec(patch1)
    return rel.code, k1, q1, (0.0, 0.0, 0.0), k2, q2


def _padded(u, m):
    u = [float(a) for a in u]
    if len(u) != m:
        raise ValueError(f"a couple of {m} parameters, not {len(u)}")
    return tuple(u + [0.0] * (3 - m))


def closest_point_conditions(kind, patch1, X1, patch2, X2, u, *, conditioning=False):
    """F(u) and Fu of the contact form (Eq. 37-38, 40) for body poses X_i = (R_i, p_i) (and the
    conditioning of Fu if asked): `couples.conditions`."""
    pair, k1, q1, p, k2, q2 = _pair(kind, patch1, patch2)
    m = patch1.dim + patch2.dim
    out = np.zeros(13)
    K.conditions(pair, k1, q1, k2, q2, p, _rotation(X1[0]), _vec(X1[1]), _rotation(X2[0]),
                 _vec(X2[1]), _padded(u, m), out)
    F, Fu = out[:m].copy(), out[3:12].reshape(3, 3)[:m, :m].copy()
    if conditioning:
        return F, Fu, float(out[12])
    return F, Fu


def evaluate_couple(kind, patch1, X1, V1, patch2, X2, V2, u_state, sigma, *,
                    project=True) -> CoupleEval:
    """Evaluates the couple whose state is ``u_state`` for body poses X_i = (R_i, p_i) and
    twists V_i = (w_i, v_i) by its kind's kernel (`couples.evaluate_one`, `evaluate_pc_one`,
    `evaluate_ps_one`). With ``project`` one Newton step on F(u) = 0 corrects the drift of the
    integrated couple before anything else is computed (its size is returned). A point-curve
    couple whose point lies on its curve has no normal: `SingularCoupleError`."""
    pair, k1, q1, p, k2, q2 = _pair(kind, patch1, patch2)
    m = patch1.dim + patch2.dim
    u = _padded(u_state, m)
    f1, f2 = frame(X1[0], X1[1], *V1), frame(X2[0], X2[1], *V2)
    out = np.zeros(K.ROW)
    project = np.bool_(project)
    sigma = float(sigma)
    if pair == K.PC:
        K.evaluate_pc_one(k2, q2, p, patch1.radius, f1, f2, u[0], sigma, project, out)
        if math.isnan(out[K.GAP]):
            raise SingularCoupleError("point-curve couple: the point lies on the curve "
                                      "(|d| = 0), its normal is undefined")
    elif pair == K.PS:
        K.evaluate_ps_one(k2, q2, p, patch1.radius, f1, f2, (u[0], u[1]), sigma, project, out)
    else:
        K.evaluate_one(pair == K.CC, k1, q1, k2, q2, f1, f2, u, sigma, project, out)
    return CoupleEval(
        u=out[K.U:K.U + m], drift=out[K.DRIFT:K.DRIFT + m], residual=float(out[K.RESIDUAL]),
        udot=out[K.UDOT:K.UDOT + m], conditioning=float(out[K.COND]), p1=out[K.P1:K.P1 + 3],
        p2=out[K.P2:K.P2 + 3], n=out[K.N:K.N + 3], ta=out[K.TA:K.TA + 3], tb=out[K.TB:K.TB + 3],
        gap=float(out[K.GAP]), v_rel=out[K.VREL:K.VREL + 3], vn=float(out[K.VN]),
        vt=out[K.VT:K.VT + 2], bias_n=float(out[K.BIAS_N]), bias_t=out[K.BIAS_T:K.BIAS_T + 2])


def point_curve_side(patch2, R2, s, n) -> float:
    """The cosine between a point-curve couple's normal n (world) and the curve's curvature
    direction c''(s) (its frame turned by R2): positive while the point lies on the concave
    side of the curve, inside a circle's passage (1 where the curve is straight)."""
    k2, q2 = kernel_spec(patch2)
    k = np.asarray(R2, dtype=float) @ np.array(jet(k2, q2, float(s), 0.0)[3])
    nk = math.sqrt(k @ k)
    return float(np.asarray(n, dtype=float) @ k) / nk if nk > 0.0 else 1.0
