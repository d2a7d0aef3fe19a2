"""`make_simulator`: the configuration Drake reports back is the one given, the context's
accuracy is the one `tolerances` names, and the docking diagram's LZB accuracy is the one
derived from the scenario's configuration; a run relaxes Python's cyclic collector and
restores it (`collector_relaxed`)."""
import pytest
from pydrake.systems.analysis import ExtractSimulatorConfig, SimulatorConfig
from pydrake.systems.primitives import Integrator

from drake_dock.systems.simulator import make_simulator, tolerances

FIELDS = [f.name for f in SimulatorConfig.__fields__]


@pytest.mark.parametrize("witness_accuracy", [None, 1e-5])
def test_config_applied_and_context_accuracy_set(witness_accuracy):
    config = SimulatorConfig(integration_scheme="runge_kutta5", max_step_size=0.003,
                             accuracy=1e-7, use_error_control=True)
    sim = make_simulator(Integrator(2), config, lambda c: c.SetContinuousState([1.0, 2.0]),
                         witness_accuracy=witness_accuracy)
    got = ExtractSimulatorConfig(sim)
    assert {f: getattr(got, f) for f in FIELDS} == {f: getattr(config, f) for f in FIELDS}
    ctx = sim.get_context()
    assert list(ctx.get_continuous_state_vector().CopyToVector()) == [1.0, 2.0]
    expected = config.accuracy if witness_accuracy is None else witness_accuracy
    assert ctx.get_accuracy() == expected
    assert tolerances(config, witness_accuracy).witness_accuracy == expected


@pytest.mark.parametrize("accuracy", [1e-4, 1e-8])
def test_docking_lzb_accuracy_follows_the_simulator_config(paper_scenario, accuracy):
    import copy
    from drake_dock.docking.model.diagram import DiagramSpec, build_docking_diagram
    scenario = copy.deepcopy(paper_scenario)
    scenario.simulator_config.accuracy = accuracy
    dd = build_docking_diagram(DiagramSpec.of(scenario))
    assert dd.contact.options.impact_rtol == tolerances(scenario.simulator_config).impact_rtol


@pytest.mark.parametrize("user", [(700, 10, 10), (200_000, 10, 10), (0, 10, 10), None])
def test_a_run_relaxes_the_collector_and_restores_it(paper_scenario, user):
    """During a run the collector's first threshold is at least `RUN_GC_THRESHOLD` (read by
    the run's progress callback), a higher one the user set is kept, a disabled collector (by
    `gc.disable` or a threshold of 0) stays disabled, and after the run the thresholds are the
    user's again."""
    import gc
    from drake_dock.docking.model.simulate import simulate
    from drake_dock.docking.placement.place import place
    from drake_dock.systems.simulator import RUN_GC_THRESHOLD
    old, enabled = gc.get_threshold(), gc.isenabled()
    seen = []
    try:
        if user is None:
            gc.disable()
        else:
            gc.set_threshold(*user)
        before = gc.get_threshold()
        simulate(paper_scenario, place(paper_scenario), duration=0.01,
                 progress=lambda *a: seen.append((gc.get_threshold(), gc.isenabled())))
        after = gc.get_threshold(), gc.isenabled()
    finally:
        gc.set_threshold(*old)
        (gc.enable if enabled else gc.disable)()
    assert seen
    want = before[0] if user is None or before[0] == 0 else max(before[0], RUN_GC_THRESHOLD)
    assert {s for s in seen} == {((want, *before[1:]), user is not None)}
    assert after == (before, user is not None)
