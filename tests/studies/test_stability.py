"""Stability where methods fail (`drake_dock.studies.stability`): each case against its closed form or an
independent reference, and the `drake-dock study stability --quick` command."""
import json
import math
import subprocess
import sys

import numpy as np
import pytest

from drake_dock.docking.scenario.loading import load_scenario
from drake_dock.docking.scenario.models_dir import PAPER_EXAMPLE
from drake_dock.errors import ZenoError
from drake_dock.studies import stability as S
from drake_dock.studies.small_scenes import G, painleve_rod, stool


def test_sawtooth_index_closed_forms():
    t = np.linspace(0.0, 1.0, 11)
    assert S.sawtooth_index(t, 3.0 + 2.0 * t) < 1e-15              # a line
    c, h = 0.7, 0.1
    F = 5.0 + c * t ** 2                                            # second difference c h^2
    assert S.sawtooth_index(t, F) == pytest.approx(c * h * h / F.mean(), rel=1e-9)
    saw = 10.0 + np.where(np.arange(11) % 2, 1.0, -1.0)
    assert S.sawtooth_index(t, saw) == pytest.approx(2.0 / saw.mean(), rel=1e-12)


# ------------------------------------------------------------------ (b) stiffness ratio
def test_lzb_stiffness_ratio_matches_compliant_chain():
    res = S.stiffness_ratio_case((1e-3, 1.0, 1e3), log=lambda s: None)
    for row in res["rows"]:
        v, ref = np.array(row["lzb"]), np.array(row["compliant"])
        np.testing.assert_allclose(v, ref, atol=1e-8)
        assert abs(v.sum() - 1.0) < 1e-12                 # momentum of unit balls, v0 = 1
        assert abs(v @ v - 1.0) < 1e-9                    # elastic: kinetic energy kept
    # The ratio changes the outcome (the effect LZB reproduces): the last ball's speed.
    last = [r["compliant"][2] for r in res["rows"]]
    assert max(last) - min(last) > 0.2


# ------------------------------------------------------------------------ (c) Painleve
def test_painleve_threshold_is_the_closed_form():
    """Just below mu_c the rod slides with the closed-form lambda_n; just above, a typed error
    naming the couple and the time."""
    _, mu_c = S.painleve_closed_form(0.0)
    res = S.high_friction_case((0.999 * mu_c, 1.001 * mu_c), log=lambda s: None)
    below, above = res["rod"]
    assert below["error"] is None
    assert below["lambda_n"] == pytest.approx(below["closed_form"], rel=1e-8)
    assert "tip_plane" in above["couples"] and above["time"] == 0.0
    assert "consistent" in above["error"]
    # mu_c from the scene's own parameters (the closed form's defaults are the scene's).
    p = painleve_rod(S.PAINLEVE_THETA).params
    c, s = math.cos(p["theta"]), math.sin(p["theta"])
    assert mu_c == pytest.approx((p["I"] / p["mass"] + p["l"] ** 2 * c * c)
                                 / (p["l"] * c * (p["l"] * s + p["rho"])), rel=1e-14)


# -------------------------------------------------------------------------- (d) grazing
def test_grazing_contact_found_iff_trajectory_reaches_the_plane():
    res = S.grazing_case((1e-7, -1e-9, -1e-5), log=lambda s: None)
    for row in res["rows"]:
        if row["delta"] > 0:
            assert row["impacts"] == 0
            assert row["min_gap"] >= row["delta"] - 1e-12
        else:
            assert row["impacts"] == 1
            assert abs(row["impact_time"] - row["closed_form_time"]) < 1e-9
            assert row["min_gap"] > -1e-8
        assert row["vz_end"] == pytest.approx(row["vz_closed_form"], abs=1e-8)


# ----------------------------------------------------------------------------- (e) Zeno
def test_zeno_guard_counts_and_error_when_off():
    e, h = 0.5, 0.05
    res = S.zeno_case((0.1,), h=h, e=e, max_impacts_off=10, log=lambda s: None)
    row = res["rows"][0]
    v1 = math.sqrt(2 * G * h)
    # Impacts at v1 e^k while that is at least the Zeno speed, then one plastic impact.
    assert row["impacts"] == math.floor(math.log(0.1 / v1) / math.log(e)) + 2
    assert abs(row["last_impact"] - row["closed_form_last_impact"]) < 1e-7
    assert row["resting_lambda_n"] == pytest.approx(row["weight"], rel=1e-8)
    off = res["guard_off"]
    assert off["couples"] == ["rim_plane"]
    assert "max_impacts = 10" in off["error"]
    # The 11th impact (k = 10): t1 + sum of the flight times 2 v1 e^k / g, k = 1..10.
    t11 = math.sqrt(2 * h / G) + sum(2 * v1 * e ** k / G for k in range(1, 11))
    assert off["time"] == pytest.approx(t11, abs=1e-7)


def test_zeno_error_is_typed():
    from drake_dock.studies.small_scenes import disk_on_incline
    from drake_dock.systems.contact_system import ContactOptions
    sc = disk_on_incline(0.0, restitution=0.5,
                         options=ContactOptions(zeno_speed=0.0, max_impacts=3))
    r = sc.params["radius"]
    run = S.SmallRun(sc.system, lambda c: sc.set_state(
        c, (np.eye(3), np.array([0, 0, r + 0.05])), (np.zeros(3), np.zeros(3))))
    with pytest.raises(ZenoError, match="rim_plane"):
        run.sim.AdvanceTo(1.0)


# ---------------------------------------------------------------------- time shares, CLI
def test_time_shares_name_only_the_declared_pairs():
    sc = stool()
    run = S.SmallRun(sc.system, lambda c: sc.set_state(
        c, (np.eye(3), np.array([0, 0, 0.2 + sc.params["foot_radius"]])),
        (np.zeros(3), np.zeros(3))))
    sc.system.timing.reset()
    run.sim.AdvanceTo(0.05)
    sh = sc.system.timing.shares(1.0)
    assert sh["pairs_declared"] == 3
    assert set(sh["seeks_per_pair"]) == {p.name for p in sc.system.pairs}
    assert sc.system.timing.contact_dynamics > 0.0


@pytest.fixture(scope="module")
def quick(tmp_path_factory):
    out = tmp_path_factory.mktemp("stability") / "out"
    p = subprocess.run([sys.executable, "-m", "drake_dock.cli", "study", "stability", "--quick",
                        "--out", str(out)], capture_output=True, text=True, timeout=900)
    assert p.returncode == 0, p.stderr
    return out, p.stdout, json.loads((out / "stability.json").read_text())


def test_quick_study_writes_figures_and_lines(quick):
    out, stdout, res = quick
    for k in ("a_step_size", "b_stiffness_ratio", "c_high_friction", "d_grazing", "e_zeno"):
        assert (out / f"stability_{k}.png").stat().st_size > 10_000
    for tag in ("(a)", "(b)", "(c)", "(d)", "(e)"):
        assert any(line.startswith(tag) for line in (out / "summary.txt").read_text()
                   .splitlines())
    assert "(d) grazing: impacts detected for delta < 0 only: True" in stdout
    assert "(e) Zeno guard: impact counts equal the closed form: True" in stdout
    marker = json.loads((out / ".drake_dock_output").read_text())   # a study output too
    assert marker["kind"] == "study stability" and "stability.json" in marker["entries"]


def test_step_size_drake_dock_smooth_at_every_output_step(quick):
    """drake_dock's contact force is a function of the state: at output steps 2e-3 and 5e-3
    it is the same smooth curve (the coarse run's samples on the fine run's curve), its
    sawtooth index is that of a smooth curve (O(h^2)); compliant point contact at the step
    of 1e-3 s is not."""
    a = quick[2]["step_size"]
    fine, coarse = a["rigid"]
    assert fine["step"] < coarse["step"]
    # Both integrate to the case's relative accuracy and locate capture by Drake's witness
    # isolation, to within its window (1e-2 of the accuracy, in seconds) after the zero.
    acc = min(load_scenario(PAPER_EXAMPLE).simulator_config.accuracy, S.RIGID_STEP_ACCURACY)
    assert coarse["capture_time"] == pytest.approx(fine["capture_time"],
                                                   abs=acc * fine["capture_time"] + 1e-2 * acc)
    for r in a["rigid"]:
        assert r["index"] < 1e-3
    tf, Ff = np.array(fine["t"]), np.array(fine["F"])
    tc, Fc = np.array(coarse["t"]), np.array(coarse["F"])
    inside = (tc > tf[0]) & (tc < tf[-1])
    # Linear interpolation of the fine curve: error below h^2 |F''| / 8, bounded by the
    # fine run's own sawtooth index times the mean force.
    bound = fine["index"] * Ff.mean() + 1e-6 * Ff.mean()
    assert np.abs(np.interp(tc[inside], tf, Ff) - Fc[inside]).max() <= bound
    sap = [c for c in a["compliant"] if c["step"] == 1e-3]
    assert sap and all(c["index"] > S.SAWTOOTH for c in sap)
