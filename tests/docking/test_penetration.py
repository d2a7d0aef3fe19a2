"""The interpenetration check against constructions of known depth: the paper's own guide sides
and tip arcs on their petal's edges (Eq. 13 against Eq. 14), a point pushed a known distance
through a petal, a point passing round a petal's tip (no crossing), a point of a ring inside the
other ring, and a ring that passes right through a petal and out of it between two samples (the
paper example keeps every feature out: tests/docking/test_paper_example.py)."""
import math

import numpy as np
import pytest

from drake_dock.docking.checks.penetration import (deepest_penetration, feature_points,
                                                   petal_coordinates, ring_depth_of)
from petal_paths import cone_point as _cone_point
from petal_paths import near_side as _near_side
from petal_paths import one_point_path as _path

NAMES = ["target_apds", "chaser_apds"]


def test_the_paper_guide_sides_and_tips_lie_on_their_petal_edges(geom):
    """Eq. (14)'s sides lie on the cone of Eq. (12) at the angular inset of Eq. (13): s = 0 and
    fraction 0 (odd sides) or 1 (even sides) of their petal; the tip arcs at zeta = H."""
    f = feature_points(geom)
    for i in range(1, 7):
        s, frac, zeta = petal_coordinates(geom, f[f"guide side {i}"], (i + 1) // 2)
        assert np.abs(s).max() < 1e-12
        assert np.abs(frac - (0.0 if i % 2 else 1.0)).max() < 1e-9
        assert zeta.min() == pytest.approx(0.0, abs=1e-12)
        assert zeta.max() == pytest.approx(geom.H, abs=1e-12)
    for k in (1, 2, 3):
        s, frac, zeta = petal_coordinates(geom, f[f"petal {k} tip arc"], k)
        assert np.abs(s).max() < 1e-12 and np.abs(zeta - geom.H).max() < 1e-12
        assert frac.min() == pytest.approx(0.0, abs=1e-9)
        assert frac.max() == pytest.approx(1.0, abs=1e-9)


def _depth_along(geom, points, max_travel=1e-3, feature="ring inside circle"):
    t, R_WA, p_WA = _path(np.asarray(points))
    return deepest_penetration(geom, t, R_WA, p_WA, NAMES, max_travel=max_travel,
                               features={feature: np.zeros((1, 3))})


@pytest.mark.parametrize("k", [1, 2, 3])
@pytest.mark.parametrize("side", [1.0, -1.0])
def test_a_point_pushed_through_a_petal_is_at_its_depth(geom, k, side):
    """From 10 mm on either side of petal k, through its face, to delta beyond it."""
    x, n = _cone_point(geom, k, 0.4, 0.12)
    for delta in (1e-6, 1e-4, 2e-3):
        found = _depth_along(geom, [x + side * 0.01 * n, x - side * delta * n])
        assert found.depth == pytest.approx(delta, rel=1e-9)
        assert found.solid == f"target_apds petal {k}" and found.time == 1e-3
    # Back out the way it came: no longer through the plate.
    back = _depth_along(geom, [x + side * 0.01 * n, x - side * 2e-3 * n, x + side * 0.02 * n])
    assert back.depth == pytest.approx(2e-3, rel=1e-9) and back.time == 1e-3


def test_a_point_passing_over_the_tip_does_not_cross(geom):
    """Outside petal 1 near its tip, up over the tip arc, down behind the petal: it changes
    side above the plate, not through it."""
    x, n = _cone_point(geom, 1, 0.5, geom.H)
    up = np.array([0.0, 0.0, 0.03])
    path = [x + 0.01 * n - 0.02 * up, x + 0.01 * n + up, x - 0.01 * n + up,
            x - 0.01 * n - 0.5 * up]
    assert _depth_along(geom, path).depth == 0.0
    # The same end reached straight through the face is a crossing.
    assert _depth_along(geom, [path[0], path[-1]]).depth > 0.005


def test_ring_depth_is_the_distance_to_the_nearest_face(geom):
    r = 0.5 * (geom.R + geom.Rs)
    X = np.array([[r, 0.0, -0.001], [0.0, r, -0.02], [geom.Rs + 0.003, 0.0, -0.02],
                  [r, 0.0, 0.001]])
    assert ring_depth_of(geom, X, 0.04) == pytest.approx([0.001, 0.02, 0.003, -0.001])


def test_a_ring_passing_through_a_petal_and_out_between_samples_is_seen(geom):
    """Two samples 1 ms apart of a point of the chaser's inside circle: 10 mm outside petal 1,
    then 50 mm behind it and 0.2 m down along the cone's generatrix, out from under the petal
    past its root. Neither sample shows it through the plate; the sub-steps do. At path fraction
    f it is -0.01 + 0.06 f behind the plate and (0.1 - 0.2 f sin(alpha1)) / sin(alpha1) from
    the root along the surface; its depth, the least of the two, is greatest where they are
    equal (25 mm)."""
    x, n = _cone_point(geom, 1, 0.5, 0.1)
    e_rho = np.array([x[0], x[1], 0.0]) / math.hypot(x[0], x[1])
    down = math.cos(geom.alpha1) * e_rho - math.sin(geom.alpha1) * np.array([0.0, 0.0, 1.0])
    start = x + 0.01 * n
    end = start - 0.06 * n + 0.2 * down
    assert _depth_along(geom, [start, end], max_travel=1.0).depth == 0.0
    found = _depth_along(geom, [start, end])
    assert found.feature == "chaser_apds ring inside circle"
    assert found.solid == "target_apds petal 1"
    s, frac, zeta = petal_coordinates(geom, end[None], 1)
    assert zeta[0] < 0.0                              # the end is no longer over the plate
    sa = math.sin(geom.alpha1)
    f = (0.1 / sa + 0.01) / (0.06 + 0.2)              # behind = to the root
    assert found.depth == pytest.approx(0.06 * f - 0.01, abs=1e-3)
    assert 0.0 < found.time < 1e-3


@pytest.mark.parametrize("delta,s,depth", [(50e-6, 2e-3, 50e-6), (3e-3, 2e-3, 2e-3),
                                           (0.5e-6, 2e-3, 0.0)])
def test_depth_near_a_free_edge_is_the_least_motion_out(geom, delta, s, depth):
    """A point pushed s through petal 1 at delta from guide side 1 lies min(s, delta) deep:
    back through the plate, or sideways off it past the side. Within the 1 um graze of the
    side it passes round the edge (an edge in contact with the side passes exactly through it)."""
    x, n = _near_side(geom, delta)
    found = _depth_along(geom, [x + 0.01 * n, x - s * n])
    assert found.depth == pytest.approx(depth, abs=1e-9)      # the edges as chords
    if depth:
        assert found.solid == "target_apds petal 1"


@pytest.mark.parametrize("zeta,s,depth", [(50e-6, 2e-3, 50e-6 * math.sqrt(2)),
                                          (3e-3, 2e-3, 2e-3), (0.5e-6, 2e-3, 0.0)])
def test_depth_near_the_root_is_the_least_motion_out(geom, zeta, s, depth):
    """A point of a guide side pushed s through the middle of petal 1 at height zeta above its
    root lies min(s, zeta / sin(alpha1)) deep (alpha1 = 45 deg): the other APDS passes the
    ring's annulus in the paper's reading, so the root, zeta / sin(alpha1) away along the
    surface, frees it as a side does; within the 1 um graze it passes below the root."""
    x, n = _cone_point(geom, 1, 0.5, zeta)
    found = _depth_along(geom, [x + 0.01 * n, x - s * n], feature="guide side 3")
    # The root as chords of 0.16 mm on the circle rho = R: within 1e-8 m of it.
    assert found.depth == pytest.approx(depth, abs=1e-8)
    if depth:
        assert found.solid == "target_apds petal 1"


@pytest.mark.parametrize("inset, depth", [(0.0, 0.0), (1e-3, 2e-3)])
def test_a_guide_side_root_passing_a_petal_is_the_annulus_passing(geom, inset, depth):
    """A point of the chaser pushed 2 mm through the middle of target petal 1 at mid-height
    (named a guide side's). On the chaser ring's outside circle (rho = R, zeta = 0: a side's
    root), the outer edge of the annulus that the target's petals pass in the paper's reading,
    it is not counted; 1 mm inside that circle it is, 2 mm deep. The sub-steps land exactly on
    the cone (s = 0) here: the point keeps its side there and the crossing is seen next."""
    x, n = _cone_point(geom, 1, 0.5, 0.1)
    own = np.array([[geom.R - inset, 0.0, 0.0]])
    path = np.array([x + 0.01 * n, x - 2e-3 * n]) - own[0]
    t, R_WA, p_WA = _path(path)
    found = deepest_penetration(geom, t, R_WA, p_WA, NAMES, features={"guide side 1": own})
    assert found.depth == pytest.approx(depth, abs=1e-9)
