"""The point-surface couple (kind "PS", a petal corner against a guide surface) against closed
forms: the distance, side and normal of a point passing a cone, the tracking of u (Eq. 47 for a
point) along prescribed motions, finite differences of the rates and the Eq. (52) terms, the
projection, and the degenerate point on the cone's axis and off the domain."""
import math

import numpy as np
import pytest
from scipy.integrate import solve_ivp

from drake_dock.core.couple import closest_point_conditions, evaluate_couple
from drake_dock.core.relations import relation
from drake_dock.core.patches import Cone, PlaneRect, Point, posed
from drake_dock.core.seeking import contact_couple, seek_couple
from tests.motions import Motion, check_rates_by_finite_differences

R0, ALPHA = 0.5, math.radians(60.0)
CONE = Cone(R0, ALPHA, (-1.0, 2.0), (-0.2, 0.4))


def cone_closed_form(p, R2, o2, r_pt=0.0):
    """(u = (theta, z), signed distance - r_pt, outward unit normal) of a world point p and the
    infinite cone rho = R0 - z cot(alpha) in the frame (R2, o2): in the meridian plane of p the
    generator through (R0, 0) has the direction (-cos alpha, sin alpha) and the outward normal
    (sin alpha, cos alpha)."""
    q = R2.T @ (p - o2)
    th = math.atan2(q[1], q[0])
    w = np.array([math.hypot(q[0], q[1]) - R0, q[2]])
    lam = w @ np.array([-math.cos(ALPHA), math.sin(ALPHA)])
    signed = w @ np.array([math.sin(ALPHA), math.cos(ALPHA)])
    n = np.array([math.cos(th) * math.sin(ALPHA), math.sin(th) * math.sin(ALPHA),
                  math.cos(ALPHA)])
    return np.array([th, lam * math.sin(ALPHA)]), signed - r_pt, R2 @ n


MOVING = [Motion(p0=(0.45, 0.1, 0.08), V=(-0.05, 0.1, -0.08), a=(0.3, 1.3), b=(0.2, 0.7)),
          Motion(p0=(0.3, 0.35, 0.02), A=(0.02, 0.03, 0.03), W=(2.0, 1.5, 3.0), b=(0.4, 1.1))]
BASE = Motion(p0=(0.0, 0.0, 0.0), V=(0.0, 0.0, 0.01), a=(0.5, 0.9), b=(0.1, 1.7))


@pytest.mark.parametrize("r_pt", [0.0, 0.002])
@pytest.mark.parametrize("m1", MOVING)
def test_point_over_cone_distance_side_and_normal(m1, r_pt):
    point = Point((0.02, 0.01, 0.03), r_pt)
    for t in np.linspace(0.0, 1.0, 11):
        X1, X2 = m1.pose(t), BASE.pose(t)
        p = X1[1] + X1[0] @ point.p
        u, signed, n = cone_closed_form(p, *X2, r_pt=r_pt)
        c = seek_couple(posed(point, *X1), posed(CONE, *X2))
        assert c.u1.shape == (0,) and c.interior
        np.testing.assert_allclose(c.u2, u, atol=1e-10)
        assert c.distance == pytest.approx(abs(signed + r_pt) - r_pt, abs=1e-12)
        ev = evaluate_couple("PS", point, X1, m1.twist(t), CONE, X2, BASE.twist(t), c.u, 1.0)
        assert ev.gap == pytest.approx(signed, abs=1e-12)
        np.testing.assert_allclose(ev.n, n, atol=1e-12)
        np.testing.assert_allclose(ev.frame.T @ ev.frame, np.eye(3), atol=1e-12)
        np.testing.assert_allclose(ev.p1, p - r_pt * n, atol=1e-12)
        ev_down = evaluate_couple("PS", point, X1, m1.twist(t), CONE, X2, BASE.twist(t), c.u,
                                  -1.0)
        assert ev_down.gap == pytest.approx(-signed - 2 * r_pt, abs=1e-12)
        assert ev.conditioning > 0.1


def test_point_over_plane_closed_form():
    """A plane rectangle with non-unit, non-orthogonal edges: u solves the 2x2 normal
    equations of the projection; the gap is the height over the plane."""
    e0, e1 = np.array([0.3, 0.0, 0.1]), np.array([0.1, 0.4, 0.0])
    plane, X = PlaneRect((0.1, -0.2, 0.0), e0, e1, size=(2.0, 2.0)), (np.eye(3), np.zeros(3))
    nrm = np.cross(e0, e1) / np.linalg.norm(np.cross(e0, e1))
    for h in (0.05, -0.03):
        p = plane.o + 0.7 * e0 + 1.1 * e1 + h * nrm
        c = seek_couple(posed(Point(p), *X), posed(plane, *X))
        np.testing.assert_allclose(c.u2, [0.7, 1.1], atol=1e-12)
        ev = evaluate_couple("PS", Point(p), X, (np.zeros(3),) * 2, plane, X,
                             (np.zeros(3),) * 2, c.u, 1.0)
        assert ev.gap == pytest.approx(h, abs=1e-14)


@pytest.mark.parametrize("m1", MOVING)
def test_tracking_follows_closed_form(m1):
    """u integrated by Eq. (47) (u' = -Fu^-1 Ft) equals the closed-form foot on the cone."""
    point = Point((0.0, 0.02, 0.0))

    def rate(t, u):
        return evaluate_couple("PS", point, m1.pose(t), m1.twist(t), CONE, BASE.pose(t),
                               BASE.twist(t), u, 1.0, project=False).udot

    def u_exact(t):
        X1 = m1.pose(t)
        return cone_closed_form(X1[1] + X1[0] @ point.p, *BASE.pose(t))[0]

    sol = solve_ivp(rate, (0.0, 1.0), u_exact(0.0), rtol=1e-12, atol=1e-13, dense_output=True,
                    method="DOP853")
    for t in np.linspace(0.0, 1.0, 9):
        np.testing.assert_allclose(sol.sol(t), u_exact(t), atol=1e-8)


@pytest.mark.parametrize("r_pt", [0.0, 0.003])
@pytest.mark.parametrize("m1", MOVING)
def test_rates_and_bias_by_finite_differences(m1, r_pt):
    """vn = g', u' = du/dt, g'' = n . (a1 - a2) + bias_n and (t . v_rel)' = t . (a1 - a2) +
    bias_t, by central differences along the couple."""
    point = Point((0.03, -0.02, 0.04), r_pt)

    def ev_at(t):
        X1 = m1.pose(t)
        u = cone_closed_form(X1[1] + X1[0] @ point.p, *BASE.pose(t))[0]
        return evaluate_couple("PS", point, X1, m1.twist(t), CONE, BASE.pose(t),
                               BASE.twist(t), u, 1.0)

    check_rates_by_finite_differences(ev_at, m1, BASE)


def test_projection_corrects_drift():
    X = (np.eye(3), np.zeros(3))
    p = np.array([0.4, 0.1, 0.1])
    u, _, _ = cone_closed_form(p, *X)
    ev = evaluate_couple("PS", Point(p), X, (np.zeros(3),) * 2, CONE, X, (np.zeros(3),) * 2,
                         u + [1e-4, -2e-4], 1.0)
    np.testing.assert_allclose(ev.u, u, atol=1e-7)          # one Newton step from 2e-4
    np.testing.assert_allclose(ev.drift, u - (u + [1e-4, -2e-4]), atol=1e-7)


def test_point_on_axis_is_not_isolated_and_off_domain_not_interior():
    """On the cone's axis every theta is closest (Fu's theta row is -rho rho_p = 0): the
    couple is not isolated. Beyond the z range the foot lies on the domain's end: not a
    potential contact."""
    X = (np.eye(3), np.zeros(3))
    on_axis = Point((0.0, 0.0, 0.1))
    c = seek_couple(posed(on_axis, *X), posed(CONE, *X))
    _, _, cond = closest_point_conditions("PS", on_axis, X, CONE, X, c.u, conditioning=True)
    assert cond < 1e-12
    assert not contact_couple("PS", on_axis, X, CONE, X, c, conditioning_min=1e-6).usable
    beyond = Point((0.2, 0.0, 0.6))                      # above z = 0.4 in the meridian
    c = seek_couple(posed(beyond, *X), posed(CONE, *X))
    assert not c.interior and c.u2[1] == pytest.approx(CONE.upper[1], abs=1e-12)
    f = contact_couple("PS", beyond, X, CONE, X, c, conditioning_min=1e-6)
    assert not f.usable and "domain end" in f.reason


@pytest.mark.parametrize("height", [0.001, -0.001, 0.005, -0.005])
def test_an_overlapping_sphere_keeps_its_centres_side(height):
    """A corner sphere of radius 2 mm whose centre lies ``height`` from a plane: sigma is the
    side of the centre (sign of height), also while the sphere overlaps the plane (|height| <
    r), and the gap is |height| - r (closed form), negative for the overlap."""
    r = 0.002
    plane, X = PlaneRect((-1.0, -1.0, 0.0), (1.0, 0.0, 0.0), (0.0, 1.0, 0.0), size=(2.0, 2.0)), \
        (np.eye(3), np.zeros(3))
    point = Point((0.1, 0.2, height), r)
    c = seek_couple(posed(point, *X), posed(plane, *X))
    still = (np.zeros(3),) * 2
    raw = evaluate_couple("PS", point, X, still, plane, X, still, c.u, 1.0)
    sigma = relation("PS").sigma(None, raw.gap, r)
    assert sigma == math.copysign(1.0, height)
    ev = evaluate_couple("PS", point, X, still, plane, X, still, c.u, sigma)
    assert ev.gap == pytest.approx(abs(height) - r, abs=1e-15)
    np.testing.assert_allclose(ev.n, [0.0, 0.0, sigma], atol=1e-15)
