"""A campaign row's Stewart columns: the peaks of the Stewart element's stroke and force over
the recorded samples, as `drake_dock.docking.model.plant.stewart_history` computes them from the
recorded plant states on its own context (the row takes them from the run's timeseries)."""
from pathlib import Path

from drake_dock.campaign.sample import measure
from drake_dock.docking.model.plant import stewart_history
from drake_dock.docking.model.simulate import simulate
from drake_dock.docking.placement.place import place
from drake_dock.docking.scenario.loading import load_scenario

MODELS = Path(__file__).resolve().parents[2] / "models"


def test_the_rows_stewart_peaks_are_those_of_stewart_history():
    s = load_scenario(MODELS / "paper_example.yaml")
    s.initial.approach_travel = 0.005      # first contact within the 0.05 s run
    result = simulate(s, place(s), duration=0.05)
    row = measure(result)
    stroke, force = stewart_history(result.dd.dp, result.record.x)
    assert row["impacts"] > 0 and stroke.max() > 0.0 and force.max() > 0.0
    assert row["peak_stewart_stroke"] == stroke.max()
    assert row["peak_stewart_force"] == force.max()
