"""The paper's example (Sect. 8.2) end to end through the CLI, checked on its output files
against conservation laws, symmetry, the geometry and a second run."""
import contextlib
import json
import pathlib
import re
import subprocess
import sys
import zipfile

import numpy as np
import pytest
from scipy.spatial.transform import Rotation

from drake_dock.core.patches import posed
from drake_dock.docking.checks.penetration import deepest_penetration
from drake_dock.docking.geometry.scene import DockingScene
from drake_dock.docking.report.headline import headline_table
from drake_dock.docking.scenario.loading import load_scenario
from drake_dock.docking.scenario.models_dir import PAPER_EXAMPLE

ROOT = pathlib.Path(__file__).resolve().parents[2]
EXE = [sys.executable, "-m", "drake_dock.cli", "run", "--no-progress"]


@pytest.fixture(scope="module")
def runs(tmp_path_factory):
    """Two independent runs of the default example, side by side (two processes)."""
    base = tmp_path_factory.mktemp("paper")
    outs = [base / "a", base / "b"]
    procs = [subprocess.Popen(EXE + ["--out", str(o)], stdout=subprocess.PIPE,
                              stderr=subprocess.PIPE, text=True) for o in outs]
    for p in procs:
        out, err = p.communicate(timeout=900)
        assert p.returncode == 0, err
    ts = dict(np.load(outs[0] / "timeseries.npz"))
    summary = json.loads((outs[0] / "summary.json").read_text())
    return dict(outs=outs, ts=ts, summary=summary, scenario=load_scenario(PAPER_EXAMPLE),
                stdout=out, stderr=err)


def _params(runs):
    s = runs["scenario"]
    b = [getattr(s.bodies, n) for n in runs["ts"]["body_names"]]
    return np.array([p.mass for p in b]), np.array([p.inertia for p in b])


def test_second_run_is_bitwise_identical(runs):
    """Every file of a second run in another process is bitwise the same, but cost.json (its
    wall times are measured) and the marker."""
    a, b = runs["outs"]
    names = sorted(p.name for p in a.iterdir())
    assert names == sorted(p.name for p in b.iterdir())
    for name in names:
        if name not in ("cost.json", ".drake_dock_output"):
            assert (a / name).read_bytes() == (b / name).read_bytes(), name


def test_files_and_fields(runs):
    """The arrays' shapes; timeseries.npz compressed, with rows for the couples that came near
    only: the six guide-side pairs (the ring circles stay far from the guide surfaces)."""
    ts, out = runs["ts"], runs["outs"][0]
    N = len(ts["t"])
    C = len(runs["summary"]["couples"])
    assert ts["couple_names"].tolist() == list(runs["summary"]["couples"])
    assert C == 6 and all(c.startswith("cc_T") for c in ts["couple_names"])
    shapes = {"p_WB": (N, 3, 3), "R_WB": (N, 3, 3, 3), "v_WB": (N, 3, 3), "w_WB": (N, 3, 3),
              "p_WA": (N, 2, 3), "R_WA": (N, 2, 3, 3), "active": (N, C), "gap": (N, C),
              "lambda_n": (N, C), "lambda_t": (N, C, 2), "p1_W": (N, C, 3),
              "p2_W": (N, C, 3)}
    for k, shape in shapes.items():
        assert ts[k].shape == shape, k
    with zipfile.ZipFile(out / "timeseries.npz") as z:
        infos = z.infolist()
    assert {i.compress_type for i in infos} == {zipfile.ZIP_DEFLATED}
    assert sum(i.compress_size for i in infos) < 0.7 * sum(i.file_size for i in infos)
    assert ts["body_names"].tolist() == ["target", "target_apds", "chaser"]
    assert ts["apds_names"].tolist() == ["target_apds", "chaser_apds"]
    assert np.all(np.diff(ts["t"]) >= 0)
    for name in ("fig6_rotation_rates", "fig7_axial_velocities",
                 "fig8_ring_distance_contact_force", "fig9_momentum", "couple_forces",
                 "energy_ledger"):
        assert (out / f"{name}.png").stat().st_size > 10_000
    assert not [p for p in out.parent.iterdir() if p.name.startswith(".")]
    # Each impact has a sample just before and one just after, at its time.
    for t in ts["impact_t"]:
        at = np.flatnonzero(ts["t"] == t)
        assert ts["sample_kind"][at].tolist() == [1, 2]


def test_drake_log_keeps_only_what_matters(runs):
    """Drake's log lines stay off the terminal; the only one of this run, Meshcat's start-up
    line with the address of a server closed at the end, is not kept: no drake.log."""
    assert "Meshcat" not in runs["stderr"] + runs["stdout"]
    assert not (runs["outs"][0] / "drake.log").exists()


def test_capture_reached_and_reported(runs):
    """Capture: the axial ring-centre distance, recomputed from the APDS frames, first reaches
    the capture distance at the reported time (the last sample)."""
    ts, s = runs["ts"], runs["summary"]
    assert s["captured"] is True
    d = np.einsum("ni,ni->n", ts["R_WA"][:, 0, :, 2], ts["p_WA"][:, 1] - ts["p_WA"][:, 0])
    cap = runs["scenario"].simulation.capture_distance
    assert abs(d[-1] - cap) < 1e-6
    assert np.all(d[:-1] > cap - 1e-9)
    assert s["capture_time_s"] == ts["t"][-1]
    assert f"captured at t = {s['capture_time_s']:.6f} s" in runs["stdout"]
    # The APDS frames' axes point towards each other.
    assert np.all(np.einsum("ni,ni->n", ts["R_WA"][:, 0, :, 2], ts["R_WA"][:, 1, :, 2]) < -0.99)


def test_momentum_conserved_through_impacts(runs):
    """Total P and L about a fixed point (on the target ring's rim at t = 0), from the
    timeseries and Table 1's masses and inertias: constant to 1e-9 of their t = 0 scales."""
    ts = runs["ts"]
    m, I = _params(runs)
    mv = m[None, :, None] * ts["v_WB"]
    about = ts["p_WA"][0, 0] + runs["scenario"].geometry.R * ts["R_WA"][0, 0][:, 0]
    r = ts["p_WB"] - about
    Iw = np.einsum("nbij,bj,nbkj,nbk->nbi", ts["R_WB"], I, ts["R_WB"], ts["w_WB"])
    P = mv.sum(1)
    L = (np.cross(r, mv) + Iw).sum(1)
    sP = np.linalg.norm(mv[0], axis=1).sum()
    sL = (np.linalg.norm(np.cross(r[0], mv[0]), axis=1) + np.linalg.norm(Iw[0], axis=1)).sum()
    assert sP > 0 and sL > 0
    assert np.abs(P - P[0]).max() <= 1e-9 * sP
    assert np.abs(L - L[0]).max() <= 1e-9 * sL
    assert len(ts["impact_t"]) >= 1
    # The velocities do jump at the impacts (Figs. 6-7).
    k = np.flatnonzero(ts["sample_kind"] == 2)[0]
    assert np.abs(ts["v_WB"][k] - ts["v_WB"][k - 1]).max() > 1e-2


def _stewart_potential(ts, s):
    """1/2 sum k x^2 + 1/2 sum k_t rpy^2 of the APDS frame in the anchor frame (target body
    axes at p_TA), x in the half-way frame: from the timeseries with scipy's rotations."""
    R_T, p_T = ts["R_WB"][:, 0], ts["p_WB"][:, 0]
    R_A, p_A = ts["R_WB"][:, 1], ts["p_WB"][:, 1]
    st = s.stewart
    anchor = p_T + np.einsum("nij,j->ni", R_T, st.p_TA)
    R_AC = np.einsum("nji,njk->nik", R_T, R_A)
    p = np.einsum("nji,nj->ni", R_T, p_A - anchor)
    rot = Rotation.from_matrix(R_AC)
    half = Rotation.from_rotvec(0.5 * rot.as_rotvec())
    x = half.inv().apply(p)
    rpy = rot.as_euler("xyz")           # extrinsic x-y-z = Drake's roll-pitch-yaw
    return 0.5 * (x**2) @ st.force_stiffness + 0.5 * (rpy**2) @ st.torque_stiffness


def test_energy_ledger_closes(runs):
    """Kinetic energy and the Stewart potential recomputed from the motion, plus the damper,
    friction and impact dissipation, equal the initial energy to 1e-6 at every sample."""
    ts, s = runs["ts"], runs["scenario"]
    m, I = _params(runs)
    ke = 0.5 * np.einsum("b,nbi,nbi->n", m, ts["v_WB"], ts["v_WB"]) + 0.5 * np.einsum(
        "nbi,nbij,bj,nbkj,nbk->n", ts["w_WB"], ts["R_WB"], I, ts["R_WB"], ts["w_WB"])
    pe = _stewart_potential(ts, s)
    E = dict(zip(ts["energy_names"].tolist(), ts["energy"].T))
    lost = -E["stewart_damper_work"] + E["friction_loss"] + E["impact_loss"]
    total0 = ke[0] + pe[0]
    assert np.abs(ke + pe + lost - total0).max() <= 1e-6 * total0
    assert lost[-1] > 0.01 * total0                 # something was dissipated
    assert runs["summary"]["energy_ledger"]["closure_error_relative"] <= 1e-6


def test_symmetric_couples_agree(runs):
    """The three couples that close first carry the same force and impulses (3-fold symmetry)
    at every sample, to 1e-6 relative."""
    ts, s = runs["ts"], runs["summary"]
    names = ts["couple_names"].tolist()
    idx = [names.index(c) for c in s["first_closing_couples"]]
    assert len(idx) == 3
    lam = ts["lambda_n"][:, idx]
    scale = np.maximum(np.abs(lam).max(1, keepdims=True), 1e-300)
    assert lam.max() > 0                               # the couples do slide in contact
    assert np.all(np.abs(lam - lam.mean(1, keepdims=True)) <= 1e-6 * scale)
    P = ts["impact_normal_impulse"][:, idx]
    np.testing.assert_allclose(P, np.broadcast_to(P.mean(1, keepdims=True), P.shape), rtol=1e-6)
    assert P[0].min() > 0


def test_gaps_and_points_on_patches(runs):
    """Active couples' gaps >= -1e-8 m; each couple point is its patch's point at the
    recorded parameters, posed by the recorded APDS frame, and the parameters lie in the
    patch domain."""
    ts = runs["ts"]
    act = ts["active"]
    assert act.any()
    assert ts["gap"][act].min() >= -1e-8
    g = runs["scenario"].geometry
    pairs = {p.name: p for p in DockingScene(g, "paper").pairs}
    apds = ts["apds_names"].tolist()
    for j, name in enumerate(ts["couple_names"].tolist()):
        pr = pairs[name]
        n1, n2 = pr.patch1.dim, pr.patch2.dim
        for k in range(0, len(ts["t"]), 7):
            u = ts["u"][k, j]
            for patch, body, uu, p in ((pr.patch1, pr.body1, u[:n1], ts["p1_W"][k, j]),
                                       (pr.patch2, pr.body2, u[n1:n1 + n2], ts["p2_W"][k, j])):
                a = apds.index(body)
                W = posed(patch, ts["R_WA"][k, a], ts["p_WA"][k, a])
                np.testing.assert_allclose(W.position(np.asarray(uu)), p, atol=1e-12)
                if not act[k, j]:
                    continue
                assert np.all(patch.margin(np.asarray(uu)) >= -1e-12)


CHROMIUM = "/usr/bin/chromium"
needs_chromium = pytest.mark.skipif(not __import__("os").path.exists(CHROMIUM),
                                    reason="Debian's chromium is not installed (.ci/run "
                                           "installs it)")


@contextlib.contextmanager
def _replay_page(runs, errors):
    """replay.html of the first run open in headless Chromium, its canvas drawn; JavaScript
    errors collected into ``errors``."""
    from playwright.sync_api import sync_playwright
    with sync_playwright() as p:
        browser = p.chromium.launch(executable_path=CHROMIUM, headless=True, args=[
            "--use-angle=swiftshader", "--enable-unsafe-swiftshader", "--no-sandbox"])
        page = browser.new_page(viewport={"width": 800, "height": 600})
        page.on("console", lambda m: m.type == "error" and errors.append(m.text))
        page.on("pageerror", lambda e: errors.append(str(e)))
        page.goto((runs["outs"][0] / "replay.html").as_uri())
        page.locator("canvas").first.wait_for(timeout=60_000)
        page.wait_for_timeout(300)
        try:
            yield page
        finally:
            browser.close()


def _restart(page):
    """Plays the replay from its start."""
    page.evaluate("() => { viewer.animator.reset(); viewer.animator.play(); }")


def _seek(page, ta):
    """Pauses the replay at animation time ``ta`` (s) and lets it draw."""
    page.evaluate(f"() => {{ viewer.animator.pause(); viewer.animator.seek({ta}); }}")
    page.wait_for_timeout(400)
    return page


def _shot(page):
    import io

    from PIL import Image
    png = page.locator("canvas").first.screenshot()
    return np.asarray(Image.open(io.BytesIO(png)).convert("RGB"), float)


@needs_chromium
def test_replay_plays_in_headless_chromium(runs):
    """replay.html in headless Chromium: titled after the scenario, lasting at least 10 s on
    screen, the canvas shows the APDS (not blank), two frames 0.9 s apart in animation time
    differ (sought, not waited for: the wall time of a screenshot varies with the machine's
    load), and no JavaScript error is logged."""
    errors = []
    with _replay_page(runs, errors) as page:
        assert page.title().startswith("paper_example")
        duration = page.evaluate("() => viewer.animator.duration")
        a, b = (_shot(_seek(page, ta)) for ta in (3.0, 3.9))
    assert duration >= 10.0
    ts = runs["ts"]
    assert duration == pytest.approx(_slowdown(runs) * (ts["t"][-1] - ts["t"][0]), abs=0.05)
    assert a.std() > 10.0                                   # not a blank canvas
    # The APDS colours (blue target APDS, orange chaser APDS) are on screen.
    blue = (a[..., 2] > a[..., 0] + 60) & (a[..., 2] > 120)
    orange = (a[..., 0] > a[..., 2] + 60) & (a[..., 0] > 120)
    assert blue.mean() > 1e-3 and orange.mean() > 1e-3
    assert (np.abs(a - b).sum(-1) > 10).mean() > 1e-3       # it plays
    assert errors == []


def _slowdown(runs) -> float:
    """Animation seconds per simulated second, as the replay's readout states it."""
    html = (runs["outs"][0] / "replay.html").read_text()
    return float(re.search(r'id="time-readout" data-slow="([0-9.e+]+)"', html).group(1))


def _green(img):
    """Pixels of the force arrows' green."""
    return int(((img[..., 1] > img[..., 0] + 60) & (img[..., 1] > img[..., 2] + 60)).sum())


@needs_chromium
def test_replay_time_readout_and_force_arrows(runs):
    """The time readout advances while the replay plays; at a time when the three couples
    slide (from the timeseries) the readout shows that time and force arrows are on screen,
    and before the first contact none is; when the replay has ended it shows the last time."""
    ts = runs["ts"]
    t0, slow = ts["t"][0], _slowdown(runs)
    idx = [ts["couple_names"].tolist().index(c) for c in runs["summary"]["first_closing_couples"]]
    sliding = ts["t"][(ts["status"][:, idx] == 2).all(1) & (ts["t"] > ts["impact_t"].max())]
    t_slide = float(sliding[len(sliding) // 2])
    errors = []
    with _replay_page(runs, errors) as page:
        _restart(page)
        readout = page.locator("#time-readout")
        now = "parseFloat(document.getElementById('time-readout').dataset.time)"
        page.wait_for_function(f"() => {now} >= 0", timeout=30_000)
        first = float(readout.get_attribute("data-time"))
        # Advances (polled: how often the page draws depends on the machine's load).
        page.wait_for_function(f"() => {now} > {first}", timeout=30_000)
        second = float(readout.get_attribute("data-time"))
        shots = {}
        for t in (t0 + 0.5 * (ts["impact_t"][0] - t0), t_slide):
            shots[t] = (_shot(_seek(page, (t - t0) * slow)),
                        float(readout.get_attribute("data-time")),
                        readout.text_content())
        # Played from near its end to the end: the readout holds the last frame's time.
        page.evaluate(f"() => {{ viewer.animator.seek({(ts['t'][-1] - t0) * slow - 0.3}); "
                      f"viewer.animator.play(); }}")
        page.wait_for_function("() => !viewer.animator.playing", timeout=30_000)
        page.wait_for_timeout(300)
        end = float(readout.get_attribute("data-time"))
    assert end == pytest.approx(ts["t"][-1], abs=1.5 / (30.0 * slow))
    assert second > first >= t0
    before, during = shots.values()
    assert _green(before[0]) < 5 and "in contact: 0 couples" in before[2]
    assert _green(during[0]) > 100
    assert abs(during[1] - t_slide) <= 1.0 / (30.0 * slow) and "3 sliding" in during[2]
    assert errors == []


def test_no_feature_enters_a_solid_of_the_other_apds(runs):
    """The independent interpenetration check (`drake_dock.docking.checks.penetration`) over the
    whole run: the couples keep every ring edge, guide side and tip arc out of the other APDS."""
    ts, g = runs["ts"], runs["scenario"].geometry
    pen = deepest_penetration(g, ts["t"], ts["R_WA"], ts["p_WA"], ts["apds_names"].tolist())
    assert pen.depth < 1e-6, pen.describe()


def test_the_docs_headline_table_is_the_runs(runs):
    """docs/results.md's headline table of the example is the one its run gives (to the
    digits it quotes)."""
    table = headline_table(runs["summary"], runs["ts"]["impact_normal_impulse"],
                           runs["ts"]["impact_restitution"])
    docs = (ROOT / "docs" / "results.md").read_text()
    assert table in docs, table
