"""What `drake-dock run` writes for an off-axis run (the session's `box_corner`): small files
(replay.html within 10 MB, the directory within 30 MB), timeseries.npz compressed with the rows
of the couples that came near only, the replay titled after the scenario and slowed to last at
least 10 s on screen, and the summary's relative kinetic energy against a second computation
from the bodies' motion."""
import json
import zipfile

import numpy as np
import pytest

from drake_dock.docking.report.replay import MIN_SCREEN_SECONDS, playback_slowdown
from drake_dock.docking.report.results import first_contact_sample

MB = 1e6
NICE = (1, 2, 5, 10, 20, 50, 100, 200, 500, 1000, 2000, 5000, 10000)


def test_the_outputs_are_small(box_corner):
    _, out = box_corner
    sizes = {p.name: p.stat().st_size for p in out.iterdir()}
    assert sizes["replay.html"] <= 10 * MB
    assert sum(sizes.values()) <= 30 * MB


def test_timeseries_holds_the_couples_that_came_near(box_corner):
    """timeseries.npz: deflate-compressed; its couples are those of the summary's table (the
    couples tracked, in contact or in an impact), far fewer than the 134 declared, each row equal
    to the run's in-memory row of that couple, matched by name."""
    full, out = box_corner
    ts = full.timeseries
    with zipfile.ZipFile(out / "timeseries.npz") as z:
        assert {i.compress_type for i in z.infolist()} == {zipfile.ZIP_DEFLATED}
    saved = np.load(out / "timeseries.npz")
    names = saved["couple_names"].tolist()
    assert names == list(full.summary["couples"]) and 0 < len(names) < 30
    every = ts["couple_names"].tolist()
    idx = [every.index(c) for c in names]
    for key in ("status", "lambda_n", "lambda_t", "gap", "p1_W", "frame_W"):
        np.testing.assert_array_equal(saved[key], ts[key][:, idx])
    for key in ("impact_couples", "impact_normal_impulse"):
        np.testing.assert_array_equal(saved[key], ts[key][:, idx])
    left = np.setdiff1d(np.arange(len(every)), idx)
    assert (ts["status"][:, left] == 0).all() and not ts["impact_couples"][:, left].any()
    np.testing.assert_array_equal(saved["t"], ts["t"])


@pytest.mark.parametrize("duration", [0.0099, 0.155, 1.5, 5.23, 10.0, 60.0])
def test_playback_lasts_at_least_ten_seconds(duration):
    """The slowdown is the smallest of 1, 2, 5, 10, ... that makes the run last 10 s."""
    slow = playback_slowdown(duration)
    assert slow in NICE
    assert duration * slow >= MIN_SCREEN_SECONDS
    smaller = [n for n in NICE if n < slow]
    assert not smaller or duration * smaller[-1] < MIN_SCREEN_SECONDS


def test_replay_is_titled_after_the_scenario(box_corner):
    _, out = box_corner
    html = (out / "replay.html").read_text()
    assert "<title>idss_box_corner: drake_dock replay</title>" in html
    assert "Drake MeshCat" not in html


def test_relative_kinetic_energy_from_the_bodies(box_corner):
    """The relative kinetic energy at contact, recomputed from the bodies' velocities, masses
    and inertias: sum 1/2 m |v - v_com|^2 + 1/2 w.I w; with the target and its APDS at rest,
    the two-body form 1/2 mu |v_chaser|^2 + 1/2 w.I_chaser w; and near 1/2 mu (v_closing^2 +
    v_lateral^2) of the scenario's rates (the chaser's 0.2 deg/s add about 10 %)."""
    full, _ = box_corner
    ts, sc = full.timeseries, full.result.scenario
    bodies = [getattr(sc.bodies, n) for n in ts["body_names"]]
    m = np.array([b.mass for b in bodies])
    k = first_contact_sample(ts)
    v, w, R = ts["v_WB"][k], ts["w_WB"][k], ts["R_WB"][k]
    v_com = m @ v / m.sum()
    ke = 0.5 * (m * ((v - v_com) ** 2).sum(1)).sum()
    for j, b in enumerate(bodies):
        I_W = R[j] @ np.diag(b.inertia) @ R[j].T
        ke += 0.5 * w[j] @ I_W @ w[j]
    s = full.summary
    assert s["relative_kinetic_energy_at_contact_J"] == pytest.approx(ke, rel=1e-9)
    assert np.abs(v[:2]).max() == 0 and np.abs(w[:2]).max() == 0    # target and APDS at rest
    mu = m[2] * m[:2].sum() / m.sum()
    I_c = R[2] @ np.diag(bodies[2].inertia) @ R[2].T
    assert ke == pytest.approx(0.5 * mu * v[2] @ v[2] + 0.5 * w[2] @ I_c @ w[2], rel=1e-9)
    ic = sc.initial
    nominal = 0.5 * mu * (ic.chaser_speed ** 2 + ic.lateral_velocity[0] ** 2)
    assert ke == pytest.approx(nominal, rel=0.15)
    assert s["energy_ledger"]["initial_total_J"] > 5 * ke        # the inertial frame's


def test_summary_fields_for_an_engineer(box_corner):
    """The outcome first; the loads at the target ring, the Stewart stroke and force, the total
    and per-couple contact force, each with its time; the couples in plain words."""
    _, out = box_corner
    s = json.loads((out / "summary.json").read_text())
    assert list(s)[1:3] == ["outcome", "outcome_reason"]
    loads = s["loads"]
    for key in ("interface_force_N", "interface_moment_Nm", "stewart_stroke_m",
                "stewart_force_N", "total_contact_force_N", "couple_normal_force_N"):
        assert loads[key]["peak"] > 0 and 0 < loads[key]["time_s"] <= s["end_time_s"], key
    assert loads["interface_force_N"]["lateral_peak"] > 0.1 * loads["interface_force_N"]["peak"]
    assert loads["total_contact_force_N"]["peak"] >= loads["couple_normal_force_N"]["peak"]
    top = loads["couple_normal_force_N"]["couple"]
    assert s["couples"][top]["description"] == \
        "chaser ring inside circle / target petal 3 tip arc"
