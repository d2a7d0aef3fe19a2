"""APDS contact geometry of Sect. 4 (Eq. 12-17), in the APDS frame.

APDS frame: origin at the centre of the guide ring, e3 along the docking axis towards the other
APDS, ring face at zeta = 0, petals in 0 <= zeta <= H (docs/model.md, "APDS geometry").

- Guide side i (i = 1..6), Eq. (14) in its sine form: the line of the auxiliary plane through the
  outer circle at phi_i = (i - 1) pi / 3, lifted onto the cone zeta = (R - rho) tan(alpha1):
      rho(theta) = R sin(alpha2) / sin(alpha2 + sigma_i (theta - phi_i)),
  sigma_i = +1 for odd i (leans towards increasing theta), -1 for even i. Domain: from phi_i to
  phi_i + sigma_i theta_end, theta_end = arcsin(R sin(alpha2) / (R - H cot(alpha1))) - alpha2,
  the exact end at zeta = H (Eq. 15 is garbled in the paper).
- Guide surface k (k = 1..3), Eq. (12)-(13): the cone rho = R - zeta cot(alpha1) between the
  sides 2k - 1 and 2k. Its domain in (theta, zeta) is not a box, so the patch is parametrised by
  s in [0, 1] across the petal and zeta in [0, H]:
      theta = phi_{2k-1} + theta_1(zeta) + s (pi/3 - 2 theta_1(zeta)),
  theta_1 as in Eq. (13). s = 0 and s = 1 are the two guide sides.
- Inside circle of the guide ring, Eq. (16)-(17): rho = Rs, zeta = 0, theta in [0, 2 pi).

Features beyond the paper's pairs (docs/model.md, "What the 12 pairs leave out"):
- tip arc k: the petal's edge at zeta = H between the ends of sides 2k - 1 and 2k, the circle
  rho = R - H cot(alpha1) for theta in [phi_{2k-1} + theta_end, phi_{2k-1} + pi/3 - theta_end];
- outside circle of the ring: rho = R, zeta = 0;
- ring face: the annulus Rs <= rho <= R at zeta = 0, u = (rho, theta).
"""

from __future__ import annotations

import dataclasses
import math

import numpy as np

from drake_dock.core.handover import SurfaceEdge
from drake_dock.core.patches import (Annulus, AnnularSector, Arc, Circle, Cone, Point,
                                     PolarCurve, Reparametrized)
from drake_dock.docking.scenario.dimensions import ApdsGeometry
from drake_dock.errors import InputError


def side_phi(i: int) -> float:
    """The azimuth of the sector boundary where guide side i stands, (i - 1) pi / 3."""
    return (i - 1) * math.pi / 3.0


def side_root(g: ApdsGeometry, i: int) -> float:
    """The azimuth of guide side i's root, phi_i + sigma_i inset (the paper's: phi_i)."""
    return side_phi(i) + side_sigma(i) * g.inset


def side_sigma(i: int) -> int:
    return 1 if i % 2 == 1 else -1


def guide_side(g: ApdsGeometry, i: int) -> PolarCurve:
    """Guide side n_i, Eq. (14) in the sine form; u = (theta,)."""
    if i not in range(1, 7):
        raise InputError("guide side", i, "1..6")
    phi, sigma = side_root(g, i), side_sigma(i)
    A = g.Rp * math.sin(g.alpha2)
    tan1 = math.tan(g.alpha1)
    # The sine form holds for 0 < w < pi (w modulo 2 pi); beyond its reach, halfway from the
    # domain's ends to those limits, rho is held (docs/model.md, "Degenerate couples").
    w_lo, w_hi = 0.5 * g.alpha2, 0.5 * (g.alpha2 + g.theta_end + math.pi)
    w_0 = 0.5 * (w_lo + w_hi) - math.pi      # w is taken in [w_0, w_0 + 2 pi)

    def radial(th):
        w = g.alpha2 + sigma * (th - phi)
        if isinstance(w, float):
            if not w_lo <= w <= w_hi:
                w = w_0 + (w - w_0) % (2.0 * math.pi)       # theta is an angle
                if not w_lo <= w <= w_hi:
                    return A / math.sin(min(max(w, w_lo), w_hi)), 0.0, 0.0
            sw, cw = math.sin(w), math.cos(w)
        else:
            out = (w < w_lo) | (w > w_hi)
            if out.any():
                w = np.where(out, w_0 + np.mod(w - w_0, 2.0 * np.pi), w)
            held = (w < w_lo) | (w > w_hi)
            w = np.clip(w, w_lo, w_hi)
            sw, cw = np.sin(w), np.cos(w)
        rho = A / sw
        r1, r2 = -sigma * A * cw / sw**2, A * (1.0 + cw**2) / sw**3
        if not isinstance(w, float) and held.any():
            r1, r2 = np.where(held, 0.0, r1), np.where(held, 0.0, r2)
        return rho, r1, r2

    def axial_of(rho, r1, r2):
        return (g.Rp - rho) * tan1, -r1 * tan1, -r2 * tan1

    def axial(th):
        return axial_of(*radial(th))

    def parts(th):
        rad = radial(th)
        return rad, axial_of(*rad)

    return PolarCurve(radial, axial, (phi, phi + sigma * g.theta_end), parts,
                      kernel_params=(A, sigma, phi, tan1, g.Rp, g.alpha2, w_lo, w_hi))


class _PetalMap:
    """s = (s, zeta) in [0,1] x [0,H] -> u = (theta, zeta) on the cone, see module docstring."""

    def __init__(self, g: ApdsGeometry, k: int):
        self.g = g
        self.phi0 = side_root(g, 2 * k - 1)
        self.width = math.pi / 3 - 2 * g.inset       # the petal's angle at its root
        self.lower = np.array([0.0, 0.0])
        self.upper = np.array([1.0, g.H])
        self.cot1 = 1.0 / math.tan(g.alpha1)
        self.A = g.Rp * math.sin(g.alpha2)
        # Eq. (13) holds while x = A / rho < 1, zeta < (R - A) tan(alpha1). Its reach is the
        # domain grown at both ends by half the distance from zeta = H to that limit; beyond
        # it theta_1 is held (docs/model.md, "Degenerate couples"): the surface continues as
        # the cone between two fixed meridians.
        grow = 0.5 * ((g.Rp - self.A) / self.cot1 - g.H)
        self.z_reach = (-grow, g.H + grow)
        # The map's parameters for the compiled kernels (kind PETAL).
        self.kernel_params = (self.phi0, self.cot1, self.A, g.alpha2, g.Rp, self.width,
                              *self.z_reach)

    def _t1(self, z):
        lo, hi = self.z_reach
        held = (z < lo) | (z > hi)
        rho = self.g.Rp - np.clip(z, lo, hi) * self.cot1
        x = self.A / rho
        x1 = x * self.cot1 / rho                 # dx/dz
        x2 = 2.0 * x * self.cot1**2 / rho**2     # d2x/dz2
        q = np.sqrt(1.0 - x**2)
        t1 = np.arcsin(x) - self.g.alpha2
        d1, d2 = x1 / q, x2 / q + x * x1**2 / q**3
        if np.any(held):
            d1, d2 = np.where(held, 0.0, d1), np.where(held, 0.0, d2)
        return t1, d1, d2

    def jet(self, s):
        """(value, jac, hess) at one point, as nested tuples of floats."""
        a, z = float(s[0]), float(s[1])
        cot = self.cot1
        lo, hi = self.z_reach
        inside = lo <= z <= hi
        rho = self.g.Rp - (z if inside else min(max(z, lo), hi)) * cot
        x = self.A / rho
        x1 = x * cot / rho
        x2 = 2.0 * x * cot**2 / rho**2
        q = math.sqrt(1.0 - x * x)
        t1 = math.asin(x) - self.g.alpha2
        d1, d2 = (x1 / q, x2 / q + x * x1**2 / q**3) if inside else (0.0, 0.0)
        w = self.width - 2 * t1
        return ((self.phi0 + t1 + a * w, z), ((w, d1 * (1 - 2 * a)), (0.0, 1.0)),
                (((0.0, -2 * d1), (-2 * d1, d2 * (1 - 2 * a))), ((0.0, 0.0), (0.0, 0.0))))

    def value(self, s):
        s = np.asarray(s, dtype=float)
        a, z = s[..., 0], s[..., 1]
        t1, _, _ = self._t1(z)
        return np.stack([self.phi0 + t1 + a * (self.width - 2 * t1), z], axis=-1)

    def jac(self, s):
        s = np.asarray(s, dtype=float)
        a, z = s[..., 0], s[..., 1]
        t1, d1, _ = self._t1(z)
        J = np.zeros(a.shape + (2, 2))
        J[..., 0, 0] = self.width - 2 * t1
        J[..., 0, 1] = d1 * (1 - 2 * a)
        J[..., 1, 1] = 1.0
        return J

    def hess(self, s):
        s = np.asarray(s, dtype=float)
        a, z = s[..., 0], s[..., 1]
        _, d1, d2 = self._t1(z)
        Hs = np.zeros(a.shape + (2, 2, 2))
        Hs[..., 0, 0, 1] = Hs[..., 0, 1, 0] = -2 * d1
        Hs[..., 0, 1, 1] = d2 * (1 - 2 * a)
        return Hs


def guide_surface(g: ApdsGeometry, k: int) -> Reparametrized:
    """Guide surface k (Eq. 12-13) between sides 2k-1 and 2k; u = (s, zeta)."""
    if k not in (1, 2, 3):
        raise InputError("guide surface", k, "1..3")
    phi0, petal = side_root(g, 2 * k - 1), _PetalMap(g, k)
    cone = Cone(g.Rp, g.alpha1, (phi0, phi0 + math.pi / 3 - 2 * g.inset), (0.0, g.H))
    return Reparametrized(cone, petal)


def petal_edges(g: ApdsGeometry, k: int) -> dict:
    """The edges of guide surface k (u = (s, zeta)) that are patches of their own
    (`drake_dock.core.handover.SurfaceEdge`): guide side 2k - 1 at s = 0 and side 2k at s = 1
    (zeta = (R - rho(theta)) tan(alpha1), Eq. 14; theta = phi_i + sigma_i theta_1(zeta),
    Eq. 13), and tip arc k at zeta = H (theta = phi_{2k-1} + theta_1(H) + s (pi/3 -
    2 theta_1(H))). Keys: the side's number i, or "tip"."""
    m = _PetalMap(g, k)
    out = {}
    for i, upper in ((2 * k - 1, False), (2 * k, True)):
        side, phi, sigma = guide_side(g, i), side_root(g, i), side_sigma(i)
        # zeta on the side is its point's z coordinate.
        out[i] = SurfaceEdge(0, upper, lambda th, side=side: side.parts(th)[1][0],
                             lambda z, phi=phi, sigma=sigma: phi + sigma * (
                                 math.asin(m.A / (g.Rp - z * m.cot1)) - g.alpha2),
                             ("component", 2))
    t1 = math.asin(m.A / (g.Rp - g.H * m.cot1)) - g.alpha2
    w = m.width - 2 * t1
    out["tip"] = SurfaceEdge(1, True, lambda th: (th - m.phi0 - t1) / w,
                             lambda s: m.phi0 + t1 + s * w, ("affine", 1.0 / w, -(m.phi0 + t1) / w))
    return out


def ring_circle(g: ApdsGeometry) -> Circle:
    """Inside circle of the guide ring, Eq. (16)-(17)."""
    return Circle(g.Rs, 0.0)


def tip_arc(g: ApdsGeometry, k: int) -> Arc:
    """The tip arc of petal k: where guide surface k (Eq. 12-13) meets zeta = H; u = (theta,),
    theta from the end of side 2k - 1 to the end of side 2k (Eq. 14-15)."""
    if k not in (1, 2, 3):
        raise InputError("tip arc", k, "1..3")
    phi0 = side_root(g, 2 * k - 1)
    return Arc(g.Rp - g.H / math.tan(g.alpha1), g.H,
               (phi0 + g.theta_end, phi0 + math.pi / 3 - 2 * g.inset - g.theta_end))


# Half-width of a petal's tip land (`tip_land`): a corner within it of a tip arc rests on the
# arc's plane (docs/model.md, "Tip on tip"). Small: the petals are thin plates, and a corner
# farther from the arc meets the tip arc at an isolated crossing (the tip-tip pairs).
TIP_LAND = 1e-5


def tip_land(g: ApdsGeometry, k: int) -> AnnularSector:
    """The land of petal k's tip: the plane zeta = H within `TIP_LAND` (10 um) of the tip arc
    (`tip_arc`), over the arc's azimuths; u = (rho, theta), normal +e3 (away from the ring).
    The thin plate's end face seen from along the axis, where the other APDS's corners land
    when two tips meet coaxially (docs/model.md, "Tip on tip")."""
    arc = tip_arc(g, k)
    return AnnularSector(arc.radius - TIP_LAND, arc.radius + TIP_LAND, g.H,
                         (float(arc.lower[0]), float(arc.upper[0])))


def ring_rim(g: ApdsGeometry) -> Circle:
    """Outside circle of the guide ring, rho = R at zeta = 0."""
    return Circle(g.R, 0.0)


# How far the ring face's contact annulus reaches past the rim (m): the rim as a rounded edge
# (`ring_face`).
FACE_OVERHANG = 1e-3


def ring_face(g: ApdsGeometry) -> Annulus:
    """The ring's face, the annulus Rs <= rho <= R + `FACE_OVERHANG` at zeta = 0; u = (rho,
    theta), normal +e3. Two rings meet face on face with their rims nearly one over the other;
    a sharp rim against the other's equal rim has no isolated couple there. The face reaching
    a millimetre past the rim stands for a rounded edge: another ring's rim coming over it
    touches the face's plane, a little before the material (docs/model.md, "Facing and the
    contact pairs")."""
    return Annulus(g.Rs, g.R + FACE_OVERHANG, 0.0)


# The petal corner's sphere (the paper gives no rounding): radius r through the corner, its
# centre r outward of it along the APDS radius, so that a coaxial ring circle of radius
# Rs = R - H cot alpha1, which passes exactly through the corners, has the centre on its convex
# side (docs/model.md, "The petal corner").
CORNER_RADIUS = 1e-3


def corner_point(g: ApdsGeometry, i: int) -> np.ndarray:
    """The corner at the top of guide side i (zeta = H), where it meets the tip arc of its
    petal: the tip arc's lower end for odd i, its upper end for even i."""
    if i not in range(1, 7):
        raise InputError("petal corner", i, "1..6")
    tip = tip_arc(g, (i + 1) // 2)
    return tip.position(tip.lower if i % 2 else tip.upper)


def petal_corner(g: ApdsGeometry, i: int) -> Point:
    """The sphere of petal corner i (`corner_point`): radius `CORNER_RADIUS`, centred
    `CORNER_RADIUS` outward of the corner along the APDS radius (the sphere passes through
    the corner)."""
    c = corner_point(g, i)
    out = np.array([c[0], c[1], 0.0]) / math.hypot(c[0], c[1])
    return Point(c + CORNER_RADIUS * out, CORNER_RADIUS)


# Reach of a guide side against the other APDS's petal edges (`pairs.side_edge_pairs`): the
# roll range of the scenario (60 deg) and a margin for tilt and offset, which the seeded sweep
# of `drake_dock.docking.geometry.reach` bounds (docs/model.md).
SIDE_REACH = math.radians(60.0 + 10.0)


def azimuth_span(curve, R=np.eye(3)):
    """(mid-direction, half-width) about the axis, rad, of a guide side or tip arc (both
    parametrized by their azimuth, Eq. 14-15) turned by R: the directions of its two ends."""
    a, b = (math.atan2(x[1], x[0]) for x in (R @ curve.position(curve.lower),
                                            R @ curve.position(curve.upper)))
    half = 0.5 * ((b - a + math.pi) % (2 * math.pi) - math.pi)
    return a + half, abs(half)


def spans_within(one, other, reach=SIDE_REACH) -> bool:
    """True when two `azimuth_span`s come within ``reach`` of each other about the axis."""
    gap = abs((one[0] - other[0] + math.pi) % (2 * math.pi) - math.pi) - one[1] - other[1]
    return gap < reach


@dataclasses.dataclass
class ApdsPatches:
    sides: dict      # i -> guide side n_i
    surfaces: dict   # k -> guide surface k
    ring: Circle     # inside circle of the ring (Eq. 16-17)
    tips: dict       # k -> tip arc of petal k
    rim: Circle      # outside circle of the ring
    face: Annulus    # the ring's face
    corners: dict = dataclasses.field(default_factory=dict)   # i -> corner at side i's top
    # i -> the bare corner point (radius 0), against the other APDS's guide surfaces
    corner_points: dict = dataclasses.field(default_factory=dict)
    lands: dict = dataclasses.field(default_factory=dict)     # k -> the land of tip k
    # k -> the edges of guide surface k that are patches of their own (`petal_edges`)
    edges: dict = dataclasses.field(default_factory=dict)


def apds_patches(g: ApdsGeometry) -> ApdsPatches:
    """The patches of an APDS of geometry ``g``, each made once: the contact pairs share them
    (`drake_dock.docking.geometry.pairs`)."""
    return ApdsPatches({i: guide_side(g, i) for i in range(1, 7)},
                       {k: guide_surface(g, k) for k in (1, 2, 3)}, ring_circle(g),
                       {k: tip_arc(g, k) for k in (1, 2, 3)}, ring_rim(g), ring_face(g),
                       {i: petal_corner(g, i) for i in range(1, 7)},
                       {i: Point(corner_point(g, i)) for i in range(1, 7)},
                       {k: tip_land(g, k) for k in (1, 2, 3)},
                       {k: petal_edges(g, k) for k in (1, 2, 3)})
