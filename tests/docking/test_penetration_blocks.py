"""The interpenetration check's shortcuts against its plain form. `Polyline.distance` (a k-d
tree) against the brute-force `distance_to_polyline`; `deepest_penetration` (sub-steps in
blocks, rows where nothing changes side passed over, the ring's solid checked only in rows
that reach below its face) against a loop over every sub-step, feature and petal written
here. Both exactly, on paths that cross petals and graze their edges."""
import dataclasses
import math

import numpy as np
import pytest

from drake_dock.docking import penetration as pen
from drake_dock.docking.rotations import rot_vec
from drake_dock.docking.scene import Approach

NAMES = ("target_apds", "chaser_apds")


def _plain(g, t, R_WA, p_WA, names, *, ring_depth=0.04, max_travel=1e-3, graze=1e-6):
    """`deepest_penetration` one sub-step at a time, every row of every feature."""
    feats = pen.feature_points(g)
    reach = max(float(np.linalg.norm(X, axis=1).max()) for X in feats.values())
    best = pen.Penetration()
    on_petals = {f: ~pen.annulus_rim(g, X) for f, X in feats.items()}
    for a, b in ((0, 1), (1, 0)):
        R, p = pen.relative_poses(R_WA, p_WA, a, b)
        watches = {f: pen._PetalWatch(tuple(f"{names[b]} petal {k}" for k in (1, 2, 3)),
                                      pen.edge_polylines(g), graze)
                   for f in feats if f.startswith(pen.PETAL_FEATURES)}
        for tt, Rab, pab in pen.sub_steps(t, R, p, reach, max_travel):
            for fname, X in feats.items():
                Y = X @ Rab.T + pab
                found = []
                if fname in watches:
                    Yp = Y[on_petals[fname]]
                    found = list(watches[fname].step(g, Yp, pen.cone_distance(g, Yp)))
                if fname.startswith(pen.RING_FEATURES):
                    found.append((f"{names[b]} ring", pen.ring_depth_of(g, Y, ring_depth)))
                for solid, depth in found:
                    d = float(depth.max()) if len(depth) else 0.0
                    if d > best.depth:
                        best = pen.Penetration(d, float(tt), f"{names[a]} {fname}", solid)
    return best


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


PATHS = [(7.0, 0.0, 0.0, 0.0), (30.0, 0.03, 0.02, 0.0), (-12.0, 0.05, -0.03, 0.02),
         (60.0, 0.0, 0.0, 0.0)]


@pytest.mark.parametrize("roll,tilt,offset,spin", PATHS)
@pytest.mark.parametrize("graze", [0.0, 1e-6])
def test_blocks_equal_the_plain_loop(geom, roll, tilt, offset, spin, graze):
    heights = np.linspace(1.2 * geom.H, 0.5 * geom.H, 4)
    t, R, p = _approach(roll, tilt, offset, heights, spin)
    got = pen.deepest_penetration(geom, t, R, p, NAMES, graze=graze)
    want = _plain(geom, t, R, p, NAMES, graze=graze)
    assert dataclasses.astuple(got) == dataclasses.astuple(want)


def test_the_paths_cross(geom):
    """The paths above are not clear: each crosses a petal by centimetres at some graze."""
    heights = np.linspace(1.2 * geom.H, 0.5 * geom.H, 4)
    for path in PATHS:
        assert pen.deepest_penetration(geom, *_approach(*path[:3], heights, path[3]), NAMES,
                                       graze=0.0).depth > 1e-2


def test_polyline_distance_equals_the_brute_force(geom):
    rng = np.random.default_rng(11)
    for P in pen.free_edges(geom).values():
        line = pen.Polyline(P)
        near = P[rng.integers(0, len(P), 400)] + rng.normal(scale=1e-3, size=(400, 3))
        far = rng.normal(scale=0.5, size=(200, 3))
        on = P[rng.integers(0, len(P), 50)]                 # on vertices, junctions among them
        ends = P[[0, len(P) - 1, len(P) // 4, len(P) // 2]]
        F = np.concatenate([near, far, on, ends])
        assert np.array_equal(line.distance(F), pen.distance_to_polyline(F, P))
