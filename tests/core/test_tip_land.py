"""A point against an annular sector (`AnnularSector`, a petal's tip land; kind "PS") against
closed forms: the sector's derivatives by finite differences, its bounded (not periodic) theta,
the couple's foot (rho, theta), gap (the height over the plane) and normal for a point over it,
the tracking of u along a motion (Eq. 47), and a point beyond the land's edge (not interior)."""
import math

import numpy as np
import pytest
from scipy.integrate import solve_ivp

from drake_dock.core.couple import evaluate_couple
from drake_dock.core.patches import AnnularSector, Point, posed
from drake_dock.core.seeking import contact_couple, seek_couple
from tests.motions import Motion, check_rates_by_finite_differences

LAND = AnnularSector(0.399, 0.401, 0.2, (0.4, 0.8))
STILL = (np.zeros(3),) * 2
BASE = Motion(p0=(0.0, 0.0, 0.0), V=(0.0, 0.0, 0.01), a=(0.5, 0.9), b=(0.1, 1.7))
MOVING = Motion(p0=(0.3, 0.25, 0.25), V=(0.0, 0.0, -0.05), a=(0.3, 1.3), b=(0.2, 0.7))


def land_closed_form(p, R2, o2):
    """(u = (rho, theta), height over the plane z = 0.2, normal) of a world point p over the
    land in the frame (R2, o2)."""
    q = R2.T @ (p - o2)
    return np.array([math.hypot(q[0], q[1]), math.atan2(q[1], q[0])]), q[2] - 0.2, R2[:, 2]


def test_derivatives_by_finite_differences_and_bounded_theta():
    u, h = np.array([0.4, 0.6]), 1e-6
    T = LAND.first(u)
    K = LAND.second(u)
    for a in range(2):
        du = np.eye(2)[a] * h
        np.testing.assert_allclose(T[:, a], (LAND.position(u + du) - LAND.position(u - du))
                                   / (2 * h), atol=1e-9)
        np.testing.assert_allclose(K[:, :, a], (LAND.first(u + du) - LAND.first(u - du))
                                   / (2 * h), atol=1e-8)
    assert LAND.periodic == (False, False)
    np.testing.assert_allclose(LAND.clip([0.5, 1.0]), [0.401, 0.8])
    assert LAND.margin([0.4, 0.9])[1] == pytest.approx(-0.1)


@pytest.mark.parametrize("height", [0.03, -0.002])
def test_a_point_over_the_land(height):
    """Foot, gap and normal of a point over the land (closed form), turned and moved."""
    R2 = np.array([[0.0, -1.0, 0.0], [1.0, 0.0, 0.0], [0.0, 0.0, 1.0]])
    o2 = np.array([0.1, -0.2, 0.3])
    p = o2 + R2 @ np.array([0.4005 * math.cos(0.5), 0.4005 * math.sin(0.5), 0.2 + height])
    u, gap, n = land_closed_form(p, R2, o2)
    c = seek_couple(posed(Point(p), np.eye(3), np.zeros(3)), posed(LAND, R2, o2))
    assert c.interior
    np.testing.assert_allclose(c.u2, u, atol=1e-12)
    ev = evaluate_couple("PS", Point(p), (np.eye(3), np.zeros(3)), STILL, LAND, (R2, o2), STILL,
                         c.u, 1.0)
    assert ev.gap == pytest.approx(gap, abs=1e-14)
    np.testing.assert_allclose(ev.n, n, atol=1e-14)
    assert ev.conditioning > 0.1


def test_tracking_and_rates_along_a_motion():
    """u integrated by Eq. (47) equals the closed-form foot; the rates and the Eq. (52) terms
    match central differences."""
    point = Point((0.0, 0.0, 0.0))

    def foot(t):
        X1 = MOVING.pose(t)
        return land_closed_form(X1[1] + X1[0] @ point.p, *BASE.pose(t))[0]

    def rate(t, u):
        return evaluate_couple("PS", point, MOVING.pose(t), MOVING.twist(t), LAND,
                               BASE.pose(t), BASE.twist(t), u, 1.0, project=False).udot

    sol = solve_ivp(rate, (0.0, 1.0), foot(0.0), rtol=1e-12, atol=1e-13, dense_output=True,
                    method="DOP853")
    for t in np.linspace(0.0, 1.0, 9):
        np.testing.assert_allclose(sol.sol(t), foot(t), atol=1e-8)
    check_rates_by_finite_differences(
        lambda t: evaluate_couple("PS", point, MOVING.pose(t), MOVING.twist(t), LAND,
                                  BASE.pose(t), BASE.twist(t), foot(t), 1.0), MOVING, BASE)


@pytest.mark.parametrize("where", [(0.405, 0.6), (0.4, 0.9)])
def test_a_point_beyond_the_land_is_not_a_contact(where):
    """Beyond the land's width (rho) or past its end (theta) the foot lies on the domain's
    edge: not interior, not a potential contact."""
    rho, th = where
    p = np.array([rho * math.cos(th), rho * math.sin(th), 0.21])
    X = (np.eye(3), np.zeros(3))
    c = seek_couple(posed(Point(p), *X), posed(LAND, *X))
    assert not c.interior
    f = contact_couple("PS", Point(p), X, LAND, X, c, conditioning_min=1e-6)
    assert not f.usable and "domain end" in f.reason
