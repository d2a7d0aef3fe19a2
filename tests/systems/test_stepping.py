"""`WitnessApproach` (step shortening before predicted witness zeros) on a bouncing disk with
known impact times: the same events at the same times as Drake's plain isolation, with fewer
derivative evaluations. The joint witness (`drake_dock.systems.witnesses`,
`ContactOptions.joint_witness`): Drake, given the least of the armed witnesses as one function,
takes the same events at the same times, bit for bit, as given one function per transition (a
second implementation, and the closed form); where an armed witness is not positive after an
event, it is given on its own beside the joint witness of the others."""
import math

import numpy as np
import pytest
from pydrake.systems.analysis import SimulatorConfig

from drake_dock.systems.contact_system import ContactOptions
from drake_dock.studies.small_scenes import G, disk_on_incline
from drake_dock.systems.simulator import make_simulator, make_witness_approach, tolerances

H, E, ACC, MAX_STEP = 0.05, 0.5, 1e-8, 0.01
CONFIG = SimulatorConfig(integration_scheme="runge_kutta5", accuracy=ACC, max_step_size=MAX_STEP)


def bounce(approach: bool, joint: bool = True, states: bool = False):
    """The first three impacts of a disk dropped from H on a plane: their times and the
    derivative evaluations (and with ``states`` the states after them); ``joint``:
    `ContactOptions.joint_witness`."""
    sc = disk_on_incline(0.0, mu=0.3, restitution=E,
                         options=ContactOptions(zeno_speed=1e-2, joint_witness=joint))
    r = sc.params["radius"]
    sim = make_simulator(sc.system, CONFIG, lambda ctx: sc.set_state(
        ctx, (np.eye(3), np.array([0, 0, r + H])), (np.zeros(3), np.zeros(3))))
    ctx = sim.get_mutable_context()
    sim.Initialize()
    if approach:
        wa = make_witness_approach(sim, [sc.system], CONFIG)
        sim.set_monitor(lambda c: wa(c))
    n0 = sc.system.evaluations
    v1 = math.sqrt(2 * G * H)
    t1 = math.sqrt(2 * H / G)
    sim.AdvanceTo(t1 + 2 * v1 / G * (E + E**2) + 0.01)      # the first three impacts
    impacts = sc.system.get_modes(ctx).impacts
    out = [i.t for i in impacts], sc.system.evaluations - n0
    return out + ([i.x_plus for i in impacts],) if states else out


def test_same_impact_times_with_fewer_evaluations():
    t_plain, n_plain = bounce(False)
    t_fast, n_fast = bounce(True)
    v1 = math.sqrt(2 * G * H)
    t1 = math.sqrt(2 * H / G)
    # Closed form: impact k after flights 2 v1 e^j / g.
    expected = [t1 + sum(2 * v1 * E**j / G for j in range(1, k + 1)) for k in range(3)]
    assert len(t_fast) == len(t_plain) == 3
    window = tolerances(CONFIG).witness_window    # Drake's isolation window
    np.testing.assert_allclose(t_plain, expected, atol=2 * window + 1e-12)
    np.testing.assert_allclose(t_fast, expected, atol=2 * window + 1e-12)
    assert n_fast < n_plain / 2, (n_fast, n_plain)


def test_lead_jet_is_the_first_root_of_the_taylor_parabola():
    from drake_dock.systems.stepping import _lead_jet
    # w = 1 - 3 h + 2 h^2 = (1 - h)(1 - 2 h): first zero at h = 1/2.
    assert _lead_jet(1.0, -3.0, 4.0) == pytest.approx(0.5, rel=1e-15)
    # Ballistic gap w = 0.01 + 0.5 h - g h^2 / 2: the positive root.
    h = (0.5 + math.sqrt(0.25 + 2 * G * 0.01)) / G
    assert _lead_jet(0.01, 0.5, -G) == pytest.approx(h, rel=1e-14)
    assert _lead_jet(0.01, -0.5, 0.0) == pytest.approx(0.02, rel=1e-15)
    assert math.isinf(_lead_jet(0.01, 0.5, 0.0))          # receding, no curvature
    assert math.isinf(_lead_jet(0.01, 0.1, 1.0))          # receding and accelerating away


def test_gap_rates_of_a_falling_disk_are_its_velocity_and_gravity():
    """The gap witness's derivatives that `WitnessApproach` predicts with: g' = v_z and
    g'' = -g for a disk in free flight above the plane, spinning about its axle (y), which
    keeps its lowest point (closed form)."""
    sc = disk_on_incline(0.0, mu=0.3, restitution=E)
    r = sc.params["radius"]
    sim = make_simulator(sc.system, CONFIG, lambda ctx: sc.set_state(
        ctx, (np.eye(3), np.array([0, 0, r + 0.01])),
        (np.array([0.0, 3.0, 0.0]), np.array([0.2, 0.0, 0.7]))))
    ctx = sim.get_mutable_context()
    sim.Initialize()
    name = f"{sc.system.pairs[0].name} gap"
    rates = sc.system.witness_rates(ctx)
    assert rates[name] == pytest.approx(0.7, rel=1e-12)
    second = sc.system.witness_second_rates(ctx, [name])
    assert second[name] == pytest.approx(-G, rel=1e-9)


def test_same_events_as_one_witness_per_transition():
    v1, t1 = math.sqrt(2 * G * H), math.sqrt(2 * H / G)
    expected = [t1 + sum(2 * v1 * E**j / G for j in range(1, k + 1)) for k in range(3)]
    window = tolerances(CONFIG).witness_window
    for approach in (False, True):      # Drake's plain isolation, and the step shortening
        t_joint, n_joint, x_joint = bounce(approach, True, states=True)
        t_each, n_each, x_each = bounce(approach, False, states=True)
        assert len(t_joint) == 3
        assert t_joint == t_each and n_joint == n_each
        for a, b in zip(x_joint, x_each):
            np.testing.assert_array_equal(a, b)
        np.testing.assert_allclose(t_joint, expected, atol=2 * window + 1e-12)


def test_the_joint_value_is_the_least_armed_one_and_steps_aside_at_a_zero():
    sc = disk_on_incline(0.0, mu=0.3, restitution=E, options=ContactOptions(zeno_speed=1e-2))
    r = sc.params["radius"]
    h = 0.2 * sc.system.options.track_distance      # the couple tracked: gap and domain ends
    sim = make_simulator(sc.system, CONFIG, lambda ctx: sc.set_state(
        ctx, (np.eye(3), np.array([0, 0, r + h])), (np.zeros(3), np.zeros(3))))
    sim.Initialize()
    ctx = sc.system.GetMyMutableContextFromRoot(sim.get_mutable_context())
    values = sc.system.witness_values(ctx)
    assert len(values) >= 2 and min(values.values()) > 0
    assert sc.system._joint_value(ctx) == min(values.values())
    assert len(sc.system.GetWitnessFunctions(ctx)) == 1
    # The disk's rim below the plane and sinking: its impact witness (v_n, the gap being
    # negative) is not positive, and it is given on its own beside the joint witness of the
    # others, whose value is the least of those.
    sc.set_state(ctx, (np.eye(3), np.array([0, 0, r - 1e-4])),
                 (np.zeros(3), np.array([0.0, 0.0, -0.1])))
    values = sc.system.witness_values(ctx)
    held = {k: v for k, v in values.items() if not v > 0}
    assert list(held) == [f"{sc.system.pairs[0].name} gap"] and held[next(iter(held))] < 0
    assert sc.system._joint_value(ctx) == min(values.values())
    given = sc.system.GetWitnessFunctions(ctx)
    (key,) = sc.system._rest                    # (pair, kind) of the held witness
    assert key == ((0, "impact"),)
    assert given == [sc.system._rest[key], sc.system._w[0]["impact"]]
    assert sc.system._rest_value(ctx, key) == min(v for k, v in values.items()
                                                  if k not in held)


def test_the_domain_end_witness_rate_is_the_couples_rate_over_its_span():
    """A disk gliding at v_x towards the end of the plane patch (x = 1, the patch's span along
    x 51 m): its regular witness is the couple's margin to that end, (1 - x) / 51, and the rate
    `WitnessApproach` predicts with is -v_x / 51 (closed form)."""
    sc = disk_on_incline(0.0, plane_end=1.0)
    r = sc.params["radius"]
    sim = make_simulator(sc.system, CONFIG, lambda ctx: sc.set_state(
        ctx, (np.eye(3), np.array([0.9, 0.0, r + 0.01])),
        (np.zeros(3), np.array([0.3, 0.0, 0.0]))))
    ctx = sim.get_mutable_context()
    sim.Initialize()
    name = f"{sc.system.pairs[0].name} domain end or Eq. 39"
    assert sc.system.witness_values(ctx)[name] == pytest.approx(0.1 / 51.0, rel=1e-9)
    assert sc.system.witness_rates(ctx)[name] == pytest.approx(-0.3 / 51.0, rel=1e-9)


def test_the_step_after_an_impact_is_predicted_from_the_state_it_leaves():
    """Drake calls the monitor before it applies an event, so `WitnessApproach` also listens to
    the events (`add_event_listener`): at each impact of the bouncing disk the witnesses it
    predicts with are those of the state the impact leaves. There the gap is not positive (the
    impact is isolated just past its zero), the gap witness is the couple's separating speed,
    e times the closing speed, and its rate the normal acceleration, -g (closed form)."""
    seen = []

    class Listener:
        def __call__(self, source, context, t, x, modes):
            now, _ = source.witness_now_after(context, t, x, modes)
            seen.append((t, dict(zip(now.layout, now.w.tolist())),
                         dict(zip(now.layout, now.d.tolist()))))

    listener = Listener()
    sc = disk_on_incline(0.0, mu=0.3, restitution=E, options=ContactOptions(zeno_speed=1e-2))
    sc.system.add_event_listener(listener.__call__)
    r = sc.params["radius"]
    sim = make_simulator(sc.system, CONFIG, lambda ctx: sc.set_state(
        ctx, (np.eye(3), np.array([0, 0, r + H])), (np.zeros(3), np.zeros(3))))
    sim.Initialize()
    wa = make_witness_approach(sim, [sc.system], CONFIG)
    sim.set_monitor(lambda c: wa(c))
    v1, t1 = math.sqrt(2 * G * H), math.sqrt(2 * H / G)
    sim.AdvanceTo(t1 + 0.01)
    name = f"{sc.system.pairs[0].name} gap"
    after = [(t, w, d) for t, w, d in seen if abs(t - t1) < 1e-6 and name in w]
    assert after, seen
    for _, w, d in after:
        assert w[name] == pytest.approx(E * v1, rel=1e-6)
        assert d[name] == pytest.approx(-G, rel=1e-9)
    # One impact by then: the next one is 2 e v1 / g = 0.1 s later.
    assert len(sc.system.get_modes(sim.get_context()).impacts) == 1
    wa.close()
