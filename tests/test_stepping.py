"""`WitnessApproach` (step shortening before predicted witness zeros) on a bouncing disk with
known impact times: the same events at the same times as Drake's plain isolation, with fewer
derivative evaluations."""
import math

import numpy as np
from pydrake.systems.analysis import ApplySimulatorConfig, Simulator, SimulatorConfig

from drake_dock.contact_system import ContactOptions
from drake_dock.small_scenes import G, disk_on_incline
from drake_dock.stepping import WitnessApproach

H, E, ACC, MAX_STEP = 0.05, 0.5, 1e-8, 0.01


def bounce(approach: bool):
    sc = disk_on_incline(0.0, mu=0.3, restitution=E, options=ContactOptions(zeno_speed=1e-2))
    r = sc.params["radius"]
    sim = Simulator(sc.system)
    ctx = sim.get_mutable_context()
    sc.set_state(ctx, (np.eye(3), np.array([0, 0, r + H])), (np.zeros(3), np.zeros(3)))
    ApplySimulatorConfig(SimulatorConfig(integration_scheme="runge_kutta5", accuracy=ACC,
                                         max_step_size=MAX_STEP), sim)
    ctx.SetAccuracy(ACC)
    sim.Initialize()
    if approach:
        wa = WitnessApproach(sim, [sc.system], MAX_STEP, 0.01 * ACC)
        sim.set_monitor(lambda c: wa(c))
    n0 = sc.system.evaluations
    v1 = math.sqrt(2 * G * H)
    t1 = math.sqrt(2 * H / G)
    sim.AdvanceTo(t1 + 2 * v1 / G * (E + E**2) + 0.01)      # the first three impacts
    return [i["t"] for i in sc.system.get_modes(ctx).impacts], sc.system.evaluations - n0


def test_same_impact_times_with_fewer_evaluations():
    t_plain, n_plain = bounce(False)
    t_fast, n_fast = bounce(True)
    v1 = math.sqrt(2 * G * H)
    t1 = math.sqrt(2 * H / G)
    # Closed form: impact k after flights 2 v1 e^j / g.
    expected = [t1 + sum(2 * v1 * E**j / G for j in range(1, k + 1)) for k in range(3)]
    assert len(t_fast) == len(t_plain) == 3
    window = 0.01 * ACC
    np.testing.assert_allclose(t_plain, expected, atol=2 * window + 1e-12)
    np.testing.assert_allclose(t_fast, expected, atol=2 * window + 1e-12)
    assert n_fast < n_plain / 2, (n_fast, n_plain)
