"""How a run ends: the outcome rules on hand-made ring-distance histories, a timeout through
the command line, and the slowest closing rate of the IDSS box: captured at 1 deg roll with a
progress bar that follows the rings, jammed at 5 deg once its closing energy is spent."""
import json
import re

import numpy as np
import pytest
import yaml

from drake_dock.cli import main
from drake_dock.docking.model.outcome import (JAM_DISTANCE, CaptureRule, OutcomeWatch,
                                              misalignment, progress_fraction)
from drake_dock.docking.scenario.models_dir import PAPER_EXAMPLE


def feed(watch, ts, ds, driven=None, lateral=None):
    n = len(ts)
    driven = [False] * n if driven is None else driven
    lateral = [0.0] * n if lateral is None else lateral
    for t, d, dr, lat in zip(ts, ds, driven, lateral):
        end = watch.update(t, d, lat, None, dr)
        if end:
            return t, end[0]
    return None


def test_steady_approach_has_no_outcome():
    ts = np.linspace(0, 10, 1001)
    assert feed(OutcomeWatch(0.1, 2.0), ts, 0.1 - 0.009 * ts) is None


def test_stalled_rings_are_jammed_after_jam_time():
    ts = np.linspace(0, 10, 1001)
    ds = np.maximum(0.1 - 0.05 * ts, 0.02)          # reach 0.02 m at t = 1.6 s, then stall
    t, outcome = feed(OutcomeWatch(0.1, 2.0), ts, ds)
    # The last millimetre of progress ends at the stall (t = 1.6 s) or one mm before it.
    assert outcome == "jammed" and 1.6 - JAM_DISTANCE / 0.05 + 2.0 - 0.011 <= t <= 3.611


def test_no_jam_while_thrust_still_acts():
    """The same stall under thrust that acts until t = 5 s: the jam clock starts when the
    thrust has ended, so the run is jammed jam_time after 5 s, not 2 s after the stall."""
    ts = np.linspace(0, 10, 1001)
    ds = np.maximum(0.1 - 0.05 * ts, 0.02)
    t, outcome = feed(OutcomeWatch(0.1, 2.0), ts, ds, driven=list(ts < 5.0))
    assert outcome == "jammed" and 7.0 - 0.011 <= t <= 7.011


def test_separating_rings_rebound_unless_thrust_still_acts():
    """Above its start and growing: rebound, in contact or not (a couple may graze); not while
    thrust still acts, which can bring the chaser back."""
    ts = np.linspace(0, 2, 201)
    ds = 0.1 - 0.1 * ts + 0.1 * ts ** 2               # back above 0.1 m after t = 1 s
    assert feed(OutcomeWatch(0.1, 5.0), ts, ds, driven=[True] * len(ts)) is None
    t, outcome = feed(OutcomeWatch(0.1, 5.0), ts, ds)
    assert outcome == "rebound" and 1.0 < t <= 1.02


def test_missed_beside_or_beyond_the_target():
    """The ring centres more than 2 R apart across the axis (the rings' disks no longer
    overlap), or the chaser's ring centre more than H behind the target's ring face: missed,
    at the first sample past the bound."""
    ts = np.linspace(0, 2, 201)
    t, outcome = feed(OutcomeWatch(0.1, 5.0, beside=1.2, beyond=0.2), ts, 0.1 + 0 * ts,
                      lateral=list(0.8 * ts))
    assert outcome == "missed" and 1.5 - 1e-9 < t <= 1.51
    t, outcome = feed(OutcomeWatch(0.1, 5.0, beside=1.2, beyond=0.2), ts, 0.1 - 0.2 * ts)
    assert outcome == "missed" and 1.5 - 1e-9 < t <= 1.51


def test_missed_past_the_ring_plane_off_the_axis_but_not_on_it():
    """Behind the target's ring face by more than the capture distance: missed where the
    centre is off the axis by more than the lateral tolerance (first sample past 0.005 m
    behind: 0.1 - 0.1 t < -0.005 from t = 1.05), not while on the axis."""
    ts = np.linspace(0, 2, 201)
    watch = lambda: OutcomeWatch(0.1, 5.0, beside=1.2, beyond=0.2, past=0.005, off_axis=0.01)
    t, outcome = feed(watch(), ts, 0.1 - 0.1 * ts, lateral=[0.3] * len(ts))
    assert outcome == "missed" and 1.05 - 1e-9 < t <= 1.06
    assert feed(watch(), ts, 0.1 - 0.1 * ts, lateral=[0.005] * len(ts)) is None


def _rot(axis, angle):
    """Rodrigues' rotation about the unit ``axis`` by ``angle``."""
    k = np.asarray(axis, float) / np.linalg.norm(axis)
    K = np.array([[0, -k[2], k[1]], [k[2], 0, -k[0]], [-k[1], k[0], 0]])
    return np.eye(3) + np.sin(angle) * K + (1 - np.cos(angle)) * K @ K


@pytest.mark.parametrize("seed", range(5))
def test_misalignment_of_a_constructed_pose(seed):
    """The chaser ring placed in a randomly turned target ring frame at a known axial and
    lateral offset, its axis facing the target's and tilted by a known angle about an axis in
    the joint plane: misalignment returns the three, to round-off (tilts down to 1e-9 rad, where
    an arccos of the axes' dot product would lose them)."""
    rng = np.random.default_rng(seed)
    R_t = _rot(rng.normal(size=3), rng.uniform(0, np.pi))
    p_t = rng.normal(size=3)
    axial, lateral, phi = rng.uniform(-0.2, 0.2), rng.uniform(0, 0.1), rng.uniform(0, 2 * np.pi)
    for tilt in (1e-9, 1e-4, 0.07, 1.2):
        a = rng.uniform(0, 2 * np.pi)
        R_c = R_t @ _rot([np.cos(a), np.sin(a), 0.0], tilt) @ _rot([1.0, 0, 0], np.pi)
        p_c = p_t + R_t @ [lateral * np.cos(phi), lateral * np.sin(phi), axial]
        got = misalignment(R_t, p_t, R_c, p_c)
        np.testing.assert_allclose(got[:2], [axial, lateral], atol=1e-14)
        assert got[2] == pytest.approx(tilt, rel=1e-12, abs=1e-15)


def test_capture_rule_is_the_latches_test():
    """to_go <= axial tolerance exactly when all three quantities are within their tolerances;
    it is the axial distance where none binds or none is given, and continuous (|change| at most
    the change of its arguments, the tilt as R times it)."""
    rule = CaptureRule(0.005, 0.01, 0.5, 0.6)
    t_tol = np.radians(0.5)
    rng = np.random.default_rng(3)
    for _ in range(2000):
        a, lat, tilt = rng.uniform(-0.02, 0.03), rng.uniform(0, 0.03), rng.uniform(0, 0.03)
        inside = a <= 0.005 and lat <= 0.01 and tilt <= t_tol
        assert (rule.to_go(a, lat, tilt) <= 0.005) == inside
        da, dl, dt = rng.normal(scale=1e-6, size=3)
        change = abs(rule.to_go(a + da, lat + dl, tilt + dt) - rule.to_go(a, lat, tilt))
        assert change <= max(abs(da), abs(dl), 0.6 * abs(dt)) * (1 + 1e-9) + 1e-18
    assert rule.to_go(0.1, 0.0, 0.0) == 0.1
    assert CaptureRule(0.005, None, None, 0.6).to_go(0.1, 0.3, 1.0) == 0.1
    # The excess counts: 2 mm too far off the axis is 2 mm to go beyond the axial tolerance.
    assert rule.to_go(0.0, 0.012, 0.0) == pytest.approx(0.007)


def test_a_misaligned_ring_past_the_axis_jams():
    """The axial distance keeps falling (the rings pass each other in a model without their
    face contact) while the lateral offset stays 5 mm beyond its tolerance: no progress towards
    capture, so the run is jammed after jam_time, not captured."""
    rule = CaptureRule(0.005, 0.01, None, 0.6)
    ts = np.linspace(0, 5, 501)
    watch = OutcomeWatch(0.1, 2.0)
    for t in ts:
        d = 0.1 - 0.05 * t
        end = watch.update(t, d, 0.015, rule.to_go(d, 0.015, 0.0))
        if end:
            break
    # to_go stops at 0.010 m when d falls below it (t = 1.8 s); jammed 2 s after the last mm.
    assert end[0] == "jammed" and 1.8 - 0.02 + 2.0 - 0.011 <= t <= 3.81
    assert "distance to capture" in end[1]


def test_progress_is_the_further_of_way_and_time():
    assert progress_fraction(1.0, 10.0, 0.05, 0.1, 0.0) == pytest.approx(0.5)
    assert progress_fraction(8.0, 10.0, 0.05, 0.1, 0.0) == pytest.approx(0.8)


def test_timeout_is_a_named_outcome(tmp_path, capsys):
    assert main(["run", str(PAPER_EXAMPLE), "--out", str(tmp_path / "o"), "--duration", "0.02"
                 ]) == 0
    s = json.loads((tmp_path / "o" / "summary.json").read_text())
    assert s["outcome"] == "timeout" and not s["captured"] and s["end_time_s"] == 0.02
    # The bar, then the writing of the outputs, then Drake's log lines: none between.
    lines = capsys.readouterr().err.splitlines()
    bar = [k for k, line in enumerate(lines) if line.startswith("[")]
    writing = [k for k, line in enumerate(lines) if "writing the outputs" in line]
    assert bar and writing == [bar[-1] + 1]
    assert not any(":drake:" in line for line in lines[:writing[0]])


def _slow_run(tmp_path, yaw_deg):
    data = yaml.safe_load(PAPER_EXAMPLE.read_text())
    data["initial"]["chaser_speed"] = 0.05
    data["initial"]["target_yaw_deg"] = yaw_deg
    f = tmp_path / f"slow_{yaw_deg}.yaml"
    f.write_text(yaml.safe_dump(data))
    out = tmp_path / f"o_{yaw_deg}"
    assert main(["run", str(f), "--out", str(out)]) == 0
    s = json.loads((out / "summary.json").read_text())
    return data, s, np.load(out / "timeseries.npz")


def test_slow_approach_runs_to_capture_with_a_progress_bar_on_the_rings(tmp_path, capsys):
    """0.05 m/s (the IDSS box's slowest closing rate) at 1 deg relative roll: captured within the
    default duration; the bar follows the rings' way towards capture and ends at 100 %."""
    data, s, ts = _slow_run(tmp_path, 1.0)
    err = capsys.readouterr().err
    assert s["outcome"] == "captured"
    assert s["capture_time_s"] < data["simulation"]["duration"]
    assert s["momentum_drift_relative"]["linear"] < 1e-9
    shown = [int(p) for p in re.findall(r"\]\s+(\d+)%", err)]
    assert shown == sorted(shown) and shown[-1] == 100
    d = ts["ring_distance"]
    assert d[-1] == pytest.approx(s["capture_tolerances"]["axial_m"], abs=1e-9)
    tol = s["capture_tolerances"]
    assert s["final_misalignment"]["lateral_m"] <= tol["lateral_m"]
    assert s["final_misalignment"]["tilt_deg"] <= tol["tilt_deg"]


def test_the_paper_example_is_captured_where_the_axial_distance_alone_captures_it():
    """The paper's rings meet coaxially: with the latches' lateral and tilt tolerances left out
    (null), the capture witness is the axial distance alone, and the default tolerances do not
    bind, so both runs end at the same capture time, bit for bit."""
    from drake_dock.docking.model.simulate import simulate
    from drake_dock.docking.placement.place import place
    from drake_dock.docking.scenario.loading import load_scenario
    s = load_scenario()
    axial_only = load_scenario()
    axial_only.simulation.capture_lateral = axial_only.simulation.capture_tilt_deg = None
    a, b = simulate(s, place(s)), simulate(axial_only, place(axial_only))
    assert a.outcome == b.outcome == "captured"
    assert a.capture_time == b.capture_time
    assert "lateral offset <= 0.01 m" in a.reason and "lateral" not in b.reason


def _relative_kinetic_energy(data, ts, k):
    """Kinetic energy of the three bodies at sample k minus that of their centre of mass (the
    part a free-drifting approach can spend on capture), from the masses, inertias and the
    sampled velocities alone."""
    total, momentum, mass = 0.0, np.zeros(3), 0.0
    for b, name in enumerate(ts["body_names"]):
        m = data["bodies"][str(name)]["mass"]
        J = np.diag(data["bodies"][str(name)]["inertia"])
        R, v, w = ts["R_WB"][k, b], ts["v_WB"][k, b], ts["w_WB"][k, b]
        wb = R.T @ w
        total += 0.5 * m * v @ v + 0.5 * wb @ J @ wb
        momentum += m * v
        mass += m
    return total - 0.5 * momentum @ momentum / mass


def test_slow_approach_at_five_degrees_roll_jams_once_its_closing_energy_is_spent(tmp_path):
    """0.05 m/s at the paper's 5 deg relative roll, in free drift: the relative kinetic energy
    (1.25 J) is spent by the Stewart dampers, friction and impacts before the petals have turned
    the target APDS, and the rings stall short of capture: a named "jammed" outcome before the
    timeout, with the relative motion spent (below 10 % of its start) when the jam is declared."""
    data, s, ts = _slow_run(tmp_path, 5.0)
    assert s["outcome"] == "jammed"
    assert s["end_time_s"] < data["simulation"]["duration"]
    assert s["final_misalignment"]["axial_m"] > s["capture_tolerances"]["axial_m"]
    start = _relative_kinetic_energy(data, ts, 0)
    m = {k: v["mass"] for k, v in data["bodies"].items()}
    mc, mt = m["chaser"], m["target"] + m["target_apds"]
    assert start == pytest.approx(0.5 * mc * mt / (mc + mt) * 0.05 ** 2, rel=1e-9)  # 1.25 J
    assert _relative_kinetic_energy(data, ts, -1) < 0.1 * start
