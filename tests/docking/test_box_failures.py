"""Off-axis approaches on the paper's geometry that once ended in numerical failures now end in
named outcomes. In that geometry the petal tips stand on the circle of the other ring's inside
circle (R - H cot(alpha1) = Rs), so a few centimetres off the axis each APDS's tips land on
the other's lip: two couples whose normals lie a few degrees off the axis, held sticking
between the same two bodies (statically indeterminate, `test_constraints`), and an LZB impact
of the two at once.

The outcome is checked against what the geometry allows: the rings cannot come closer than H
(the tips on the lips) while the holding couples' normals point along the axis."""
import json
import math

import pytest
import yaml

from drake_dock.cli import main
from drake_dock.docking.model.simulate import simulate
from drake_dock.docking.placement.place import place
from drake_dock.docking.report.results import summary, timeseries
from drake_dock.docking.scenario.loading import load_scenario
from drake_dock.docking.scenario.models_dir import MODELS_DIR


def _run(tmp_path, data: dict, name: str, *extra) -> dict:
    f = tmp_path / f"{name}.yaml"
    f.write_text(yaml.safe_dump(data))
    out = tmp_path / name
    assert main(["run", str(f), "--out", str(out), "--no-progress", *extra]) == 0
    return json.loads((out / "summary.json").read_text())


def _held_at_the_lips(s, H=0.2):
    """Jammed with the rings a petal height apart, held by tip-on-lip couples whose normals
    lie within 30 deg of the axis (no lateral guidance)."""
    assert s["outcome"] == "jammed"
    assert s["final_misalignment"]["axial_m"] == pytest.approx(H, abs=0.01)
    held = s["end_state"]["holding_couples"]
    assert held and all("tip" in h["couple"] and h["normal_angle_deg"] < 30 for h in held)
    assert "held by" in s["outcome_reason"]
    assert s["end_state"]["relative_kinetic_energy_J"] >= 0.0


def test_two_centimetres_off_the_axis_jams_at_the_lips(tmp_path):
    """models/idss_lateral.yaml 2 cm off the axis: both tips on both lips, sticking
    (a Painleve inconsistency before redundant sticking was accepted)."""
    data = yaml.safe_load((MODELS_DIR / "idss_lateral.yaml").read_text())
    data["initial"]["lateral_offset"] = [0.02, 0.0]
    _held_at_the_lips(_run(tmp_path, data, "lateral_2cm"))


def test_five_centimetres_off_at_twice_the_speed_jams_at_the_lips(tmp_path):
    """A scenario file holding only the approach, 5 cm off at 0.2 m/s: the impact of the two
    tips on the lips is solved (two couples that start to slide from rest together, one of
    them just outside its static cone) and the run jams there."""
    _held_at_the_lips(_run(tmp_path, {"initial": {"lateral_offset": [0.05, 0.0],
                                                   "chaser_speed": 0.2}}, "offset_5cm"))


def test_box_corner_pushed_at_500_newtons_runs_past_the_old_failure():
    """models/idss_box_corner.yaml with 500 N of thrust from the first contact: the chaser is
    pushed sideways off the lip. Run past 3.04 s, where a Painleve inconsistency ended it, the
    run is a named outcome with the momentum balanced by the thrust's impulse (the run alone,
    without its figures and replay)."""
    data = yaml.safe_load((MODELS_DIR / "idss_box_corner.yaml").read_text())
    data["thrust"] = {"force": 500.0, "duration": 5.0}
    data.setdefault("simulation", {})["duration"] = 3.2
    s = load_scenario(data=yaml.safe_dump(data))
    result = simulate(s, place(s))
    s = summary(result, timeseries(result))
    assert s["outcome"] in ("timeout", "missed", "jammed")
    assert s["end_time_s"] >= 3.04 or s["outcome"] == "missed"
    assert s["momentum_drift_relative"]["linear"] < 1e-8
    assert math.isfinite(s["energy_ledger"]["closure_error_relative"])
