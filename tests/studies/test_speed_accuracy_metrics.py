"""The speed-accuracy study's metrics, their errors relative to the contact's effect, and the
converged reading: closed forms, hand-made families, and a second computation of the impulse
and the Stewart stroke from a run's outputs and the plant's poses."""
import math

import numpy as np
import pytest

from drake_dock.docking.geometry.pairs import CHASER_APDS
from drake_dock.docking.geometry.scene import DockingScene
from drake_dock.docking.model.simulate import simulate
from drake_dock.docking.placement.place import place
from drake_dock.docking.report.results import rigid_chaser_force, timeseries
from drake_dock.docking.scenario.loading import load_scenario
from drake_dock.docking.scenario.models_dir import PAPER_EXAMPLE
from drake_dock.studies.docking_metrics import (METRICS, SceneStart, contact_effect, errors,
                                                rigid_metrics, sampled_peak, scene_start)
from drake_dock.studies.work_precision import Point, converged_points, converged_speedups

START = SceneStart(e3=np.array([0.0, 0.0, 1.0]), spin0=0.01, v0=np.array([0.02, 0.0, -1.0]),
                   chaser_mass=7600.0, free_capture_time=0.09)
REF = {"capture_time": 0.15, "apds_spin_rate": -0.49, "chaser_axial_velocity": -0.986,
       "peak_contact_force": 313.0, "peak_stewart_stroke": 0.062, "chaser_impulse": 107.6}


def test_contact_effect_is_the_change_the_contact_makes():
    e = contact_effect(REF, START)
    np.testing.assert_allclose([e[k] for k in METRICS],
                               [0.06, 0.5, 0.014, 313.0, 0.062, 107.6], rtol=1e-12)


def _family(values, steps, k, model="point", stiffness=1e7, wall=None):
    """Compliant SAP runs of one family: metric ``k`` takes ``values`` at ``steps``."""
    wall = wall or [1e-4 / h for h in steps]
    eff = contact_effect(REF, START)
    out = []
    for v, h, w in zip(values, steps, wall):
        m = dict(REF, **{k: v})
        out.append(Point("compliant", "point", f"h={h:g}", model, stiffness, h, math.nan, w,
                         True, m, errors(m, REF, eff)))
    return out


@pytest.mark.parametrize("k", METRICS)
def test_error_normalisation_on_a_power_law_family(k):
    """m(h) = m_ref + C h^2: the error is C h^2 / E (E the contact effect), and the converged
    runs are exactly those with h <= h* = sqrt(tol E / C)."""
    E = contact_effect(REF, START)[k]
    C, tol = 40.0 * E, 1e-3
    steps = [1e-2, 3e-3, 1e-3, 3e-4, 1e-4]
    pts = _family([REF[k] + C * h * h for h in steps], steps, k)
    np.testing.assert_allclose([p.errors[k] for p in pts], [C * h * h / E for h in steps],
                               rtol=1e-6)    # m - m_ref loses digits
    h_star = math.sqrt(tol * E / C)
    assert [p.step for p in converged_points(pts, k, tol)] == [h for h in steps if h <= h_star]


def test_a_run_within_the_tolerance_by_chance_is_not_converged():
    """A coarse run that lands on the reference does not count while a finer run of its family
    is out; a family of its own (another stiffness) is not affected."""
    k = "peak_stewart_stroke"
    ref = REF[k]
    pts = _family([ref, ref * 1.01, ref * (1 + 5e-4), ref * (1 + 1e-4)],
                  [1e-2, 1e-3, 1e-4, 3e-5], k)
    other = _family([ref * (1 + 2e-4)], [3e-3], k, stiffness=1e8, wall=[0.2])
    conv = converged_points(pts + other, k, 1e-3)
    assert [(p.stiffness, p.step) for p in conv] == [(1e7, 1e-4), (1e7, 3e-5), (1e8, 3e-3)]
    r = converged_speedups(pts + other, 1e-3)[k]
    assert r.drake_dock is None and r.ratio is None and r.compliant is other[0]


def _pt(method, step, accuracy, wall, err, model="point", k=1e6):
    errs = {m: err for m in METRICS}
    return Point(method, "point", "", model, k, step, accuracy, wall, err is not None,
                 dict.fromkeys(METRICS), errs)


def test_converged_speedup_is_fastest_converged_compliant_over_drake_dock():
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
    r = converged_speedups(pts, 1e-3)[METRICS[0]]
    assert (r.drake_dock, r.compliant) == (d4, b_ok)
    np.testing.assert_allclose(r.ratio, 0.3 / 0.22)
    np.testing.assert_allclose(r.best, 1e-4)


def test_sampled_peak_of_a_parabola_is_its_vertex():
    t = np.array([0.0, 0.1, 0.25, 0.33, 0.41, 0.6, 0.9])
    y = 2.0 - 3.0 * (t - 0.37) ** 2
    np.testing.assert_allclose(sampled_peak(t, y), 2.0, rtol=1e-13)
    assert sampled_peak(t, t) == 0.9                         # largest at the end: the sample


@pytest.fixture(scope="module")
def paper_run():
    sc = load_scenario(PAPER_EXAMPLE)
    state = place(sc)
    r = simulate(sc, state=state)
    return sc, r, rigid_metrics(r, scene_start(sc, state)), timeseries(r)


def test_impulse_is_the_integral_of_the_contact_force(paper_run):
    """chaser_impulse (the chaser's momentum change) against the contact's own forces: the
    couples' lambda integrated over the samples (trapezoids, impacts excluded) plus the LZB
    impulses of each impact in the contact frames of its pre-impact sample."""
    sc, r, m, ts = paper_run
    t, F = rigid_chaser_force(r)
    step = np.diff(t) > 0
    J = (0.5 * np.diff(t)[step, None] * (F[:-1] + F[1:])[step]).sum(0)
    sign = np.array([1.0 if p.body1 == CHASER_APDS else -1.0
                     for p in DockingScene(sc.geometry, "paper").pairs])
    assert len(ts["impact_t"]) >= 3
    for i, t_i in enumerate(ts["impact_t"]):
        k = np.flatnonzero((ts["t"] == t_i) & (ts["sample_kind"] == 1))[0]
        lam = np.concatenate([ts["impact_tangential_impulse"][i],
                              ts["impact_normal_impulse"][i][:, None]], axis=1)
        J += np.einsum("c,cxy,cy->x", sign, ts["frame_W"][k], lam)
    np.testing.assert_allclose(np.linalg.norm(J), m["chaser_impulse"], rtol=1e-5)


def test_stroke_from_the_plant_poses(paper_run):
    """The peak stroke against |R_WT^T (p_WC - p_WT) - p_TA|, the APDS body's offset from the
    Stewart anchor computed from the two bodies' poses (it grows up to capture here)."""
    sc, r, m, ts = paper_run
    dp = r.dd.dp
    pc = dp.plant.CreateDefaultContext()
    direct = []
    for x in r.record.x:
        dp.plant.SetPositionsAndVelocities(pc, x)
        X_WT = dp.plant.EvalBodyPoseInWorld(pc, dp.bodies["target"])
        p_WC = dp.plant.EvalBodyPoseInWorld(pc, dp.bodies["target_apds"]).translation()
        p = X_WT.rotation().matrix().T @ (p_WC - X_WT.translation()) - sc.stewart.p_TA
        direct.append(np.linalg.norm(p))
    assert int(np.argmax(direct)) == len(direct) - 1 and direct[-1] > 0.01
    np.testing.assert_allclose(m["peak_stewart_stroke"], direct[-1], rtol=1e-10)
