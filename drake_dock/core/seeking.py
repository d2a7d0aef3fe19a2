"""Seeking the couple of minimal distance between two patches (Sect. 5.1), by the compiled seek
(`drake_dock.core.kernels.seek`): `seek_couple` packs the posed patches for it (their kernel
descriptions, `jets.patch_spec`, and their domains and coarse grids, kept on each patch), reads
the nearest finished couple and raises the typed errors. `contact_couple` finishes the couple on
the contact form (Eq. 37-38) inside the domains, or says why it is not a potential contact
(docs/model.md, "Degenerate couples").
"""
from __future__ import annotations

import dataclasses
import math

import numpy as np

from drake_dock.core.couple import closest_point_conditions, kernel_spec
from drake_dock.core.kernels import seek as K
from drake_dock.core.kernels.jets import N_PARAMS
from drake_dock.errors import SeekingError

# Grids of the point seeks: a point against a surface, against a curve (`seek_couple`).
POINT_SURFACE_GRID = 16
POINT_CURVE_GRID = 64
POINT_CURVE_ITER = 30


@dataclasses.dataclass
class Couple:
    """The couple of minimal distance (u1*, u2*) of a pair of posed patches."""

    u1: np.ndarray
    u2: np.ndarray
    p1: np.ndarray  # world point on patch 1 (a point patch: its centre)
    p2: np.ndarray  # world point on patch 2
    distance: float  # |p1 - p2| (a point patch: less its radius)
    newton_iterations: int
    interior: bool = True  # both points inside their domains (Eq. 22 holds)

    @property
    def u(self):
        return np.concatenate([self.u1, self.u2])


def _pose(P):
    """A posed patch's R and p as writable C-ordered copies (one compiled signature whatever
    the caller's arrays)."""
    return np.array(P.R, dtype=float, order="C"), np.array(P.p, dtype=float)


def _specs(pa, pb):
    """The kernel descriptions (kind, parameters) of a seek's patches, a point as a `POINT` by
    its coordinates; a ValueError unless patch 1 is a point or a curve and patch 2 a curve or a
    surface, each with a kernel description."""
    if pa.dim > 1 or pb.dim not in (1, 2):
        raise ValueError(f"no seek between {type(pa).__name__} (dimension {pa.dim}) and "
                         f"{type(pb).__name__} (dimension {pb.dim}): patch 1 is a point or a "
                         f"curve, patch 2 a curve or a surface")
    if pa.dim == 0:
        prm = np.zeros(N_PARAMS)
        prm[:3] = pa.p
        return (K.POINT, prm), kernel_spec(pb)
    return kernel_spec(pa), kernel_spec(pb)


def _not_converged(dist, iterations=K.CLOSEST_MAX_ITER):
    return SeekingError(f"closest-couple Newton did not converge in {iterations} "
                        f"iterations (at distance {dist:.3g} m)")


def seek_couple(P1, P2, *, distance_rtol=None, rtol_beyond=0.0, n_coarse=12, levels=2,
                n_fine=21, candidates=3) -> Couple:
    """The couple of minimal distance between the posed patches P1 and P2 (Sect. 5.1): a curve
    against a curve or a surface by the hierarchical grid of ``n_coarse`` points per parameter,
    ``levels`` finer grids of ``n_fine`` around the ``candidates`` best distinct coarse
    couples and their Newton finishes (`kernels.seek.seek`), the nearest kept; a point against
    a surface or a curve by `point_surface` and `point_curve`. With ``distance_rtol`` the
    Newton finish ends once the distance has converged to that fraction, where it is beyond
    ``rtol_beyond``. A Newton finish that does not converge raises `SeekingError` unless it
    ends within `CREEP_TOUCH` of touching, or (a curve's seek) another start is nearer, or
    (a curve's seek) the nearest start, once every start that did not converge is continued
    for `CREEP_MAX_ITER` further iterations, has converged; a non-finite distance raises it
    too; a patch without a kernel description a ValueError."""
    pa, pb = P1.patch, P2.patch
    (k1, q1), (k2, q2) = _specs(pa, pb)
    R1, o1 = _pose(P1)
    A, B = K.Placed(k1, q1, R1, o1), K.Placed(k2, q2, *_pose(P2))
    rtol = -1.0 if distance_rtol is None else float(distance_rtol)
    if pa.dim == 1:
        return _seek_curve(A, K.Domain(*pa.kernel_domain(n_coarse)), B,
                           K.Domain(*pb.kernel_domain(n_coarse)), levels, n_fine, candidates,
                           rtol, float(rtol_beyond))
    if pb.dim == 1:
        x = R1 @ pa.p + o1
        s, it, x2, concave = K.point_curve(x, B, K.Domain(*pb.kernel_domain(POINT_CURVE_GRID)),
                                           POINT_CURVE_ITER)
        # A potential contact only on the curve's concave side (docs/model.md, "The petal
        # corner").
        u2, status = np.array([s]), 0
        interior = concave and is_interior(pb, u2)
    else:
        u2, it, status, x, x2, interior = K.point_surface(
            A, B, K.Domain(*pb.kernel_domain(POINT_SURFACE_GRID)), rtol, float(rtol_beyond))
    centre = float(np.linalg.norm(x - x2))
    if status and centre > K.CREEP_TOUCH:
        raise _not_converged(centre)
    dist = centre - pa.radius
    if not math.isfinite(dist):
        raise SeekingError("no finite distance between the point and the patch (a "
                           "non-finite pose)")
    return Couple(np.zeros(0), u2, x, x2, dist, int(it), bool(interior))


def _seek_curve(A, D1, B, D2, levels, n_fine, candidates, rtol, rtol_beyond) -> Couple:
    """`seek_couple` of a curve (`kernels.seek.Placed` A over its `Domain` D1) against a curve
    or a surface (B, D2) by `kernels.seek.seek`, creeping on where needed."""
    U, its, status, X1, X2, interior = K.seek(A, D1, B, D2, levels, n_fine, candidates, rtol,
                                              rtol_beyond)
    # The nearest couple. A start whose Newton did not converge (it creeps: a nearly flat
    # valley, e.g. a ring's circle almost parallel to the other ring's face, or a circle that
    # touches or pierces a face, where the minima form a curve) counts where it is not the
    # nearest, or where it ended within CREEP_TOUCH of touching (the contact-form finish and
    # the modes then take it as a touch). Else every start that did not converge is continued
    # for CREEP_MAX_ITER further iterations (`kernels.seek.creep_on`: each creeps along the
    # valley to its own minimum, every step descending) and the nearest taken again; it is an
    # error if that one has still not converged beyond CREEP_TOUCH.
    best, dist = _nearest(X1, X2)
    if best < 0:
        raise SeekingError("no finite distance between the patches (a non-finite pose)")
    if status[best] and dist > K.CREEP_TOUCH:
        for c in np.flatnonzero(status):
            U[c], it, status[c], X1[c], X2[c], interior[c] = K.creep_on(
                A, D1, B, D2, U[c], rtol, rtol_beyond)
            its[c] += it
        best, dist = _nearest(X1, X2)
        if status[best] and dist > K.CREEP_TOUCH:
            raise _not_converged(dist, K.CLOSEST_MAX_ITER + K.CREEP_MAX_ITER)
    return Couple(U[best, :1], U[best, 1:], X1[best], X2[best], dist, int(its[best]),
                  bool(interior[best]))


def _nearest(X1, X2):
    """(index, distance) of the first nearest couple of points X1[c], X2[c]; (-1, inf) where no
    distance is finite."""
    best, dist = -1, np.inf
    for c in range(X1.shape[0]):
        d = float(np.linalg.norm(X1[c] - X2[c]))
        if d < dist:
            best, dist = c, d
    return best, dist


def is_interior(patch, u, rtol=1e-9) -> bool:
    """True when u lies inside the patch's domain by more than rtol of its span. A couple on a
    domain end is not a potential contact of its pair: there the closest-point conditions (22)
    do not hold, and an edge or a tip touching is a contact of another pair (or none)."""
    return bool(np.all(patch.margin(u) > rtol * patch.span))


@dataclasses.dataclass
class ContactCouple:
    """The couple a seek hands to tracking: ``u`` solves the contact form (Eq. 37-38) when
    ``usable``; otherwise it is the seek's couple and ``reason`` says why it is not a potential
    contact (docs/model.md, "Degenerate couples"). ``finish_failed``: the couple was interior
    and isolated but its contact-form finish failed."""

    u: np.ndarray
    usable: bool
    reason: str = ""
    finish_failed: bool = False


def contact_couple(kind, patch1, X1, patch2, X2, c: Couple, *, conditioning_min,
                   max_iter=20) -> ContactCouple:
    """The seek's couple ``c`` of patches on body poses X_i = (R_i, p_i), finished by Newton on
    the contact form F(u) = 0 (Eq. 37-38; the distance's gradient is flat at a tangent touch).

    Rules: the couple must be interior (`is_interior`) and isolated (J's conditioning above
    10 ``conditioning_min``); every Newton iterate must stay interior with J regular
    (conditioning above ``conditioning_min``), and the iteration must converge within
    ``max_iter`` steps (F at its round-off floor, or steps below 1e-9 of the smallest span).
    Otherwise the couple is not usable and the seek's couple is returned with the reason; no
    patch is evaluated outside its domain and no singular J is solved."""
    u0 = c.u
    n1 = patch1.dim
    if not c.interior:
        return ContactCouple(u0, False, "the closest couple lies on a domain end (a point-curve "
                                        "couple: or on the curve's convex side)")
    _, _, cond = closest_point_conditions(kind, patch1, X1, patch2, X2, u0, conditioning=True)
    if not cond > 10 * conditioning_min:
        return ContactCouple(u0, False, f"the couple is not isolated (J conditioning "
                                        f"{cond:.2e}, Eq. 40)")
    uc = u0
    step = np.inf
    for _ in range(max_iter):
        F, Fu, cond = closest_point_conditions(kind, patch1, X1, patch2, X2, uc,
                                               conditioning=True)
        if not cond > conditioning_min:
            return ContactCouple(u0, False, f"J turns singular along the contact-form finish "
                                            f"(conditioning {cond:.2e})", True)
        un = uc - np.linalg.solve(Fu, F)
        if not (np.all(np.isfinite(un)) and is_interior(patch1, un[:n1])
                and is_interior(patch2, un[n1:])):
            return ContactCouple(u0, False, "the contact-form finish leaves the domain: no "
                                            "contact-form couple inside it near the seek's", True)
        step = np.abs(un - uc).max()
        uc = un
        if np.abs(F).max() <= 1e-15 * (1.0 + np.abs(Fu).max()):
            return ContactCouple(uc, True)
    # F stalled at its round-off (far from the origin |F| cannot reach the test above) while
    # the steps became negligible: converged.
    span = np.concatenate([patch1.span, patch2.span]).min()
    if step <= 1e-9 * span:
        return ContactCouple(uc, True)
    return ContactCouple(u0, False, f"the contact-form finish did not converge in {max_iter} "
                                    f"Newton steps", True)
