"""A campaign row (`drake_dock.campaign.sample.measure`, from the timeseries without its
per-couple arrays) against two independent computations: its Stewart columns against the
peaks of `drake_dock.docking.model.plant.stewart_history` (Drake's bushing on its own context, from
the recorded plant states), and its other columns against the run's `summary` (from the full
timeseries: the couple table's normal forces, the loads and the ledger); and a sample's row is
made with Python's cyclic collector relaxed."""
import math
from pathlib import Path

import pytest

from drake_dock.campaign.sample import measure
from drake_dock.docking.model.plant import stewart_history
from drake_dock.docking.model.simulate import simulate
from drake_dock.docking.placement.place import place
from drake_dock.docking.report.results import summary, timeseries
from drake_dock.docking.scenario.loading import load_scenario

MODELS = Path(__file__).resolve().parents[2] / "models"


@pytest.fixture(scope="module")
def run():
    s = load_scenario(MODELS / "paper_example.yaml")
    s.initial.approach_travel = 0.005      # first contact within the 0.05 s run
    return simulate(s, place(s), duration=0.05)


def test_the_rows_stewart_peaks_are_those_of_stewart_history(run):
    row = measure(run)
    stroke, force = stewart_history(run.dd.dp, run.record.x)
    assert row["impacts"] > 0 and stroke.max() > 0.0 and force.max() > 0.0
    assert math.isclose(row["peak_stewart_stroke"], stroke.max(), rel_tol=1e-12)
    assert math.isclose(row["peak_stewart_force"], force.max(), rel_tol=1e-12)


def test_the_row_is_the_summarys(run):
    row = measure(run)
    s = summary(run, timeseries(run))
    fm = s["final_misalignment"]
    assert row["peak_contact_force"] == s["loads"]["couple_normal_force_N"]["peak"] > 0
    assert (row["outcome"], row["reason"], row["capture_time"], row["end_time"],
            row["impacts"]) == (s["outcome"], s["outcome_reason"], s["capture_time_s"],
                                s["end_time_s"], s["number_of_impacts"])
    assert (row["final_axial"], row["final_lateral"], row["final_tilt_deg"]) == (
        fm["axial_m"], fm["lateral_m"], fm["tilt_deg"])
    assert row["momentum_drift"] == s["momentum_drift_relative"]["linear"]
    assert row["energy_closure"] == s["energy_ledger"]["closure_error_relative"]


def test_a_sample_relaxes_the_collector_throughout_and_restores_it(monkeypatch):
    """`run_sample` holds Python's cyclic collector at `RUN_GC_THRESHOLD` or above over the
    whole row (read inside it), and gives back the thresholds it found."""
    import gc
    import drake_dock.campaign.sample as sample
    from drake_dock.systems.simulator import RUN_GC_THRESHOLD
    seen = []
    monkeypatch.setattr(sample, "scenario_row",
                        lambda scenario, reuse=True: seen.append(gc.get_threshold()) or {})
    old = gc.get_threshold()
    try:
        gc.set_threshold(700, 10, 10)
        sample.run_sample(load_scenario(MODELS / "paper_example.yaml"), (0, 1, {}))
        after = gc.get_threshold()
    finally:
        gc.set_threshold(*old)
    assert seen == [(RUN_GC_THRESHOLD, 10, 10)] and after == (700, 10, 10)
