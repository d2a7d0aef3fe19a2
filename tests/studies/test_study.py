"""The compliant baseline scene and `drake-dock study speed-accuracy --quick`."""
import csv
import json
import math
import re
import subprocess
import sys

import numpy as np
import pytest
from pydrake.systems.analysis import Simulator
from scipy.integrate import solve_ivp

from drake_dock.studies.compliant import (CompliantConfig, build_compliant_diagram,
                                          hunt_crossley_dissipation)
from drake_dock.docking.plant import set_initial_state
from drake_dock.docking.scene import initial_state
from drake_dock.docking.scenario import PAPER_EXAMPLE, load_scenario
from drake_dock.studies.speed_accuracy import METRICS, Point, converged_points, converged_speedups


@pytest.fixture(scope="module")
def paper():
    sc = load_scenario(PAPER_EXAMPLE)
    return sc, initial_state(sc)


def test_hunt_crossley_dissipation_gives_the_restitution():
    """Independent check at another stiffness, mass and exponent-free scaling: a mass m on
    the spring k x (1 + d xdot) from speed v rebounds at e."""
    e, v = 0.1, 0.7
    d = hunt_crossley_dissipation(e, v)
    m, k = 3.0, 2e5

    def f(t, y):
        return [y[1], -k * y[0] * (1 + d * y[1]) / m]

    def out(t, y):
        return y[0] if t > 1e-6 else 1.0
    out.terminal, out.direction = True, -1
    sol = solve_ivp(f, (0, 1), [0.0, v], events=out, rtol=1e-11, atol=1e-14,
                    max_step=1e-4)
    assert sol.t_events[0].size == 1
    np.testing.assert_allclose(-sol.y_events[0][0][1] / v, e, rtol=1e-5)


def _momentum(plant, ctx):
    return plant.CalcSpatialMomentumInWorldAboutPoint(ctx, np.zeros(3))


@pytest.mark.parametrize("model", ["point", "hydroelastic"])
def test_compliant_scene_same_bodies_state_and_conservation(paper, model):
    """Before first contact (at 0.0101 s) the chaser flies at its initial velocity and the
    target stays at rest (closed form); through the contacts up to 0.03 s, linear and angular
    momentum are conserved (contact forces and the Stewart element are internal)."""
    sc, state = paper
    cfg = CompliantConfig(model, 1e8 if model == "hydroelastic" else 1e7, 1e-3)
    cd = build_compliant_diagram(sc, cfg)
    assert cd.n_pieces == 2 * (3 * cfg.n_around * cfg.n_height + cfg.n_ring)
    sim = Simulator(cd.diagram)
    root = sim.get_mutable_context()
    plant = cd.dp.plant
    pc = plant.GetMyMutableContextFromRoot(root)
    set_initial_state(cd.dp, pc, state)
    h0 = _momentum(plant, pc)
    sim.AdvanceTo(0.008)
    X = plant.EvalBodyPoseInWorld(pc, cd.dp.bodies["chaser"])
    R0, p0 = state.X_WB["chaser"]
    v0 = state.V_WB["chaser"][1]
    np.testing.assert_allclose(X.translation(), p0 + 0.008 * v0, atol=1e-9)
    Xt = plant.EvalBodyPoseInWorld(pc, cd.dp.bodies["target"])
    np.testing.assert_allclose(Xt.translation(), state.X_WB["target"][1], atol=1e-12)
    sim.AdvanceTo(0.03)
    h1 = _momentum(plant, pc)
    m_c = sc.bodies.chaser.mass
    scale_p = m_c * np.linalg.norm(v0)
    # Contact took place: the chaser's velocity changed.
    v_c = plant.EvalBodySpatialVelocityInWorld(pc, cd.dp.bodies["chaser"]).translational()
    assert np.linalg.norm(v_c - v0) > 1e-3
    np.testing.assert_allclose(h1.translational(), h0.translational(), atol=1e-9 * scale_p)
    # The chaser moves along its position vector: |m p x v| is ~0; the scale is the chaser's
    # momentum at the ring's radius (the lever of the contact forces).
    scale_l = m_c * np.linalg.norm(v0) * sc.geometry.R
    np.testing.assert_allclose(h1.rotational(), h0.rotational(), atol=1e-9 * scale_l)


def test_bad_compliant_config_is_named():
    with pytest.raises(ValueError, match="compliant.stiffness"):
        CompliantConfig("point", -1.0, 1e-3).validate()
    with pytest.raises(ValueError, match="compliant.model"):
        CompliantConfig("soft", 1e7, 1e-3).validate()


@pytest.fixture(scope="module")
def quick_study(tmp_path_factory):
    out = tmp_path_factory.mktemp("study") / "out"
    p = subprocess.run([sys.executable, "-m", "drake_dock.cli", "study", "speed-accuracy",
                        "--quick", "--out", str(out)], capture_output=True, text=True,
                       timeout=900)
    assert p.returncode == 0, p.stderr
    assert "points.csv" in json.loads((out / ".drake_dock_output").read_text())["entries"]
    with open(out / "points.csv") as f:
        rows = list(csv.DictReader(f))
    return p.stdout, rows, out


def test_quick_study_prints_one_speedup_line_per_metric(quick_study):
    stdout, rows, out = quick_study
    lines = [ln for ln in stdout.splitlines() if ln.startswith("speed-up ")]
    assert [ln.split(":")[0][len("speed-up "):] for ln in lines] == list(METRICS)
    tol = 1e-3
    for k, ln in zip(METRICS, lines):
        # Recomputed from the CSV: fastest within tolerance on each side.
        def fastest(method):
            w = [float(r["wall_time"]) for r in rows if r["method"] == method
                 and r["role"] == "point" and r[f"error_{k}"] != ""
                 and float(r[f"error_{k}"]) <= tol]
            return min(w) if w else None
        t_dd, t_cc = fastest("drake_dock"), fastest("compliant")
        if t_dd and t_cc:
            m = re.match(rf"speed-up {k}: ([0-9.]+)x", ln)
            assert m, ln
            np.testing.assert_allclose(float(m.group(1)), t_cc / t_dd, rtol=0.06)
        else:
            assert "unbounded" in ln or "none" in ln, ln
    assert (out / "work_precision.png").read_bytes()[:8] == b"\x89PNG\r\n\x1a\n"
    written = (out / "speedups.txt").read_text().splitlines()
    assert [ln for ln in written if ln.startswith("speed-up ")] == lines
    assert [ln for ln in written if ln.startswith("  ")] == [
        ln for ln in stdout.splitlines() if ln.startswith("  ") and ": " in ln
        and ln.split(":")[0].strip() in METRICS]
    # The contact effect on the chaser's axial velocity, from the reference's value and the
    # scenario's approach speed (the chaser moves along the axis at t = 0).
    ref = next(r for r in rows if r["role"] == "reference")
    v = abs(float(ref["chaser_axial_velocity"]))
    speed = load_scenario(PAPER_EXAMPLE).initial.chaser_speed
    m = re.search(r"contact effect on chaser_axial_velocity: ([0-9.e+-]+) ", stdout)
    assert m, stdout
    np.testing.assert_allclose(float(m.group(1)), abs(v - speed) / v, rtol=4e-3)  # 3 digits


def test_quick_study_reference_self_converged(quick_study):
    """The reference (accuracy 1e-8) and the run at 1e-7 agree to 1e-6 on every metric: the
    reference is converged far below the 1e-3 tolerance of the comparison."""
    _, rows, _ = quick_study
    roles = [r["role"] for r in rows]
    assert roles.count("reference") == 1 and roles.count("self-convergence") == 1
    sc = rows[roles.index("self-convergence")]
    for k in METRICS:
        assert float(sc[f"error_{k}"]) < 1e-6, (k, sc[f"error_{k}"])
    # Every drake_dock point captures and is within the tolerance on all four metrics.
    for r in rows:
        if r["method"] == "drake_dock":
            assert r["captured"] == "1"
            for k in METRICS:
                assert float(r[f"error_{k}"]) <= 1e-3, (r["label"], k)
    assert sum(r["method"] == "compliant" for r in rows) == 3
    assert all(math.isfinite(float(r["wall_time"])) for r in rows)


def _pt(method, step, accuracy, wall, err, model="point", k=1e6):
    errs = {m: err for m in METRICS}
    return Point(method, "point", "", model, k, step, accuracy, wall, err is not None,
                 {m: None for m in METRICS}, errs)


def test_converged_points_drop_lucky_runs():
    """A run within the tolerance counts as converged only if every finer run of its family
    (method, model, stiffness; step or accuracy) is within it too."""
    nan = math.nan
    lucky = _pt("compliant", 1e-2, nan, 0.01, 5e-4)           # coarse, within by chance
    bad = _pt("compliant", 1e-3, nan, 0.1, 2e-3)
    fine = _pt("compliant", 1e-4, nan, 1.0, 5e-4)
    b_none = _pt("compliant", 1e-2, nan, 0.02, None, k=1e7)    # no capture
    b_ok = _pt("compliant", 1e-3, nan, 0.3, 1e-4, k=1e7)
    rk = _pt("compliant", 0.0, 1e-2, 0.5, 9e-4, k=1e7)         # continuous: its own family
    rk_bad = _pt("compliant", 0.0, 1e-3, 0.8, 2e-3, k=1e7)
    d1 = _pt("drake_dock", 0.01, 1e-2, 0.2, 2e-3, model="rigid", k=nan)
    d2 = _pt("drake_dock", 0.01, 1e-3, 0.25, 1e-4, model="rigid", k=nan)
    d3 = _pt("drake_dock", 0.01, 1e-4, 0.3, 1e-5, model="rigid", k=nan)
    d4 = _pt("drake_dock", 0.002, 1e-2, 0.22, 9e-4, model="rigid", k=nan)
    pts = [lucky, bad, fine, b_none, b_ok, rk, rk_bad, d1, d2, d3, d4]
    conv = converged_points(pts, METRICS[0], 1e-3)
    assert [pts.index(p) for p in conv] == [pts.index(p) for p in (fine, b_ok, d2, d3, d4)]
    ratio, t_dd, t_cc = converged_speedups(pts, 1e-3)[METRICS[0]]
    assert (t_dd, t_cc) == (0.22, 0.3)
    np.testing.assert_allclose(ratio, 0.3 / 0.22)
