"""The free-body kernels (`drake_dock.core.kernels.free_bodies`) against closed forms and
conservation laws, without Drake: the rotation of a quaternion (Rodrigues' formula), q' (the
rotation's rate [w] R), M^-1 (the momenta of the kinetic energy mapped back to the velocities),
the velocity-product terms (a torque-free body conserves its momenta and kinetic energy) and a
contact row (the relative velocity of two body points, its rate by finite differences)."""
import numpy as np
import pytest

from drake_dock.core.kernels.free_bodies import (body_kinematics, frame_kinematics,
                                                 mass_inverse_and_bias, point_rows, qdot,
                                                 rotation)

RNG = np.random.default_rng(7)


def _hat(a):
    return np.array([[0, -a[2], a[1]], [a[2], 0, -a[0]], [-a[1], a[0], 0]])


def _rodrigues(axis, angle):
    K = _hat(axis / np.linalg.norm(axis))
    return np.eye(3) + np.sin(angle) * K + (1 - np.cos(angle)) * K @ K


def _bodies(nb=2):
    """nb bodies: masses, centres of mass in the body frame, inertias about them (SPD)."""
    m = RNG.uniform(1.0, 50.0, nb)
    c_B = RNG.normal(0, 0.4, (nb, 3))
    I_B = []
    for _ in range(nb):
        A = RNG.normal(size=(3, 3))
        I_B.append(A @ A.T + np.eye(3))
    I_B = np.array(I_B)
    qs = np.arange(nb, dtype=np.int64) * 7
    vs = np.arange(nb, dtype=np.int64) * 6
    return m, c_B, I_B, np.linalg.inv(I_B), qs, vs


def _state(nb, scale=1.0):
    q, v = np.empty(7 * nb), RNG.normal(0, 1.0, 6 * nb)
    for b in range(nb):
        a = RNG.normal(size=4)
        q[7 * b:7 * b + 4] = scale * a / np.linalg.norm(a)
        q[7 * b + 4:7 * b + 7] = RNG.normal(size=3)
    return q, v


def test_rotation_of_a_quaternion_is_rodrigues_and_ignores_its_norm():
    axis, angle = np.array([0.3, -1.0, 0.5]), 1.234
    e = axis / np.linalg.norm(axis)
    quat = np.concatenate([[np.cos(angle / 2)], np.sin(angle / 2) * e])
    np.testing.assert_allclose(rotation(*quat), _rodrigues(axis, angle), atol=1e-15)
    np.testing.assert_allclose(rotation(*(2.5 * quat)), _rodrigues(axis, angle), atol=1e-15)


def test_qdot_turns_the_rotation_at_the_world_angular_velocity():
    m, c_B, I_B, I_inv, qs, vs = _bodies(1)
    q, v = _state(1)
    qd = np.empty(7)
    qdot(qs, vs, q, v, qd)
    h = 1e-6
    Rp, Rm = rotation(*(q[:4] + h * qd[:4])), rotation(*(q[:4] - h * qd[:4]))
    np.testing.assert_allclose((Rp - Rm) / (2 * h), _hat(v[:3]) @ rotation(*q[:4]), atol=1e-8)
    np.testing.assert_array_equal(qd[4:], v[3:])
    assert abs(q[:4] @ qd[:4]) < 1e-15        # a unit quaternion stays unit


def _momenta(m, c, I_cm, w, vo):
    """[H about the origin, L] of a body: the gradient of its kinetic energy in (w, vo)."""
    v_cm = vo + np.cross(w, c)
    return np.concatenate([I_cm @ w + np.cross(c, m * v_cm), m * v_cm])


def test_mass_inverse_maps_the_momenta_back_to_the_velocities():
    nb = 3
    m, c_B, I_B, I_inv, qs, vs = _bodies(nb)
    q, v = _state(nb, scale=1.7)
    Rb, pb, wb, vb = (np.empty((nb, 3, 3)), np.empty((nb, 3)), np.empty((nb, 3)),
                      np.empty((nb, 3)))
    body_kinematics(qs, vs, q, v, Rb, pb, wb, vb)
    Minv, bias = np.zeros((6 * nb, 6 * nb)), np.zeros(6 * nb)
    mass_inverse_and_bias(vs, m, c_B, I_inv, I_B, Rb, wb, Minv, bias)
    p = np.concatenate([_momenta(m[b], Rb[b] @ c_B[b], Rb[b] @ I_B[b] @ Rb[b].T, wb[b], vb[b])
                        for b in range(nb)])
    np.testing.assert_allclose(Minv @ p, v, rtol=1e-12, atol=1e-12)
    np.testing.assert_allclose(Minv, Minv.T, atol=1e-12)
    assert np.linalg.eigvalsh(Minv).min() > 0


def test_torque_free_body_conserves_momenta_and_energy():
    """v' = -M^-1 C v (no force): RK4 over 1 s conserves the linear momentum, the angular
    momentum about the world origin and the kinetic energy to the method's error."""
    m, c_B, I_B, I_inv, qs, vs = _bodies(1)
    q, v = _state(1)

    def rates(x):
        q, v = x[:7], x[7:]
        Rb, pb, wb, vb = np.empty((1, 3, 3)), np.empty((1, 3)), np.empty((1, 3)), np.empty((1, 3))
        body_kinematics(qs, vs, q, v, Rb, pb, wb, vb)
        Minv, bias = np.zeros((6, 6)), np.zeros(6)
        mass_inverse_and_bias(vs, m, c_B, I_inv, I_B, Rb, wb, Minv, bias)
        qd = np.empty(7)
        qdot(qs, vs, q, v, qd)
        return np.concatenate([qd, -Minv @ bias])

    def invariants(x):
        q, v = x[:7], x[7:]
        R = rotation(*q[:4])
        c, I_cm = R @ c_B[0], R @ I_B[0] @ R.T
        w, vo = v[:3], v[3:]
        v_cm = vo + np.cross(w, c)
        p_cm = q[4:] + c
        L = m[0] * v_cm
        H = I_cm @ w + np.cross(p_cm, L)
        T = 0.5 * m[0] * v_cm @ v_cm + 0.5 * w @ I_cm @ w
        return np.concatenate([L, H, [T]])

    x = np.concatenate([q, v])
    start = invariants(x)
    h = 1e-3
    for _ in range(1000):
        k1 = rates(x)
        k2 = rates(x + h / 2 * k1)
        k3 = rates(x + h / 2 * k2)
        k4 = rates(x + h * k3)
        x = x + h / 6 * (k1 + 2 * k2 + 2 * k3 + k4)
    np.testing.assert_allclose(invariants(x), start, rtol=1e-8, atol=1e-8 * np.abs(start).max())


@pytest.mark.parametrize("world_second", [False, True])
def test_contact_row_is_the_relative_point_velocity_and_its_rate(world_second):
    """W^T v = D (v_p1 - v_p2) for points fixed on their bodies (frames with offsets), and the
    bias acc = D d/dt(v_p1 - v_p2) at constant twists (v' = 0), by central differences of the
    points' velocities along the motion."""
    nb = 2
    m, c_B, I_B, I_inv, qs, vs = _bodies(nb)
    q, v = _state(nb)
    fb = np.array([0, -1 if world_second else 1], dtype=np.int64)
    R_BF = np.array([_rodrigues(np.array([1.0, 2, 3]), 0.4), _rodrigues(np.array([0, 1.0, 0]), 1)])
    p_BF = RNG.normal(size=(2, 3))
    s = RNG.normal(size=(2, 3))           # the points in their frames
    D = np.linalg.qr(RNG.normal(size=(3, 3)))[0]

    def points(q, v):
        Rb, pb, wb, vb = (np.empty((nb, 3, 3)), np.empty((nb, 3)), np.empty((nb, 3)),
                          np.empty((nb, 3)))
        body_kinematics(qs, vs, q, v, Rb, pb, wb, vb)
        R, o, w, vf = (np.empty((2, 3, 3)), np.empty((2, 3)), np.empty((2, 3)),
                       np.empty((2, 3)))
        frame_kinematics(fb, R_BF, p_BF, Rb, pb, wb, vb, R, o, w, vf)
        p = [o[f] + R[f] @ s[f] for f in range(2)]
        pv = [vf[f] + np.cross(w[f], R[f] @ s[f]) for f in range(2)]
        return p, pv, pb, wb

    p, pv, pb, wb = points(q, v)
    W, acc = np.empty((6 * nb, 3)), np.empty(3)
    point_rows(vs, pb, wb, fb[0], fb[1], p[0], p[1], D, W, acc)
    np.testing.assert_allclose(W.T @ v, D @ (pv[0] - pv[1]), atol=1e-12)
    qd = np.empty(7 * nb)
    qdot(qs, vs, q, v, qd)
    h = 1e-5
    vp = points(q + h * qd, v)[1]
    vm = points(q - h * qd, v)[1]
    fd = D @ ((vp[0] - vp[1]) - (vm[0] - vm[1])) / (2 * h)
    np.testing.assert_allclose(acc, fd, atol=1e-7 * (1 + np.abs(fd).max()))
