"""The contact system with its couples, constraint solve and mode selection by the compiled
kernels (with the plant as calculator, `ContactOptions(engine=False)`) against the same
system in Python (`ContactOptions(compiled=False)`): the same trajectory, impacts and modes, to
1e-12; and with the whole evaluation in one compiled call (`engine`), the same to the witness
isolation's window, on a disk dropped spinning onto an incline (impacts) and on a stool sliding
and spinning on its three feet (three couples in contact, no impact)."""
import math

import numpy as np
import pytest
from pydrake.systems.analysis import ApplySimulatorConfig, Simulator, SimulatorConfig

from drake_dock.systems.contact_types import ContactOptions
from drake_dock.studies.small_scenes import disk_on_incline, stool


def _run(make, compiled, X, V, times, engine=False):
    sc = make(ContactOptions(zeno_speed=1e-2, compiled=compiled, engine=engine))
    assert (sc.system.evaluator.engine is not None) == engine
    assert (sc.system.evaluator.kernel is not None) == compiled
    assert (sc.system.evaluator.solver is not None) == compiled
    sim = Simulator(sc.system)
    ctx = sim.get_mutable_context()
    sc.set_state(ctx, X, V)
    ApplySimulatorConfig(SimulatorConfig(integration_scheme="runge_kutta5", accuracy=1e-8,
                                         max_step_size=0.05), sim)
    ctx.SetAccuracy(1e-8)
    sim.Initialize()
    out = []
    for t in times:
        sim.AdvanceTo(t)
        out.append(ctx.get_continuous_state_vector().CopyToVector())
    modes = sc.system.get_modes(ctx)
    return np.array(out), [st.mode for st in modes.pairs], [i["t"] for i in modes.impacts]


@pytest.mark.parametrize("scene", ["disk", "stool"])
def test_compiled_couples_give_the_python_trajectory(scene):
    if scene == "disk":
        def make(opt):
            return disk_on_incline(math.radians(10.0), mu=0.3, restitution=0.5, options=opt)
        X, V = (np.eye(3), np.array([0.0, 0.0, 0.35])), (np.array([0.0, 2.0, 0.0]),
                                                           np.array([0.5, 0.0, 0.0]))
    else:
        def make(opt):
            return stool(options=opt)
        X = (np.eye(3), np.array([0.0, 0.0, 0.25]))
        V = (np.array([0.0, 0.0, 0.5]), np.array([0.2, 0.0, 0.0]))
    times = (0.05, 0.2, 0.4)
    x_c, modes_c, imp_c = _run(make, True, X, V, times)
    x_p, modes_p, imp_p = _run(make, False, X, V, times)
    assert modes_c == modes_p and len(imp_c) == len(imp_p)
    assert imp_c if scene == "disk" else all(m.in_contact for m in modes_c)
    np.testing.assert_allclose(imp_c, imp_p, rtol=0, atol=1e-12)
    np.testing.assert_allclose(x_c, x_p, rtol=0, atol=1e-12 * (1 + np.abs(x_p).max()))


@pytest.mark.parametrize("scene", ["disk", "stool"])
def test_engine_gives_the_plant_paths_trajectory(scene):
    """The engine's trajectory equals the plant path's: impact times within the witness
    isolation's window (Drake isolates a zero to a window set by the accuracy, 1e-8 here; a
    step that the witness approach ends at a predicted zero decides by round-off whether the
    zero is isolated then or in the next step) and states at the sample times to 1e-9."""
    if scene == "disk":
        def make(opt):
            return disk_on_incline(math.radians(10.0), mu=0.3, restitution=0.5, options=opt)
        X, V = (np.eye(3), np.array([0.0, 0.0, 0.35])), (np.array([0.0, 2.0, 0.0]),
                                                           np.array([0.5, 0.0, 0.0]))
    else:
        def make(opt):
            return stool(options=opt)
        X = (np.eye(3), np.array([0.0, 0.0, 0.25]))
        V = (np.array([0.0, 0.0, 0.5]), np.array([0.2, 0.0, 0.0]))
    times = (0.05, 0.2, 0.4)
    x_e, modes_e, imp_e = _run(make, True, X, V, times, engine=True)
    x_p, modes_p, imp_p = _run(make, True, X, V, times)
    assert modes_e == modes_p and len(imp_e) == len(imp_p)
    np.testing.assert_allclose(imp_e, imp_p, rtol=0, atol=1e-9)
    np.testing.assert_allclose(x_e, x_p, rtol=0, atol=1e-9 * (1 + np.abs(x_p).max()))
