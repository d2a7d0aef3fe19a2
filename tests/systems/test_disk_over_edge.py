"""The hand-over in the contact system (`drake_dock.systems.transitions`): a disk sliding
frictionless off a plane's end onto the edge there (`disk_on_incline` with ``edge``) pivots
over the edge like a particle on a cylinder of radius r and leaves it at the closed-form angle
cos(theta_c) = (2 + v0^2 / (g r)) / 3; the run between and after is checked against that closed
form and energy conservation."""
import math

import numpy as np
import pytest
from scipy.integrate import quad

from drake_dock.core.hybrid import Mode
from drake_dock.studies.small_scenes import G, disk_on_incline
from test_contact_system import couple, energy, start

V0, END = 1.0, 0.5


@pytest.fixture(scope="module")
def run():
    sc = disk_on_incline(0.0, mu=0.0, plane_end=END, edge=True)
    r = sc.params["radius"]
    sim, root, ctx = start(sc.system, lambda c: sc.set_state(
        c, (np.eye(3), np.array([0, 0, r])), (np.zeros(3), np.array([V0, 0, 0]))))
    return sc, sim, ctx, r


def test_disk_hands_over_to_the_edge_and_leaves_it_at_the_closed_form_angle(run):
    """Plane until t_h = END / v0, then the edge pair in contact (the plane pair far); the
    contact force passes through the centre, so the disk does not turn and its centre moves on
    the circle of radius r about the edge (theta' ^ 2 = (v0 / r)^2 + 2 g (1 - cos theta) / r)
    until lambda_n = 0 at theta_c, then flies: at t_c + 0.05 s its position and velocity equal
    the closed form to 1e-6 (its spin stays 0 to 1e-7 rad/s), and the energy is conserved to 1e-8 of the kinetic energy."""
    sc, sim, ctx, r = run
    t_h = END / V0
    sim.AdvanceTo(t_h - 1e-3)
    assert couple(sc.system, ctx, "rim_plane")["status"] == Mode.SLIDING
    assert couple(sc.system, ctx, "rim_edge")["status"] == Mode.FAR
    e0 = energy(sc.system, ctx)
    sim.AdvanceTo(t_h + 1e-3)
    assert couple(sc.system, ctx, "rim_edge")["status"] == Mode.SLIDING
    assert couple(sc.system, ctx, "rim_plane")["status"] == Mode.FAR
    assert abs(couple(sc.system, ctx, "rim_edge")["gap"]) < 1e-8
    c_th = (2.0 + V0 ** 2 / (G * r)) / 3.0
    th_c = math.acos(c_th)
    rate = lambda th: math.sqrt((V0 / r) ** 2 + 2 * G * (1 - math.cos(th)) / r)   # theta'
    t_c = t_h + quad(lambda th: 1.0 / rate(th), 0.0, th_c, epsabs=1e-14, epsrel=1e-13)[0]
    sim.AdvanceTo(t_c - 1e-3)
    assert couple(sc.system, ctx, "rim_edge")["status"] == Mode.SLIDING
    sim.AdvanceTo(t_c + 1e-3)
    assert couple(sc.system, ctx, "rim_edge")["status"] == Mode.TRACKED
    T = t_c + 0.05
    sim.AdvanceTo(T)
    x = ctx.get_continuous_state_vector().CopyToVector()
    q, v = x[:sc.system.nq], x[sc.system.nq:sc.system.nq + sc.system.nv]
    speed = math.sqrt(G * r * c_th)
    vx, vz = speed * c_th, -speed * math.sin(th_c) - G * (T - t_c)
    px = END + r * math.sin(th_c) + vx * (T - t_c)
    pz = r * c_th - speed * math.sin(th_c) * (T - t_c) - 0.5 * G * (T - t_c) ** 2
    np.testing.assert_allclose(q[4:7], [px, 0.0, pz], atol=1e-6)
    np.testing.assert_allclose(v[3:6], [vx, 0.0, vz], atol=1e-6)
    np.testing.assert_allclose(v[:3], 0.0, atol=1e-7)
    e1 = energy(sc.system, ctx)
    ke = 0.5 * sc.params["mass"] * V0 ** 2
    assert abs((e1[0] + e1[1]) - (e0[0] + e0[1])) < 1e-8 * ke
    assert sc.system.get_modes(ctx).impacts == []
