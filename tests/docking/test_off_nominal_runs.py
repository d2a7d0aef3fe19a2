"""Off-nominal runs that used to crash in seeking (docs/model.md, "Degenerate couples"): the
ring-surface seek's contact-form finish went far outside the petal's domain (a math domain
error at t = 0.206 s) or solved a singular J (LinAlgError at t = 0.167 s). With the ring's
circle through the petal, the pair is now classed crossing and the run goes on."""
import dataclasses
from pathlib import Path

import pytest

from drake_dock.docking.model.simulate import simulate
from drake_dock.docking.placement.place import place
from drake_dock.docking.scenario.loading import load_scenario

MODELS = Path(__file__).resolve().parents[2] / "models"


def _misaligned():
    """The paper example inside the IDSS box: roll 4 deg, closing at 0.1 m/s, off-axis and
    tilted, with lateral and angular rates."""
    s = load_scenario(MODELS / "paper_example.yaml")
    ic = s.initial
    ic.target_yaw_deg, ic.chaser_speed = 4.0, 0.1
    ic.lateral_offset, ic.tilt_deg = [-0.0563, 0.0827], [4.0, 4.0]
    ic.lateral_velocity, ic.angular_velocity_deg_s = [0.04, 0.0], [0.2, -0.2, 0.2]
    return s


def _box_corner_paper_pairs():
    """models/idss_box_corner.yaml with the paper's 12 pairs (where the seek crashed)."""
    s = load_scenario(MODELS / "idss_box_corner.yaml")
    s.contact.pairs = "paper"
    return s


@pytest.mark.parametrize("make, crashed_at", [
    (_misaligned, 0.206),
    (_box_corner_paper_pairs, 0.167)],
    ids=["misaligned", "idss_box_corner"])
def test_runs_past_the_former_seek_crash(make, crashed_at):
    duration = crashed_at + 0.02
    s = make()
    result = simulate(s, place(s), duration=duration)
    assert result.outcome == "timeout" and result.end_time == pytest.approx(duration)


def test_idss_sample_139_lifts_off_and_runs_to_a_named_outcome():
    """Sample 139 of the IDSS plan, run with the paper's pairs and no thrust (the plan's `set`
    left out; the sample's initial conditions only): the sliding couple cc_T3_C3 unloads with
    its gap drifted open; it detaches (the stabilised normal row of Eq. 52,
    `drake_dock.core.constraints`) and the run goes on, without a numerical error, to a named
    outcome whose reason agrees with the time series (no couple active at its end). Over its
    6 s and its impacts the energy ledger closes to 1e-6 with the default integration scheme
    (RK5; docs/algorithms.md, "Integration")."""
    import numpy as np
    from drake_dock.campaign.plan import load_plan
    from drake_dock.campaign.sample import sample_scenario
    from drake_dock.campaign.points import sample_specs
    from drake_dock.docking.model.outcome import OUTCOMES
    from drake_dock.docking.report.results import (IN_CONTACT, final_misalignment, summary,
                                                   timeseries)
    plan, base, fields = load_plan(MODELS / "idss_envelope.yaml")
    (_, _, values), = sample_specs(plan, fields, [139])
    scenario = sample_scenario(base, values)
    scenario = dataclasses.replace(scenario, thrust=None, contact=dataclasses.replace(
        scenario.contact, pairs="paper"))
    result = simulate(scenario, place(scenario))
    ts = timeseries(result)
    contact = ts["status"] >= IN_CONTACT
    active = contact[:, list(ts["couple_names"]).index("cc_T3_C3")]
    on = np.nonzero(active)[0]
    assert on.size and not active[on[-1] + 1:].any() and on[-1] + 1 < len(active)
    assert result.outcome in OUTCOMES and result.end_time > ts["t"][on[-1]] + 1.0
    if result.outcome in ("jammed", "timeout"):
        assert ("held by no couple" in result.reason) == (not contact[-1].any())
    else:               # missed through the other ring (the 12 pairs have no ring faces)
        end = final_misalignment(ts)
        sim = scenario.simulation
        assert result.outcome == "missed" and not contact[-1].any()
        assert end["axial_m"] < -sim.capture_distance and end["lateral_m"] > sim.capture_lateral
    ledger = summary(result, ts)["energy_ledger"]
    assert ledger["closure_error_relative"] <= 1e-6