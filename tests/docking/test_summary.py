"""summary.json and cost.json of a run, checked against closed forms and second computations:
the relative kinetic energy at contact against 1/2 mu v^2, the energy ledger's split between the
centre of mass's motion and the relative motion, the interface force against the net contact
force on the chaser (computed from the raw record), the total contact force against the couples'
multipliers, the Stewart stroke against the body poses; and the couples in plain words against
the APDS geometry."""
import json
import math

import numpy as np
import pytest

from drake_dock.docking.geometry.apds import apds_patches
from drake_dock.docking.geometry.pairs import feature_words
from drake_dock.docking.geometry.scene import DockingScene
from drake_dock.docking.report.results import near_couples, rigid_chaser_force
from drake_dock.docking.scenario.dimensions import ApdsGeometry
from drake_dock.docking.scenario.loading import load_scenario
from drake_dock.run import format_summary, run

COST_KEYS = {"wall_time_s", "derivative_evaluations", "time_shares", "cost_by_pair_type",
             "samples", "mode_changes"}


@pytest.fixture(scope="module")
def paper(tmp_path_factory):
    out = tmp_path_factory.mktemp("summary") / "paper"
    full = run(load_scenario(), out, full=True, name="paper_example")
    return full, out


def test_outcome_first_and_cost_apart(paper):
    full, out = paper
    s = json.loads((out / "summary.json").read_text())
    cost = json.loads((out / "cost.json").read_text())
    assert list(s)[:3] == ["scenario_name", "outcome", "outcome_reason"]
    assert s["scenario_name"] == "paper_example" and s["outcome"] == "captured"
    assert not COST_KEYS & set(s)
    assert COST_KEYS <= set(cost)
    assert cost["derivative_evaluations"] == full.result.evaluations > 0
    assert cost["simulated_s"] == s["end_time_s"]


def test_relative_kinetic_energy_is_half_mu_v_squared(paper):
    """The paper's example closes at v = chaser_speed with no rotation and the target at rest:
    the kinetic energy in the centre-of-mass frame is 1/2 mu v^2 (mu the reduced mass of the
    chaser against the target with its APDS), the rest of the inertial 1/2 m_c v^2 is the
    centre of mass's motion, P^2 / 2M."""
    full, _ = paper
    s, sc = full.summary, full.result.scenario
    m_c = sc.bodies.chaser.mass
    m_t = sc.bodies.target.mass + sc.bodies.target_apds.mass
    v = sc.initial.chaser_speed
    mu = m_c * m_t / (m_c + m_t)
    assert s["relative_kinetic_energy_at_contact_J"] == pytest.approx(0.5 * mu * v**2, rel=1e-12)
    led = s["energy_ledger"]
    assert led["initial_total_J"] == pytest.approx(0.5 * m_c * v**2, rel=1e-12)
    assert led["initial_centre_of_mass_motion_J"] == pytest.approx(
        (m_c * v) ** 2 / (2 * (m_c + m_t)), rel=1e-12)


def test_interface_force_is_the_net_force_on_the_chaser(paper):
    """The contact force at the target ring is minus the net contact force on the chaser (the
    only contacts are between the two APDS), computed here from the raw record's multipliers
    and frames: the same peak and time."""
    full, _ = paper
    t, F = rigid_chaser_force(full.result)
    mag = np.linalg.norm(F, axis=1)
    peak = full.summary["loads"]["interface_force_N"]
    assert peak["peak"] == pytest.approx(mag.max(), rel=1e-12)
    assert peak["time_s"] == t[np.argmax(mag)]
    # Symmetric example: all of it along the axis.
    assert peak["axial_peak"] == pytest.approx(peak["peak"], rel=1e-9)
    assert peak["lateral_peak"] < 1e-6 * peak["peak"]


def test_contact_force_peaks_from_the_multipliers(paper):
    """The total contact force is the sum over couples of |(lambda_t, lambda_n)| (the contact
    frames are orthonormal); its peak is three times the peak couple's resultant in the
    symmetric example, and the peak couple is one of the three that close first."""
    full, _ = paper
    ts, s = full.timeseries, full.summary
    lam = np.sqrt(ts["lambda_n"] ** 2 + (ts["lambda_t"] ** 2).sum(-1))
    total = s["loads"]["total_contact_force_N"]
    assert total["peak"] == pytest.approx(lam.sum(1).max(), rel=1e-12)
    couple = s["loads"]["couple_normal_force_N"]
    assert couple["couple"] in s["first_closing_couples"]
    assert couple["peak"] == pytest.approx(ts["lambda_n"].max(), rel=1e-12)
    assert total["peak"] == pytest.approx(3 * lam.max(), rel=1e-6)
    assert s["couples"][couple["couple"]]["peak_normal_force_N"] == pytest.approx(couple["peak"])


def test_stewart_stroke_from_the_poses(paper):
    """The symmetric example strokes the Stewart element along the axis only: the peak equals
    the largest axial offset of the APDS frame from its anchor on the target, from the body
    poses."""
    full, _ = paper
    ts, sc = full.timeseries, full.result.scenario
    R_T, p_T, p_A = ts["R_WB"][:, 0], ts["p_WB"][:, 0], ts["p_WB"][:, 1]
    offset = np.einsum("nji,nj->ni", R_T, p_A - p_T) - np.asarray(sc.stewart.p_TA)
    stroke = full.summary["loads"]["stewart_stroke_m"]
    assert stroke["peak"] == pytest.approx(np.abs(offset[:, 2]).max(), rel=1e-9)
    assert stroke["axial_peak"] == pytest.approx(stroke["peak"], rel=1e-9)


def test_couples_table_holds_the_couples_that_came_near(paper):
    full, _ = paper
    ts, s = full.timeseries, full.summary
    names = ts["couple_names"].tolist()
    assert list(s["couples"]) == [names[j] for j in near_couples(ts)]
    far = set(names) - set(s["couples"])
    for c in far:
        j = names.index(c)
        assert (ts["status"][:, j] == 0).all() and ts["lambda_n"][:, j].max() == 0
    for c in s["first_closing_couples"]:
        assert s["couples"][c]["impacts"] == s["number_of_impacts"]
        assert "guide side" in s["couples"][c]["description"]


def test_printed_summary_names_the_loads(paper):
    full, _ = paper
    text = format_summary(full.summary, full.cost)
    lines = text.splitlines()
    assert lines[0].startswith("captured at t = 0.154938 s")
    s = full.summary
    assert f"force {s['loads']['interface_force_N']['peak']:.4g} N" in text
    assert f"relative kinetic energy at contact {s['relative_kinetic_energy_at_contact_J']:.4g}" \
        in text
    assert "cost.json" in lines[-1]


def _azimuth(p):
    return math.atan2(p[1], p[0])


def test_feature_words_follow_the_geometry():
    """Each patch of an APDS has its own words, and a guide side's petal is the guide surface
    its mid-point lies on (its azimuth inside the surface's, from the patches' equations)."""
    g = ApdsGeometry()
    P = apds_patches(g)
    patches = [P.ring, P.rim, P.face, *P.sides.values(), *P.surfaces.values(),
               *P.tips.values(), *P.lands.values(), *P.corners.values()]
    words = [feature_words(P, p) for p in patches]
    assert len(set(words)) == len(words)
    for i, side in P.sides.items():
        k = int(feature_words(P, side).split("petal ")[1].rstrip(")"))
        mid = side.position(np.array([0.5 * (side.lower[0] + side.upper[0])]))
        surf = P.surfaces[k]
        lo, hi = surf.lower.copy(), surf.upper.copy()
        a, b = (_azimuth(surf.position(np.array([s, 0.0]))) for s in (lo[0], hi[0]))
        az = _azimuth(mid)
        half = abs(((b - a + math.pi) % (2 * math.pi) - math.pi) / 2)
        centre = a + ((b - a + math.pi) % (2 * math.pi) - math.pi) / 2
        assert abs((az - centre + math.pi) % (2 * math.pi) - math.pi) <= half + 1e-9, (i, k)
    described = [p.description for p in DockingScene(g, "complete").pairs]
    assert len(set(described)) == len(described) and all(" / " in d for d in described)


def test_summary_stores_the_scenario(paper):
    """summary.json's `scenario` is the full scenario of the run: JSON is YAML, so it loads
    back to the run's scenario."""
    full, out = paper
    s = json.loads((out / "summary.json").read_text())
    assert load_scenario(data=json.dumps(s["scenario"])) == full.result.scenario
    assert list(s)[-1] == "scenario"


def test_outputs_doc_lists_the_summary_keys(paper):
    """docs/outputs.md's table of summary.json names every top-level key, in the file's order."""
    import re
    from pathlib import Path
    doc = (Path(__file__).resolve().parents[2] / "docs" / "outputs.md").read_text()
    section = doc.split("## summary.json")[1].split("\n## ")[0]
    listed = [k for row in re.findall(r"^\| ((?:`[A-Za-z_0-9]+`(?:, )?)+) \|", section, re.M)
              for k in re.findall(r"`([A-Za-z_0-9]+)`", row)]
    _, out = paper
    assert listed == list(json.loads((out / "summary.json").read_text()))
