"""Off-nominal runs that used to crash in seeking (docs/model.md, "Degenerate couples"): the
ring-surface seek's contact-form finish went far outside the petal's domain (a math domain
error at t = 0.206 s) or solved a singular J (LinAlgError at t = 0.167 s). With the ring's
circle through the petal, the pair is now classed crossing and the run goes on."""
from pathlib import Path

import pytest

from drake_dock.docking.scenario import load_scenario
from drake_dock.docking.simulate import simulate

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
    result = simulate(make(), duration=duration)
    assert result.outcome == "timeout" and result.end_time == pytest.approx(duration)


def test_idss_sample_139_lifts_off_and_is_captured():
    """Sample 139 of the IDSS plan: the sliding couple cc_T3_C3 unloads at t = 1.965 s with its
    gap drifted 8e-9 m open; it detaches there (the stabilised normal row of Eq. 52,
    `drake_dock.core.constraints`) and the run ends captured. Over its 5.6 s and 41 impacts
    the energy ledger closes to 1e-6 with the default integration scheme (RK5; with
    Bogacki-Shampine, the same step cap leaves it open by 3.6e-6: docs/model.md,
    "Integration")."""
    from drake_dock.docking.results import summary, timeseries
    from drake_dock.campaign.plan import load_plan
    from drake_dock.campaign.sample import sample_scenario
    from drake_dock.campaign.sampling import sample_specs
    plan, base, fields = load_plan(MODELS / "idss_envelope.yaml")
    (_, _, values), = sample_specs(plan, fields, [139])
    result = simulate(sample_scenario(base, values))
    assert result.outcome == "captured" and result.end_time > 1.97
    ledger = summary(result, timeseries(result))["energy_ledger"]
    assert ledger["closure_error_relative"] <= 1e-6
