"""The funnel study's pieces against closed forms: the clearance of the tips inside the other
ring, the plan's geometries, the bisection of the capture range on a made-up monotone test, and
the probe approach."""
import math

import pytest

from drake_dock.docking.scenario.loading import load_scenario
from drake_dock.docking.scenario.models_dir import MODELS_DIR
from drake_dock.studies.funnel import (FunnelPlan, capture_range, clearance, geometries,
                                       probe)


def test_clearance_is_passage_less_tip_radius():
    """c = Rs - (Rp - H cot(alpha1)): 0 for the paper's geometry (the tips on the passage
    circle), H for petals on the inside circle at 45 deg."""
    paper = load_scenario().geometry
    assert clearance(paper) == pytest.approx(0.0, abs=1e-15)
    funnel = load_scenario(MODELS_DIR / "apds_funnel.yaml").geometry
    assert clearance(funnel) == pytest.approx(funnel.H, rel=1e-12)
    assert clearance(funnel) > 0.1        # the IDSS box's lateral misalignment


def test_the_plan_geometries_are_valid_and_ordered():
    base = load_scenario(MODELS_DIR / "apds_funnel.yaml").geometry
    gs = geometries(base, FunnelPlan.full())
    labels = [label for label, _ in gs]
    assert labels[0].startswith("paper") and clearance(gs[0][1]) == pytest.approx(0.0, abs=1e-15)
    fam = [g for label, g in gs if label.startswith("funnel")]
    assert [g.H for g in fam] == list(FunnelPlan.full().funnel_heights)
    assert all(g.Rp == g.Rs == FunnelPlan.full().funnel_passage for g in fam)
    assert all(g.petal_inset_deg == base.petal_inset_deg for g in fam)
    rim = [g for label, g in gs if label.startswith("petals on R")]
    # Petals on the rim with a wider passage: clearance Rs - (R - H cot(alpha1)) > 0.
    assert all(clearance(g) == pytest.approx(g.Rs - 0.4, abs=1e-12) for g in rim)


@pytest.mark.parametrize("edge, hi, steps", [(0.137, 0.25, 6), (0.0, 0.25, 3),
                                             (0.3, 0.25, 4), (0.2501, 0.25, 5)])
def test_capture_range_brackets_a_monotone_edge(edge, hi, steps):
    """On captured(e) = e <= edge the bisection returns the bracket's lower
    end within hi / 2**steps below the edge, or hi when hi itself captures; each run is
    logged once."""
    ranged, tried = capture_range(lambda e: e <= edge, hi, steps)
    if edge >= hi:
        assert ranged == hi and len(tried) == 2
    else:
        assert ranged <= edge < ranged + hi / 2 ** steps
        assert len(tried) == 2 + steps
    assert len({e for e, _ in tried}) == len(tried)


def test_a_failing_centre_has_no_range():
    ranged, tried = capture_range(lambda e: False, 0.2, 5)
    assert ranged == 0.0 and tried == [(0.0, False)]


def test_the_probe_is_the_plan_approach():
    base = load_scenario(MODELS_DIR / "apds_funnel.yaml")
    plan = FunnelPlan.full()
    s = probe(base, base.geometry, 150.0, plan, 0.05, 90.0)
    assert s.initial.lateral_offset == pytest.approx([0.0, 0.05], abs=1e-15)
    assert s.initial.chaser_speed == plan.closing_speed
    assert s.initial.tilt_deg == [0.0, 0.0] and s.initial.angular_velocity_deg_s == [0, 0, 0]
    assert s.thrust.force == 150.0 and s.thrust.duration == plan.thrust_duration
    assert probe(base, base.geometry, 0.0, plan, 0.0, 30.0).thrust is None
    assert math.isclose(s.initial.target_yaw_deg, plan.roll_deg)
