"""The crosscheck (`drake-dock study crosscheck`): the compliant model's thrust and geometry
against closed forms, the forces and the counting rules against hand-made data, and the quick
study on the paper's example, where Drake's compliant contact must agree with drake_dock."""
import copy
import csv
import json
import math
import re
import subprocess
import sys

import numpy as np
import pytest
from pydrake.systems.analysis import Simulator

from drake_dock.docking.model.plant import set_initial_state
from drake_dock.docking.placement.place import place
from drake_dock.docking.scenario.loading import load_scenario
from drake_dock.docking.scenario.models_dir import MODELS_DIR, PAPER_EXAMPLE
from drake_dock.docking.scenario.validation import validate
from drake_dock.errors import InputError
from drake_dock.studies.compliant import (CompliantConfig, apds_pieces, build_compliant_diagram,
                                          run_compliant)
from drake_dock.studies.conditions import ConditionsPlan, conditions
from drake_dock.studies.crosscheck import (CrosscheckPlan, agreement, capture_time_differences,
                                           counts_as_converged, peak_mean_force,
                                           plan_conditions, summary_lines)

FUNNEL = MODELS_DIR / "apds_funnel.yaml"


def _chaser_velocity(cd, root):
    plant = cd.dp.plant
    pc = plant.GetMyContextFromRoot(root)
    return plant.EvalBodySpatialVelocityInWorld(pc, cd.dp.bodies["chaser"]).translational()


@pytest.fixture(scope="module")
def free_flight():
    """The funnel scenario 0.3 m from its first contact, not rotating, and its compliant
    diagram (1 ms steps)."""
    sc = copy.deepcopy(load_scenario(FUNNEL))
    sc.initial.approach_travel = 0.3
    sc.initial.angular_velocity_deg_s = [0.0, 0.0, 0.0]
    validate(sc)
    cd = build_compliant_diagram(sc, CompliantConfig("point", 1e7, 1e-3, dissipation=1.0,
                                                     approximation="similar"))
    return sc, place(sc), cd


@pytest.mark.parametrize("since", [None, 0.0, -4.9505])
def test_thrust_in_free_flight_gives_the_chaser_F_over_m(free_flight, since):
    """Far from contact, with no rotation: before the first contact (None) the chaser keeps
    its velocity; from it the thrust F along the chaser's docking axis gives F / m_c; with
    the first contact set 4.9505 s back, the 5 s window closes 0.0495 s in: the steps of 1 ms
    starting at 0 ... 0.049 s (each takes the thrust at its start) push, 50 of them."""
    sc, state, cd = free_flight
    sim = Simulator(cd.diagram)
    root = sim.get_mutable_context()
    set_initial_state(cd.dp, cd.dp.plant.GetMyMutableContextFromRoot(root), state)
    if since is not None:
        cd.thrust.set_first_contact_time(cd.thrust.GetMyMutableContextFromRoot(root), since)
    v0 = np.asarray(state.V_WB["chaser"][1])
    sim.AdvanceTo(0.1)
    axis = state.X_WB["chaser"][0][:, 2]           # the chaser APDS frame's e3 (same axes)
    on = {None: 0.0, 0.0: 0.1, -4.9505: 0.05}[since]
    F, m = sc.thrust.force, sc.bodies.chaser.mass
    np.testing.assert_allclose(_chaser_velocity(cd, root), v0 + F / m * on * axis,
                               atol=1e-12)
    # The axis points from the chaser's ring towards the target's.
    R_WC, p_WC = state.X_WB["chaser"]
    ring_c = p_WC + R_WC @ np.asarray(sc.chaser_apds_offset)
    to_target = state.X_WB["target_apds"][1] - ring_c
    assert axis @ to_target > 0.99 * np.linalg.norm(to_target)


def test_the_thrust_starts_at_the_first_step_with_a_contact_force():
    """The paper's example with a thrust section: the chaser's velocity is constant until the
    step in which contact first pushes it, the thrust acts from that step's end (the latch
    reads Drake's contact results; this checks it against the momentum), as F e3 after it."""
    sc = copy.deepcopy(load_scenario(PAPER_EXAMPLE))
    sc.thrust = copy.deepcopy(load_scenario(FUNNEL).thrust)
    validate(sc)
    state = place(sc)
    cfg = CompliantConfig("point", 1e7, 5e-4, dissipation=1.0, approximation="similar")
    cd = build_compliant_diagram(sc, cfg)
    run = run_compliant(sc, state, cfg, t_max=0.03, cd=cd)
    v = run.chaser_velocities
    moved = np.flatnonzero(np.linalg.norm(v - v[0], axis=1) > 0)
    assert len(moved) and run.t[moved[0]] == pytest.approx(run.first_contact_time, abs=1e-12)
    k = moved[0]
    assert not run.thrust_force[:k].any()
    F = np.linalg.norm(run.thrust_force[k:], axis=1)
    np.testing.assert_allclose(F, sc.thrust.force, rtol=1e-12)
    # The thrust is the only external force: the three bodies' momentum changes by its
    # impulse, step by step (contact and the Stewart element are internal), to the contact
    # solver's convergence (the similar approximation's iterations leave ~1e-7 of the
    # momentum; one step of thrust is 2e-5 of it).
    plant = cd.dp.plant
    pc = plant.CreateDefaultContext()

    def momentum(x):
        plant.SetPositionsAndVelocities(pc, x)
        return plant.CalcSpatialMomentumInWorldAboutPoint(pc, np.zeros(3)).translational()
    P = np.array([momentum(x) for x in run.states])
    J = np.cumsum(run.thrust_force * np.diff(run.t)[:, None], axis=0)
    scale = sc.bodies.chaser.mass * sc.initial.chaser_speed
    np.testing.assert_allclose(P[1:] - P[0], J, atol=1e-6 * scale)
    assert np.linalg.norm(J[-1]) > 1.0            # the thrust did act (300 N over 20 ms)
    # The first contact in the compliant model falls within a step of the rigid first
    # contact: the initial state's approach travel at the closing speed.
    t_rigid = sc.initial.approach_travel / sc.initial.chaser_speed
    assert abs(run.first_contact_time - t_rigid) < 2 * cfg.time_step


def test_the_compliant_pieces_follow_the_petal_root_radius_and_the_ring_annulus():
    """Against the cone rho = Rp - zeta cot(alpha1) (docs/model.md): the petal cells' outer
    faces lie on it (their points are its points), the root row at Rp, the tip row at the tip
    radius; the ring sectors span Rs..R with the complete set and Rs..Rs + 0.05 with the
    paper's 12 pairs."""
    g = load_scenario(FUNNEL).geometry
    cfg = CompliantConfig("point", 1e7, 1e-3, n_around=6, n_height=2, n_ring=36)
    pieces = apds_pieces(g, cfg)
    n_petal = 3 * cfg.n_around * cfg.n_height
    assert len(pieces) == n_petal + cfg.n_ring
    Rp = g.petal_root_radius
    assert Rp != g.R
    cot = 1.0 / math.tan(math.radians(g.alpha1_deg))
    outer = np.vstack([p[:9] for p in pieces[:n_petal]])       # the surface points
    rho = np.hypot(outer[:, 0], outer[:, 1])
    np.testing.assert_allclose(rho, Rp - outer[:, 2] * cot, atol=1e-12)
    assert outer[:, 2].min() == pytest.approx(0.0, abs=1e-12)
    assert outer[:, 2].max() == pytest.approx(g.H, abs=1e-12)
    inner = np.vstack([p[9:] for p in pieces[:n_petal]])       # grown towards the axis
    assert (np.hypot(inner[:, 0], inner[:, 1]) < Rp - inner[:, 2] * cot).all()
    ring = np.vstack(pieces[n_petal:])
    r = np.hypot(ring[:, 0], ring[:, 1])
    assert (r.min(), r.max()) == (pytest.approx(g.Rs), pytest.approx(g.R))
    assert ring[:, 2].max() == 0.0
    paper = load_scenario(PAPER_EXAMPLE).geometry
    ring = np.vstack(apds_pieces(paper, cfg, "paper")[n_petal:])
    r = np.hypot(ring[:, 0], ring[:, 1])
    assert (r.min(), r.max()) == (pytest.approx(paper.Rs), pytest.approx(paper.Rs + 0.05))


def test_peak_mean_force_closed_forms():
    """A constant force F gives F; a rigid impulse J (two samples at one time) on top of it
    gives F + J / W, whether the window is aligned on the impulse's start or end; a run
    shorter than the window gives 0."""
    t = np.linspace(0.0, 1.0, 101)
    F = np.array([3.0, -4.0, 0.0])               # |F| = 5
    P = t[:, None] * F
    assert peak_mean_force(t, P, 0.05) == pytest.approx(5.0, rel=1e-12)
    J = np.array([0.0, 0.0, 2.0])
    ti = np.r_[t[:51], 0.5, t[51:]]
    Pi = ti[:, None] * F + np.r_[np.zeros(51), np.ones(51)][:, None] * J
    W = 0.05
    expect = np.linalg.norm(W * F + J) / W
    assert peak_mean_force(ti, Pi, W) == pytest.approx(expect, rel=1e-12)
    assert peak_mean_force(t[:3], P[:3], 0.05) == 0.0


def test_counting_agreement_and_the_summary_lines():
    """Hand-made rows: only a compliant run whose refined run ends alike counts (never an
    error); agreement is over those; the capture-time median is over the counted conditions
    captured by both."""
    assert counts_as_converged("captured", "captured")
    assert not counts_as_converged("captured", "jammed")
    assert not counts_as_converged("error", "error")
    rows = [
        {"name": "a", "counts": True, "agree": True, "rigid_outcome": "captured",
         "compliant_outcome": "captured", "rigid_capture_time_s": 2.0,
         "compliant_capture_time_s": 2.1, "capture_time_difference": 0.05},
        {"name": "b", "counts": True, "agree": False, "rigid_outcome": "jammed",
         "compliant_outcome": "captured", "compliant_capture_time_s": 3.0,
         "capture_time_difference": None},
        {"name": "c", "counts": True, "agree": True, "rigid_outcome": "captured",
         "compliant_outcome": "captured", "rigid_capture_time_s": 2.0,
         "compliant_capture_time_s": 1.6, "capture_time_difference": -0.2},
        {"name": "d", "counts": False, "agree": True, "rigid_outcome": "captured",
         "compliant_outcome": "captured", "refined_outcome": "jammed",
         "capture_time_difference": 0.9},
        {"name": "e", "counts": True, "agree": True, "rigid_outcome": "captured",
         "compliant_outcome": "captured", "rigid_capture_time_s": 2.0,
         "compliant_capture_time_s": 2.02, "capture_time_difference": 0.01},
    ]
    assert agreement(rows) == (3, 4)
    assert sorted(capture_time_differences(rows)) == [-0.2, 0.01, 0.05]
    lines = summary_lines({"rows": rows, "plan": {"target_agreement": 0.9,
                                                  "target_capture_time": 0.1,
                                                  "stiffness_factor": 4.0,
                                                  "step_factor": 0.5}})
    assert lines[0].startswith("outcome agreement: 3/4 ")
    assert lines[1].startswith("median capture-time difference: 5 % ")
    assert "disagreement: b: rigid jammed, compliant captured 3 s" in lines
    assert any(ln.startswith("not counted: d:") for ln in lines)


def test_the_plan_takes_the_sweeps_conditions_and_names_bad_values():
    plan = CrosscheckPlan(random=3, corners=2)
    sweep = dict(conditions(ConditionsPlan()))
    got = plan_conditions(plan)
    assert [n for n, _ in got] == ["scenario", "random 1", "random 2", "random 3",
                                   "corner 1", "corner 2"]
    assert got[0][1] == {} and all(c == sweep[n] for n, c in got[1:])
    with pytest.raises(InputError, match=r"crosscheck\.random.*61"):
        CrosscheckPlan(random=61).validate()
    with pytest.raises(InputError, match=r"crosscheck\.step_factor"):
        CrosscheckPlan(step_factor=2.0).validate()
    with pytest.raises(InputError, match=r"compliant\.approximation"):
        CompliantConfig(approximation="tamsi").validate()


def test_quick_crosscheck_on_the_paper_example_agrees(tmp_path):
    """`drake-dock study crosscheck models/paper_example.yaml --quick`: the example's own
    conditions run by both engines; Drake's compliant contact captures within 1 % of
    drake_dock's capture time, and the refined run with it (the run counts)."""
    out = tmp_path / "cc"
    p = subprocess.run([sys.executable, "-m", "drake_dock.cli", "study", "crosscheck",
                        str(PAPER_EXAMPLE), "--quick", "--out", str(out)],
                       capture_output=True, text=True, timeout=600)
    assert p.returncode == 0, p.stderr
    rows = list(csv.DictReader(open(out / "crosscheck.csv")))
    assert [r["name"] for r in rows] == ["scenario"]
    r = rows[0]
    assert (r["rigid_outcome"], r["compliant_outcome"], r["refined_outcome"]) == (
        "captured",) * 3
    t_r, t_c = float(r["rigid_capture_time_s"]), float(r["compliant_capture_time_s"])
    assert abs(t_c - t_r) < 0.01 * t_r
    assert "outcome agreement: 1/1 " in p.stdout
    m = re.search(r"median capture-time difference: ([0-9.e+-]+) %", p.stdout)
    assert m and float(m.group(1)) == pytest.approx(100 * abs(t_c - t_r) / t_r, rel=1e-2)
    summary = json.loads((out / "summary.json").read_text())
    assert summary["agreement"] == {"agree": 1, "counted": 1, "conditions": 1}
    assert (out / "crosscheck.png").read_bytes()[:8] == b"\x89PNG\r\n\x1a\n"
