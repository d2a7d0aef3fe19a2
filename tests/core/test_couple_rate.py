"""Eq. (47) tracking along prescribed smooth motions of the two APDSes (kinematics only)."""
import math

import numpy as np
import pytest
from scipy.integrate import solve_ivp

from closest_reference import scipy_closest
from drake_dock.core.patches import Segment, posed
from drake_dock.core.seeking import seek_couple
from drake_dock.core.couple_rate import SingularCoupleError, couple_rate
from drake_dock.docking.geometry.pairs import R_MATCHED
from drake_dock.docking.geometry.rotations import rot_x, rot_z
from drake_dock.docking.geometry.scene import DockingScene


def chaser_motion(t, offset=0.0):
    """A smooth prescribed motion of the chaser APDS frame relative to the fixed target APDS:
    pose (R, p) and world twist (w, v). ``offset`` moves it sideways (a ring nearly coaxial
    with a cone has no isolated closest couple)."""
    a, ad = 0.08 * math.sin(1.3 * t), 0.08 * 1.3 * math.cos(1.3 * t)
    b, bd = 0.05 * math.sin(0.7 * t), 0.05 * 0.7 * math.cos(0.7 * t)
    Rz, Rb = rot_z(a), rot_x(b)
    R = Rz @ Rb @ R_MATCHED
    w = ad * np.array([0.0, 0.0, 1.0]) + Rz @ (bd * np.array([1.0, 0.0, 0.0]))
    p = np.array([offset + 0.03 * math.sin(t), 0.02 * t, 0.12 - 0.04 * t])
    v = np.array([0.03 * math.cos(t), 0.02, -0.04])
    return R, p, w, v


# Curve-surface couples are tracked in test_couple.py on a scene that keeps a positive gap: the
# contact form of the conditions (Eq. 37-38) describes a couple that is apart or touching, not
# a ring passing through a surface.
@pytest.mark.parametrize("name, offset", [("cc_T2_C4", 0.0), ("cc_T6_C6", 0.0)])
def test_tracking_matches_reseeking(geom, name, offset):
    pair = next(p for p in DockingScene(geom, "paper").pairs if p.name == name)
    fixed = (np.eye(3), np.zeros(3))

    def placed(t):
        R, p, w, v = chaser_motion(t, offset)
        pose = {"target_apds": fixed, "chaser_apds": (R, p)}
        tw = {"target_apds": (np.zeros(3), np.zeros(3)), "chaser_apds": (w, v)}
        return (posed(pair.patch1, *pose[pair.body1]), posed(pair.patch2, *pose[pair.body2]),
                tw[pair.body1], tw[pair.body2])

    P1, P2, _, _ = placed(0.0)
    c0 = seek_couple(P1, P2)
    assert c0.interior
    n1 = pair.patch1.dim

    def rhs(t, u):
        P1, P2, t1, t2 = placed(t)
        return couple_rate(P1, P2, u[:n1], u[n1:], t1, t2)

    ts = np.linspace(0.0, 1.0, 11)
    sol = solve_ivp(rhs, (0, 1), c0.u, method="DOP853", rtol=1e-12, atol=1e-14, t_eval=ts)
    assert sol.success
    for k, t in enumerate(ts):
        P1, P2, _, _ = placed(t)
        # The re-sought couple: the local minimum of the distance next to the tracked couple
        # (bounded L-BFGS from it, tests/closest_reference.py).
        u1, u2, _ = scipy_closest(P1, P2, [sol.y[:, k]])
        np.testing.assert_allclose(sol.y[:, k], np.concatenate([u1, u2]), atol=1e-8)
        # And it is the global closest couple of the pair while interior.
        assert np.linalg.norm(P1.position(u1) - P2.position(u2)) <= \
            seek_couple(P1, P2).distance + 1e-9


def test_parallel_curves_raise_typed_error():
    """Two parallel segments: Eq. (39) fails and the couple is not isolated."""
    a = posed(Segment([0, 0, 0], [1, 0, 0]), np.eye(3), np.zeros(3))
    b = posed(Segment([0, 0, 0.1], [1, 0, 0.1]), np.eye(3), np.zeros(3))
    z = (np.zeros(3), np.zeros(3))
    with pytest.raises(SingularCoupleError, match="cc_test"):
        couple_rate(a, b, np.array([0.5]), np.array([0.5]), z, (np.zeros(3), [0, 0, 1.0]),
                    name="cc_test", time=0.25)
