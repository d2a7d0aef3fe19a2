"""The conditions sweep's sampling against the IDSS box it states, its determinism, and its
outputs read back."""
import csv
import json
import math

import numpy as np
import pytest

from drake_dock.studies.conditions import (IDSS_BOX, ConditionsPlan, conditions, rows_csv,
                                           summary_lines,
                                           with_condition, write_conditions)

PLAN = ConditionsPlan(random=200, corners=32, seed=11)


def test_random_conditions_fill_the_box_and_stay_inside():
    rows = [c for name, c in conditions(PLAN) if name.startswith("random")]
    speed = np.array([c["chaser_speed"] for c in rows])
    off = np.array([math.hypot(*c["lateral_offset"]) for c in rows])
    vel = np.array([math.hypot(*c["lateral_velocity"]) for c in rows])
    tilt = np.array([c["tilt_deg"] for c in rows])
    yaw = np.array([c["target_yaw_deg"] for c in rows])
    rate = np.array([c["angular_velocity_deg_s"] for c in rows])
    lo, hi = IDSS_BOX["chaser_speed"]
    assert lo <= speed.min() and speed.max() <= hi
    assert off.max() <= IDSS_BOX["lateral_offset"] and vel.max() <= IDSS_BOX["lateral_velocity"]
    assert np.abs(tilt).max() <= IDSS_BOX["tilt_deg"]
    assert np.abs(yaw).max() <= IDSS_BOX["target_yaw_deg"]
    assert np.abs(rate).max() <= IDSS_BOX["angular_velocity_deg_s"]
    # Uniform over the disk by area: the fraction within half the radius is 1/4.
    assert np.mean(off < 0.5 * IDSS_BOX["lateral_offset"]) == pytest.approx(0.25, abs=0.08)
    assert speed.min() < lo + 0.1 * (hi - lo) and speed.max() > hi - 0.1 * (hi - lo)


def test_corners_put_every_parameter_at_an_extreme():
    for name, c in conditions(PLAN):
        if not name.startswith("corner"):
            continue
        assert c["chaser_speed"] in IDSS_BOX["chaser_speed"]
        assert math.hypot(*c["lateral_offset"]) == pytest.approx(IDSS_BOX["lateral_offset"])
        assert math.hypot(*c["lateral_velocity"]) == pytest.approx(IDSS_BOX["lateral_velocity"])
        assert np.allclose(np.abs(c["tilt_deg"]), IDSS_BOX["tilt_deg"])
        assert abs(c["target_yaw_deg"]) == IDSS_BOX["target_yaw_deg"]
        assert np.allclose(np.abs(c["angular_velocity_deg_s"]),
                           IDSS_BOX["angular_velocity_deg_s"])


def test_the_same_seed_gives_the_same_conditions_and_every_one_is_a_valid_scenario(
        paper_scenario):
    a, b = conditions(PLAN), conditions(PLAN)
    assert json.dumps(a) == json.dumps(b)
    assert json.dumps(a) != json.dumps(conditions(ConditionsPlan(200, 32, seed=12)))
    for _, c in a[:20] + a[-5:]:
        s = with_condition(paper_scenario, c)
        assert s.initial.chaser_speed == c["chaser_speed"]
    assert paper_scenario.initial.chaser_speed == 1.0      # the base is not changed


def test_rows_are_written_and_read_back(tmp_path):
    rows = [{"name": "random 1", "chaser_speed": 0.07, "lateral_offset": "[0.01, 0.02]",
             "tilt_deg": "[1.0, -2.0]", "outcome": "captured", "penetration_m": 2e-3,
             "momentum_drift_linear": 1e-15, "momentum_drift_angular": 2e-15,
             "energy_closure": 1e-9},
            {"name": "corner 1", "chaser_speed": 0.1, "lateral_offset": "[0.1, 0.0]",
             "tilt_deg": "[4.0, 4.0]", "outcome": "error", "reason": "NumericalError: x"}]
    write_conditions({"plan": {}, "rows": rows}, tmp_path / "out")
    back = list(csv.DictReader(open(tmp_path / "out" / "conditions.csv")))
    assert [r["outcome"] for r in back] == ["captured", "error"]
    assert float(back[0]["penetration_m"]) == 2e-3 and back[1]["reason"] == "NumericalError: x"
    assert (tmp_path / "out" / "conditions.png").stat().st_size > 10000
    assert rows_csv(rows) == (tmp_path / "out" / "conditions.csv").read_text()


def test_the_summary_prints_the_median_wall_time_per_run():
    """The median of the rows' wall times (numpy's, from the same rows), errors included."""
    walls = [0.31, 2.5, 0.07, 11.0, 0.9, 4.2]
    rows = [{"name": f"random {k}", "outcome": "jammed" if k % 3 else "error",
             "reason": "NumericalError: x", "wall_time_s": w} for k, w in enumerate(walls)]
    line, = [ln for ln in summary_lines({"rows": rows}) if ln.startswith("median wall")]
    assert float(line.split()[5]) == pytest.approx(np.median(walls), rel=1e-3)


def test_every_run_has_the_plans_contact_set(paper_scenario, monkeypatch):
    """The sweep runs the plan's contact set (complete by default) whatever the base states,
    and leaves the base as it was."""
    import drake_dock.studies.conditions as study
    seen = []

    def fake(scenario, name, condition):
        seen.append(scenario.contact.pairs)
        return {"name": name, "outcome": "timeout", "penetration_m": 0.0}

    monkeypatch.setattr(study, "run_condition", fake)
    study.run_conditions(paper_scenario, ConditionsPlan(random=2, corners=1), log=lambda s: None)
    study.run_conditions(paper_scenario, ConditionsPlan(1, 0, pairs="paper"), log=lambda s: None)
    assert seen == ["complete"] * 3 + ["paper"]
    assert paper_scenario.contact.pairs == "paper"


@pytest.mark.parametrize("analytic,mesh,which", [(2e-4, 3e-4, "mesh"), (5e-4, 1e-7, "analytic"),
                                                 (0.0, 0.0, "")])
def test_a_row_keeps_both_checks_and_the_deeper_one(monkeypatch, analytic, mesh, which):
    """The row's penetration_m and its text are the deeper check's (the analytic one on a tie);
    each check's depth has a column of its own, in the CSV and in the summary."""
    import drake_dock.studies.conditions as study
    from drake_dock.docking.checks.penetration import Penetration
    found = {"analytic": Penetration(analytic, 1.5, "chaser_apds guide side 1",
                                     "target_apds petal 2"),
             "mesh": Penetration(mesh, 2.5, "target_apds tip arc 1", "chaser_apds petal 3")}
    monkeypatch.setattr(study, "deepest_penetration", lambda *a: found["analytic"])
    monkeypatch.setattr(study, "deepest_penetration_mesh", lambda *a: found["mesh"])
    ts = {"t": None, "R_WA": None, "p_WA": None, "apds_names": np.array(["a", "b"])}
    row = study.penetrations(None, ts)
    assert row["penetration_m"] == max(analytic, mesh)
    assert (row["penetration_analytic_m"], row["penetration_mesh_m"]) == (analytic, mesh)
    assert row["penetration"] == (found[which].describe() + f" ({which} check)" if which
                                  else "no interpenetration")
    back = next(csv.DictReader(rows_csv([{"name": "random 1", "outcome": "jammed", **row}])
                               .splitlines()))
    assert float(back["penetration_mesh_m"]) == mesh
    line, = [ln for ln in summary_lines({"rows": [{"outcome": "jammed", "momentum_drift_linear": 0,
                                                    "momentum_drift_angular": 0,
                                                    "energy_closure": 0, **row}]})
             if ln.startswith("interpenetration")]
    assert line.endswith(f"(analytic check {analytic * 1e3:.3g} mm, mesh check "
                         f"{mesh * 1e3:.3g} mm)")
