"""The interpenetration check's shortcuts against its plain form. `Polyline.distance` (a k-d
tree) against the brute-force `distance_to_polyline`; `deepest_penetration` (sub-steps in
blocks, rows where nothing changes side passed over, the ring's solid checked only in rows
that reach below its face, the three petals' places at once; with and without ``sparse``,
the rows with a crossing over a petal found for a block at once) against a loop over every
sub-step, feature and petal written here, with its own petal places and the brute-force edge
distance. Both exactly, on paths that cross petals, graze their edges, overlap the rings,
stop a point exactly on the cone at a block's edge, tie depths, turn a point into a gap
between petals over passed-over rows before it drops through the cone, and cross the cone
next to the tip height."""
import dataclasses
import math

import numpy as np
import pytest

from drake_dock.docking.checks import cone_reach
from drake_dock.docking.checks import penetration as pen
from drake_dock.docking.geometry.rotations import rot_vec
from drake_dock.docking.placement.search import Approach

NAMES = ("target_apds", "chaser_apds")


def _places(g, X, k):
    """Petal k's (s, fraction, zeta) of points X (Eq. 12-13), written out here."""
    s = (np.hypot(X[:, 0], X[:, 1]) - g.R) * math.sin(g.alpha1) + X[:, 2] * math.cos(g.alpha1)
    zeta = X[:, 2] - s * math.cos(g.alpha1)
    rho = g.R - np.clip(zeta, 0.0, g.H) / math.tan(g.alpha1)
    inset = np.arcsin(np.clip(g.R * math.sin(g.alpha2) / rho, -1.0, 1.0)) - g.alpha2
    phi = (2 * k - 2) * math.pi / 3
    dth = np.mod(np.arctan2(X[:, 1], X[:, 0]) - phi + math.pi, 2 * math.pi) - math.pi
    return s, (dth - inset) / (math.pi / 3 - 2 * inset), zeta


def _over(g, frac, zeta, tol=1e-9):
    return (frac >= -tol) & (frac <= 1 + tol) & (zeta >= -tol) & (zeta <= g.H + tol)


class _Watch:
    """One feature against the three petals, one sub-step at a time."""

    def __init__(self, solids, edges, graze):
        self.solids, self.edges, self.graze = solids, edges, graze
        self.X = self.s = self.crossed = None

    def step(self, g, X, s):
        X_now, s_now = X, s
        if self.s is None:
            self.crossed = np.zeros((3, len(s)), dtype=bool)
        else:
            flip = np.flatnonzero(np.sign(s) * np.sign(self.s) < 0)
            for k in (1, 2, 3) if len(flip) else ():
                w = self.s[flip] / (self.s[flip] - s[flip])
                (_, f0, z0), (_, f1, z1) = (_places(g, Y[flip], k) for Y in (self.X, X))
                on = _over(g, f0 + w * (f1 - f0), z0 + w * (z1 - z0))
                idx = flip[on]
                if len(idx) and self.graze > 0.0:
                    a = pen.foot_on_cone(g, self.X[idx], self.s[idx])
                    at = a + w[on][:, None] * (pen.foot_on_cone(g, X[idx], s[idx]) - a)
                    idx = idx[pen.distance_to_polyline(at, self.edges[k]) > self.graze]
                self.crossed[k - 1, idx] = ~self.crossed[k - 1, idx]
            on = s == 0.0
            if on.any():
                X, s = np.where(on[:, None], self.X, X), np.where(on, self.s, s)
        self.X, self.s = X, s
        for k in np.flatnonzero(self.crossed.any(axis=1)) + 1:
            held = np.flatnonzero(self.crossed[k - 1])
            _, frac, zeta = _places(g, X[held], k)
            inside = held[_over(g, frac, zeta)]
            off = pen.distance_to_polyline(
                pen.foot_on_cone(g, X_now[inside], s_now[inside]), self.edges[k])
            depth = np.zeros(len(s))
            depth[inside] = np.minimum(np.abs(s_now[inside]), off)
            yield self.solids[k - 1], depth


def _plain(g, t, R_WA, p_WA, names, *, ring_depth=0.04, max_travel=1e-3, features=None,
           graze=1e-6):
    """`deepest_penetration` one sub-step at a time, every row of every feature."""
    feats = pen.feature_points(g) if features is None else features
    reach = max(float(np.linalg.norm(X, axis=1).max()) for X in feats.values())
    best = pen.Penetration()
    on_petals = {f: ~pen.annulus_rim(g, X) for f, X in feats.items()}
    edges = pen.free_edges(g)
    for a, b in ((0, 1), (1, 0)):
        R, p = pen.relative_poses(R_WA, p_WA, a, b)
        watches = {f: _Watch(tuple(f"{names[b]} petal {k}" for k in (1, 2, 3)), edges, graze)
                   for f in feats if f.startswith(pen.PETAL_FEATURES)}
        for tt, Rab, pab in pen.sub_steps(t, R, p, reach, max_travel):
            for fname, X in feats.items():
                Y = X @ Rab.T + pab
                found = []
                if fname in watches:
                    Yp = Y[on_petals[fname]]
                    found = list(watches[fname].step(g, Yp, _places(g, Yp, 1)[0]))
                if fname.startswith(pen.RING_FEATURES):
                    found.append((f"{names[b]} ring", pen.ring_depth_of(g, Y, ring_depth)))
                for solid, depth in found:
                    d = float(depth.max()) if len(depth) else 0.0
                    if d > best.depth:
                        best = pen.Penetration(d, float(tt), f"{names[a]} {fname}", solid)
    return best


def _same(g, *args, **kwargs):
    """The check, with and without ``sparse`` (the rows to step found first), equals the
    plain loop."""
    want = _plain(g, *args, **kwargs)
    for sparse in (False, True):
        got = pen.deepest_penetration(g, *args, sparse=sparse, **kwargs)
        assert dataclasses.astuple(got) == dataclasses.astuple(want), sparse
    return got


def _approach(roll_deg, tilt, offset, heights, spin=0.0):
    """Samples of the chaser's APDS coming down the target's axis (`Approach`): ring-face
    heights ``heights``, turned by roll about the axis and tilted about x, offset sideways,
    spinning ``spin`` rad about the target's axis from sample to sample."""
    a = Approach(math.radians(roll_deg), (tilt, 0.0), (offset, 0.0))
    n = len(heights)
    R, p = np.empty((n, 2, 3, 3)), np.zeros((n, 2, 3))
    R[:, 0] = np.eye(3)
    for i, h in enumerate(heights):
        Rc, p[i, 1] = a.pose(h)
        R[i, 1] = rot_vec(np.array([0.0, 0.0, i * spin])) @ Rc
    return np.linspace(0.0, 1.0, n), R, p


def _moved(heights, lateral=None, turn=None):
    """Samples of APDS 0 moved along its axis (and sideways, and turned about it)."""
    n = len(heights)
    R, p = np.tile(np.eye(3), (n, 2, 1, 1)), np.zeros((n, 2, 3))
    p[:, 0, 2] = heights
    if lateral is not None:
        p[:, 0, 0] = lateral
    for i, a in enumerate(turn or ()):
        R[i, 0] = rot_vec(np.array([0.0, 0.0, a]))
    return np.arange(n, dtype=float), R, p


def test_an_approach_through_the_petals(geom):
    heights = np.linspace(1.2 * geom.H, 0.5 * geom.H, 4)
    found = _same(geom, *_approach(7.0, 0.0, 0.0, heights), NAMES, graze=1e-6)
    assert found.depth > 1e-3                            # the path does cross a petal


def test_a_slanted_approach_through_the_petals(geom):
    """A translation down and sideways: with ``sparse`` only the points whose path can cross
    a petal are watched (`cone_reach`), most of them are not, and the result is the same."""
    t, R, p = _approach(3.0, 0.02, 0.03, [0.5 * geom.H, 0.3 * geom.H, 0.2 * geom.H])
    p[:, 1, :2] += np.array([[0.0, 0.0], [-0.012, 0.005], [-0.02, 0.008]])
    X = np.concatenate([v for k, v in pen.feature_points(geom).items()
                        if k.startswith(pen.PETAL_FEATURES)])
    kept = cone_reach.watched_on_translation(geom, X @ R[0, 1].T, p[:, 1], 1e-3)   # chaser's
    assert 0 < kept.sum() < 0.5 * len(X)
    assert _same(geom, t, R, p, NAMES, graze=1e-6).depth > 1e-3


def test_a_point_moved_sideways_then_down_through_a_petal(geom):
    """Two segments of a translation in different directions (sideways along x, then down):
    each is tested for the cone on its own, and the crossing of the second is kept."""
    th, z = math.radians(30.0), 0.1
    r = geom.R - z / math.tan(geom.alpha1) + 2e-3 / math.sin(geom.alpha1)
    P = np.array([[r * math.cos(th), r * math.sin(th), z]])
    found = _same(geom, *_moved([0.0, 0.0, -0.01], [0.0, 0.004, 0.004]), NAMES,
                  features={"guide side 1": P})
    assert found.depth > 2e-3


def test_a_crossing_above_the_tip_height_reached_within_a_long_sub_step(geom):
    """Sub-steps of 6.65 mm: a point crosses the cone 5 um above the tip height on its path,
    and the crossing interpolated between the two sub-steps around it lies over the plate,
    65 um deep: the points watched on a translation are those whose path meets the cone
    within 2 max_travel of the petals' heights."""
    th, z = math.radians(30.0), geom.H + 5e-6
    r = geom.R - z / math.tan(geom.alpha1)
    P0 = np.array([r * math.cos(th), r * math.sin(th), z])
    D = 6.65e-3 * np.array([-math.sin(th), math.cos(th), 0.0]) + np.array([0.0, 0.0, -1.7e-4])
    t, R, p = np.array([0.0, 1.0]), np.tile(np.eye(3), (2, 2, 1, 1)), np.zeros((2, 2, 3))
    p[1, 1] = -D
    found = _same(geom, t, R, p, NAMES, features={"guide side 1": (P0 - 0.3 * D)[None]},
                  max_travel=7e-3, graze=0.0)
    assert found.depth > 5e-5


def test_an_approach_through_the_rings(geom):
    found = _same(geom, *_approach(30.0, 0.03, 0.02, np.linspace(0.06, -0.03, 3), 0.02),
                  NAMES, graze=0.0)
    assert found.depth > 1e-2


def _on_the_cone(g):
    """A point with a cone distance of exactly 0.0 (`cone_distance`)."""
    a = (math.hypot(0.4, 0.3) - g.R) * math.sin(g.alpha1)
    z = -a / math.cos(g.alpha1)
    while a + z * math.cos(g.alpha1) != 0.0:
        z = np.nextafter(z, np.inf if a + z * math.cos(g.alpha1) < 0 else -np.inf)
    P = np.array([[0.4, 0.3, float(z)]])
    assert pen.cone_distance(g, P)[0] == 0.0
    return P


@pytest.mark.parametrize("m", [62, 63, 64])
def test_a_point_stopping_on_the_cone_at_a_blocks_edge(geom, m):
    """The point reaches the cone exactly at sub-step m (a block holds 64), stays there, and
    goes on through the petal."""
    P = _on_the_cone(geom)
    side = pen.feature_points(geom)["guide side 3"][5:8]
    top = m * 1e-3 * 0.999
    for heights in ([top, 0.0, -top], [top, 0.0, 0.0, 0.0, -top]):
        for feats in ({"guide side 1": P}, {"guide side 1": np.vstack([P, side])},
                      {"ring inside circle": P, "ring face": np.vstack([P, side])}):
            for graze in (0.0, 1e-6):
                _same(geom, *_moved(heights), NAMES, features=feats, graze=graze)
    assert _same(geom, *_moved([top, 0.0, -top]), NAMES, features={"guide side 1": P},
                 graze=0.0).depth > 0.0


def test_ring_depths_that_tie_and_that_are_shallow(geom):
    ring = {k: v for k, v in pen.feature_points(geom).items() if k.startswith("ring")}
    tie = _same(geom, *_moved([-0.01] * 3, [0.0, 0.15, 0.3]), NAMES, features=ring)
    assert tie.depth == pytest.approx(0.01, abs=1e-12)
    assert _same(geom, *_moved([-1e-7] * 2, [0.0, 0.01]), NAMES, features=ring).depth > 0.0


@pytest.mark.parametrize("quiet", [1, 5, 63])
def test_a_point_turned_into_a_gap_then_dropped_through_the_cone(geom, quiet):
    """Over the petal, turned 45 deg into the gap between petals and held there for ``quiet``
    rows that change nothing, then dropped through the cone and turned back: it never
    crosses a plate."""
    th = math.radians(30.0)
    X = np.array([[0.5 * math.cos(th), 0.5 * math.sin(th), 0.11]])
    turn = [0.0] + [math.radians(45.0)] * (quiet + 1) + [0.0]
    heights = [0.0] * (quiet + 1) + [-0.02, -0.02]
    found = _same(geom, *_moved(heights, turn=turn), NAMES, features={"guide side x": X},
                  max_travel=10.0)
    assert found.depth == 0.0


def test_polyline_distance_equals_the_brute_force(geom):
    rng = np.random.default_rng(11)
    for P in pen.free_edges(geom).values():
        line = pen.Polyline(P)
        near = P[rng.integers(0, len(P), 400)] + rng.normal(scale=1e-3, size=(400, 3))
        far = rng.normal(scale=0.5, size=(200, 3))
        on = P[rng.integers(0, len(P), 50)]                 # on vertices, junctions among them
        ends = P[[0, len(P) - 1, len(P) // 4, len(P) // 2]]
        mid = 0.5 * (P[:-1] + P[1:])[rng.integers(0, len(P) - 1, 50)]     # equal distances
        F = np.concatenate([near, far, on, ends, mid])
        assert np.array_equal(line.distance(F), pen.distance_to_polyline(F, P))


@pytest.mark.parametrize("z", [5e-4, -5e-4])
def test_a_point_crossing_the_cone_next_to_the_tip_height(geom, z):
    """A point over petal 1 pushed sideways through the cone 0.5 mm below the petal's tip
    height, where it crosses the plate, and 0.5 mm above it, where it passes over the tip."""
    th, zp = math.radians(30.0), geom.H - z
    r = geom.R - zp / math.tan(geom.alpha1) + 2e-3
    P = np.array([[r * math.cos(th), r * math.sin(th), zp]])
    found = _same(geom, *_moved([0.0] * 3, [0.0, 0.002, 0.004]), NAMES,
                  features={"guide side 1": P})
    assert (found.depth > 1e-4) == (z > 0)


@pytest.mark.parametrize("quiet", [0, 63])
def test_a_crossing_just_inside_a_side_edge_turned_into_the_gap(geom, quiet):
    """A point 0.5 mm off petal 1, 3 deg inside guide side 1, held for ``quiet`` rows, then
    in one sub-step turned 7 deg into the gap while it drops 4 mm, and turned back: it crosses
    the cone over the plate near the start of that sub-step (the crossing, interpolated from
    the sub-step's two places, lies over the petal, the end does not)."""
    z = 0.1
    th = float(pen._inset(geom, np.array([z]))[0]) + math.radians(3.0)
    r = geom.R - z / math.tan(geom.alpha1) + 0.5e-3 / math.sin(geom.alpha1)
    X = np.array([[r * math.cos(th), r * math.sin(th), z]])
    turn = [0.0] * (quiet + 1) + [math.radians(-7.0), 0.0]
    heights = [0.0] * (quiet + 1) + [-0.004, -0.004]
    found = _same(geom, *_moved(heights, turn=turn), NAMES, features={"guide side 1": X},
                  max_travel=10.0)
    assert found.depth > 1e-3


def test_a_crossing_at_the_tip_height_within_the_plates_tolerance(geom):
    """A point pushed through the cone 5e-10 m above the tip height (over the plate by its
    1e-9 tolerance, `_over`), then lowered 5 mm."""
    th, z = math.radians(30.0), geom.H + 5e-10
    r = geom.R - z / math.tan(geom.alpha1) + 1e-3
    X = np.array([[r * math.cos(th), r * math.sin(th), z]])
    found = _same(geom, *_moved([0.0, 0.0, -0.005], [0.0, -0.004, -0.004]), NAMES,
                  features={"guide side 1": X}, graze=0.0)
    assert found.depth > 1e-3
