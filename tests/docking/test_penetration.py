"""The interpenetration check against constructions of known depth: a point pushed a known
distance through a petal or into a ring, the paper's own guide sides lying on their petal's
edges (Eq. 13 against Eq. 14), and a ring that passes right through a petal between two samples
(the paper example keeps every feature out: tests/docking/test_paper_example.py)."""
import math

import numpy as np
import pytest

from drake_dock.docking.penetration import (deepest_penetration, feature_points,
                                            petal_depth_of, ring_depth_of)


def _cone_point(g, k, s, zeta):
    """The point of petal k's guide surface at fraction s across the petal and height zeta, and
    the cone's outward unit normal there (from Eq. 12 and 13 written out here)."""
    rho = g.R - zeta / math.tan(g.alpha1)
    inset = math.asin(g.R * math.sin(g.alpha2) / rho) - g.alpha2
    th = (2 * k - 2) * math.pi / 3 + inset + s * (math.pi / 3 - 2 * inset)
    e_rho = np.array([math.cos(th), math.sin(th), 0.0])
    x = rho * e_rho + np.array([0.0, 0.0, zeta])
    n = math.sin(g.alpha1) * e_rho + np.array([0.0, 0.0, math.cos(g.alpha1)])
    return x, n


@pytest.mark.parametrize("k", [1, 2, 3])
def test_a_point_pushed_through_a_petal_is_at_its_depth(geom, k):
    for zeta in (0.05, 0.1, 0.15):
        x, n = _cone_point(geom, k, 0.5, zeta)
        delta = np.array([1e-6, 1e-4, 2e-3, 1e-2])
        X = x - delta[:, None] * n
        assert petal_depth_of(geom, X, k, 0.05) == pytest.approx(delta, rel=1e-9, abs=1e-15)
        assert np.all(petal_depth_of(geom, x + delta[:, None] * n, k, 0.05) < 0)
        others = [j for j in (1, 2, 3) if j != k]
        assert all(np.all(petal_depth_of(geom, X, j, 0.05) < 0) for j in others)


def test_the_paper_guide_sides_lie_on_their_petal_edges(geom):
    """Eq. (14)'s sides, sampled by the check, lie on the cone of Eq. (12) at the angular inset
    of Eq. (13): depth zero in their own petal (side 2k-1 and 2k bound petal k)."""
    f = feature_points(geom)
    for i in range(1, 7):
        d = petal_depth_of(geom, f[f"guide side {i}"], (i + 1) // 2, 0.05)
        assert np.abs(d).max() < 1e-12
    for k in (1, 2, 3):
        assert np.abs(petal_depth_of(geom, f[f"petal {k} tip arc"], k, 0.05)).max() < 1e-12


def test_ring_depth_is_the_distance_to_the_nearest_face(geom):
    r = 0.5 * (geom.R + geom.Rs)
    X = np.array([[r, 0.0, -0.001], [0.0, r, -0.02], [geom.Rs + 0.003, 0.0, -0.02],
                  [r, 0.0, 0.001]])
    assert ring_depth_of(geom, X, 0.04) == pytest.approx([0.001, 0.02, 0.003, -0.001])


def test_a_ring_passing_through_a_petal_between_samples_is_seen(geom):
    """Two samples 1 ms apart of a point of the chaser's inside circle: 10 mm outside petal 1's
    guide surface, then moved 0.1 m towards the axis, 61 mm beyond the surface and past the
    50 mm solid behind it. Neither sample is inside; the sub-steps between them are."""
    x, n = _cone_point(geom, 1, 0.5, 0.1)
    th = math.atan2(x[1], x[0])
    radial = np.array([math.cos(th), math.sin(th), 0.0])
    feats = {"ring inside circle": np.array([geom.Rs * radial])}
    p0 = x + 0.01 * n - geom.Rs * radial
    p_WA = np.zeros((2, 2, 3))
    p_WA[:, 1] = [p0, p0 - 0.1 * radial]
    R_WA = np.broadcast_to(np.eye(3), (2, 2, 3, 3)).copy()
    t, names = np.array([0.0, 1e-3]), ["target_apds", "chaser_apds"]
    ends = deepest_penetration(geom, t, R_WA, p_WA, names, max_travel=1.0, features=feats)
    assert ends.depth == 0.0
    found = deepest_penetration(geom, t, R_WA, p_WA, names, features=feats)
    assert found.feature == "chaser_apds ring inside circle"
    assert found.solid == "target_apds petal 1"
    # The deepest sub-step is near the solid's middle, 25 mm from both its faces.
    assert found.depth == pytest.approx(0.025, abs=1e-3) and 0.0 < found.time < 1e-3
