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

from drake_dock.docking.model.plant import set_initial_state
from drake_dock.docking.placement.place import place
from drake_dock.docking.scenario.loading import load_scenario
from drake_dock.docking.scenario.models_dir import PAPER_EXAMPLE
from drake_dock.studies.compliant import (CompliantConfig, build_compliant_diagram,
                                          hunt_crossley_dissipation)
from drake_dock.studies.docking_metrics import METRICS


@pytest.fixture(scope="module")
def paper():
    sc = load_scenario(PAPER_EXAMPLE)
    return sc, place(sc)


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
    """The quick plan on the paper example alone (the scenario given: one scene)."""
    out = tmp_path_factory.mktemp("study") / "out"
    p = subprocess.run([sys.executable, "-m", "drake_dock.cli", "study", "speed-accuracy",
                        str(PAPER_EXAMPLE), "--quick", "--out", str(out)], capture_output=True,
                       text=True, timeout=900)
    assert p.returncode == 0, p.stderr
    assert "points.csv" in json.loads((out / ".drake_dock_output").read_text())["entries"]
    with open(out / "points.csv") as f:
        rows = list(csv.DictReader(f))
    return p.stdout, rows, out


def _family(r):
    """(settings but the step or accuracy, fineness) of a CSV row."""
    if r["method"] == "drake_dock":
        return ("drake_dock", r["scheme"], r["step"]), -math.log10(float(r["accuracy"]))
    if float(r["step"]) > 0:
        return ("SAP", r["model"], r["stiffness"]), -math.log10(float(r["step"]))
    return ("RK3", r["model"], r["stiffness"]), -math.log10(float(r["accuracy"]))


def _converged_walls(rows, method, k, tol):
    """Wall times of the rows converged on ``k``, recomputed from the CSV: within ``tol`` with
    every finer row of their family within it too."""
    def ok(r):
        return r[f"error_{k}"] != "" and float(r[f"error_{k}"]) <= tol
    pts = [r for r in rows if r["method"] == method and r["role"] == "point"]
    return [float(r["wall_time"]) for r in pts if ok(r) and all(
        ok(q) for q in pts if _family(q)[0] == _family(r)[0] and _family(q)[1] > _family(r)[1])]


def test_quick_study_prints_one_converged_speedup_line_per_metric(quick_study):
    stdout, rows, out = quick_study
    assert {r["scene"] for r in rows} == {"paper_example"}
    lines = [ln for ln in stdout.splitlines() if ln.startswith("converged speed-up ")]
    assert [ln.split(":")[0][len("converged speed-up "):] for ln in lines] == list(METRICS)
    tol = 1e-3
    for k, ln in zip(METRICS, lines):
        t_dd = min(_converged_walls(rows, "drake_dock", k, tol), default=None)
        t_cc = min(_converged_walls(rows, "compliant", k, tol), default=None)
        if t_dd and t_cc:
            m = re.match(rf"converged speed-up {k}: ([0-9.e+]+)x", ln)
            assert m, ln
            np.testing.assert_allclose(float(m.group(1)), t_cc / t_dd, rtol=6e-3)  # 3 digits
        elif t_dd:
            assert "none: no converged compliant configuration" in ln, ln
        else:
            assert "none: no converged drake_dock run" in ln, ln
    assert (out / "work_precision_paper_example.png").read_bytes()[:8] == b"\x89PNG\r\n\x1a\n"
    written = (out / "speedups.txt").read_text().splitlines()
    assert [ln for ln in written if ln.startswith("converged speed-up ")] == lines
    # The contact effect on the chaser's axial velocity, from the reference's value and the
    # scenario's approach speed (the chaser moves along the axis at t = 0).
    ref = next(r for r in rows if r["role"] == "reference")
    v = abs(float(ref["chaser_axial_velocity"]))
    speed = load_scenario(PAPER_EXAMPLE).initial.chaser_speed
    m = re.search(r"contact effect on chaser_axial_velocity: ([0-9.e+-]+) ", stdout)
    assert m, stdout
    np.testing.assert_allclose(float(m.group(1)), speed - v, rtol=1e-3)  # 4 digits


def test_quick_study_impulse_from_the_axial_velocity(quick_study):
    """On the paper example the chaser moves along the axis (the three petals' lateral forces
    cancel): every captured run's impulse is m_c (speed - |axial velocity at capture|)."""
    _, rows, _ = quick_study
    sc = load_scenario(PAPER_EXAMPLE)
    captured = [r for r in rows if r["captured"] == "1"]
    assert {r["method"] for r in captured} == {"drake_dock", "compliant"}
    for r in captured:
        np.testing.assert_allclose(
            float(r["chaser_impulse"]), sc.bodies.chaser.mass
            * (sc.initial.chaser_speed - abs(float(r["chaser_axial_velocity"]))), rtol=1e-6)


def test_quick_study_reference_self_converged(quick_study):
    """The reference (accuracy 1e-8) and the run at 1e-7 agree to 1e-6 of each metric's contact
    effect: the reference is converged far below the 1e-3 tolerance of the comparison."""
    _, rows, _ = quick_study
    roles = [r["role"] for r in rows]
    assert roles.count("reference") == 1 and roles.count("self-convergence") == 1
    sc = rows[roles.index("self-convergence")]
    for k in METRICS:
        assert float(sc[f"error_{k}"]) < 1e-6, (k, sc[f"error_{k}"])
    # Every drake_dock point captures and is within the tolerance on every metric.
    for r in rows:
        if r["method"] == "drake_dock":
            assert r["captured"] == "1"
            for k in METRICS:
                assert float(r[f"error_{k}"]) <= 1e-3, (r["label"], k)
    assert sum(r["method"] == "compliant" for r in rows) == 3
    assert all(math.isfinite(float(r["wall_time"])) for r in rows)
