"""The point-curve couple (kind "PC", a petal corner against a ring's inside circle) against
closed forms: the distance and normal of a point passing a circle, the tracking of s (Eq. 47
for a point) along prescribed motions, finite differences of the rates and the Eq. (52) terms,
and the degenerate point on the circle's axis."""
import math

import numpy as np
import pytest
from scipy.integrate import solve_ivp

from drake_dock.core.couple import closest_point_conditions, evaluate_couple, point_curve_side
from drake_dock.core.patches import Arc, Circle, Point, posed
from drake_dock.core.seeking import contact_couple, seek_couple
from drake_dock.errors import SingularCoupleError
from tests.motions import Motion, check_rates_by_finite_differences

R_C = 0.4


def closed_form(p, R2, o2, radius=R_C, r_pt=0.0):
    """(s, distance - r_pt, unit normal) of a world point p and the circle of radius ``radius``
    at z = 0 of the frame (R2, o2)."""
    q = R2.T @ (p - o2)
    s = math.atan2(q[1], q[0]) % (2 * math.pi)
    c = radius * np.array([math.cos(s), math.sin(s), 0.0])
    dq = q - c
    dist = math.sqrt((math.hypot(q[0], q[1]) - radius) ** 2 + q[2] ** 2)
    return s, dist - r_pt, R2 @ dq / np.linalg.norm(dq)


MOVING = [Motion(p0=(0.1, -0.3, 0.05), V=(0.02, 0.5, -0.1), a=(0.3, 1.3), b=(0.2, 0.7)),
          Motion(p0=(0.45, 0.2, -0.02), A=(0.05, 0.1, 0.03), W=(2.0, 1.5, 3.0), b=(0.4, 1.1))]
RING = Motion(p0=(0.0, 0.0, 0.0), V=(0.0, 0.0, 0.01), a=(0.5, 0.9), b=(0.3, 1.7))


@pytest.mark.parametrize("r_pt", [0.0, 0.002])
@pytest.mark.parametrize("m1", MOVING)
def test_point_passing_circle_distance_and_normal(m1, r_pt):
    point, ring = Point((0.02, 0.01, 0.03), r_pt), Circle(R_C)
    for t in np.linspace(0.0, 1.0, 11):
        X1, X2 = m1.pose(t), RING.pose(t)
        p = X1[1] + X1[0] @ point.p
        s, dist, n = closed_form(p, *X2, r_pt=r_pt)
        c = seek_couple(posed(point, *X1), posed(ring, *X2))
        assert c.u1.shape == (0,)
        assert abs((c.u2[0] - s + math.pi) % (2 * math.pi) - math.pi) < 1e-12
        assert c.distance == pytest.approx(dist, abs=1e-12)
        ev = evaluate_couple("PC", point, X1, m1.twist(t), ring, X2, RING.twist(t), c.u, 1.0)
        assert ev.gap == pytest.approx(dist, abs=1e-12)
        np.testing.assert_allclose(ev.n, n, atol=1e-12)
        np.testing.assert_allclose(ev.frame.T @ ev.frame, np.eye(3), atol=1e-12)
        assert abs(ev.ta @ (X2[0] @ np.array([-math.sin(s), math.cos(s), 0.0]))) \
            == pytest.approx(1.0, abs=1e-12)
        assert ev.conditioning > 0.0
        # The side: the cosine of n with the curvature direction -e_rho, (R - rho_p) / |d|;
        # a potential contact (``interior``) only inside the passage, rho_p < R.
        q = X2[0].T @ (p - X2[1])
        rho_p = math.hypot(q[0], q[1])
        side = (R_C - rho_p) / math.sqrt((rho_p - R_C) ** 2 + q[2] ** 2)
        assert point_curve_side(ring, X2[0], c.u2[0], ev.n) == pytest.approx(side, abs=1e-12)
        assert c.interior == (rho_p < R_C)


@pytest.mark.parametrize("m1", MOVING)
def test_tracking_follows_closed_form(m1):
    """s integrated by Eq. (47) (u' = -Ft / Fu) equals the polar angle of the point in the
    ring's frame."""
    point, ring = Point((0.0, 0.05, 0.0)), Circle(R_C)

    def rate(t, u):
        return evaluate_couple("PC", point, m1.pose(t), m1.twist(t), ring, RING.pose(t),
                               RING.twist(t), u, 1.0, project=False).udot

    def s_exact(t):
        X1 = m1.pose(t)
        return closed_form(X1[1] + X1[0] @ point.p, *RING.pose(t))[0]

    sol = solve_ivp(rate, (0.0, 1.0), [s_exact(0.0)], rtol=1e-12, atol=1e-13,
                    dense_output=True, method="DOP853")
    for t in np.linspace(0.0, 1.0, 9):
        err = (sol.sol(t)[0] - s_exact(t) + math.pi) % (2 * math.pi) - math.pi
        assert abs(err) < 1e-8


@pytest.mark.parametrize("r_pt", [0.0, 0.003])
@pytest.mark.parametrize("m1", MOVING)
def test_rates_and_bias_by_finite_differences(m1, r_pt):
    """vn = g', vt = the tangential velocity, and g'' = n . (a1 - a2) + bias_n,
    (t . v_rel)' = t . (a1 - a2) + bias_t, by central differences along the couple."""
    point, ring = Point((0.03, -0.02, 0.04), r_pt), Circle(R_C)

    def ev_at(t):
        X1 = m1.pose(t)
        s = closed_form(X1[1] + X1[0] @ point.p, *RING.pose(t))[0]
        return evaluate_couple("PC", point, X1, m1.twist(t), ring, RING.pose(t),
                               RING.twist(t), [s], 1.0)

    check_rates_by_finite_differences(ev_at, m1, RING)


def test_projection_corrects_drift():
    point, ring = Point((0.1, 0.2, 0.3)), Circle(R_C)
    X = (np.eye(3), np.zeros(3))
    s = math.atan2(0.2, 0.1)
    ev = evaluate_couple("PC", point, X, (np.zeros(3),) * 2, ring, X, (np.zeros(3),) * 2,
                         [s + 1e-4], 1.0)
    assert abs(ev.u[0] - s) < 1e-8           # one Newton step from 1e-4
    assert ev.drift[0] == pytest.approx(s - (s + 1e-4), abs=1e-8)


def test_point_on_axis_is_not_isolated_and_on_curve_raises():
    ring, X = Circle(R_C), (np.eye(3), np.zeros(3))
    on_axis = Point((0.0, 0.0, 0.2))
    c = seek_couple(posed(on_axis, *X), posed(ring, *X))
    assert c.distance == pytest.approx(math.hypot(R_C, 0.2), abs=1e-15)
    _, _, cond = closest_point_conditions("PC", on_axis, X, ring, X, c.u, conditioning=True)
    assert cond == 0.0
    f = contact_couple("PC", on_axis, X, ring, X, c, conditioning_min=1e-6)
    assert not f.usable and "not isolated" in f.reason
    on_curve = Point((R_C, 0.0, 0.0))
    with pytest.raises(SingularCoupleError):
        evaluate_couple("PC", on_curve, X, (np.zeros(3),) * 2, ring, X, (np.zeros(3),) * 2,
                        [0.0], 1.0)


@pytest.mark.parametrize("q", [(0.3, 0.3, 0.1), (-0.2, 0.5, 0.0), (0.1, -0.4, -0.2)])
def test_arc_seek_bounded(q):
    """A bounded arc (generic 1-D seek): the polar angle where it lies on the arc, else the
    nearer end (closed form)."""
    arc, X = Arc(0.5, 0.1, (0.2, 1.4)), (np.eye(3), np.zeros(3))
    point = Point(q)
    c = seek_couple(posed(point, *X), posed(arc, *X))
    ends = [np.linalg.norm(np.array(q) - arc.position(np.array([a]))) for a in (0.2, 1.4)]
    th = math.atan2(q[1], q[0])
    inside = 0.2 <= th <= 1.4
    want = (math.sqrt((math.hypot(q[0], q[1]) - 0.5) ** 2 + (q[2] - 0.1) ** 2) if inside
            else min(ends))
    assert c.distance == pytest.approx(want, abs=1e-12)
    assert c.interior == inside


@pytest.mark.parametrize("r_pt", [0.0, 0.002])
@pytest.mark.parametrize("m1", MOVING)
def test_both_orientations_and_the_projection(m1, r_pt):
    """From the closed-form s 1e-3 off, one projection lands within 1e-5 of it and a second
    within 1e-10 (Newton on F = t2 . d: quadratic), drift = s - s_state; with sigma = -1 the
    normal is -d/|d| and the gap -|d| - r (closed form), the rate s' the same as with +1."""
    point, ring = Point((0.03, -0.02, 0.04), r_pt), Circle(R_C)
    rng = np.random.default_rng(3)
    for t in (0.1, 0.45, 0.8):
        X1, X2, V1, V2 = m1.pose(t), RING.pose(t), m1.twist(t), RING.twist(t)
        s, dist, n = closed_form(X1[1] + X1[0] @ point.p, *X2)
        s0 = s + 1e-3 * rng.normal()
        ev = evaluate_couple("PC", point, X1, V1, ring, X2, V2, [s0], -1.0)
        assert abs(ev.u[0] - s) < 1e-5 and ev.drift[0] == pytest.approx(ev.u[0] - s0, abs=1e-15)
        again = evaluate_couple("PC", point, X1, V1, ring, X2, V2, ev.u, -1.0)
        assert abs(again.u[0] - s) < 1e-10
        plus = evaluate_couple("PC", point, X1, V1, ring, X2, V2, [s], 1.0)
        minus = evaluate_couple("PC", point, X1, V1, ring, X2, V2, [s], -1.0)
        np.testing.assert_allclose(minus.n, -n, atol=1e-12)
        assert minus.gap == pytest.approx(-dist - r_pt, abs=1e-12)
        assert plus.gap == pytest.approx(dist - r_pt, abs=1e-12)
        assert minus.udot[0] == pytest.approx(plus.udot[0], abs=1e-12)
        assert minus.vn == pytest.approx(-plus.vn, abs=1e-12)


def test_scene_corner_pairs_random_poses_raise_only_typed_errors():
    """The 12 corner pairs of `contact.pairs: complete` at seeded random chaser poses (tilt to
    20 deg, offsets to 0.3 m, ring distances -0.2 to 0.4 m, any roll) and with the corner
    placed on the ring's axis and on the circle: the seek, the contact-form finish and the
    evaluation give finite results in the domain or a typed error, never a Python or numpy
    one."""
    from drake_dock.docking.geometry.pairs import R_MATCHED
    from drake_dock.docking.geometry.rotations import rot_vec, rot_z
    from drake_dock.docking.geometry.scene import DockingScene
    from drake_dock.docking.scenario.dimensions import ApdsGeometry
    from drake_dock.errors import DrakeDockError
    pairs = [p for p in DockingScene(ApdsGeometry(), "complete").pairs if p.kind == "PC"]
    assert len(pairs) == 12
    rng = np.random.default_rng(18)
    usable = 0
    for pr in pairs:
        for _ in range(20):
            R = rot_vec(rng.uniform(-0.35, 0.35, 3) * (1, 1, 0)) @ rot_z(rng.uniform(-1, 1)) \
                @ R_MATCHED
            poses = {"target_apds": (np.eye(3), np.zeros(3)),
                     "chaser_apds": (R, np.array([*rng.uniform(-0.3, 0.3, 2),
                                                  rng.uniform(-0.2, 0.4)]))}
            X1, X2 = poses[pr.body1], poses[pr.body2]
            V = (rng.normal(size=3) * 0.1, rng.normal(size=3) * 0.1)
            try:
                c = seek_couple(posed(pr.patch1, *X1), posed(pr.patch2, *X2))
                assert np.isfinite(c.distance) and 0.0 <= c.u2[0] < 2 * math.pi
                f = contact_couple("PC", pr.patch1, X1, pr.patch2, X2, c, conditioning_min=1e-6)
                if f.usable:
                    usable += 1
                    ev = evaluate_couple("PC", pr.patch1, X1, V, pr.patch2, X2, V, f.u, 1.0)
                    assert np.all(np.isfinite(ev.udot)) and math.isfinite(ev.bias_n)
                    assert ev.gap == pytest.approx(c.distance, abs=1e-12)
            except DrakeDockError:
                pass
    assert usable > 100
    # Degenerate: the corner on the other ring's axis, and on its circle.
    pr = pairs[0]
    p = pr.patch1.p
    for o in (np.array([p[0], p[1], p[2] - 0.3]),
              p - np.array([pr.patch2.radius, 0.0, 0.0])):
        X2 = (np.eye(3), o)
        c = seek_couple(posed(pr.patch1, np.eye(3), np.zeros(3)), posed(pr.patch2, *X2))
        f = contact_couple("PC", pr.patch1, (np.eye(3), np.zeros(3)), pr.patch2, X2, c,
                           conditioning_min=1e-6)
        try:
            evaluate_couple("PC", pr.patch1, (np.eye(3), np.zeros(3)), V, pr.patch2, X2, V,
                            f.u, 1.0)
        except SingularCoupleError:
            pass



@pytest.mark.parametrize("r_pt", [0.0, 0.003])
@pytest.mark.parametrize("m1", MOVING)
def test_contact_points_lie_on_the_line_of_action(m1, r_pt):
    """The couple's points are the sphere's point nearest the curve and the curve's point:
    p1 - p2 = g n (closed form: the sphere's centre lies |d| from the curve along n, its
    surface r nearer), so forces +-F at them have no moment when the couple touches (g = 0),
    whatever their direction (friction included): momentum and angular momentum conserved."""
    point, ring = Point((0.03, -0.02, 0.04), r_pt), Circle(R_C)
    for t in (0.2, 0.55, 0.9):
        X1 = m1.pose(t)
        centre = X1[1] + X1[0] @ point.p
        s = closed_form(centre, *RING.pose(t))[0]
        e = evaluate_couple("PC", point, X1, m1.twist(t), ring, RING.pose(t), RING.twist(t),
                            [s], 1.0)
        np.testing.assert_allclose(e.p1 - e.p2, e.gap * e.n, atol=1e-15)
        np.testing.assert_allclose(np.linalg.norm(centre - e.p1), r_pt, atol=1e-15)
