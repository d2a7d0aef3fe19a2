"""The relative-roll study: its grid against the range the scenario allows, and three of its
runs against a closed form, the mirror image and the independent checks."""
import csv

import pytest

from drake_dock.errors import InputError
from drake_dock.studies.conditions import PENETRATION_LIMIT, with_condition
from drake_dock.studies.roll import RollPlan, rolls, run_rolls, write_rolls


def test_the_grid_spans_the_allowed_range_symmetrically(paper_scenario):
    grid = rolls(RollPlan())
    assert grid[0] == -59.9 and grid[-1] == 59.9 and 0.0 in grid
    assert grid == sorted(grid) and grid == [-r for r in reversed(grid)]
    inner = grid[1:-1]
    assert all(b - a == pytest.approx(2.5) for a, b in zip(inner, inner[1:]))
    assert 60.0 - 2.5 <= -grid[1] < 60.0
    for r in grid:                                   # every roll is a valid scenario
        s = with_condition(paper_scenario, {"target_yaw_deg": r})
        assert s.initial.target_yaw_deg == r
    with pytest.raises(InputError, match="target_yaw_deg"):
        with_condition(paper_scenario, {"target_yaw_deg": 60.0})
    assert rolls(RollPlan(step_deg=60.0, edge_deg=20.0)) == [-20.0, 0.0, 20.0]


def test_three_rolls_run_to_their_outcomes(paper_scenario, tmp_path):
    """Roll 0: the petals pass between each other and the inside circles pass the tip arcs of
    their radius at ring distance H, so the chaser flies free to capture at (H + approach_travel
    - capture_distance) / chaser_speed (to the witness's isolation). +-36.5 deg (inside
    2 theta_end, where a ring's circle sinks nearly coaxially over the tip arcs: a flat valley
    of couples that the seek must cross) are mirror images of each other: the same capture
    time (to the witness's isolation) and impacts. Every run
    conserves momentum and keeps the features out of the other APDS by both checks."""
    result = run_rolls(paper_scenario, RollPlan(step_deg=100.0, edge_deg=36.5), log=lambda s: 0)
    rows = {r["target_yaw_deg"]: r for r in result["rows"]}
    assert sorted(rows) == [-36.5, 0.0, 36.5]
    ic, sim, g = paper_scenario.initial, paper_scenario.simulation, paper_scenario.geometry
    free = (g.H + ic.approach_travel - sim.capture_distance) / ic.chaser_speed
    assert rows[0.0]["outcome"] == "captured" and rows[0.0]["impacts"] == 0
    # Capture is a witness, isolated by Drake's integrator to a few nanoseconds here.
    assert rows[0.0]["capture_time_s"] == pytest.approx(free, abs=1e-8)
    a, b = rows[-36.5], rows[36.5]
    assert a["outcome"] == b["outcome"] == "captured"
    assert a["impacts"] == b["impacts"] > 0
    assert a["capture_time_s"] == pytest.approx(b["capture_time_s"], abs=1e-8)
    for r in rows.values():
        assert r["penetration_analytic_m"] <= PENETRATION_LIMIT
        assert r["penetration_mesh_m"] <= PENETRATION_LIMIT
        assert max(r["momentum_drift_linear"], r["momentum_drift_angular"]) < 1e-9
    write_rolls(result, tmp_path / "roll")
    back = list(csv.DictReader(open(tmp_path / "roll" / "roll.csv")))
    assert [float(r["target_yaw_deg"]) for r in back] == [-36.5, 0.0, 36.5]
    assert (tmp_path / "roll" / "roll.png").stat().st_size > 10000
