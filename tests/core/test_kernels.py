"""The patch jets and the couple kernels (through `drake_dock.core.couple`) against closed forms,
finite differences and invariants: the jets' tangents and curvatures against difference
quotients of the patches' points; a segment over a plane, a tilted circle over a plane and two
skew segments in closed form (the gap, the points, the normal, the conditioning, Eq. 47 along a
motion); and on the APDS pairs of several geometries, moving, the contact form F (Eq. 37-38)
against its definition, Fu (Eq. 40) against difference quotients of F, the one-step projection
(Newton: quadratic), u' (Eq. 47), g' = v_n and the Eq. (52) terms against differences along
the motion, and the frame (Definition 2)."""
import math

import numpy as np
import pytest

from couple_scenes import settle
from drake_dock.core.couple import closest_point_conditions, evaluate_couple
from drake_dock.core.seeking import seek_couple
from drake_dock.core.kernels.jets import jet, patch_spec, position
from drake_dock.core.patches import Circle, Cone, PlaneRect, PolarCurve, Segment, posed
from drake_dock.docking.geometry.apds import apds_patches
from drake_dock.docking.geometry.pairs import R_MATCHED
from drake_dock.docking.geometry.rotations import rot_vec, rot_x
from drake_dock.docking.geometry.scene import DockingScene
from drake_dock.docking.scenario.dimensions import ApdsGeometry
from motions import Motion, check_rates_by_finite_differences

GEOMETRIES = [ApdsGeometry(), ApdsGeometry(R=0.9, Rs=0.55, H=0.3, alpha1_deg=50.0,
                                           alpha2_deg=25.0)]
STILL = (np.zeros(3), np.zeros(3))
EYE = (np.eye(3), np.zeros(3))


def _patches(g):
    P = apds_patches(g)
    return ([*P.sides.values(), *P.surfaces.values(), P.ring, *P.tips.values(), P.rim, P.face,
             Segment((0.1, -0.2, 0.3), (0.7, 0.4, -0.1)),
             PlaneRect((-1.0, -0.5, 0.2), (0.8, 0.1, 0.0), (0.0, 0.9, 0.3), (2.0, 1.5)),
             Cone(0.5, 0.9, (0.2, 1.4), (0.0, 0.3))])


def _jet(patch, u):
    """(r, [T_a], [K_ab]) of the kernel jet at u, as arrays."""
    kind, prm = patch_spec(patch)
    r, t0, t1, k00, k01, k11 = jet(kind, prm, u[0], u[1] if patch.dim == 2 else 0.0)
    if patch.dim == 1:
        return np.array(r), np.array([t0]), np.array([[k00]])
    return np.array(r), np.array([t0, t1]), np.array([[k00, k01], [k01, k11]])


@pytest.mark.parametrize("g", GEOMETRIES)
def test_jets_are_the_patches_points_and_their_derivatives(g):
    """The kernel's r is the patch's point (`Patch.position`); T and K are the central
    differences of r and of T, at random points of each domain."""
    rng = np.random.default_rng(1)
    h = 1e-6
    for patch in _patches(g):
        for _ in range(10):
            u = patch.lower + (0.05 + 0.9 * rng.random(patch.dim)) * patch.span
            r, T, K = _jet(patch, u)
            np.testing.assert_allclose(r, patch.position(u), rtol=0, atol=1e-14)
            for a in range(patch.dim):
                e = np.zeros(patch.dim)
                e[a] = h * patch.span[a]
                jp, jm = _jet(patch, u + e), _jet(patch, u - e)
                scale = 1.0 + np.abs(T).max() + np.abs(K).max()
                np.testing.assert_allclose(T[a], (jp[0] - jm[0]) / (2 * e[a]), rtol=0,
                                           atol=1e-7 * scale, err_msg=f"{patch} T{a}")
                np.testing.assert_allclose(K[:, a], (jp[1] - jm[1]) / (2 * e[a]), rtol=0,
                                           atol=1e-7 * scale, err_msg=f"{patch} K.{a}")


@pytest.mark.parametrize("g", GEOMETRIES)
def test_position_is_the_jets_point(g):
    """`position` (the seek's grids) gives the bits of the jet's r, for every kind, at random
    points of each domain and on its ends."""
    rng = np.random.default_rng(2)
    for patch in _patches(g):
        kind, prm = patch_spec(patch)
        U = patch.lower + rng.random((200, patch.dim)) * patch.span
        for u in np.concatenate([U, [patch.lower, patch.upper]]):
            u1 = u[1] if patch.dim == 2 else 0.0
            assert position(kind, prm, u[0], u1) == jet(kind, prm, u[0], u1)[0], (patch, u)


def test_a_patch_without_a_kernel_description_is_refused():
    """A polar curve without the sine form's parameters has no kernel: the wrappers raise a
    ValueError naming its type; so do patches of the wrong dimension for the kind."""
    curve = PolarCurve(lambda th: (1.0 + 0 * th, 0 * th, 0 * th),
                       lambda th: (0 * th, 0 * th, 0 * th), (0.0, 1.0))
    assert patch_spec(curve) is None
    seg = Segment((0, 0, 0), (1, 0, 0))
    with pytest.raises(ValueError, match="PolarCurve"):
        evaluate_couple("CC", curve, EYE, STILL, seg, EYE, STILL, [0.5, 0.5], 1.0)
    with pytest.raises(ValueError, match="PolarCurve"):
        closest_point_conditions("CC", seg, EYE, curve, EYE, [0.5, 0.5])
    with pytest.raises(ValueError, match="dimensions"):
        evaluate_couple("CS", seg, EYE, STILL, seg, EYE, STILL, [0.5, 0.5, 0.5], 1.0)


def test_segment_over_a_plane_is_not_isolated():
    """A segment parallel to a plane at height h: at every s the gap is h, n the plane's
    normal, p2 the foot of p1; the couple is not isolated (conditioning 0) and Eq. (47) gives
    zeros, not NaNs."""
    plane = PlaneRect((-1.0, -1.0, 0.0), (2.0, 0.0, 0.0), (0.0, 2.0, 0.0))
    seg = Segment((-0.4, 0.1, 0.0), (0.5, -0.2, 0.0))
    h = 0.07
    X1 = (rot_x(0.0), np.array([0.0, 0.0, h]))
    for s in (0.2, 0.5, 0.9):
        p1 = np.array([-0.4 + 0.9 * s, 0.1 - 0.3 * s, h])
        u = [s, (p1[0] + 1.0) / 2.0, (p1[1] + 1.0) / 2.0]
        ev = evaluate_couple("CS", seg, X1, (np.zeros(3), np.array([0.1, 0.2, 0.0])), plane,
                             EYE, STILL, u, 1.0)
        assert ev.gap == pytest.approx(h, abs=1e-15)
        np.testing.assert_allclose(ev.n, [0, 0, 1], atol=1e-15)
        np.testing.assert_allclose(ev.p2, [p1[0], p1[1], 0.0], atol=1e-15)
        assert ev.conditioning == 0.0
        assert np.all(np.isfinite(ev.udot)) and not np.any(ev.udot)


@pytest.mark.parametrize("beta", [0.3, 0.7, 1.2])
def test_tilted_circle_over_a_plane(beta):
    """A circle of radius R tilted by beta about x, centre c at height h: its lowest point
    c - R (0, cos beta, sin beta) at the gap h - R sin beta over the plane, n = +z (sigma = +1;
    -z with sigma = -1 and the gap negated); the couple is isolated, and one projection from
    a couple 1e-3 off lands within 1e-5 of it (Newton, quadratic)."""
    plane = PlaneRect((-1.0, -1.0, 0.0), (2.0, 0.0, 0.0), (0.0, 2.0, 0.0))
    R, h = 0.3, 0.4
    c = np.array([0.1, -0.2, h])
    X1 = (rot_x(beta), c)
    low = c - R * np.array([0.0, math.cos(beta), math.sin(beta)])
    u = np.array([1.5 * math.pi, (low[0] + 1.0) / 2.0, (low[1] + 1.0) / 2.0])
    for sigma in (1.0, -1.0):
        ev = evaluate_couple("CS", Circle(R), X1, STILL, plane, EYE, STILL, u, sigma)
        assert ev.gap == pytest.approx(sigma * (h - R * math.sin(beta)), abs=1e-15)
        np.testing.assert_allclose(ev.n, [0, 0, sigma], atol=1e-15)
        np.testing.assert_allclose(ev.p1, low, atol=1e-15)
        np.testing.assert_allclose(ev.p2, [low[0], low[1], 0.0], atol=1e-15)
        assert ev.conditioning > 0.1 and ev.residual < 1e-15
    du = 1e-3 * np.array([1.0, -0.7, 0.4])
    ev = evaluate_couple("CS", Circle(R), X1, STILL, plane, EYE, STILL, u + du, 1.0)
    np.testing.assert_allclose(ev.u, u, atol=1e-5)
    np.testing.assert_allclose(ev.drift, ev.u - (u + du), atol=1e-15)
    F, _ = closest_point_conditions("CS", Circle(R), X1, plane, EYE, u + du)
    assert ev.residual == pytest.approx(np.linalg.norm(F), rel=1e-12)


def _common_perpendicular(a1, e1, a2, e2):
    """(s, t, p1, p2) of the lines a1 + s e1 and a2 + t e2: p1 - p2 perpendicular to both."""
    w = a1 - a2
    A = np.array([[e1 @ e1, -(e1 @ e2)], [e1 @ e2, -(e2 @ e2)]])
    s, t = np.linalg.solve(A, [-(w @ e1), -(w @ e2)])
    return s, t, a1 + s * e1, a2 + t * e2


def test_skew_segments_follow_their_common_perpendicular():
    """Two skew segments, Body 1 moving: the couple is the common perpendicular of their lines
    (closed form), the gap its length along n = sigma t1 x t2 / |t1 x t2|, the conditioning
    sin^2 / (1 + cos^2) of the angle between them (Fu is constant for straight patches);
    u' (Eq. 47) and g' = v_n are the central differences of the closed-form couple and gap."""
    a, b = np.array([0.0, -0.3, 0.2]), np.array([0.8, 0.5, 0.25])
    A, B = np.array([0.1, 0.6, 0.0]), np.array([0.6, -0.4, -0.1])
    seg1, seg2 = Segment(a, b), Segment(A, B)
    m1 = Motion(p0=(0.02, 0.0, 0.05), A=(0.01, 0.02, 0.01), W=(1.1, 0.8, 1.6), a=(0.2, 0.9),
                b=(0.1, 1.3))

    def exact(t):
        R, p = m1.pose(t)
        e1, e2 = R @ (b - a), B - A
        s, u2, p1, p2 = _common_perpendicular(p + R @ a, e1, A, e2)
        n = np.cross(e1, e2)
        n /= np.linalg.norm(n)
        return np.array([s, u2]), n @ (p1 - p2), p1, p2, n, e1, e2

    for t in (0.1, 0.5, 0.8):
        u, gap, p1, p2, n, e1, e2 = exact(t)
        ev = evaluate_couple("CC", seg1, m1.pose(t), m1.twist(t), seg2, EYE, STILL, u, 1.0)
        np.testing.assert_allclose(ev.u, u, atol=1e-14)
        assert ev.gap == pytest.approx(gap, abs=1e-14)
        np.testing.assert_allclose(ev.n, n, atol=1e-14)
        np.testing.assert_allclose(ev.p1, p1, atol=1e-14)
        np.testing.assert_allclose(ev.p2, p2, atol=1e-14)
        cos = e1 @ e2 / np.linalg.norm(e1) / np.linalg.norm(e2)
        assert ev.conditioning == pytest.approx((1 - cos ** 2) / (1 + cos ** 2), rel=1e-12)
        h = 1e-6
        up, gp = exact(t + h)[:2]
        um, gm = exact(t - h)[:2]
        np.testing.assert_allclose(ev.udot, (up - um) / (2 * h), atol=1e-8)
        assert ev.vn == pytest.approx((gp - gm) / (2 * h), abs=1e-9)
        rev = evaluate_couple("CC", seg1, m1.pose(t), m1.twist(t), seg2, EYE, STILL, u, -1.0)
        assert rev.gap == pytest.approx(-gap, abs=1e-14) and rev.vn == pytest.approx(-ev.vn)
        np.testing.assert_allclose(rev.n, -n, atol=1e-14)


def _contact_form(kind, p1, X1, p2, X2, u):
    """F (Eq. 37-38) from the patches' points and tangents (`Patch.position`, `first`)."""
    n1 = p1.dim
    r1 = X1[1] + X1[0] @ p1.position(u[:n1]) if n1 else X1[1] + X1[0] @ p1.p
    d = r1 - (X2[1] + X2[0] @ p2.position(u[n1:]))
    T2 = X2[0] @ p2.first(u[n1:])
    F = [T2[:, a] @ d for a in range(p2.dim)]
    if kind == "CC":
        return np.array([(X1[0] @ p1.first(u[:1])[:, 0]) @ d, F[0]])
    if kind == "CS":
        return np.array([*F, (X1[0] @ p1.first(u[:1])[:, 0]) @ np.cross(T2[:, 0], T2[:, 1])])
    return np.array(F)


def _moving_pairs(g, d):
    """The APDS pairs (complete set) with an interior couple at ring distance d, the chaser
    tilted, moving by m1, the target by m2, each with its settled couple at t = 0: (pair,
    motion of body 1, of body 2, u)."""
    m_c = Motion(rot_vec((0.03, -0.02, 0.01)) @ R_MATCHED, (0.01, -0.005, d),
                 A=(0.004, 0.003, 0.005), W=(1.3, 0.9, 1.7), a=(0.01, 1.1), b=(0.008, 0.7))
    m_t = Motion(A=(0.002, -0.001, 0.003), W=(0.8, 1.4, 0.6), a=(0.012, 0.5), b=(0.006, 1.2))
    motion = {"target_apds": m_t, "chaser_apds": m_c}
    out = []
    for pr in DockingScene(g, "complete").pairs:
        m1, m2 = motion[pr.body1], motion[pr.body2]
        X1, X2 = m1.pose(0.0), m2.pose(0.0)
        c = seek_couple(posed(pr.patch1, *X1), posed(pr.patch2, *X2))
        if not c.interior:
            continue
        u = settle(pr.kind, pr.patch1, X1, pr.patch2, X2, c.u)
        F, _, cond = closest_point_conditions(pr.kind, pr.patch1, X1, pr.patch2, X2, u,
                                              conditioning=True)
        if cond > 1e-3 and np.abs(F).max() < 1e-12:
            out.append((pr, m1, m2, u))
    return out


@pytest.mark.parametrize("g", GEOMETRIES)
@pytest.mark.parametrize("d", [0.1, 0.03])
def test_apds_couples_against_their_definitions_and_differences(g, d):
    """On the APDS pairs with an interior isolated couple, both bodies moving: F equals its
    definition from the patches' points (Eq. 37-38) and Fu the central differences of F
    (Eq. 40) off the couple; one projection from 1e-4 off the settled couple lands within
    1e-6 of it, drift = u - u_state, residual = |F(u_state)|; at the couple the frame is
    orthonormal and right-handed, n along sigma (p1 - p2) (the points separated by the gap),
    v_rel . n = v_n; and u' (Eq. 47), g' = v_n and g'', (t . v_rel)' (Eq. 52) equal the
    differences along the motion of the settled couples."""
    pairs = _moving_pairs(g, d)
    assert {pr.kind for pr, *_ in pairs} >= {"CC", "CS"}
    rng = np.random.default_rng(int(1000 * d))
    for pr, m1, m2, u0 in pairs:
        X1, X2 = m1.pose(0.0), m2.pose(0.0)
        args = (pr.kind, pr.patch1, X1, pr.patch2, X2)
        span = np.concatenate([pr.patch1.span, pr.patch2.span])
        off = u0 + 1e-3 * span * rng.normal(size=len(u0))
        F, Fu = closest_point_conditions(*args, off)
        np.testing.assert_allclose(F, _contact_form(*args, off), atol=1e-13, err_msg=pr.name)
        for a in range(len(off)):
            e = np.zeros(len(off))
            e[a] = 1e-6 * span[a]
            dF = (closest_point_conditions(*args, off + e)[0]
                  - closest_point_conditions(*args, off - e)[0]) / (2 * e[a])
            np.testing.assert_allclose(Fu[:, a], dF, atol=1e-6 * (1 + np.abs(Fu).max()),
                                       err_msg=f"{pr.name} column {a}")
        near = u0 + 1e-4 * span * rng.normal(size=len(u0))
        ev = evaluate_couple(pr.kind, pr.patch1, X1, m1.twist(0.0), pr.patch2, X2,
                             m2.twist(0.0), near, 1.0)
        np.testing.assert_allclose(ev.u, u0, atol=1e-6 * span.max(), err_msg=pr.name)
        np.testing.assert_allclose(ev.drift, ev.u - near, atol=1e-15)
        assert ev.residual == pytest.approx(np.linalg.norm(closest_point_conditions(*args,
                                                                                    near)[0]))
        sigma = -1.0 if pr.kind in ("CC", "CS") and len(pr.name) % 2 else 1.0
        ev = evaluate_couple(pr.kind, pr.patch1, X1, m1.twist(0.0), pr.patch2, X2,
                             m2.twist(0.0), u0, sigma)
        Rf = ev.frame
        np.testing.assert_allclose(Rf.T @ Rf, np.eye(3), atol=1e-12)
        assert np.linalg.det(Rf) > 0
        dp = ev.p1 - ev.p2
        np.testing.assert_allclose(dp, ev.gap * ev.n, atol=1e-12, err_msg=pr.name)
        assert ev.vn == pytest.approx(ev.n @ ev.v_rel, abs=1e-15)
        state = {"u": u0}

        def ev_at(t, pr=pr, m1=m1, m2=m2, state=state, sigma=sigma):
            Y1, Y2 = m1.pose(t), m2.pose(t)
            u = settle(pr.kind, pr.patch1, Y1, pr.patch2, Y2, state["u"])
            return evaluate_couple(pr.kind, pr.patch1, Y1, m1.twist(t), pr.patch2, Y2,
                                   m2.twist(t), u, sigma)

        check_rates_by_finite_differences(ev_at, m1, m2, times=(0.0, 0.05), h=1e-4)
