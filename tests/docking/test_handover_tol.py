"""The hand-over rule's tolerance (`ContactOptions.handover_tol`) is not the drift guard's
(`drift_tol`): a tighter drift guard does not refuse hand-overs and so change the motion; where
a couple handed over drifts more than it allows, the run stops in a `DriftError` with the time
and the couple. The scene: the funnel variant (models/apds_funnel.yaml), whose chaser ring is
handed from the guide side T5 to the petal surface T3 at 1.48757 s with a Newton step of
1.5e-7 of the surface's span."""
import pytest

from drake_dock.docking.model.diagram import DiagramSpec, build_docking_diagram
from drake_dock.docking.model.simulate import simulate
from drake_dock.docking.placement.place import place
from drake_dock.docking.scenario.loading import load_scenario
from drake_dock.docking.scenario.models_dir import MODELS_DIR
from drake_dock.errors import DriftError
from drake_dock.systems.contact_types import ContactOptions
from drake_dock.systems.simulator import tolerances


def _run(**options):
    s = load_scenario(MODELS_DIR / "apds_funnel.yaml")
    base = DiagramSpec.of(s).contact_options()
    assert (base.drift_tol, base.handover_tol) == (ContactOptions().drift_tol,
                                                    ContactOptions().handover_tol)
    opts = ContactOptions(impact_rtol=tolerances(s.simulator_config).impact_rtol,
                          reseek_horizon=s.simulator_config.max_step_size, **options)
    dd = build_docking_diagram(DiagramSpec.of(s, options=opts))
    return simulate(s, place(s), dd=dd)


def test_a_drift_guard_the_run_keeps_leaves_the_motion_bitwise():
    """drift_tol 3e-7, above every drift of the run, gives the default's run bit for bit."""
    ref, tight = _run(), _run(drift_tol=3e-7)
    assert ref.outcome == tight.outcome == "captured"
    assert tight.capture_time == ref.capture_time
    assert [i.couples for i in tight.impacts] == [i.couples for i in ref.impacts]


def test_a_drift_guard_below_the_handed_couples_step_is_reported():
    """drift_tol 1e-7, below the 1.5e-7 step of the couple handed over at 1.48757 s."""
    with pytest.raises(DriftError) as e:
        _run(drift_tol=1e-7)
    assert e.value.couples == ("cs_Cring_T3",)
    assert e.value.time == pytest.approx(1.48757, abs=1e-4)
    assert "drift_tol = 1e-07" in str(e.value)
