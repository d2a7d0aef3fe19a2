"""The named-examples study: a drift of the base scenario against the free-flight closed form,
and a shipped scenario's row against its YAML file and the ring distance at which the tip arcs
reach the other ring's inside circle."""
import copy
import csv
import json

import pytest
import yaml

from drake_dock.docking.scenario.models_dir import MODELS_DIR
from drake_dock.studies.examples import (EXAMPLE_FIELDS, ExamplesPlan, run_examples,
                                         summary_lines, write_examples)


def test_a_drift_and_a_shipped_scenario_run_to_their_outcomes(paper_scenario, tmp_path):
    """Roll 0: the petals pass between each other, so the chaser flies free to capture at
    (H + approach_travel - capture_distance) / chaser_speed (with the `complete` set, whose
    tip-arc pairs close at ring distance H, as the roll study's). `idss_lateral` keeps the
    inputs of its file and jams with the ring faces about H apart, where its tip arcs stand on
    the other ring's inside circle (docs/model.md)."""
    plan = ExamplesPlan(files=("idss_lateral",),
                        drifts=(("coaxial", (("target_yaw_deg", 0.0),)),))
    base = copy.deepcopy(paper_scenario)
    base.contact.pairs = "complete"      # the tip arcs' pairs place the first contact at H
    result = run_examples(base, plan, log=lambda s: 0)
    lateral, coaxial = result["rows"]
    ic, sim, g = paper_scenario.initial, paper_scenario.simulation, paper_scenario.geometry
    free = (g.H + ic.approach_travel - sim.capture_distance) / ic.chaser_speed
    assert coaxial["outcome"] == "captured" and coaxial["impacts"] == 0
    assert coaxial["capture_time_s"] == pytest.approx(free, abs=1e-8)
    assert coaxial["end_time_s"] == coaxial["capture_time_s"]
    assert coaxial["final_axial_m"] == pytest.approx(sim.capture_distance, abs=1e-6)
    assert json.loads(coaxial["impacts_by_couple"]) == {}
    assert coaxial["chaser_speed"] == ic.chaser_speed and coaxial["target_yaw_deg"] == 0.0

    given = yaml.safe_load((MODELS_DIR / "idss_lateral.yaml").read_text())
    assert lateral["chaser_speed"] == given["initial"]["chaser_speed"]
    assert json.loads(lateral["lateral_offset"]) == given["initial"]["lateral_offset"]
    assert lateral["outcome"] == "jammed"
    assert lateral["final_axial_m"] == pytest.approx(given["geometry"]["H"], abs=0.01)
    counts = json.loads(lateral["impacts_by_couple"])
    # every impact has at least one couple, and no couple more impacts than the run
    assert sum(counts.values()) >= lateral["impacts"] > 0
    assert max(counts.values()) <= lateral["impacts"]
    for r in result["rows"]:
        assert r["penetration_m"] == 0.0
        assert max(r["momentum_drift_linear"], r["momentum_drift_angular"]) < 1e-9

    write_examples(result, tmp_path / "examples")
    with open(tmp_path / "examples" / "examples.csv", newline="") as f:
        back = list(csv.DictReader(f))
    assert [r["name"] for r in back] == ["idss_lateral", "coaxial"]
    assert list(back[0]) == list(EXAMPLE_FIELDS)
    assert float(back[1]["capture_time_s"]) == coaxial["capture_time_s"]
    lines = json.loads((tmp_path / "examples" / "summary.json").read_text())["lines"]
    assert lines == summary_lines(result) and lines[1].startswith("coaxial: captured")
