"""The rigid contact system on small scenes with closed forms: a disk sliding then rolling on an
incline (C-S), a rod pushed along and pulled off a fixed edge (C-C), energy and friction work,
Painleve's rod, a bouncing disk (LZB + Zeno guard), a three-footed stool (three couples)."""
import math

import numpy as np
import pytest
from pydrake.systems.analysis import SimulatorConfig
from pydrake.systems.framework import DiagramBuilder
from pydrake.systems.primitives import ConstantVectorSource, TrajectorySource
from pydrake.trajectories import PiecewisePolynomial

from drake_dock.core.hybrid import Mode
from drake_dock.errors import PainleveError
from drake_dock.systems.contact_system import COUPLE_SLICES, ContactOptions
from drake_dock.studies.small_scenes import (WITNESS_ACCURACY_FLOOR, G, disk_on_incline,
                                             painleve_rod, rod_on_edge, stool)
from drake_dock.systems.simulator import make_simulator

ACC = 1e-10


def start(system, set_state, accuracy=ACC, diagram=None):
    # The context's accuracy sets Drake's witness isolation window (1e-2 of it, in seconds);
    # the integrator keeps its own target accuracy.
    sim = make_simulator(diagram or system, SimulatorConfig(
        integration_scheme="runge_kutta5", accuracy=accuracy, max_step_size=0.05),
        lambda root: set_state(system.GetMyMutableContextFromRoot(root) if diagram else root),
        witness_accuracy=max(accuracy, WITNESS_ACCURACY_FLOOR))
    root = sim.get_mutable_context()
    sim.Initialize()
    return sim, root, system.GetMyMutableContextFromRoot(root) if diagram else root


def couple(system, ctx, name):
    y = system.get_couple_output_port(name).Eval(ctx)
    return {k: y[s] for k, s in COUPLE_SLICES.items()}


def energy(system, ctx):
    return system.GetOutputPort("energy").Eval(ctx)


# --------------------------------------------------------------------------- disk on incline
THETA, V0 = math.radians(20.0), 1.0


@pytest.fixture(scope="module", params=["plane", "annulus"])
def disk_run(request):
    """Disk launched down the incline without spin (mu = mu_s = 0.3): it slides, friction spins
    it up, the slip stops at t* and it rolls. On a plane patch, and on a ring face (`Annulus`,
    the face patch of `contact.pairs: complete`) whose polar parameters turn under the path."""
    sc = disk_on_incline(THETA, mu=0.3, face=request.param)
    r = sc.params["radius"]
    sim, root, ctx = start(sc.system, lambda c: sc.set_state(
        c, (np.eye(3), np.array([0, 0, r])), (np.zeros(3), np.array([V0, 0, 0]))))
    p = sc.params
    m, mu = p["mass"], p["mu"]
    a_slide = G * (math.sin(THETA) - mu * math.cos(THETA))
    alpha = mu * m * G * math.cos(THETA) * r / p["I_axle"]
    t_star = V0 / (alpha * r - a_slide)
    a_roll = G * math.sin(THETA) / (1 + p["I_axle"] / (m * r * r))
    samples = {}
    for t in (0.1, t_star - 1e-3, t_star + 1e-3, 0.6):
        sim.AdvanceTo(t)
        E = sc.system.eval(ctx)
        samples[t] = dict(x=ctx.get_continuous_state_vector().CopyToVector(), vdot=E.vdot,
                          c=couple(sc.system, ctx, "rim_plane"), e=energy(sc.system, ctx))
    return dict(sc=sc, m=m, mu=mu, r=r, a_slide=a_slide, alpha=alpha, t_star=t_star,
                a_roll=a_roll, samples=samples)


def tangential_force(c):
    """The friction force on the disk in the world: lambda_t on the couple's tangents ta, tb
    (the columns of its frame)."""
    return c["frame"].reshape(3, 3)[:, :2] @ c["lambda_t"]


def test_disk_slides_then_rolls_closed_form(disk_run):
    d = disk_run
    m, mu, t_star = d["m"], d["mu"], d["t_star"]
    lam_n = m * G * math.cos(THETA)
    for t, s in d["samples"].items():
        c, vdot = s["c"], s["vdot"]
        # Velocity layout of a free body: [w, v]; the disk's axle is y.
        np.testing.assert_allclose(c["lambda_n"], lam_n, rtol=1e-8)
        if t < t_star:
            assert c["status"] == Mode.SLIDING
            np.testing.assert_allclose(tangential_force(c), [-mu * lam_n, 0.0, 0.0],
                                       rtol=1e-8, atol=1e-8 * lam_n)
            np.testing.assert_allclose(vdot[3], d["a_slide"], rtol=1e-8)
            np.testing.assert_allclose(vdot[1], d["alpha"], rtol=1e-8)
            np.testing.assert_allclose(s["x"][10], V0 + d["a_slide"] * t, rtol=1e-8)
        else:
            assert c["status"] == Mode.STICKING     # rolling
            f_roll = m * G * math.sin(THETA) - m * d["a_roll"]
            np.testing.assert_allclose(tangential_force(c), [-f_roll, 0.0, 0.0], rtol=1e-8,
                                       atol=1e-8 * lam_n)
            assert abs(c["lambda_t"][0]) < mu * lam_n
            np.testing.assert_allclose(vdot[3], d["a_roll"], rtol=1e-8)
            v_star = V0 + d["a_slide"] * t_star
            np.testing.assert_allclose(s["x"][10], v_star + d["a_roll"] * (t - t_star),
                                       rtol=1e-7)
            np.testing.assert_allclose(s["x"][7 + 1] * d["r"], s["x"][10], rtol=1e-8)
        # The couple stays closed: |gap| within 1e-9 m under the full dynamics.
        assert abs(c["gap"]) < 1e-9


def test_friction_work_equals_integral(disk_run):
    """Energy lost while sliding = integral of mu lambda_n |v_t| (closed form here), and the
    energy balance KE + PE + friction loss is constant."""
    d = disk_run
    s = d["samples"][0.1]
    t = 0.1
    lam_n = d["m"] * G * math.cos(THETA)
    slip_rate = d["alpha"] * d["r"] - d["a_slide"]
    closed = d["mu"] * lam_n * (V0 * t - 0.5 * slip_rate * t * t)
    e = s["e"]     # [KE, PE, friction loss, ...]
    np.testing.assert_allclose(e[2], closed, rtol=1e-6)
    ke0 = 0.5 * d["m"] * V0 ** 2
    pe0 = d["m"] * G * math.cos(THETA) * d["r"] * 0.0   # reference: PE at t = 0 below
    for s in d["samples"].values():
        e = s["e"]
        total = e[0] + e[1] + e[2]
        first = next(iter(d["samples"].values()))["e"]
        np.testing.assert_allclose(total, first[0] + first[1] + first[2], atol=1e-6 * ke0)
    assert pe0 == 0.0


def test_frictionless_sliding_does_no_work():
    """A spinning disk sliding on a frictionless incline for 1 s: KE + PE constant to 1e-9."""
    sc = disk_on_incline(THETA, mu=0.0)
    r = sc.params["radius"]
    sim, root, ctx = start(sc.system, lambda c: sc.set_state(
        c, (np.eye(3), np.array([0, 0, r])), (np.array([0, 5.0, 0]), np.array([0.5, 0, 0]))),
        accuracy=1e-11)
    e0 = energy(sc.system, ctx)
    scale = e0[0]
    for t in np.linspace(0.1, 1.0, 10):
        sim.AdvanceTo(t)
        e = energy(sc.system, ctx)
        assert abs((e[0] + e[1]) - (e0[0] + e0[1])) < 1e-9 * scale
        c = couple(sc.system, ctx, "rim_plane")
        assert c["status"] == Mode.SLIDING and abs(c["gap"]) < 1e-9
    # Spin unchanged (no friction torque), acceleration g sin(theta).
    x = ctx.get_continuous_state_vector().CopyToVector()
    np.testing.assert_allclose(x[7 + 1], 5.0, rtol=1e-9)
    np.testing.assert_allclose(sc.system.eval(ctx).vdot[3], G * math.sin(THETA), rtol=1e-9)


# --------------------------------------------------------------------------- rod on an edge
def rod_scene(force, mu=0.2, mu_s=None):
    sc = rod_on_edge(mu=mu, mu_s=mu_s)
    b = DiagramBuilder()
    sys = b.AddSystem(sc.system)
    src = b.AddSystem(force)
    b.Connect(src.get_output_port(), sys.GetInputPort("rod_wrench"))
    diagram = b.Build()
    sim, root, ctx = start(sys, lambda c: sc.set_state(
        c, (np.eye(3), np.zeros(3)), (np.zeros(3), np.zeros(3))), diagram=diagram)
    return sc, sim, root, ctx


@pytest.mark.parametrize("push, mu_s", [(5.0, None), (2.0, None), (3.5, 0.4)])
def test_edge_pushed_along_edge(push, mu_s):
    """Rod on a fixed edge pushed along the edge by F at its mass centre: it slides with
    a = (F - mu m g)/m if F > mu_s m g, else it sticks with lambda_t = -F."""
    mu = 0.2
    sc, sim, root, ctx = rod_scene(ConstantVectorSource([0, 0, 0, push, 0, 0]), mu, mu_s)
    m = sc.params["mass"]
    mus = sc.params["mu_s"]
    sim.AdvanceTo(0.5)
    c = couple(sc.system, ctx, "rod_edge")
    vdot = sc.system.eval(ctx).vdot
    x = ctx.get_continuous_state_vector().CopyToVector()
    np.testing.assert_allclose(c["lambda_n"], m * G, rtol=1e-8)
    # Tangent ta is along the fixed edge (x).
    if push > mus * m * G:
        a = (push - mu * m * G) / m
        assert c["status"] == Mode.SLIDING
        np.testing.assert_allclose(vdot[3], a, rtol=1e-8)
        np.testing.assert_allclose(c["lambda_t"][0], -mu * m * G, rtol=1e-8)
        np.testing.assert_allclose(x[4], 0.5 * a * 0.25, rtol=1e-8)
    else:
        assert c["status"] == Mode.STICKING
        np.testing.assert_allclose(c["lambda_t"][0], -push, rtol=1e-8)
        assert abs(vdot[3]) < 1e-9 and abs(x[4]) < 1e-9
    assert abs(c["gap"]) < 1e-9
    np.testing.assert_allclose(vdot[:3], 0, atol=1e-9)


def test_detachment_when_pull_exceeds_weight():
    """Pulled up by F = c t, the rod leaves the edge at t* = m g / c; lambda_n = m g - c t
    before, and after it z'' = c t / m - g."""
    cpull = 30.0
    traj = PiecewisePolynomial.FirstOrderHold([0.0, 2.0], np.array(
        [[0, 0], [0, 0], [0, 0], [0, 0], [0, 0], [0.0, 2.0 * cpull]]))
    sc, sim, root, ctx = rod_scene(TrajectorySource(traj))
    m = sc.params["mass"]
    t_star = m * G / cpull
    sim.AdvanceTo(0.3)
    c = couple(sc.system, ctx, "rod_edge")
    np.testing.assert_allclose(c["lambda_n"], m * G - cpull * 0.3, rtol=1e-8)
    assert c["status"] >= Mode.SLIDING              # in contact
    T = t_star + 0.2
    sim.AdvanceTo(T)
    c = couple(sc.system, ctx, "rod_edge")
    assert c["status"] == Mode.TRACKED and c["lambda_n"] == 0.0
    x = ctx.get_continuous_state_vector().CopyToVector()
    z = cpull * (T ** 3 - t_star ** 3) / (6 * m) - cpull * t_star ** 2 * (T - t_star) / (2 * m) \
        - G * (T - t_star) ** 2 / 2
    np.testing.assert_allclose(x[6], z, rtol=1e-7)
    np.testing.assert_allclose(c["gap"], z, rtol=1e-7)
    np.testing.assert_allclose(sc.system.eval(ctx).vdot[5], cpull * T / m - G, rtol=1e-8)


# --------------------------------------------------------------------------- Painleve
def painleve_A(p, s):
    """Normal effective inverse mass of the tip of a sliding rod (independent planar form):
    a_z = A lambda_n + b with friction -mu s lambda_n along x."""
    c, sn = math.cos(p["theta"]), math.sin(p["theta"])
    l, rho = p["l"], p["rho"]
    return 1 / p["mass"] + l * c * (l * c + p["mu"] * s * (l * sn + rho)) / p["I"]


def painleve_start(mu, omega=0.0, options=ContactOptions()):
    theta = math.radians(30.0)
    sc = painleve_rod(theta, mu=mu, options=options)
    p = sc.params
    l, rho = p["l"], p["rho"]
    ax = np.array([math.cos(theta), 0, math.sin(theta)])
    R = np.array([[math.cos(theta), 0, -math.sin(theta)], [0, 1, 0],
                  [math.sin(theta), 0, math.cos(theta)]])
    com = np.array([0, 0, rho]) + l * ax
    w = np.array([0, omega, 0])
    r = -l * ax - np.array([0, 0, rho])        # contact point from the mass centre
    v = np.array([-1.0, 0, 0]) - np.cross(w, r)  # tip slides at -1 m/s along x, v_z = 0
    return sc, (R, com), (w, v), r


def test_painleve_inconsistency_is_reported():
    """mu = 3 at 30 deg: A < 0 for the tip sliding towards -x and gravity pushes the tip into
    the plane (b < 0): no consistent mode; with ``painleve="error"`` the run stops there."""
    sc, X, V, _ = painleve_start(3.0, options=ContactOptions(painleve="error"))
    assert painleve_A(sc.params, -1.0) < 0
    with pytest.raises(PainleveError, match="tip_plane") as err:
        start(sc.system, lambda c: sc.set_state(c, X, V))
    assert err.value.time == 0.0


@pytest.mark.parametrize("value", ["Impact", "warn", None])
def test_painleve_option_is_checked(value):
    """`ContactOptions.painleve` is "impact" or "error"; anything else is refused, naming the
    field, the value and the allowed ones (it would otherwise act as "error")."""
    from drake_dock.errors import InputError
    with pytest.raises(InputError, match=r"ContactOptions\.painleve = .*'impact', 'error'") as e:
        ContactOptions(painleve=value)
    assert e.value.field == "ContactOptions.painleve" and e.value.value == value
    assert ContactOptions(painleve="error").painleve == "error"


def _tip_impulse(p, v_tip):
    """The planar sticking impulse (P_x, P_z) at the rod's tip that stops the tip's velocity
    v_tip = (v_x, v_z), and the kinetic energy it takes: for a planar body, a point impulse P
    at r = (r_x, r_z) from the mass centre changes the point's velocity by K P with
    K = I2 / m + [r_z, -r_x]^T [r_z, -r_x] / I, so P = -K^-1 v_tip (Cramer's rule) and the
    loss is v_tip . K^-1 v_tip / 2."""
    th, l, rho = p["theta"], p["l"], p["rho"]
    rx, rz = -l * math.cos(th), -(l * math.sin(th) + rho)
    a, b = 1 / p["mass"] + rz * rz / p["I"], -rz * rx / p["I"]
    d = 1 / p["mass"] + rx * rx / p["I"]
    det = a * d - b * b
    Px = -(d * v_tip[0] - b * v_tip[1]) / det
    Pz = -(-b * v_tip[0] + a * v_tip[1]) / det
    return Px, Pz, -0.5 * (Px * v_tip[0] + Pz * v_tip[1])


def test_painleve_inconsistency_is_an_impact_without_collision():
    """The same rod with the default ``painleve="impact"``: at t = 0 an impact without
    collision (Genot and Brogliato) stops the tip. Its impulse and energy loss are the planar
    closed form's (to 1e-9), inside the cone (|P_t| <= mu P_n); the tip then sticks and the rod
    pivots about it, and the energy ledger (kinetic + potential + impact loss + friction loss)
    stays closed (to 1e-8 of the initial energy) through 0.3 s."""
    sc, X, V, _ = painleve_start(3.0)
    sim, root, ctx = start(sc.system, lambda c: sc.set_state(c, X, V))
    imp = sc.system.get_modes(ctx).impacts
    assert len(imp) == 1 and imp[0].without_collision and imp[0].t == 0.0
    Px, Pz, lost = _tip_impulse(sc.params, (-1.0, 0.0))
    assert Pz > 0 and abs(Px) <= sc.params["mu"] * Pz
    np.testing.assert_allclose(imp[0].normal_impulse, [Pz], rtol=1e-9)
    np.testing.assert_allclose(imp[0].tangential_impulse[0][0], Px, rtol=1e-9)
    np.testing.assert_allclose(imp[0].energy_lost, lost, rtol=1e-9)
    e0 = energy(sc.system, ctx)
    total0 = e0[0] + e0[1] + lost
    for T in (0.1, 0.3):
        sim.AdvanceTo(T)
        c = couple(sc.system, ctx, "tip_plane")
        assert c["status"] == Mode.STICKING and np.abs(c["vt"]).max() < 1e-9
        e = energy(sc.system, ctx)
        assert abs(e[0] + e[1] + e[5] + e[2] - total0) <= 1e-8 * total0


def test_impact_without_collision_on_the_planar_rod():
    """`impact_without_collision` on the rod's planar rows (mass centre translation and the
    spin about y) against the planar closed form: the impulse to 1e-12 and the tip stopped;
    for a tip moving up and forward the sticking impulse would pull (P_z < 0): None."""
    from drake_dock.core.iwc import impact_without_collision
    sc, _, _, _ = painleve_start(3.0)
    p = sc.params
    Px, Pz, _ = _tip_impulse(p, (1.0, 0.5))
    assert Pz < 0
    th, l, rho = p["theta"], p["l"], p["rho"]
    rx, rz = -l * math.cos(th), -(l * math.sin(th) + rho)
    # Generalized velocity (v_x, v_y, v_z, omega_y), the tip's rows n = z and t = (x, y).
    M = np.diag([p["mass"], p["mass"], p["mass"], p["I"]])
    Wn = np.array([[0.0], [0.0], [1.0], [-rx]])
    Wt = np.array([[1.0, 0.0], [0.0, 1.0], [0.0, 0.0], [rz, 0.0]])
    assert impact_without_collision(M, Wn, Wt, np.array([1.0, 0.0, 0.5, 0.0]), 3.0) is None
    res = impact_without_collision(M, Wn, Wt, np.array([-1.0, 0.0, 0.0, 0.0]), 3.0)
    np.testing.assert_allclose([res.P_t[0, 0], res.P_n[0]], _tip_impulse(p, (-1.0, 0.0))[:2],
                               rtol=1e-12)
    assert abs(res.P_t[0, 1]) <= 1e-15 and np.abs(Wn.T @ res.v_plus).max() < 1e-15


def test_painleve_indeterminacy_is_reported():
    """Same rod spinning fast enough that b > 0: detaching and sliding are both consistent."""
    sc, X, V, r = painleve_start(3.0, omega=-12.0)
    assert 12.0 ** 2 * (-r[2]) - G > 0
    with pytest.raises(PainleveError, match="several consistent"):
        start(sc.system, lambda c: sc.set_state(c, X, V))


def test_rod_below_painleve_limit_slides():
    """mu = 0.5: A > 0, one consistent mode, lambda_n = -b / A = m... from the planar form."""
    sc, X, V, _ = painleve_start(0.5)
    sim, root, ctx = start(sc.system, lambda c: sc.set_state(c, X, V))
    A = painleve_A(sc.params, -1.0)
    assert A > 0
    c = couple(sc.system, ctx, "tip_plane")
    np.testing.assert_allclose(c["lambda_n"], G / A, rtol=1e-8)


# --------------------------------------------------------------------------- impacts, stool
def test_bouncing_disk_lzb_and_zeno_guard():
    """Disk dropped from h with e = 0.5: impact at sqrt(2h/g), rebound speed e sqrt(2 g h);
    the bounces end by the Zeno guard in resting contact with lambda_n = m g."""
    h, e = 0.05, 0.5
    opt = ContactOptions(zeno_speed=1e-2)
    sc = disk_on_incline(0.0, mu=0.3, restitution=e, options=opt)
    r = sc.params["radius"]
    sim, root, ctx = start(sc.system, lambda c: sc.set_state(
        c, (np.eye(3), np.array([0, 0, r + h])), (np.zeros(3), np.zeros(3))))
    t1 = math.sqrt(2 * h / G)
    sim.AdvanceTo(t1 + 0.01)
    imp = sc.system.get_modes(ctx).impacts
    assert len(imp) == 1
    np.testing.assert_allclose(imp[0].t, t1, rtol=1e-7)
    x = ctx.get_continuous_state_vector().CopyToVector()
    np.testing.assert_allclose(x[12], e * math.sqrt(2 * G * h) - G * 0.01, rtol=1e-7)
    # Sum of the bounce flight times: 2 e v / g / (1 - e) after the first impact.
    v1 = math.sqrt(2 * G * h)
    sim.AdvanceTo(t1 + 2 * e * v1 / G / (1 - e) + 0.05)
    c = couple(sc.system, ctx, "rim_plane")
    assert c["status"] == Mode.STICKING
    np.testing.assert_allclose(c["lambda_n"], sc.params["mass"] * G, rtol=1e-8)
    assert abs(c["gap"]) < 1e-9
    n = len(sc.system.get_modes(ctx).impacts)
    # Impacts at v1 e^k while that is at least the Zeno speed, then one plastic impact.
    assert n == math.floor(math.log(opt.zeno_speed / v1) / math.log(e)) + 2
    assert sc.system.get_modes(ctx).impacts[-1].restitution == 0.0


def test_stool_three_couples_share_weight():
    sc = stool()
    sim, root, ctx = start(sc.system, lambda c: sc.set_state(
        c, (np.eye(3), np.array([0, 0, 0.2 + sc.params["foot_radius"]])),
        (np.zeros(3), np.zeros(3))))
    sim.AdvanceTo(0.2)
    lam = [couple(sc.system, ctx, f"foot{k}_plane")["lambda_n"] for k in range(3)]
    np.testing.assert_allclose(lam, sc.params["mass"] * G / 3, rtol=1e-8)


@pytest.mark.parametrize("mu", [0.0, 0.3])
def test_stool_dropped_flat_lands_on_three_feet(mu):
    """Dropped flat from 1 mm, the stool hits on its three feet at once at the free-fall time
    sqrt(2 h / g); with a plastic impact it stays, each foot carrying m g / 3, without sliding.
    With friction the LZB solver must decide the feet's stick/slip together (one at a time it
    would not end)."""
    h = 1e-3
    sc = stool(mu=mu)
    sim, root, ctx = start(sc.system, lambda c: sc.set_state(
        c, (np.eye(3), np.array([0, 0, 0.2 + sc.params["foot_radius"] + h])),
        (np.zeros(3), np.zeros(3))))
    sim.AdvanceTo(0.05)
    imp = sc.system.get_modes(ctx).impacts
    assert len(imp) == 1 and len(imp[0].couples) == 3
    np.testing.assert_allclose(imp[0].t, math.sqrt(2 * h / G), rtol=1e-7)
    np.testing.assert_allclose(imp[0].normal_impulse,
                               sc.params["mass"] * math.sqrt(2 * G * h) / 3, rtol=1e-7)
    lam = [couple(sc.system, ctx, f"foot{k}_plane")["lambda_n"] for k in range(3)]
    np.testing.assert_allclose(lam, sc.params["mass"] * G / 3, rtol=1e-8)
    x = ctx.get_continuous_state_vector().CopyToVector()
    np.testing.assert_allclose(x[sc.system.nq:sc.system.nq + 6], 0.0, atol=1e-9)


# --------------------------------------------------------------------------- transitions
def test_contact_ends_at_the_patch_end():
    """A disk sliding (frictionless) off the end of the plane patch at x = 0.5: at the domain
    end the contact is released (documented rule) and the disk falls freely."""
    sc = disk_on_incline(0.0, mu=0.0, plane_end=0.5)
    r = sc.params["radius"]
    sim, root, ctx = start(sc.system, lambda c: sc.set_state(
        c, (np.eye(3), np.array([0, 0, r])), (np.zeros(3), np.array([1.0, 0, 0]))))
    sim.AdvanceTo(0.45)
    assert couple(sc.system, ctx, "rim_plane")["status"] == Mode.SLIDING
    sim.AdvanceTo(0.6)
    assert couple(sc.system, ctx, "rim_plane")["status"] == Mode.FAR
    x = ctx.get_continuous_state_vector().CopyToVector()
    np.testing.assert_allclose(x[6], r - G * 0.1 ** 2 / 2, rtol=1e-7)
    np.testing.assert_allclose(sc.system.eval(ctx).vdot[3:], [0, 0, -G], atol=1e-12)


def test_parallel_edges_in_contact_raise_typed_error():
    """The rod spins on the fixed edge until the two edges turn parallel: Eq. (39) fails for a
    couple in contact, which is reported with the couple and the time: the conditioning
    sin^2 / (1 + cos^2) of the angle phi between the edges reaches conditioning_min."""
    from drake_dock.errors import SingularCoupleError
    sc = rod_on_edge(mu=0.0, wrench=False)
    sim, root, ctx = start(sc.system, lambda c: sc.set_state(
        c, (np.eye(3), np.zeros(3)), (np.array([0, 0, 2.0]), np.zeros(3))))
    with pytest.raises(SingularCoupleError, match="rod_edge") as err:
        sim.AdvanceTo(1.0)
    c = ContactOptions().conditioning_min
    phi = math.asin(math.sqrt(2 * c / (1 + c)))      # sin^2/(1 + cos^2) = c
    np.testing.assert_allclose(err.value.time, (math.pi / 2 - phi) / 2.0, rtol=1e-6)


def test_drift_is_measured_and_bounded():
    """The projection of the integrated couple stays at round-off along a rolling run, and a
    drift above drift_tol raises DriftError naming the couple."""
    from drake_dock.errors import DriftError
    sc = disk_on_incline(THETA, mu=0.3)
    r = sc.params["radius"]
    sim, root, ctx = start(sc.system, lambda c: sc.set_state(
        c, (np.eye(3), np.array([0, 0, r])), (np.zeros(3), np.array([V0, 0, 0]))))
    worst = 0.0
    for t in np.linspace(0.05, 0.5, 10):
        sim.AdvanceTo(t)
        ev = sc.system.eval(ctx).evals[0]
        worst = max(worst, float(np.abs(ev.drift).max()), ev.residual)
    assert worst < 1e-9
    sc2 = disk_on_incline(THETA, mu=0.3, options=ContactOptions(drift_tol=1e-300,
                                                                drift_feedback=0.0))
    with pytest.raises(DriftError, match="rim_plane"):
        sim2, _, _ = start(sc2.system, lambda c: sc2.set_state(
            c, (np.eye(3), np.array([0, 0, r])), (np.zeros(3), np.array([V0, 0, 0]))))
        sim2.AdvanceTo(0.2)


@pytest.mark.parametrize("depth", [1e-3, 0.2])
def test_initial_interpenetration_is_refused(depth):
    """A disk started below the plane (declared sigma) is refused at Initialize with the pair,
    its signed gap (-depth, the disk's rim below the plane) and the allowed range; a disk
    started resting (gap 0) is accepted and stays at rest on lambda_n = m g."""
    from drake_dock.errors import InputError
    sc = disk_on_incline(0.0, mu=0.3)
    r = sc.params["radius"]
    with pytest.raises(InputError, match="pair rim_plane = .*interpenetrating") as ex:
        start(sc.system, lambda c: sc.set_state(
            c, (np.eye(3), np.array([0, 0, r - depth])), (np.zeros(3), np.zeros(3))))
    if ex.value.value.startswith("signed gap"):
        np.testing.assert_allclose(float(ex.value.value.split()[2]), -depth, rtol=1e-9)
    else:
        assert "intersecting" in ex.value.value
    assert "impact_gap_tol" in str(ex.value)
    sc = disk_on_incline(0.0, mu=0.3)
    sim, root, ctx = start(sc.system, lambda c: sc.set_state(
        c, (np.eye(3), np.array([0, 0, r])), (np.zeros(3), np.zeros(3))))
    sim.AdvanceTo(0.05)
    np.testing.assert_allclose(couple(sc.system, ctx, "rim_plane")["lambda_n"],
                               sc.params["mass"] * G, rtol=1e-8)
