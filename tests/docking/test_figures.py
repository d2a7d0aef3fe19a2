"""The run figures read back from their PNG files: every axes carries ink and at least one
series, every series a figure function lists is on the image in its colour (outside any
legend), no legend sits on the data, no axis spans more than 12 decades; and the interface loads
against the chaser's momentum balance and the Stewart stroke against the body poses. Three runs,
one each for the module: the paper's example (symmetric: three equal forces, zero transverse
rates), the same with a lateral push on the chaser (`drake_dock.docking.model.control`), and
`models/idss_box_corner.yaml` (off the axis, many impacts; its first 1.5 s)."""
import numpy as np
import pytest
from PIL import Image

from drake_dock.docking.geometry.scene import DockingScene
from drake_dock.docking.model.control import WrenchController, with_controller
from drake_dock.docking.model.diagram import DiagramSpec, build_docking_diagram
from drake_dock.docking.model.outcome import misalignment
from drake_dock.docking.report.figure_kit import PALETTE, decades
from drake_dock.docking.report.interface_loads import interface_loads
from drake_dock.docking.report.run_figures import IMPULSE_FLOOR
from drake_dock.docking.scenario.loading import load_scenario
from drake_dock.run import run
from matplotlib.colors import to_rgb

PUSH_N, PUSH_AFTER_S = 2000.0, 0.06     # lateral force on the chaser (world x) and its start
MAX_DECADES = 12
MIN_PIXELS = 12                         # pixels of a series' colour that must be on screen
TOLERANCE = 32                          # per channel, of 255 (anti-aliasing)


def _push(t, x):
    return [0.0, 0.0, 0.0, PUSH_N if t > PUSH_AFTER_S else 0.0, 0.0, 0.0]


@pytest.fixture(scope="module")
def runs(tmp_path_factory, box_corner):
    base = tmp_path_factory.mktemp("figures")
    scenario = load_scenario()
    paper = run(scenario, base / "paper", full=True)
    dd = build_docking_diagram(DiagramSpec.of(scenario))
    n = dd.dp.plant.num_positions() + dd.dp.plant.num_velocities()
    pushed = run(scenario, base / "pushed", dd=with_controller(dd, WrenchController(n, _push)),
                 full=True)
    return {"paper": (paper, base / "paper"), "pushed": (pushed, base / "pushed"),
            "box": box_corner}


def _pixels_of(img, box, rgb):
    left, top, right, bottom = box
    region = img[top:bottom, left:right].astype(int)
    return int((np.abs(region - 255 * np.asarray(rgb)).max(-1) <= TOLERANCE).sum())


def _ink(img, box):
    """Dark or coloured pixels inside the axes frame (the spines and the pale grey impact lines
    excluded)."""
    left, top, right, bottom = box
    region = img[top + 2:bottom - 2, left + 2:right - 2].astype(int)
    return int((region.min(-1) < 190).sum())


@pytest.mark.parametrize("which", ["paper", "pushed", "box"])
def test_every_listed_series_is_on_its_figure(runs, which):
    out, path = runs[which]
    names = [r.name for r in out.figures]
    assert names == out.summary["figures"]
    assert sorted(names) == sorted(p.name for p in path.glob("*.png"))
    assert len(names) == 8
    for rec in out.figures:
        img = np.asarray(Image.open(path / rec.name).convert("RGB"))
        used = {s.color for ax in rec.axes for s in ax.series}
        unused = [to_rgb(c) for c in PALETTE if to_rgb(c) not in used
                  and np.ptp(to_rgb(c)) > 0.3]           # far from the greys of text
        for ax in rec.axes:
            assert ax.legend_boxes == [], (rec.name, "a legend on the data")
            assert ax.series, (rec.name, "a panel without data")
            assert _ink(img, ax.box) > 300, (rec.name, "blank axes")
            for s in ax.series:
                assert _pixels_of(img, ax.box, s.color) >= MIN_PIXELS, (rec.name, s.label)
            # The detector tells colours apart: a colour drawn nowhere in the figure is absent.
            for c in unused:
                assert _pixels_of(img, ax.box, c) < MIN_PIXELS, (rec.name, c)


@pytest.mark.parametrize("which", ["paper", "box"])
def test_no_axis_spans_more_than_12_decades(runs, which):
    """On a log axis the ratio of its limits, on a linear one the ratio of its largest value
    to its span (round-off drawn as data gives a span of 1e-13 of the values and matplotlib's
    offset notation) stays within 12 decades."""
    out, _ = runs[which]
    for rec in out.figures:
        for ax in rec.axes:
            for name, (lo, hi, scale) in ax.limits.items():
                assert hi > lo, (rec.name, name)
                assert decades(lo, hi, scale) <= MAX_DECADES, (rec.name, name, lo, hi, scale)


def test_fig8_shows_the_couples_with_the_largest_forces(runs):
    """Off the axis the couples that close first are not those that carry the load: Fig. 8
    shows the three with the largest peak normal force (from the timeseries), the summary's
    peak couple among them; its impulses stop at round-off of the run's largest."""
    out, _ = runs["box"]
    ts = out.timeseries
    peak = ts["lambda_n"].max(0)
    top = sorted(np.argsort(peak)[-3:])
    series, notes = _series(out, "fig8_ring_distance_contact_force.png")
    names = ts["couple_names"].tolist()
    assert series[1] == [names[j] for j in top]
    assert out.summary["loads"]["couple_normal_force_N"]["couple"] in series[1]
    assert set(series[1]) != set(out.summary["first_closing_couples"])
    rec = next(r for r in out.figures if r.name.startswith("fig8"))
    lo, hi, scale = rec.axes[2].limits["y"]
    assert scale == "log" and lo >= IMPULSE_FLOOR * ts["impact_normal_impulse"].max() / 3
    assert "not plotted" in notes[2][0]            # the round-off impulses are named


def test_couple_forces_legend_says_normal_and_friction(runs):
    out, _ = runs["box"]
    series, _ = _series(out, "couple_forces.png")
    assert {label for labels in series for label in labels} == {"normal", "friction"}


def test_initial_configuration_states_offset_and_tilt(runs):
    """The initial configuration's views give the chaser ring centre's offset and its axis's
    tilt, which equal the misalignment of the two APDS frames at t = 0
    (`drake_dock.docking.model.outcome.misalignment`): the box corner's offset lies along x and its
    tilt in the x-z plane, so the view along y shows both and the view along x shows none."""
    out, _ = runs["box"]
    ts = out.timeseries
    axial, lateral, tilt = misalignment(ts["R_WA"][0, 0], ts["p_WA"][0, 0], ts["R_WA"][0, 1],
                                        ts["p_WA"][0, 1])
    _, notes = _series(out, "initial_configuration.png")
    along_y, along_x = notes[0][0], notes[1][0]
    assert f"x = {1e3 * lateral:+.1f} mm, z = {1e3 * axial:.1f} mm" in along_y
    assert f"tilted {np.degrees(tilt):+.2f} deg in the x-z plane" in along_y
    assert "y = +0.0 mm" in along_x and "tilted +0.00 deg in the y-z plane" in along_x
    assert lateral > 0.09 and np.degrees(tilt) > 3.9


def _series(out, name):
    rec = next(r for r in out.figures if r.name == name)
    return [[s.label for s in ax.series] for ax in rec.axes], [ax.notes for ax in rec.axes]


def test_listed_series_follow_the_run(runs):
    """What each figure lists follows from the run: the three symmetric couples in Fig. 8,
    the couples that carried force in couple_forces, no transverse rotation rate panel in the
    symmetric example (zero by symmetry, named in a note) and all three rates with the push."""
    paper, _ = runs["paper"]
    ts = paper.timeseries
    series, _ = _series(paper, "fig8_ring_distance_contact_force.png")
    assert series[1] == paper.summary["first_closing_couples"]
    carried = (ts["lambda_n"] > 0).any(0)
    series, _ = _series(paper, "couple_forces.png")
    assert len(series) == int(carried.sum()) == 3
    series, notes = _series(paper, "fig6_rotation_rates.png")
    assert len(series) == 1 and "transverse rates: target, target_apds, chaser" in notes[0][0]
    series, _ = _series(runs["pushed"][0], "fig6_rotation_rates.png")
    assert series[1] == ["target", "target_apds", "chaser"]
    series, notes = _series(paper, "interface_loads.png")
    assert series[0] == ["F_z"] and "F_x, F_y" in notes[0][0]
    series, _ = _series(runs["pushed"][0], "interface_loads.png")
    assert series[0] == ["F_x", "F_y", "F_z"]


def _trapezoid(t, y):
    return (0.5 * (y[1:] + y[:-1]) * np.diff(t)[:, None]).sum(0)


@pytest.mark.parametrize("which", ["paper", "pushed"])
def test_interface_loads_balance_the_chaser(runs, which):
    """After the last impact (and once the push is on), the chaser's change of momentum and of
    angular momentum about a fixed point O equal the time integrals of the push and of minus
    the interface loads (force at the target ring and moment about its centre, moved to O),
    to the quadrature error (1e-5 of the loads carried)."""
    out, _ = runs[which]
    ts = out.timeseries
    scenario = out.result.scenario
    start = max(ts["impact_t"].max(), PUSH_AFTER_S if which == "pushed" else 0.0)
    k = ts["t"] > start
    t = ts["t"][k]
    loads = interface_loads(ts, DockingScene(scenario.geometry, "paper").pairs)
    R, c = ts["R_WA"][k, 0], ts["p_WA"][k, 0]
    F = np.einsum("nij,nj->ni", R, loads["F_A"][k])
    M = np.einsum("nij,nj->ni", R, loads["M_A"][k])
    O = ts["p_WA"][0, 0] + np.array([0.6, 0.0, 0.0])
    push = np.array([PUSH_N if which == "pushed" else 0.0, 0.0, 0.0])
    on_chaser = push - F
    torque = np.cross(c - O, -F) - M + np.cross(ts["p_WB"][k, 2] - O, push)
    j = ts["body_names"].tolist().index("chaser")
    m, inertia = scenario.bodies.chaser.mass, np.diag(scenario.bodies.chaser.inertia)
    v, w, p, Rb = ts["v_WB"][k, j], ts["w_WB"][k, j], ts["p_WB"][k, j], ts["R_WB"][k, j]
    L = m * np.cross(p - O, v) + np.einsum("nij,jk,nlk,nl->ni", Rb, inertia, Rb, w)
    impulse = _trapezoid(t, on_chaser)
    angular = _trapezoid(t, torque)
    scale_p = _trapezoid(t, np.abs(on_chaser)).max()
    scale_l = _trapezoid(t, np.abs(torque)).max()
    assert scale_p > 1.0 and scale_l > 1.0          # loads were carried
    np.testing.assert_allclose(m * (v[-1] - v[0]), impulse, atol=1e-5 * scale_p)
    np.testing.assert_allclose(L[-1] - L[0], angular, atol=1e-5 * scale_l)


def test_stewart_stroke_from_the_poses(runs):
    """The symmetric example turns and pushes the target APDS along and about the docking
    axis only: the stroke's axial translation and yaw equal the APDS frame's offset from the
    anchor (target frame, at p_TA) and its rotation angle about the axis, from the poses."""
    out, _ = runs["paper"]
    ts = out.timeseries
    p_TA = np.asarray(out.result.scenario.stewart.p_TA)
    R_T, p_T, R_A, p_A = (ts["R_WB"][:, 0], ts["p_WB"][:, 0], ts["R_WB"][:, 1],
                          ts["p_WB"][:, 1])
    offset = np.einsum("nji,nj->ni", R_T, p_A - p_T) - p_TA
    R_TA = np.einsum("nji,njk->nik", R_T, R_A)
    yaw = np.arctan2(R_TA[:, 1, 0], R_TA[:, 0, 0])
    np.testing.assert_allclose(ts["stewart_x"][:, 2], offset[:, 2], atol=1e-12)
    np.testing.assert_allclose(ts["stewart_rpy"][:, 2], yaw, atol=1e-12)
    assert np.abs(offset[:, 2]).max() > 0.01         # a stroke of centimetres


def test_a_drift_below_round_off_is_named_round_off_in_a_title_and_above_it_shown():
    from drake_dock.docking.report.results import ROUND_OFF, drift_text
    assert drift_text(0.38 * ROUND_OFF) == drift_text(-0.38 * ROUND_OFF) == "< 1e-10 (round-off)"
    assert float(drift_text(6.17e-7)) == 6.2e-7         # one decimal, by default
    assert drift_text(None) == "undefined"
