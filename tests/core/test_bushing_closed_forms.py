"""The compiled bushing (`drake_dock.core.kernels.bushing`) against closed forms, without Drake:
a translation of C along one axis of A gives the force -k x on that axis and no torque; a
rotation about one axis of A gives the torque -k_t theta about it; velocities alone give the
damping forces; a rigid motion of the two frames together gives no damping; action and
reaction (F_A shifted to Co is -F_C, in any state, for the whole and for the damping part);
the power of the spring part is minus the rate of the potential 1/2 k_f . xyz^2 +
1/2 k_t . rpy^2 (finite differences: any motion for the rotational part, a rotation about a
fixed axis for the translational part, where Drake's rate of xyz is exact, and not otherwise);
the power of the damping part; the gimbal-lock flag."""
import math

import numpy as np
import pytest

from drake_dock.core.kernels.bushing import (GIMBAL_LOCK, GIMBAL_LOCK_COS_PITCH, NONFINITE, OK,
                                             bushing_coordinates, bushing_wrenches,
                                             half_rotation, roll_pitch_yaw)
from drake_dock.core.kernels.frames import frame

RNG = np.random.default_rng(5)
K_T = np.array([105.0, 120.0, 938.0])      # distinct per axis, to catch a permutation
D_T = np.array([10.0, 13.0, 520.0])
K_F = np.array([938.0, 71400.0, 947.0])
D_F = np.array([520.0, 77.0, 532.0])
Z = np.zeros(3)


def _hat(a):
    return np.array([[0, -a[2], a[1]], [a[2], 0, -a[0]], [-a[1], a[0], 0]])


def _rot(axis, angle):
    K = _hat(np.asarray(axis, float) / np.linalg.norm(axis))
    return np.eye(3) + math.sin(angle) * K + (1 - math.cos(angle)) * K @ K


def _random_rotation():
    return _rot(RNG.normal(size=3), RNG.uniform(0, math.pi))


def _call(R_WA, p_WA, w_WA, v_WA, R_WC, p_WC, w_WC, v_WC, k_t=K_T, d_t=D_T, k_f=K_F, d_f=D_F):
    out = np.zeros((4, 6))
    status = bushing_wrenches(frame(R_WA, p_WA, w_WA, v_WA), frame(R_WC, p_WC, w_WC, v_WC),
                              np.array([k_t, d_t, k_f, d_f], dtype=float), out)
    return status, out


def _coordinates(R_WA, p_WA, R_WC, p_WC, xyz, rpy):
    return bushing_coordinates(frame(R_WA, p_WA), frame(R_WC, p_WC), xyz, rpy)


def _random_frames(tilt=math.radians(40), stroke=0.2):
    R_WA, p_WA = _random_rotation(), RNG.normal(0, 2, 3)
    R_AC = _rot(RNG.normal(size=3), RNG.uniform(0, tilt))
    R_WC, p_WC = R_WA @ R_AC, p_WA + R_WA @ RNG.uniform(-stroke, stroke, 3)
    return (R_WA, p_WA, RNG.normal(0, .5, 3), RNG.normal(0, .5, 3),
            R_WC, p_WC, RNG.normal(0, .5, 3), RNG.normal(0, .5, 3))


def _shift(F, r):
    """The spatial force F = [tau, f] about P shifted to Q = P + r: [tau - r x f, f]."""
    return np.r_[F[:3] - np.cross(r, F[3:]), F[3:]]


@pytest.mark.parametrize("axis", [0, 1, 2])
def test_translation_along_an_axis_of_A(axis):
    R_WA, p_WA = _random_rotation(), RNG.normal(0, 2, 3)
    x = 0.137
    p_WC = p_WA + x * R_WA[:, axis]
    status, (F_C, F_A, F_Cd, F_Ad) = _call(R_WA, p_WA, Z, Z, R_WA, p_WC, Z, Z)
    assert status == OK
    f = -K_F[axis] * x * R_WA[:, axis]
    np.testing.assert_allclose(F_C, np.r_[Z, f], rtol=0, atol=1e-12 * abs(f).max())
    np.testing.assert_allclose(F_A, np.r_[Z, -f], rtol=0, atol=1e-12 * abs(f).max())
    assert not F_Cd.any() and not F_Ad.any()          # no velocities: no damping


def test_translation_without_rotation_applies_f_at_the_midpoint():
    """R_AC = I: B = A, f = -K_F [x y z]_A, and its moment about Co is that of f at the midpoint
    of Ao and Co (not zero unless f is parallel to r: distinct stiffnesses)."""
    R_WA, p_WA = _random_rotation(), RNG.normal(0, 2, 3)
    r_A = np.array([0.05, -0.1, 0.15])
    r = R_WA @ r_A
    status, (F_C, F_A, _, _) = _call(R_WA, p_WA, Z, Z, R_WA, p_WA + r, Z, Z)
    assert status == OK
    f = R_WA @ (-K_F * r_A)
    np.testing.assert_allclose(F_C, np.r_[np.cross(-r / 2, f), f], atol=1e-11 * abs(f).max())
    np.testing.assert_allclose(F_A, np.r_[np.cross(r / 2, -f), -f], atol=1e-11 * abs(f).max())


@pytest.mark.parametrize("axis", [0, 1, 2])
@pytest.mark.parametrize("theta", [0.3, -1.2, 2.9])
def test_rotation_about_an_axis_of_A(axis, theta):
    if axis == 1 and abs(theta) > math.pi / 2:
        theta = math.copysign(1.5, theta)               # pitch stays in [-pi/2, pi/2]
    R_WA, p_WA = _random_rotation(), RNG.normal(0, 2, 3)
    e = np.eye(3)[axis]
    status, (F_C, F_A, _, _) = _call(R_WA, p_WA, Z, Z, R_WA @ _rot(e, theta), p_WA, Z, Z)
    assert status == OK
    t = -K_T[axis] * theta * R_WA[:, axis]
    np.testing.assert_allclose(F_C, np.r_[t, Z], rtol=0, atol=1e-12 * abs(t).max())
    np.testing.assert_allclose(F_A, np.r_[-t, Z], rtol=0, atol=1e-12 * abs(t).max())


@pytest.mark.parametrize("axis", [0, 1, 2])
def test_velocities_alone_give_the_damping(axis):
    """At R_AC = I, Co = Ao: C turning at w and moving at u along axis i of A (A at rest) gives
    the torque -d_t[i] w and the force -d_f[i] u on that axis, all of it damping."""
    R_WA, p_WA = _random_rotation(), RNG.normal(0, 2, 3)
    n, w, u = R_WA[:, axis], 0.7, -0.3
    status, (F_C, F_A, F_Cd, F_Ad) = _call(R_WA, p_WA, Z, Z, R_WA, p_WA, w * n, u * n)
    assert status == OK
    expected = np.r_[-D_T[axis] * w * n, -D_F[axis] * u * n]
    np.testing.assert_allclose(F_C, expected, rtol=0, atol=1e-12 * abs(expected).max())
    scale = 1e-12 * abs(expected).max()           # the angles are round-off, not zero
    np.testing.assert_allclose(F_Cd, F_C, rtol=0, atol=scale)
    np.testing.assert_allclose(F_Ad, F_A, rtol=0, atol=scale)
    np.testing.assert_allclose(F_A, -expected, rtol=0, atol=scale)


def test_a_rigid_motion_of_both_frames_gives_no_damping():
    for _ in range(50):
        R_WA, p_WA, w, v, R_WC, p_WC, _, _ = _random_frames()
        v_C = v + np.cross(w, p_WC - p_WA)              # C moving rigidly with A
        status, (F_C, F_A, F_Cd, F_Ad) = _call(R_WA, p_WA, w, v, R_WC, p_WC, w, v_C)
        assert status == OK
        scale = abs(F_C).max()
        assert abs(F_Cd).max() < 1e-12 * scale and abs(F_Ad).max() < 1e-12 * scale


def test_action_and_reaction():
    """F_A (about Ao) shifted to Co is exactly -F_C (about Co): the bushing's forces on A and on
    C are opposite, with a common line of action through the midpoint Bo of Ao and Co (-f acts
    on A at the point Ap coincident with Bo). So the total wrench of F_C and F_A about any
    common point is zero, for the whole and for the damping part."""
    for _ in range(200):
        R_WA, p_WA, w_A, v_A, R_WC, p_WC, w_C, v_C = _random_frames()
        status, (F_C, F_A, F_Cd, F_Ad) = _call(R_WA, p_WA, w_A, v_A, R_WC, p_WC, w_C, v_C)
        assert status == OK
        r = p_WC - p_WA
        for Fc, Fa in ((F_C, F_A), (F_Cd, F_Ad)):
            scale = abs(Fc).max()
            np.testing.assert_allclose(_shift(Fa, r), -Fc, rtol=0, atol=1e-13 * scale)
            P = RNG.normal(0, 3, 3)                     # any point: the total is zero
            total = _shift(Fa, P - p_WA) + _shift(Fc, P - p_WC)
            assert abs(total).max() < 1e-12 * scale * (1 + np.linalg.norm(P - p_WA))
        # the force on A acts through the midpoint: its moment about Bo is -t alone
        t_A = _shift(F_A, r / 2)[:3]
        t_C = _shift(F_C, -r / 2)[:3]
        np.testing.assert_allclose(t_A, -t_C, atol=1e-12 * abs(F_C).max())


def _potential(R_WA, p_WA, R_WC, p_WC):
    xyz, rpy = np.zeros(3), np.zeros(3)
    assert _coordinates(R_WA, p_WA, R_WC, p_WC, xyz, rpy) == OK
    return 0.5 * K_F @ xyz**2 + 0.5 * K_T @ rpy**2


def _motion(t, changing_axis):
    """Frame A on a rigid motion (constant w_A, v_A) and C relative to A: R_AC turning about a
    fixed axis (or, with changing_axis, about an axis that turns too) and r_A on a parabola.
    Returns the eight kernel inputs at time t."""
    R0, p0 = _MOTION["R0"], _MOTION["p0"]
    w_A, v_A = _MOTION["w_A"], _MOTION["v_A"]
    lam, th0, th1 = _MOTION["lam"], 0.35, 0.8
    r0, r1, r2 = _MOTION["r0"], _MOTION["r1"], _MOTION["r2"]
    R_WA = _rot(w_A, np.linalg.norm(w_A) * t) @ R0
    p_WA = p0 + v_A * t
    R_AC = _rot(lam, th0 + th1 * t)
    w_AC_A = th1 * lam / np.linalg.norm(lam)
    if changing_axis:                                   # then a second turn about another axis
        mu, s1 = np.array([0.2, -1.0, 0.4]), 0.6
        R_AC = R_AC @ _rot(mu, 0.3 + s1 * t)
        w_AC_A = w_AC_A + R_AC @ _rot(mu, 0.3 + s1 * t).T @ (s1 * mu / np.linalg.norm(mu))
    r_A = r0 + r1 * t + r2 * t * t
    rdot_A = r1 + 2 * r2 * t
    R_WC = R_WA @ R_AC
    p_WC = p_WA + R_WA @ r_A
    w_WC = w_A + R_WA @ w_AC_A
    v_WC = v_A + np.cross(w_A, R_WA @ r_A) + R_WA @ rdot_A
    return R_WA, p_WA, w_A, v_A, R_WC, p_WC, w_WC, v_WC


_MOTION = {"R0": _random_rotation(), "p0": RNG.normal(0, 2, 3), "w_A": RNG.normal(0, .5, 3),
           "v_A": RNG.normal(0, .5, 3), "lam": RNG.normal(size=3),
           "r0": np.array([0.04, -0.06, 0.1]), "r1": np.array([-0.2, 0.1, 0.05]),
           "r2": np.array([0.3, -0.2, 0.1])}


def _spring_power(t, changing_axis, k_t, k_f):
    x = _motion(t, changing_axis)
    status, (F_C, F_A, F_Cd, F_Ad) = _call(*x, k_t=k_t, k_f=k_f)
    assert status == OK
    V_A, V_C = np.r_[x[2], x[3]], np.r_[x[6], x[7]]
    return (F_C - F_Cd) @ V_C + (F_A - F_Ad) @ V_A, F_Cd @ V_C + F_Ad @ V_A


def _potential_rate(t, changing_axis, k_t, k_f, h=1e-5):
    def V(s):
        R_WA, p_WA, _, _, R_WC, p_WC, _, _ = _motion(s, changing_axis)
        xyz, rpy = np.zeros(3), np.zeros(3)
        assert _coordinates(R_WA, p_WA, R_WC, p_WC, xyz, rpy) == OK
        return 0.5 * k_f @ xyz**2 + 0.5 * k_t @ rpy**2
    return (V(t + h) - V(t - h)) / (2 * h)


@pytest.mark.parametrize("t", [0.0, 0.4, 0.9])
def test_spring_power_is_minus_the_potential_rate_about_a_fixed_axis(t):
    P, _ = _spring_power(t, False, K_T, K_F)
    dV = _potential_rate(t, False, K_T, K_F)
    assert abs(P + dV) < 1e-7 * abs(dV)


@pytest.mark.parametrize("t", [0.0, 0.4, 0.9])
def test_torque_spring_power_is_minus_the_potential_rate_for_any_rotation(t):
    """tau . q' is the rate of 1/2 k_t . q^2 whatever the rotation (t . w_AC = tau . q')."""
    P, _ = _spring_power(t, True, K_T, Z)
    dV = _potential_rate(t, True, K_T, Z)
    assert abs(P + dV) < 1e-7 * abs(dV)


def test_force_spring_power_is_not_the_potential_rate_when_the_axis_turns():
    """Drake takes frame B's angular velocity in A to be w_AC / 2, which it is only when R_AC
    turns about a fixed axis: otherwise the power of the translational springs is not minus
    the rate of 1/2 k_f . xyz^2 (the relative difference is of order one here). Documents the
    model the kernel reproduces (and why `stewart_potential` is exact only about one axis)."""
    P, _ = _spring_power(0.4, True, Z, K_F)
    dV = _potential_rate(0.4, True, Z, K_F)
    assert abs(P + dV) > 1e-2 * abs(dV)


def test_damping_power_is_minus_the_dissipation():
    """The damping part's power is -(d_t . q'^2 + d_f . xyz'^2) <= 0, with q' and xyz' the
    finite-difference rates of the coordinates (a rotation about a fixed axis)."""
    t, h = 0.4, 1e-5
    coords = []
    for s in (t - h, t + h):
        R_WA, p_WA, _, _, R_WC, p_WC, _, _ = _motion(s, False)
        xyz, rpy = np.zeros(3), np.zeros(3)
        _coordinates(R_WA, p_WA, R_WC, p_WC, xyz, rpy)
        coords.append((xyz, rpy))
    xyz_dt = (coords[1][0] - coords[0][0]) / (2 * h)
    q_dt = (coords[1][1] - coords[0][1]) / (2 * h)
    _, P_damp = _spring_power(t, False, K_T, K_F)
    expected = -(D_T @ q_dt**2 + D_F @ xyz_dt**2)
    assert P_damp < 0 and abs(P_damp - expected) < 1e-7 * abs(expected)


def test_half_rotation_and_angles():
    for _ in range(100):
        R = _random_rotation()
        R9 = tuple(R.ravel())
        H = np.array(half_rotation(R9)).reshape(3, 3)
        np.testing.assert_allclose(H @ H, R, atol=1e-14)
        np.testing.assert_allclose(H.T @ H, np.eye(3), atol=1e-14)
        assert np.trace(H) >= 1.0                        # the half angle is <= 90 deg
        roll, pitch, yaw = roll_pitch_yaw(R9)
        Rrpy = _rot([0, 0, 1], yaw) @ _rot([0, 1, 0], pitch) @ _rot([1, 0, 0], roll)
        np.testing.assert_allclose(Rrpy, R, atol=1e-14)
        assert abs(pitch) <= math.pi / 2


@pytest.mark.parametrize("pitch_deg, status", [(89.4, OK), (-89.4, OK), (89.6, GIMBAL_LOCK),
                                               (90.0, GIMBAL_LOCK), (-90.0, GIMBAL_LOCK)])
def test_gimbal_lock_flag(pitch_deg, status):
    """Drake throws where |cos pitch| < 0.008 (89.54 deg); the kernel returns GIMBAL_LOCK there
    and writes NaN into every output."""
    assert math.cos(math.radians(89.6)) < GIMBAL_LOCK_COS_PITCH < math.cos(math.radians(89.4))
    R_WA, p_WA = _random_rotation(), RNG.normal(0, 2, 3)
    R_AC = _rot([0, 0, 1], 0.3) @ _rot([0, 1, 0], math.radians(pitch_deg)) @ _rot([1, 0, 0], 0.2)
    got, out = _call(R_WA, p_WA, Z, RNG.normal(size=3), R_WA @ R_AC, p_WA + 0.1, RNG.normal(size=3),
                     Z)
    assert got == status
    if status == GIMBAL_LOCK:
        assert all(np.isnan(F).all() for F in out)
    else:
        assert all(np.isfinite(F).all() for F in out)


def test_non_finite_input_is_flagged():
    R_WA, p_WA, w_A, v_A, R_WC, p_WC, w_C, v_C = _random_frames()
    v_C = v_C.copy()
    v_C[1] = np.inf
    status, _ = _call(R_WA, p_WA, w_A, v_A, R_WC, p_WC, w_C, v_C)
    assert status == NONFINITE
