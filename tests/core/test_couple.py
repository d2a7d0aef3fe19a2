"""Couple kinematics (Definition 2, Eq. 23-25, 40, 47, 52) against finite differences and
re-seeking along prescribed smooth motions."""
import numpy as np
import pytest
from scipy.integrate import solve_ivp

from drake_dock.core.couple import closest_point_conditions, evaluate_couple
from drake_dock.core.patches import Circle, PlaneRect, Segment, posed
from drake_dock.core.seeking import seek_couple
from drake_dock.docking.geometry.rotations import rot_x, rot_z
from couple_scenes import cc_scene, cs_scene, settle


def _frame_on(P, T):
    """Rotation whose columns are (T, n x T, n)... with n the unit normal P."""
    n = P / np.linalg.norm(P)
    t = T - (T @ n) * n
    t /= np.linalg.norm(t)
    return n, t


def scene_at(scene, t, u):
    kind, c1, m1, c2, m2 = scene
    X1, X2 = m1.pose(t), m2.pose(t)
    u = settle(kind, c1, X1, c2, X2, u)
    return evaluate_couple(kind, c1, X1, m1.twist(t), c2, X2, m2.twist(t), u, 1.0)


@pytest.fixture(params=["CS", "CC"])
def scene(request, geom):
    return cs_scene(geom) if request.param == "CS" else cc_scene(geom)


def initial_couple(scene):
    kind, c1, m1, c2, m2 = scene
    c = seek_couple(posed(c1, *m1.pose(0.0)), posed(c2, *m2.pose(0.0)))
    assert c.interior and c.distance > 1e-3
    return c.u


def test_eq47_tracking_matches_reseeking(scene):
    """u* integrated with Eq. (47) over 1 s equals the re-sought couple to 1e-8."""
    kind, c1, m1, c2, m2 = scene
    u0 = initial_couple(scene)

    def rhs(t, u):
        return evaluate_couple(kind, c1, m1.pose(t), m1.twist(t), c2, m2.pose(t), m2.twist(t),
                               u, 1.0, project=False).udot

    ts = np.linspace(0.0, 1.0, 11)
    sol = solve_ivp(rhs, (0, 1), u0, method="DOP853", rtol=1e-12, atol=1e-14, t_eval=ts)
    assert sol.success
    for k, t in enumerate(ts):
        c = seek_couple(posed(c1, *m1.pose(t)), posed(c2, *m2.pose(t)))
        assert c.interior
        np.testing.assert_allclose(sol.y[:, k], c.u, atol=1e-8)


def test_frame_gap_and_velocity(scene):
    """Definition 2: orthonormal frame, n along P1 - P2, gap = |P1 - P2|; the gap rate and the
    couple rate equal central differences along the motion (Eq. 23-25, 47)."""
    kind, c1, m1, c2, m2 = scene
    u = initial_couple(scene)
    h = 1e-5
    for t in (0.2, 0.55, 0.9):
        ev = scene_at(scene, t, u)
        u = ev.u
        Rf = ev.frame
        np.testing.assert_allclose(Rf.T @ Rf, np.eye(3), atol=1e-12)
        assert np.linalg.det(Rf) > 0
        d = ev.p1 - ev.p2
        np.testing.assert_allclose(ev.gap, np.linalg.norm(d), rtol=1e-10)
        np.testing.assert_allclose(np.cross(ev.n, d), 0, atol=1e-12)
        ep, em = scene_at(scene, t + h, u), scene_at(scene, t - h, u)
        np.testing.assert_allclose(ev.udot, (ep.u - em.u) / (2 * h), rtol=1e-6, atol=1e-9)
        np.testing.assert_allclose(ev.vn, (ep.gap - em.gap) / (2 * h), rtol=1e-7, atol=1e-10)


def test_second_derivatives_eq52(scene):
    """g'' = n.(a1 - a2) + bias_n and (t.v_rel)' = t.(a1 - a2) + bias_t, with a_i the
    accelerations of the material points, against central differences of g' and v_t."""
    kind, c1, m1, c2, m2 = scene
    u = initial_couple(scene)
    h = 1e-5
    for t in (0.3, 0.8):
        ev = scene_at(scene, t, u)
        u = ev.u
        arel = m1.acceleration(t, ev.p1) - m2.acceleration(t, ev.p2)
        ep, em = scene_at(scene, t + h, u), scene_at(scene, t - h, u)
        gdd = ev.n @ arel + ev.bias_n
        vtd = np.array([ev.ta @ arel, ev.tb @ arel]) + ev.bias_t
        scale = np.abs(arel).max() + 1e-3
        np.testing.assert_allclose(gdd, (ep.vn - em.vn) / (2 * h), atol=1e-6 * scale)
        np.testing.assert_allclose(vtd, (ep.vt - em.vt) / (2 * h), atol=1e-6 * scale)


def test_contact_form_regular_at_tangent_touch():
    """A circle standing on a plane (zero gap): the contact-form Jacobian is regular (the
    gradient of |d|^2 is not), n is the plane normal and the couple is the lowest point."""
    plane = PlaneRect([-1, -1, 0], [1, 0, 0], [0, 1, 0], size=(2, 2))
    hoop = Circle(0.3)
    R = rot_x(np.pi / 2)        # hoop in the x-z plane
    X1, X2 = (R, np.array([0.1, 0.2, 0.3])), (np.eye(3), np.zeros(3))
    u = np.array([1.5 * np.pi, 1.1, 1.2])   # lowest point of the hoop, above (0.1, 0.2)
    F, Fu = closest_point_conditions("CS", hoop, X1, plane, X2, u)
    np.testing.assert_allclose(F, 0, atol=1e-15)
    assert abs(np.linalg.det(Fu)) > 1e-3
    z = (np.zeros(3), np.zeros(3))
    ev = evaluate_couple("CS", hoop, X1, (np.array([0, 2.0, 0]), np.array([0.6, 0, 0])),
                         plane, X2, z, u, 1.0)
    np.testing.assert_allclose(ev.n, [0, 0, 1], atol=1e-15)
    assert abs(ev.gap) < 1e-15
    # Rolling without slip (w_y r = v_x): no sliding; the contact point runs round the hoop
    # at the spin rate and along the plane with the hoop's centre.
    np.testing.assert_allclose(ev.vt, [0, 0], atol=1e-15)
    np.testing.assert_allclose(ev.udot, [2.0, 0.6, 0.0], atol=1e-12)


def test_singular_conditioning_for_parallel_segments():
    a, b = Segment([0, 0, 0], [1, 0, 0]), Segment([0, 0, 0.1], [1, 0, 0.1])
    z = (np.zeros(3), np.zeros(3))
    ev = evaluate_couple("CC", a, (np.eye(3), np.zeros(3)), z, b, (np.eye(3), np.zeros(3)), z,
                         np.array([0.5, 0.5]), 1.0)
    assert ev.conditioning < 1e-14
    assert np.all(np.isfinite(ev.udot)) and np.all(np.isfinite(ev.n))
