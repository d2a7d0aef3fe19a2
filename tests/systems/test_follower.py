"""The follower force (`drake_dock.systems.follower.FollowerForce`) against closed forms: a
body turned by theta about x carries its e3 to (0, -sin theta, cos theta), and about any axis
to Drake's rotation of the same quaternion; it acts in its windows only, closed at the start
and open at the end, and never before the first contact."""
import math

import numpy as np
import pytest
from pydrake.common.eigen_geometry import Quaternion
from pydrake.math import RotationMatrix

from drake_dock.systems.follower import FollowerForce


def _follower(axis_B=(0.0, 0.0, 1.0), windows=((0.0, math.inf),)):
    return FollowerForce(300.0, axis_B, 7, 12, windows)


def _q(quat, at=7, n=14):
    q = np.zeros(n)
    q[at:at + 4] = quat
    return q


def test_the_axis_turns_with_the_body():
    th = 0.3
    w = _follower().axis(_q([math.cos(th / 2), math.sin(th / 2), 0.0, 0.0]))
    np.testing.assert_allclose(w, [0.0, -math.sin(th), math.cos(th)], atol=1e-15)


def test_the_axis_against_drakes_rotation_of_an_unnormalised_quaternion():
    rng = np.random.default_rng(3)
    a = rng.normal(size=3)
    a /= np.linalg.norm(a)
    for _ in range(5):
        quat = rng.normal(size=4)
        R = RotationMatrix(Quaternion(quat / np.linalg.norm(quat))).matrix()
        np.testing.assert_allclose(_follower(tuple(a)).axis(_q(2.5 * quat)), R @ a,
                                   atol=1e-14)


@pytest.mark.parametrize("since, acts", [(-math.inf, False), (-0.1, False), (0.5, True),
                                         (0.99, True), (1.0, False), (2.0, True), (3.0, False)])
def test_it_acts_in_its_windows(since, acts):
    f = _follower(windows=((0.5, 1.0), (2.0, 3.0)))
    tau = np.zeros(18)
    f.add_to(tau, _q([1.0, 0.0, 0.0, 0.0]), since)
    expected = np.zeros(18)
    if acts:
        expected[12 + 5] = 300.0     # the force's z component, after the torque
    assert np.array_equal(tau, expected)
