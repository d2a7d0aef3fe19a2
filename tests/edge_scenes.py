"""Small scenes of the edge and face pairs with closed-form couples along prescribed motions: a
ring's circle over a straight edge and over a circular arc (C-C), a straight edge over a skew
straight edge and over an arc (C-C, a guide side against another side or a tip arc), a tilted
ring rim over a ring face (C-S), and an edge made of a straight side and a tip arc meeting at a
corner.

Body 2 (the edge or face) turns about its z axis by chi(t) and translates by p2(t); Body 1 (the
ring) is posed relative to it by R_rel = Rz(beta) Rx(tau) Rz(psi) and its centre c (Body 2's
frame). All curves of Body 2 lie in its plane z = 0, so a horizontal ring at height c_z is at
least c_z from them, with equality where its projection crosses them: the couple."""
import math

import numpy as np

from drake_dock.core.patches import Annulus, Arc, Circle, Cone, Segment
from drake_dock.docking.geometry.rotations import rot_x, rot_z

EZ = np.array([0.0, 0.0, 1.0])


class Wave:
    """f(t) = a + b sin(w t + p) + v t, with f'(t)."""

    def __init__(self, a, b=0.0, w=1.0, p=0.0, v=0.0):
        self.a, self.b, self.w, self.p, self.v = a, b, w, p, v

    def __call__(self, t):
        return self.a + self.b * math.sin(self.w * t + self.p) + self.v * t

    def rate(self, t):
        return self.b * self.w * math.cos(self.w * t + self.p) + self.v


class EdgeScene:
    """A pair of Body 1 (a ring's circle, radius r, or an edge) against Body 2 along a
    prescribed motion;
    ``exact(t)`` gives the couple, gap and points in closed form."""

    def __init__(self, kind, patch1, patch2, c, psi, tau=Wave(0.0), beta=Wave(0.0),
                 chi=Wave(0.0, 0.2, 1.1), p2=(Wave(0.0, 0.01, 1.0), Wave(0.0, v=-0.02),
                                             Wave(0.0, 0.005, 2.0))):
        self.kind, self.patch1, self.patch2 = kind, patch1, patch2
        self.c, self.psi, self.tau, self.beta, self.chi, self.p2 = c, psi, tau, beta, chi, p2
        self.r = getattr(patch1, "radius", None)
        self.branches = (1,)          # the closed-form couples at the least distance

    def relative(self, t):
        R = rot_z(self.beta(t)) @ rot_x(self.tau(t)) @ rot_z(self.psi(t))
        w = (self.beta.rate(t) * EZ + self.tau.rate(t) * (rot_z(self.beta(t)) @ [1.0, 0, 0])
             + self.psi.rate(t) * (rot_z(self.beta(t)) @ rot_x(self.tau(t)) @ EZ))
        return R, w, np.array([f(t) for f in self.c]), np.array([f.rate(t) for f in self.c])

    def poses(self, t):
        """World poses X_i = (R_i, p_i) and twists V_i = (w_i, v_i) of the two bodies."""
        R2, p2 = rot_z(self.chi(t)), np.array([f(t) for f in self.p2])
        w2, v2 = self.chi.rate(t) * EZ, np.array([f.rate(t) for f in self.p2])
        Rr, wr, c, cd = self.relative(t)
        p1 = p2 + R2 @ c
        v1 = v2 + np.cross(w2, R2 @ c) + R2 @ cd
        return (R2 @ Rr, p1), (w2 + R2 @ wr, v1), (R2, p2), (w2, v2)

    def world(self, t, x1, x2):
        """Body 2's frame points x1 (on the ring) and x2 to the world."""
        R2, p2 = rot_z(self.chi(t)), np.array([f(t) for f in self.p2])
        return p2 + R2 @ x1, p2 + R2 @ x2


def ring_angle(scene, t, x):
    """The ring's parameter of its point above x (Body 2's frame) for a horizontal ring."""
    c = np.array([f(t) for f in scene.c])
    return (math.atan2(x[1] - c[1], x[0] - c[0]) - scene.psi(t) - scene.beta(t)) % (2 * math.pi)


def line_crossing(scene, t, a, b, branch):
    """The ring's projection crossing the line a + s (b - a): (s, point), the larger root s for
    branch +1."""
    c = np.array([f(t) for f in scene.c])
    w, e = a[:2] - c[:2], b[:2] - a[:2]
    ee, we = e @ e, w @ e
    s = (-we + branch * math.sqrt(we * we - ee * (w @ w - scene.r ** 2))) / ee
    return s, a + s * (b - a)


def arc_crossing(scene, t, radius, branch):
    """The ring's projection crossing the circle |x| = radius about Body 2's axis: (theta,
    point), on the side +1 or -1 of the line from the axis to the ring's centre."""
    c = np.array([f(t) for f in scene.c])
    D = math.hypot(c[0], c[1])
    e = c[:2] / D
    ell = (radius ** 2 - scene.r ** 2 + D * D) / (2 * D)
    h = math.sqrt(radius ** 2 - ell * ell)
    x = ell * e + branch * h * np.array([-e[1], e[0]])
    return math.atan2(x[1], x[0]), np.array([x[0], x[1], 0.0])


def exact_cc(scene, t, u2, x2):
    """(u, gap, p1, p2, n) of a horizontal ring above the Body 2 point x2 (parameter u2)."""
    cz = scene.c[2](t)
    x1 = x2 + cz * EZ
    p1, p2 = scene.world(t, x1, x2)
    return np.array([ring_angle(scene, t, x2), u2]), cz, p1, p2, EZ


def ring_over_segment():
    """A ring (radius 0.4) at 30 mm +- 10 mm over the straight edge x in [-1, 1] of Body 2,
    crossing it at an angle while both bodies turn and translate."""
    seg = Segment((-1.0, 0.0, 0.0), (1.0, 0.0, 0.0))
    s = EdgeScene("CC", Circle(0.4), seg,
                  (Wave(0.0, 0.1, 0.7), Wave(0.15, v=0.1), Wave(0.03, 0.01, 1.3)),
                  Wave(0.0, 0.5, 0.9))

    def exact(t, branch=+1):
        u2, x2 = line_crossing(s, t, seg.a, seg.b, branch)
        return exact_cc(s, t, u2, x2)

    s.exact, s.branches = exact, (1, -1)      # two crossings at the same distance
    return s


def ring_over_arc():
    """A ring (radius 0.4) at 25 mm +- 10 mm over a tip-like arc (radius 0.45, theta in
    [0.2, 1.4]); its projection crosses the arc once inside that range."""
    arc = Arc(0.45, 0.0, (0.2, 1.4))
    s = EdgeScene("CC", Circle(0.4), arc,
                  (Wave(0.19, 0.02, 0.8), Wave(-0.06, 0.03, 1.1), Wave(0.025, 0.01, 1.7)),
                  Wave(0.3, 0.4, 0.6))

    def exact(t, branch=+1):
        th, x2 = arc_crossing(s, t, arc.radius, branch)
        return exact_cc(s, t, th, x2)

    s.exact = exact
    return s


def _segment_line(scene, t):
    """Body 1's segment as the line a + s e in Body 2's frame (s its parameter)."""
    R, _, c, _ = scene.relative(t)
    return c + R @ scene.patch1.a, R @ (scene.patch1.b - scene.patch1.a)


def segment_over_segment():
    """A straight edge (half-length 0.6) tilted by tau ~ 0.1 rad out of Body 2's plane and
    turned by psi ~ 0.8 rad across Body 2's straight edge x in [-1, 1], ~40 mm above it,
    sliding along it: the couple is the common normal of the two skew lines, s = (b e - c d) /
    (a c - b^2), t = (a e - b d) / (a c - b^2) with a = e1.e1, b = e1.e2, c = e2.e2, d = e1.w,
    e = e2.w, w = a1 - a2; the gap is its length and the normal runs along it."""
    seg = Segment((-1.0, 0.0, 0.0), (1.0, 0.0, 0.0))
    s = EdgeScene("CC", Segment((-0.6, 0.0, 0.0), (0.6, 0.0, 0.0)), seg,
                  (Wave(0.0, 0.15, 0.9, v=0.1), Wave(0.02, 0.03, 1.2), Wave(0.04, 0.01, 1.3)),
                  Wave(0.8, 0.3, 0.7), tau=Wave(0.1, 0.03, 1.1), beta=Wave(0.0, 0.1, 0.8))

    def exact(t, branch=+1):
        a1, e1 = _segment_line(s, t)
        e2, w = seg.b - seg.a, a1 - seg.a
        a, b, c, d, e = e1 @ e1, e1 @ e2, e2 @ e2, e1 @ w, e2 @ w
        u = np.array([b * e - c * d, a * e - b * d]) / (a * c - b * b)
        x1, x2 = a1 + u[0] * e1, seg.a + u[1] * e2
        gap = float(np.linalg.norm(x1 - x2))
        p1, p2 = s.world(t, x1, x2)
        return u, gap, p1, p2, (p1 - p2) / gap

    s.exact = exact
    return s


def segment_over_arc():
    """A level straight edge (half-length 0.3) ~30 mm above a tip-like arc (radius 0.45, theta
    in [0.2, 1.4]), crossing it near theta = 0.8 at an angle psi ~ 1.1 rad while moving along
    it: the couple is where the edge's projection crosses the circle (the root s of
    |a + s e|^2 = r^2 near the edge's middle), at the gap c_z, normal +z."""
    arc = Arc(0.45, 0.0, (0.2, 1.4))
    s = EdgeScene("CC", Segment((-0.3, 0.0, 0.0), (0.3, 0.0, 0.0)), arc,
                  (Wave(0.32, 0.03, 0.8), Wave(0.31, 0.02, 1.1, v=-0.05),
                   Wave(0.03, 0.01, 1.7)), Wave(1.1, 0.2, 0.6))

    def exact(t, branch=+1):
        a1, e1 = _segment_line(s, t)
        A, B, C = e1[:2] @ e1[:2], 2 * a1[:2] @ e1[:2], a1[:2] @ a1[:2] - arc.radius ** 2
        roots = [(-B + k * math.sqrt(B * B - 4 * A * C)) / (2 * A) for k in (-1, 1)]
        u1 = min(roots, key=lambda r: abs(r - 0.5))
        x2 = a1 + u1 * e1
        x2[2] = 0.0
        p1, p2 = s.world(t, x2 + a1[2] * EZ, x2)
        return (np.array([u1, math.atan2(x2[1], x2[0])]), a1[2], p1, p2,
                rot_z(s.chi(t)) @ EZ)

    s.exact = exact
    return s


def rim_over_face():
    """A ring rim (radius 0.6) tilted by tau ~ 0.1 rad about an axis turned by beta, its
    centre offset ~0.1 m, over a ring face (0.4 <= rho <= 0.6): the couple is the rim's lowest
    point, at height c_z - r sin(tau), above the face."""
    face = Annulus(0.4, 0.6, 0.0)
    s = EdgeScene("CS", Circle(0.6), face,
                  (Wave(0.02, 0.01, 0.9), Wave(0.1, 0.01, 1.2), Wave(0.09, 0.01, 1.4)),
                  Wave(0.2, 0.6, 0.8), tau=Wave(0.1, 0.02, 1.0), beta=Wave(0.05, 0.1, 0.7))

    def exact(t, branch=+1):
        tau, beta = s.tau(t), s.beta(t)
        c = np.array([f(t) for f in s.c])
        x1 = c + rot_z(beta) @ np.array([0.0, -s.r * math.cos(tau), -s.r * math.sin(tau)])
        x2 = np.array([x1[0], x1[1], 0.0])
        u = np.array([(-0.5 * math.pi - s.psi(t)) % (2 * math.pi), math.hypot(x2[0], x2[1]),
                      math.atan2(x2[1], x2[0]) % (2 * math.pi)])
        p1, p2 = s.world(t, x1, x2)
        return u, x1[2], p1, p2, EZ

    s.exact = exact
    return s


def arc_over_cone():
    """A tip-like arc (radius 0.4) held level, its centre ~0.1 m off the axis of a guide-surface
    cone (rho = 0.6 - z cot 45 deg, Eq. 12) and ~0.32 m up, outside it: the couple is the arc's
    point nearest the axis, rho = r - D (D the centre's distance from the axis), at the gap
    (rho + z cot(alpha) - R0) sin(alpha), with the foot on the cone's meridian through it and
    the normal (sin(alpha) e_rho + cos(alpha) e_z)."""
    alpha, R0 = math.pi / 4, 0.6
    cone = Cone(R0, alpha, (2.0, 4.3), (0.0, 0.4))
    s = EdgeScene("CS", Arc(0.4, 0.0, (math.pi - 1.5, math.pi + 1.5)), cone,
                  (Wave(0.1, 0.02, 0.8), Wave(0.0, 0.03, 1.1), Wave(0.32, 0.01, 1.3)),
                  Wave(0.0, 0.3, 0.9))

    def exact(t, branch=+1):
        c = np.array([f(t) for f in s.c])
        D = math.hypot(c[0], c[1])
        x1 = np.array([c[0] * (1.0 - s.r / D), c[1] * (1.0 - s.r / D), c[2]])
        e = x1[:2] / (s.r - D)
        n = np.array([math.sin(alpha) * e[0], math.sin(alpha) * e[1], math.cos(alpha)])
        gap = (s.r - D + c[2] / math.tan(alpha) - R0) * math.sin(alpha)
        x2 = x1 - gap * n
        u = np.array([ring_angle(s, t, x1), math.atan2(x2[1], x2[0]) % (2 * math.pi), x2[2]])
        p1, p2 = s.world(t, x1, x2)
        return u, gap, p1, p2, rot_z(s.chi(t)) @ n

    s.exact = exact
    return s


# The petal-like tip: a straight side from A on the outer circle (radius 0.6) to the corner Q
# on the tip circle (radius 0.4), then the tip arc from Q (a corner, as at an APDS petal tip).
TIP_RADIUS, THETA_Q = 0.4, 0.3
CORNER = np.array([TIP_RADIUS * math.cos(THETA_Q), TIP_RADIUS * math.sin(THETA_Q), 0.0])
SIDE_START = np.array([0.6, 0.0, 0.0])


def tip_handover():
    """A ring (radius 0.4) at 20 mm +- 5 mm whose projection crosses the side, the crossing
    running up to the corner Q and on along the tip arc (the ring moves along the bisector of
    the two edges' directions at Q): (side scene, arc scene, closed-form hand-over time, when
    |Q - c| = r)."""
    side = Segment(SIDE_START, CORNER)
    arc = Arc(TIP_RADIUS, 0.0, (THETA_Q, THETA_Q + 0.8))
    c = (Wave(0.6995, v=-0.127), Wave(-0.2683, v=0.1546), Wave(0.02, 0.005, 1.5))
    psi = Wave(0.1, 0.3, 1.2)
    scenes = [EdgeScene("CC", Circle(0.4), side, c, psi),
              EdgeScene("CC", Circle(0.4), arc, c, psi)]

    def exact_side(t):
        u2, x2 = line_crossing(scenes[0], t, side.a, side.b, +1)
        return exact_cc(scenes[0], t, u2, x2)

    def exact_arc(t):
        th, x2 = arc_crossing(scenes[1], t, TIP_RADIUS, +1)
        return exact_cc(scenes[1], t, th, x2)

    scenes[0].exact, scenes[1].exact = exact_side, exact_arc
    # |Q - c(t)|^2 = r^2 with c linear in t: a quadratic; its root in [0, 1].
    q0 = CORNER[:2] - np.array([c[0].a, c[1].a])
    v = -np.array([c[0].v, c[1].v])           # Q - c(t) = q0 + v t
    A, B, C = v @ v, 2 * q0 @ v, q0 @ q0 - 0.16
    roots = [(-B + k * math.sqrt(B * B - 4 * A * C)) / (2 * A) for k in (-1, 1)]
    (t_h,) = [x for x in roots if 0.0 <= x <= 1.0]
    return scenes[0], scenes[1], t_h


class Fn:
    """f(t) with its rate f'(t), given as two functions."""

    def __init__(self, f, df):
        self.f, self.df = f, df

    def __call__(self, t):
        return self.f(t)

    def rate(self, t):
        return self.df(t)


def _ring_angle(phi, psi):
    """The parameter of the point at angle phi in the plane of a ring posed by
    Rz(beta) Rx(pi/2) Rz(psi) (phi from its radial axis towards +z)."""
    return (phi - psi) % (2 * math.pi)


def ring_over_plate_edge():
    """A ring (radius 0.4) standing in a vertical plane y = c_y across the edge x = 0 of the
    plate 0 <= x <= 1, -1 <= y <= 1 (z = 0), in contact throughout: on the face while
    c_x = 0.03 cos(2 pi t) >= 0 (its lowest point, c_z = r), pivoting over the edge point
    (0, c_y, 0) while c_x < 0 (|c - edge point| = r). Returns (surface scene, edge scene,
    `SurfaceEdge`, (t_on, t_off) = (0.25, 0.75), the times c_x = 0)."""
    from drake_dock.core.handover import SurfaceEdge
    from drake_dock.core.patches import PlaneRect
    r = 0.4
    cx = Fn(lambda t: 0.03 * math.cos(2 * math.pi * t),
            lambda t: -0.06 * math.pi * math.sin(2 * math.pi * t))
    cz = Fn(lambda t: r if cx(t) >= 0 else math.sqrt(r * r - cx(t) ** 2),
            lambda t: 0.0 if cx(t) >= 0 else -cx(t) * cx.rate(t) / math.sqrt(r * r - cx(t) ** 2))
    c = (cx, Wave(0.0, 0.1, 1.3, v=0.02), cz)
    psi, tau = Wave(0.3, 0.5, 0.9), Wave(0.5 * math.pi)
    plate = PlaneRect((0.0, -1.0, 0.0), (1.0, 0.0, 0.0), (0.0, 1.0, 0.0), size=(1.0, 2.0))
    edge = Segment((0.0, -1.0, 0.0), (0.0, 1.0, 0.0))
    surf = EdgeScene("CS", Circle(r), plate, c, psi, tau=tau)
    over = EdgeScene("CC", Circle(r), edge, c, psi, tau=tau)
    R2 = lambda t: rot_z(surf.chi(t))

    def exact_face(t):
        x = np.array([cx(t), c[1](t), 0.0])
        u = np.array([_ring_angle(-0.5 * math.pi, psi(t)), x[0], x[1] + 1.0])
        return (u, 0.0, *surf.world(t, x, x), R2(t) @ EZ)

    def exact_edge(t):
        x = np.array([0.0, c[1](t), 0.0])
        u = np.array([_ring_angle(math.atan2(-cz(t), -cx(t)), psi(t)), 0.5 * (x[1] + 1.0)])
        return (u, 0.0, *over.world(t, x, x), R2(t) @ np.array([cx(t), 0.0, cz(t)]) / r)

    surf.exact, over.exact = exact_face, exact_edge
    return surf, over, SurfaceEdge(0, False, lambda e: 2.0 * e, lambda f: 0.5 * f), (0.25, 0.75)


def ring_over_petal_tip():
    """A ring (radius 0.4) in the meridian plane theta_0(t) of an APDS (`ApdsGeometry()`), in
    contact throughout: rolling on guide surface 1 (tangent to its generatrix at zeta_f =
    H + p) while p(t) = 0.02 sin(2 pi (t - 1/4)) < 0, pivoting over the tip arc's point at
    theta_0 (by the angle p / (r sin alpha1), so that the centre's velocity is continuous)
    while p >= 0. The cone's nearest point to a point of the meridian half-plane lies on the
    same meridian. Returns (surface scene, tip scene, `SurfaceEdge`, (0.25, 0.75))."""
    from drake_dock.docking.geometry.apds import guide_surface, petal_edges, tip_arc
    from drake_dock.docking.scenario.dimensions import ApdsGeometry
    g = ApdsGeometry()
    a1, r = g.alpha1, 0.4
    cot, Rt = 1.0 / math.tan(a1), g.R - g.H / math.tan(a1)
    A = g.R * math.sin(g.alpha2)
    th0 = Wave(math.pi / 6, 0.05, 1.1)
    p = Fn(lambda t: 0.02 * math.sin(2 * math.pi * (t - 0.25)),
           lambda t: 0.04 * math.pi * math.cos(2 * math.pi * (t - 0.25)))

    def meridian(t):
        """(rho_c, z_c), their rates, and the contact point's (rho, z) and unit normal."""
        if p(t) < 0:
            zf = g.H + p(t)
            m = np.array([math.sin(a1), math.cos(a1)])
            foot = np.array([g.R - zf * cot, zf])
            return foot + r * m, p.rate(t) * np.array([-cot, 1.0]), foot, m
        phi = 0.5 * math.pi - a1 + p(t) / (r * math.sin(a1))
        e = np.array([math.cos(phi), math.sin(phi)])
        rate = p.rate(t) / math.sin(a1) * np.array([-e[1], e[0]])
        return np.array([Rt, g.H]) + r * e, rate, np.array([Rt, g.H]), e

    def centre(t, k):
        (rho, z), (drho, dz), _, _ = meridian(t)
        b, db = th0(t), th0.rate(t)
        return ((rho * math.cos(b), rho * math.sin(b), z)[k],
                (drho * math.cos(b) - rho * math.sin(b) * db,
                 drho * math.sin(b) + rho * math.cos(b) * db, dz)[k])

    c = tuple(Fn(lambda t, k=k: centre(t, k)[0], lambda t, k=k: centre(t, k)[1])
              for k in range(3))
    psi, tau = Wave(0.2, 0.3, 0.7), Wave(0.5 * math.pi)
    surf = EdgeScene("CS", Circle(r), guide_surface(g, 1), c, psi, tau=tau, beta=th0)
    tip = EdgeScene("CC", Circle(r), tip_arc(g, 1), c, psi, tau=tau, beta=th0)

    def exact(scene, t):
        _, _, (rho, z), m = meridian(t)
        b = th0(t)
        x = np.array([rho * math.cos(b), rho * math.sin(b), z])
        n = rot_z(scene.chi(t)) @ np.array([m[0] * math.cos(b), m[0] * math.sin(b), m[1]])
        ring = _ring_angle(math.atan2(-m[1], -m[0]), psi(t))
        if scene is tip:
            return (np.array([ring, b]), 0.0, *tip.world(t, x, x), n)
        t1 = math.asin(A / rho) - g.alpha2
        s = (b - t1) / (math.pi / 3 - 2 * t1)
        return (np.array([ring, s, z]), 0.0, *surf.world(t, x, x), n)

    surf.exact, tip.exact = (lambda t: exact(surf, t)), (lambda t: exact(tip, t))
    return surf, tip, petal_edges(g, 1)["tip"], (0.25, 0.75)
