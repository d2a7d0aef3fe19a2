"""The bounding-sphere covers (`drake_dock.core.covers`, compiled in
`drake_dock.core.kernels.cover`): every sampled point of a cell lies in its sphere and its slab,
every cell in its block's sphere; the compiled covers equal those of the Python patches (which
cover a patch no kernel describes, a point); without slabs the touched steps equal a brute
force over every sphere pair and step (the exact least distance of a sphere pair over a step),
with them they lie among those and include the steps where the pointwise bound (spheres and
slabs) reaches 0 at sampled travels; the least gap is the least sphere-pair gap; and the
covers' distance bound lies below the seek's distance."""
import dataclasses
import math

import numpy as np
import pytest

from drake_dock.core import covers
from drake_dock.core.kernels import cover as compiled
from drake_dock.core.patches import Circle, Cone, PlaneRect, Point, Segment, posed
from drake_dock.core.seeking import seek_couple
from drake_dock.docking.geometry.pairs import CHASER_APDS
from drake_dock.docking.geometry.scene import DockingScene
from drake_dock.docking.placement.search import Approach
from drake_dock.docking.placement.search import COVER_CELLS, pair_touch_steps, travel_grid
from drake_dock.docking.scenario.dimensions import ApdsGeometry


def _patches():
    pairs = DockingScene(ApdsGeometry(), "paper").pairs
    apds = {id(p): p for pr in pairs for p in (pr.patch1, pr.patch2)}
    return list(apds.values()) + [Circle(0.3, 0.1), Cone(0.6, 0.8, (0.1, 1.2), (0.0, 0.2)),
                                  PlaneRect((-1, -1, 0), (2, 0, 0), (0, 2, 0)),
                                  Segment((0, 0, 0), (1, 2, 3))]


@pytest.mark.parametrize("patch", _patches(), ids=lambda p: type(p).__name__)
def test_cells_enclose_the_patch(patch):
    n, block = COVER_CELLS[patch.dim]
    ref = covers.patch_cover(patch, n, block)
    got = compiled.patch_cover(patch, n, block)
    np.testing.assert_allclose(got.centres, ref.centres, rtol=0, atol=1e-12)
    np.testing.assert_allclose(got.radii, ref.radii, rtol=1e-12, atol=1e-15)
    np.testing.assert_allclose(got.normals, ref.normals, rtol=0, atol=1e-12)
    np.testing.assert_allclose(got.flat, ref.flat, rtol=1e-12, atol=1e-15)
    assert np.isinf(ref.flat).all() == (patch.dim == 1)
    U, half, blocks = covers.block_layout(patch, n, block)
    rng = np.random.default_rng(0)
    for i in range(20):                      # points all over every cell, corners first
        t = rng.choice([-1.0, 1.0], U.shape) if i < 4 else rng.uniform(-1, 1, U.shape)
        x = patch.position(U + t * half)
        assert np.all(np.linalg.norm(x - ref.centres, axis=1) <= ref.radii)
        off_plane = np.abs(np.einsum("nk,nk->n", x - ref.centres, ref.normals))
        assert np.all((off_plane <= ref.flat) | np.isinf(ref.flat))
    inside = (np.linalg.norm(ref.centres[blocks] - ref.block_centres[:, None], axis=-1)
              + ref.radii[blocks])
    assert np.all(inside <= ref.block_radii[:, None] * (1 + 1e-15))



def test_a_patch_without_kernel_description_has_the_python_cover():
    point = Point((0.1, 0.2, 0.3), 0.01)
    assert compiled.patch_cover(point, 1, 1) is covers.patch_cover(point, 1, 1)

def _posed_covers(pr, approach):
    R, p0 = approach.pose(0.0)
    c1, c2 = (compiled.patch_cover(p, *COVER_CELLS[p.dim]) for p in (pr.patch1, pr.patch2))
    moving, fixed = (c1, c2) if pr.body1 == CHASER_APDS else (c2, c1)
    return moving.posed(R, p0), fixed, -(approach.pose(1.0)[1] - p0)


APPROACHES = [Approach(math.radians(5.0)),
              Approach(0.05, (0.04, -0.03), (0.06, 0.02), (0.3, -0.2, -0.932737905308882))]


def _spheres_only(cover):
    return dataclasses.replace(cover, flat=np.full_like(cover.flat, np.inf))


def _brute_force_steps(moving, fixed, e, grid):
    """The steps of the decreasing grid in which some sphere pair of the posed covers touches:
    its least distance over the step is |w - lam* e| - r at the clamped projection lam* of
    w = c1 - c2 on e (the block spheres left out: every cell pair)."""
    w = (moving.centres[:, None, :] - fixed.centres[None, :, :]).reshape(-1, 3)
    r = (moving.radii[:, None] + fixed.radii[None, :]).ravel()
    out = np.zeros(len(grid) - 1, dtype=bool)
    for k in range(len(grid) - 1):
        lam = np.clip((w @ e) / (e @ e), grid[k + 1], grid[k])
        out[k] = (np.linalg.norm(w - lam[:, None] * e, axis=-1) - r <= 1e-9).any()
    return out


@pytest.mark.parametrize("approach", APPROACHES)
def test_touch_steps_of_every_pair_lie_within_its_spheres_brute_force(approach):
    """The touched steps of every pair of the paper's set (`pair_touch_steps`, the search's):
    with the spheres only they are the brute force's (`_brute_force_steps`); the slabs only
    take steps away, each where the pointwise bound of spheres and slabs is positive at both
    ends and the middle of the step."""
    g = ApdsGeometry()
    pairs = DockingScene(g, "paper").pairs
    grid = np.array(travel_grid(g, approach))
    got = pair_touch_steps(pairs, approach, grid)
    for j, pr in enumerate(pairs):
        moving, fixed, e = _posed_covers(pr, approach)
        brute = _brute_force_steps(moving, fixed, e, grid)
        spheres = compiled.touch_steps(_spheres_only(moving), _spheres_only(fixed), e, grid)
        np.testing.assert_array_equal(spheres, brute, pr.name)
        assert not (got[j] & ~brute).any(), pr.name
        for k in np.flatnonzero(brute & ~got[j]):
            for lam in (grid[k + 1], 0.5 * (grid[k] + grid[k + 1]), grid[k]):
                assert _least_bound(moving, fixed, -lam * e) > 0.0, (pr.name, k, lam)


def _least_bound(moving, fixed, shift):
    """min over cell pairs of the larger of their sphere and slab bounds on the distance, the
    moving cover's centres shifted by ``shift``."""
    w = (moving.centres + shift)[:, None] - fixed.centres[None]
    rm, rf = moving.radii[:, None], fixed.radii[None]
    bound = np.linalg.norm(w, axis=-1) - rm - rf
    bound = np.maximum(bound, np.abs(np.einsum("ijk,jk->ij", w, fixed.normals)) - rm
                       - fixed.flat[None])
    bound = np.maximum(bound, np.abs(np.einsum("ijk,ik->ij", w, moving.normals)) - rf
                       - moving.flat[:, None])
    return bound.min()


@pytest.mark.parametrize("name", ["cc_T2_C4", "cs_Cring_T1", "cs_Tring_C2"])
def test_touch_steps_equal_a_brute_force(name):
    """Spheres only, a step is touched iff some sphere pair's least distance over the step is
    <= 0: that distance is |w - lam* e| - r at the clamped projection lam* of w on e. With the
    slabs, the touched steps are among those and include every step where the pointwise bound
    of spheres and slabs is <= 0 at one of 17 travels spread over the step."""
    g = ApdsGeometry()
    approach = APPROACHES[0]
    pr = next(p for p in DockingScene(g, "paper").pairs if p.name == name)
    moving, fixed, e = _posed_covers(pr, approach)
    grid = np.array(travel_grid(g, approach))
    brute = _brute_force_steps(moving, fixed, e, grid)
    spheres = compiled.touch_steps(_spheres_only(moving), _spheres_only(fixed), e, grid)
    np.testing.assert_array_equal(spheres, brute)
    got = compiled.touch_steps(moving, fixed, e, grid)
    assert not (got & ~spheres).any()
    for k in np.flatnonzero(spheres & ~got):
        for lam in np.linspace(grid[k + 1], grid[k], 17):
            assert _least_bound(moving, fixed, -lam * e) > 0.0, (k, lam)
    if name.startswith("cs"):
        assert (spheres & ~got).any()      # the ring just inside the petal's cone


def test_bound_lies_below_the_seek_distance():
    """At every grid point of the paper's approach: the covers' least distance (min over cell
    pairs of the larger of |c1 - c2| - r1 - r2 and each slab's |n . (c1 - c2)| - r - kappa)
    <= the seek's distance of every pair, and > 0 at both ends of every step that is
    not touched."""
    g = ApdsGeometry()
    approach = APPROACHES[0]
    pairs = DockingScene(g, "paper").pairs
    grid = np.array(travel_grid(g, approach))[::3]
    touched = pair_touch_steps(pairs, approach, grid)
    for j, pr in enumerate(pairs):
        moving, fixed, e = _posed_covers(pr, approach)
        for k, lam in enumerate(grid):
            bound = _least_bound(moving, fixed, -lam * e)
            R, p = approach.pose(lam)
            poses = {CHASER_APDS: (R, p), "target_apds": (np.eye(3), np.zeros(3))}
            cp = seek_couple(posed(pr.patch1, *poses[pr.body1]),
                             posed(pr.patch2, *poses[pr.body2]))
            assert bound <= cp.distance + 1e-12, (pr.name, lam)
            near = touched[j, max(k - 1, 0):k + 1]
            if not near.any():
                assert bound > 0.0, (pr.name, lam)


def test_cover_gap_is_the_least_sphere_gap_and_lies_below_the_seek():
    """`cover_gap` (block-pruned, compiled) equals the least |c1 - c2| - (rho1 + rho2) over
    every cell sphere pair (numpy, here) to 1e-12 (given a threshold, a cell gap below it where
    the least gap is), and lies below the seek's distance, for the complete set's pairs at
    random
    relative poses of the two APDS (tilt up to 10 deg, offset up to 0.15 m, ring distance -0.2
    to 0.5 m)."""
    from drake_dock.docking.geometry.pairs import R_MATCHED
    from drake_dock.docking.geometry.rotations import rot_vec, rot_z
    g = ApdsGeometry()
    rng = np.random.default_rng(11)
    pairs = DockingScene(g, "complete").pairs
    for trial in range(6):
        R = rot_vec((*rng.uniform(-0.17, 0.17, 2), 0.0)) @ rot_z(rng.uniform(-1, 1)) @ R_MATCHED
        X = {CHASER_APDS: (R, np.array([*rng.uniform(-0.1, 0.1, 2), rng.uniform(-0.2, 0.5)])),
             "target_apds": (np.eye(3), np.zeros(3))}
        for pr in pairs[trial::6]:
            c1, c2 = (compiled.patch_cover(p, *COVER_CELLS[p.dim]) for p in (pr.patch1, pr.patch2))
            a, b = c1.posed(*X[pr.body1]), c2.posed(*X[pr.body2])
            got = compiled.cover_gap(a, b)
            ref = (np.linalg.norm(a.centres[:, None] - b.centres[None], axis=-1)
                   - a.radii[:, None] - b.radii[None]).min()
            assert got == pytest.approx(ref, rel=0, abs=1e-12), pr.name
            # With a threshold: a gap below it when the least gap is, else the least gap.
            for below in (ref - 0.01, ref + 1e-6, ref + 0.05):
                early = compiled.cover_gap(a, b, below)
                if ref < below:
                    assert ref - 1e-12 <= early < below, (pr.name, below)
                else:
                    assert early == got, (pr.name, below)
            P1, P2 = posed(pr.patch1, *X[pr.body1]), posed(pr.patch2, *X[pr.body2])
            cp = seek_couple(P1, P2)
            assert got <= cp.distance + 1e-12, pr.name
