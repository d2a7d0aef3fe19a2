"""The triangle-mesh interpenetration check (`drake_dock.docking.checks.mesh_check`) against the
paper's equations and closed forms: its vertices on the cone, the guide sides (Eq. 14) and the tip
arcs; its chords within the sagitta of the widest row; a point pushed through a petal lies at its
distance to the cone or to the nearest free edge; a point passing round a guide side or over a tip
does not cross; a ring pushed into the other ring's solid lies at its distance to the solid's
nearest face; the depth error falls as the mesh is refined; and the analytic check
(`drake_dock.docking.checks.penetration`) agrees on the same motions and on a short recorded run."""
import collections
import math
from pathlib import Path

import numpy as np
import pytest

from drake_dock.docking.checks.mesh_check import (MeshResolution, closest_on_triangles,
                                                  deepest_penetration_mesh, grid_triangles,
                                                  mesh_features, petal_grid, ring_grids)
from drake_dock.docking.checks.penetration import deepest_penetration
from drake_dock.docking.geometry.rotations import rot_x, rot_z
from drake_dock.errors import InputError
from petal_paths import cone_point, near_side, one_point_path

NAMES = ["target_apds", "chaser_apds"]
DEFAULT = MeshResolution()


def sagittas(g, res=DEFAULT):
    """The chord errors of the widest rows, as sagittas of their arcs: a chord spanning the angle
    d of a circle of radius r lies r d^2 / 8 from it. The petal's root row (rho = R, theta
    across pi/3 in ``across`` chords) lies R d^2 / 8 from the outside circle in the ring plane
    and sin(alpha1) times that from the cone; the ring's circles have ``around`` chords."""
    d = math.pi / 3 / res.across
    return {"surface": math.sin(g.alpha1) * g.R * d * d / 8, "edge": g.R * d * d / 8,
            "ring": g.R * (2 * math.pi / res.around) ** 2 / 8}


def cone_offset(g, X):
    """Signed distance of points X to the cone of Eq. (12), positive away from the axis."""
    rho = np.hypot(X[..., 0], X[..., 1])
    return (rho - g.R) * math.sin(g.alpha1) + X[..., 2] * math.cos(g.alpha1)


def depth_along(g, points, feature="ring inside circle", **kw):
    t, R_WA, p_WA = one_point_path(np.asarray(points))
    one = {feature: np.zeros((1, 3))}
    return (deepest_penetration_mesh(g, t, R_WA, p_WA, NAMES, features=one, **kw),
            deepest_penetration(g, t, R_WA, p_WA, NAMES, features=one,
                                max_travel=kw.get("max_travel", 1e-3)))


def test_the_vertices_lie_on_the_cone_the_guide_sides_and_the_tip_arcs(geom):
    """Every petal vertex on the cone (Eq. 12); the first and last columns on guide sides
    2k - 1 and 2k in Eq. (14)'s sine form, rho = R sin(alpha2) / sin(alpha2 + sigma (theta -
    phi_i)); the last row on the tip arc rho = R - H cot(alpha1), zeta = H (its ends are the
    sides' last points); the side's chords within the root's sagitta of Eq. (14) sampled finely."""
    tan1, A = math.tan(geom.alpha1), geom.R * math.sin(geom.alpha2)
    for k in (1, 2, 3):
        V = petal_grid(geom, k, DEFAULT)
        assert np.abs(cone_offset(geom, V)).max() < 1e-12
        for col, i, sigma in ((V[0], 2 * k - 1, 1), (V[-1], 2 * k, -1)):
            th = np.arctan2(col[:, 1], col[:, 0])
            w = np.mod(geom.alpha2 + sigma * (th - (i - 1) * math.pi / 3), 2 * math.pi)
            assert np.abs(np.hypot(col[:, 0], col[:, 1]) - A / np.sin(w)).max() < 1e-12
            assert col[0, 2] == 0.0 and col[-1, 2] == pytest.approx(geom.H, abs=1e-15)
        tip = V[:, -1]
        assert np.abs(np.hypot(tip[:, 0], tip[:, 1]) - (geom.R - geom.H / tan1)).max() < 1e-12
        assert np.all(tip[:, 2] == geom.H)
    side = petal_grid(geom, 1, DEFAULT)[0]
    rho = np.linspace(geom.R, geom.R - geom.H / tan1, 20001)
    th = np.arcsin(A / rho) - geom.alpha2
    fine = np.column_stack([rho * np.cos(th), rho * np.sin(th), (geom.R - rho) * tan1])
    seg = [np.linalg.norm(fine - a - np.clip((fine - a) @ (b - a) / ((b - a) @ (b - a)), 0, 1)
                          [:, None] * (b - a), axis=1) for a, b in zip(side[:-1], side[1:])]
    assert np.min(seg, axis=0).max() < sagittas(geom)["edge"]


def test_the_chords_lie_within_the_sagitta_of_the_widest_row(geom):
    """Points spread over every triangle of petal 1 lie on the axis side of the cone (a chord
    of a circle lies inside it) by at most the root row's sagitta, and reach it."""
    tri = grid_triangles(petal_grid(geom, 1, DEFAULT))
    worst = 0.0
    for u in np.linspace(0.0, 1.0, 7):
        for v in np.linspace(0.0, 1.0 - u, 7):
            s = cone_offset(geom, tri[:, 0] + u * (tri[:, 1] - tri[:, 0])
                            + v * (tri[:, 2] - tri[:, 0]))
            assert s.max() < 1e-12
            worst = min(worst, s.min())
    assert 0.9 * sagittas(geom)["surface"] < -worst <= sagittas(geom)["surface"] * (1 + 1e-6)
    stated = DEFAULT.chord_errors(geom)
    assert (stated["petal"], stated["petal root"], stated["ring"]) == pytest.approx(
        (sagittas(geom)["surface"], sagittas(geom)["edge"], sagittas(geom)["ring"]))


def test_the_closest_point_of_a_triangle_is_the_nearest_of_many_samples():
    """Random points and triangles (seeded): the closest point lies on the triangle, no sample
    of the triangle (a barycentric grid of step 1/400) is nearer, and the nearest sample lies
    within the grid's spacing of it."""
    rng = np.random.default_rng(7)
    P, A, B, C = (rng.normal(size=(200, 3)) for _ in range(4))
    Q = closest_on_triangles(P, A, B, C)
    u, v = np.meshgrid(np.linspace(0, 1, 401), np.linspace(0, 1, 401), indexing="ij")
    u, v = u[u + v <= 1], v[u + v <= 1]
    for p, a, b, c, q in zip(P, A, B, C, Q):
        S = a + u[:, None] * (b - a) + v[:, None] * (c - a)
        near = np.linalg.norm(S - p, axis=1).min()
        assert np.linalg.norm(q - p) <= near + 1e-12
        assert near - np.linalg.norm(q - p) < 0.01 * np.linalg.norm([b - a, c - a])
        w = np.linalg.lstsq(np.column_stack([b - a, c - a]), q - a, rcond=None)[0]
        assert w.min() >= -1e-9 and w.sum() <= 1 + 1e-9


def test_the_ring_solid_is_closed(geom):
    """Every edge of the ring's triangles is shared by exactly two of them (coarse mesh)."""
    res = MeshResolution(around=48, radial=3, deep=2)
    tri = np.concatenate([grid_triangles(V, wrap=True) for V in ring_grids(geom, res, 0.04)])
    ends = np.round(np.concatenate([tri[:, [0, 1]], tri[:, [1, 2]], tri[:, [2, 0]]]), 12)
    count = collections.Counter(tuple(sorted(map(tuple, e))) for e in ends.tolist())
    assert len(tri) == 2 * 48 * 2 * (3 + 2) and set(count.values()) == {2}


@pytest.mark.parametrize("k", [1, 2, 3])
@pytest.mark.parametrize("side", [1.0, -1.0])
def test_a_point_pushed_through_a_petal_is_at_its_distance_to_the_cone(geom, k, side):
    """From 10 mm on either side of petal k, through its face (off the mesh's vertices), to
    delta beyond it: delta deep, within the chord error; the analytic check agrees."""
    x, n = cone_point(geom, k, 0.37, 0.123)
    for delta in (1e-4, 2e-3):
        mesh, analytic = depth_along(geom, [x + side * 0.01 * n, x - side * delta * n])
        assert mesh.depth == pytest.approx(delta, abs=sagittas(geom)["surface"])
        assert analytic.depth == pytest.approx(mesh.depth, abs=sagittas(geom)["surface"])
        assert mesh.solid == f"target_apds petal {k}" and mesh.time == 1e-3
    mesh, _ = depth_along(geom, [x + side * 0.01 * n, x - side * 2e-3 * n, x + side * 0.02 * n])
    assert mesh.depth == pytest.approx(2e-3, abs=sagittas(geom)["surface"])


def test_a_point_passing_over_the_tip_or_round_a_side_does_not_cross(geom):
    """Outside petal 1 near its tip, up over the tip arc and down behind the petal; outside it
    20 mm beyond guide side 1, behind it and across under the plate: no crossing. Straight
    through the plate to the same ends is a crossing."""
    x, n = cone_point(geom, 1, 0.5, geom.H)
    up = np.array([0.0, 0.0, 0.03])
    over = [x + 0.01 * n - 0.02 * up, x + 0.01 * n + up, x - 0.01 * n + up,
            x - 0.01 * n - 0.5 * up]
    (y_out, n_out), (y_in, n_in) = near_side(geom, -0.02), near_side(geom, 0.01)
    round_side = [y_out + 0.01 * n_out, y_out - 0.01 * n_out, y_in - 0.01 * n_in]
    for path, front in ((over, over[0]), (round_side, y_in + 0.01 * n_in)):
        assert depth_along(geom, path)[0].depth == 0.0
        assert depth_along(geom, [front, path[-1]])[0].depth > 0.005


@pytest.mark.parametrize("delta,s", [(50e-6, 2e-3), (3e-3, 2e-3), (0.5e-6, 2e-3)])
def test_depth_near_a_guide_side_is_the_least_motion_out(geom, delta, s):
    """A point pushed s through petal 1 at delta from guide side 1 lies min(s, delta) deep,
    within the chord errors of the surface and of the side; within the 1 um graze of the side
    it passes round the edge."""
    x, n = near_side(geom, delta)
    mesh, analytic = depth_along(geom, [x + 0.01 * n, x - s * n])
    tol = sagittas(geom)["surface"] + sagittas(geom)["edge"]
    expect = min(s, delta) if delta > 1e-6 else 0.0
    assert mesh.depth == pytest.approx(expect, abs=tol)
    assert analytic.depth == pytest.approx(mesh.depth, abs=tol)


@pytest.mark.parametrize("zeta,depth", [(50e-6, 50e-6 * math.sqrt(2)), (3e-3, 2e-3),
                                        (0.3e-6, 0.0)])
def test_depth_near_the_root_is_the_least_motion_out(geom, zeta, depth):
    """A point of a guide side pushed 2 mm through petal 1 at height zeta, between two mesh
    columns: min(2 mm, zeta / sin(alpha1)) deep (alpha1 = 45 deg), the root being a free edge
    in the paper's reading; within the graze of the root (or below its chord) it passes."""
    x, n = cone_point(geom, 1, 0.5 + 0.5 / DEFAULT.across, zeta)
    mesh, _ = depth_along(geom, [x + 0.01 * n, x - 2e-3 * n], feature="guide side 3")
    assert mesh.depth == pytest.approx(depth, abs=sagittas(geom)["surface"]
                                       + sagittas(geom)["edge"])


@pytest.mark.parametrize("inset,depth", [(0.0, 0.0), (1e-3, 2e-3)])
def test_a_guide_side_root_passing_a_petal_is_not_checked(geom, inset, depth):
    """A point named a guide side's, on the ring's outside circle (a root), pushed 2 mm through
    the middle of target petal 1 is not counted; 1 mm inside that circle it is, 2 mm deep."""
    x, n = cone_point(geom, 1, 0.4, 0.1)
    own = np.array([[geom.R - inset, 0.0, 0.0]])
    t, R_WA, p_WA = one_point_path(np.array([x + 0.01 * n, x - 2e-3 * n]) - own[0])
    found = deepest_penetration_mesh(geom, t, R_WA, p_WA, NAMES, features={"guide side 1": own})
    assert found.depth == pytest.approx(depth, abs=sagittas(geom)["surface"])


def test_a_ring_passing_through_a_petal_between_samples_agrees_with_the_analytic_check(geom):
    """Two samples 1 ms apart of a point of the chaser's inside circle: 10 mm outside petal 1,
    then 50 mm behind it and 0.2 m down the generatrix, out past its root (the analytic
    check's own construction, 25 mm deep at most): the sub-steps see it, and both checks find
    the same depth at the same sub-step."""
    x, n = cone_point(geom, 1, 0.5, 0.1)
    e_rho = np.array([x[0], x[1], 0.0]) / math.hypot(x[0], x[1])
    down = math.cos(geom.alpha1) * e_rho - math.sin(geom.alpha1) * np.array([0.0, 0.0, 1.0])
    start = x + 0.01 * n
    mesh, analytic = depth_along(geom, [start, start - 0.06 * n + 0.2 * down])
    assert mesh.depth == pytest.approx(analytic.depth, abs=sagittas(geom)["surface"]
                                       + sagittas(geom)["edge"])
    assert mesh.depth == pytest.approx(0.025, abs=1e-3) and mesh.time == analytic.time
    assert mesh.feature == "chaser_apds ring inside circle"
    assert mesh.solid == "target_apds petal 1"


def facing_path(heights, offset=(0.0, 0.0), roll_deg=0.0):
    """The chaser's APDS frame facing the target's (turned half round x, rolled about the axis)
    with its ring face at the heights (m) above the target's ring face, its centre offset
    laterally; samples 1 ms apart."""
    n = len(heights)
    R_WA = np.broadcast_to(np.eye(3), (n, 2, 3, 3)).copy()
    R_WA[:, 1] = rot_z(math.radians(roll_deg)) @ rot_x(math.pi)
    p_WA = np.zeros((n, 2, 3))
    p_WA[:, 1, :2], p_WA[:, 1, 2] = offset, heights
    return np.arange(n) * 1e-3, R_WA, p_WA


def circle(r, n=2048, z=0.0):
    th = 2 * math.pi * np.arange(n) / n
    return np.column_stack([r * np.cos(th), r * np.sin(th), np.full(n, z)])


@pytest.mark.parametrize("feature,points,offset,height,depth", [
    ("ring inside circle", "inside", 3e-3, -0.02, 3e-3),     # the circle's point rho = Rs + 3 mm
    ("ring outside circle", "outside", 2e-3, -0.01, 2e-3),   # rho = R - 2 mm
    ("ring face", "face", 0.0, -4e-3, 4e-3)])                # the face 4 mm below
def test_a_ring_pushed_into_the_other_ring_lies_at_its_distance_to_the_nearest_face(
        geom, feature, points, offset, height, depth):
    """The chaser lowered from 5 mm above the target's ring face to ``height``, offset along x:
    its deepest point lies min(-z, ring_depth + z, rho - Rs, (R + z - rho) / sqrt 2) inside the
    target's ring (the last term its 45 deg outer chamfer), z the sample's height and rho the
    point's radius in the target's frame, deepest over the samples (and the reverse likewise);
    within the ring's chord error."""
    X = {"inside": circle(geom.Rs), "outside": circle(geom.R),
         "face": np.concatenate([circle(r, 256) for r in np.linspace(geom.Rs, geom.R, 9)[1:-1]])}
    heights = np.linspace(5e-3, height, 26)
    t, R_WA, p_WA = facing_path(heights, (offset, 0.0))
    found = deepest_penetration_mesh(geom, t, R_WA, p_WA, NAMES, features={feature: X[points]})
    rho = {"inside": geom.Rs + offset, "outside": geom.R - offset, "face": geom.Rs}[points]
    if points == "face":                            # every face point lies on the solid's annulus
        expected = max(min(-z, depth) for z in heights)
    else:
        expected = max(min(-z, rho - geom.Rs, (geom.R + z - rho) * math.sqrt(0.5))
                       for z in heights)
    assert found.depth == pytest.approx(expected, abs=sagittas(geom)["ring"])
    assert found.solid.endswith("apds ring")


@pytest.mark.parametrize("point,depth", [((0.5, 0.0, -0.001), 0.001), ((0.0, 0.5, -0.02), 0.02),
                                         ((0.403, 0.0, -0.02), 0.003), ((0.5, 0.0, 0.001), 0.0),
                                         ((0.3, 0.0, -0.02), 0.0), ((0.5, 0.0, -0.05), 0.0)])
def test_a_point_inside_the_ring_at_the_first_sample_is_found(geom, point, depth):
    """A point placed in or beside the target's ring solid from the start (one sample): inside
    (the ray's parity), at its distance to the nearest face (closed form)."""
    t, R_WA, p_WA = facing_path([point[2]], point[:2])
    found = deepest_penetration_mesh(geom, t, R_WA, p_WA, NAMES,
                                     features={"ring face": np.zeros((1, 3))})
    assert found.depth == pytest.approx(depth, abs=1e-12)


def test_the_depth_error_falls_as_the_mesh_is_refined(geom):
    """A point pushed 1 mm through petal 1 off the vertices: the mesh's depth error falls with
    the chord error (about four times per halving of the chords) and stays within it."""
    x, n = cone_point(geom, 1, 0.37, 0.123)
    errors = []
    for across in (8, 16, 32, 64, 128):
        res = MeshResolution(across=across, up=2 * across // 5 or 2)
        mesh, _ = depth_along(geom, [x + 0.01 * n, x - 1e-3 * n], resolution=res)
        errors.append(abs(mesh.depth - 1e-3))
        assert errors[-1] <= sagittas(geom, res)["surface"]
    assert all(b < 0.6 * a for a, b in zip(errors, errors[1:]))
    assert errors[-1] < errors[0] / 50


def test_a_facing_approach_with_a_roll_agrees_with_the_analytic_check(geom):
    """The chaser, rolled 4 deg, lowered coaxially from a ring distance of 80 mm to 50 mm, where
    guide sides cut through the other's petals (no couple holds them here): both checks, given
    the same feature points, find the same depth within the chord errors."""
    t, R_WA, p_WA = facing_path(np.linspace(0.08, 0.05, 16), roll_deg=4.0)
    f = mesh_features(geom, DEFAULT)
    mesh = deepest_penetration_mesh(geom, t, R_WA, p_WA, NAMES)
    analytic = deepest_penetration(geom, t, R_WA, p_WA, NAMES, features=f)
    assert mesh.depth > 1e-3
    assert mesh.depth == pytest.approx(analytic.depth, abs=sagittas(geom)["surface"]
                                       + sagittas(geom)["edge"])


@pytest.fixture(scope="module")
def recorded():
    """0.25 s of an IDSS box corner (models/idss_box_corner.yaml): the approach and the first
    impacts, ring inside circles and guide sides in contact with the other's petals."""
    from drake_dock.docking.model.simulate import simulate
    from drake_dock.docking.placement.place import place
    from drake_dock.docking.report.results import timeseries
    from drake_dock.docking.scenario.loading import load_scenario
    s = load_scenario(Path(__file__).resolve().parents[2] / "models" / "idss_box_corner.yaml")
    r = simulate(s, place(s), duration=0.25)
    assert len(r.impacts) >= 3
    ts = timeseries(r)
    return s.geometry, ts["t"], ts["R_WA"], ts["p_WA"], ts["apds_names"].tolist()


def test_a_recorded_run_is_clear_by_both_checks(recorded):
    """The couples keep the features out: the analytic check finds nothing, the mesh check
    nothing deeper than its chord error (a point touching a petal from the axis side lies
    beyond the petal's chords)."""
    g, t, R_WA, p_WA, names = recorded
    assert deepest_penetration(g, t, R_WA, p_WA, names).depth == 0.0
    assert deepest_penetration_mesh(g, t, R_WA, p_WA, names).depth <= sagittas(g)["surface"]


def test_a_recorded_run_pushed_together_agrees_with_the_analytic_check(recorded):
    """The same run with the chaser moved 0.5 mm along the target's axis towards it at every
    sample: both checks, given the same feature points, find the same point of the same
    feature in the same petal at the same time, as deep within the chord errors."""
    g, t, R_WA, p_WA, names = recorded
    p = p_WA.copy()
    p[:, 1] -= 5e-4 * R_WA[:, 0, :, 2]
    mesh = deepest_penetration_mesh(g, t, R_WA, p, names)
    analytic = deepest_penetration(g, t, R_WA, p, names, features=mesh_features(g, DEFAULT))
    assert mesh.depth > 1e-4
    assert mesh.depth == pytest.approx(analytic.depth, abs=sagittas(g)["surface"]
                                       + sagittas(g)["edge"])
    assert (mesh.time, mesh.feature, mesh.solid) == (analytic.time, analytic.feature,
                                                     analytic.solid)


def test_input_errors_are_typed(geom):
    t, R_WA, p_WA = one_point_path(np.zeros((2, 3)))
    bad = [dict(resolution=MeshResolution(across=1)), dict(ring_depth=0.0),
           dict(max_travel=-1.0), dict(graze=math.nan), dict(resolution="fine")]
    for kw in bad:
        with pytest.raises(InputError):
            deepest_penetration_mesh(geom, t, R_WA, p_WA, NAMES, **kw)
    with pytest.raises(InputError):
        deepest_penetration_mesh(geom, t, R_WA[:1], p_WA, NAMES)
    with pytest.raises(InputError):
        deepest_penetration_mesh(geom, t, R_WA, p_WA, NAMES[:1])
