"""The paper's initial configuration (Sect. 8.2): first contact after the declared travel,
checked with an independent distance computation (scipy minimisation on the patches, not the
project's hierarchical seeking)."""
import math

import numpy as np
import pytest
from scipy.optimize import brentq

from closest_reference import brute_force_closest, random_starts, scipy_closest
from drake_dock.core.patches import posed
from drake_dock.core.seeking import seek_couple
from drake_dock.docking.geometry.rotations import rot_x, rot_z
from drake_dock.docking.geometry.scene import DockingScene
from drake_dock.docking.model.plant import PlantSpec, add_docking_plant, set_initial_state
from drake_dock.docking.placement.place import place
from pydrake.systems.framework import DiagramBuilder


@pytest.fixture(scope="module")
def paper_setup(paper_scenario):
    state = place(paper_scenario)
    builder = DiagramBuilder()
    dp = add_docking_plant(builder, PlantSpec.of(paper_scenario))
    diagram = builder.Build()
    ctx = diagram.CreateDefaultContext()
    pc = dp.plant.GetMyContextFromRoot(ctx)
    set_initial_state(dp, pc, state)
    poses = {}
    for name, frame in dp.apds_frames.items():
        X = frame.CalcPoseInWorld(pc)
        poses[name] = (X.rotation().matrix(), X.translation())
    return state, poses


def test_first_contact_after_declared_travel(paper_scenario, paper_setup):
    state, poses = paper_setup
    travel = paper_scenario.initial.approach_travel
    pairs = {p.name: p for p in DockingScene(paper_scenario.geometry, "paper").pairs}
    axis = poses["target_apds"][0][:, 2]

    def placed(pair, s):
        R2, p2 = poses["chaser_apds"]
        pp = {"target_apds": poses["target_apds"], "chaser_apds": (R2, p2 - s * axis)}
        return posed(pair.patch1, *pp[pair.body1]), posed(pair.patch2, *pp[pair.body2])

    # The three closing pairs: the signed gap (sign fixed at s = 0) crosses zero at s = travel.
    assert len(state.closing_pairs) == 3
    assert all(n.startswith("cc_") for n in state.closing_pairs)
    roots, points = [], []
    for name in state.closing_pairs:
        P1, P2 = placed(pairs[name], 0.0)
        _, _, d0 = scipy_closest(P1, P2, random_starts(P1, P2))
        ref = d0 / np.linalg.norm(d0)

        def gap(s):
            Q1, Q2 = placed(pairs[name], s)
            _, _, d = scipy_closest(Q1, Q2, random_starts(Q1, Q2))
            return np.linalg.norm(d) * (1 if d @ ref >= 0 else -1)

        roots.append(brentq(gap, 0.5 * travel, 1.5 * travel, xtol=1e-10))
        Q1, Q2 = placed(pairs[name], travel)
        u1, _, _ = scipy_closest(Q1, Q2, random_starts(Q1, Q2))
        points.append(Q1.position(u1))
    np.testing.assert_allclose(roots, travel, atol=1e-6)
    # The three couples are images of each other under turns of 120 deg about the axis
    # through the target ring centre (3-fold symmetry).
    c = poses["target_apds"][1]
    rel = [p - c for p in points]
    Rz = poses["target_apds"][0] @ rot_z(2 * math.pi / 3) @ poses["target_apds"][0].T
    images = [Rz @ r for r in rel]
    for im in images:
        assert min(np.linalg.norm(im - r) for r in rel) < 1e-6
    # No pair of the 12 is closed before: at s = travel - 1e-6 every interior distance > 0.
    for name, pair in pairs.items():
        P1, P2 = placed(pair, travel - 1e-6)
        _, _, d = scipy_closest(P1, P2, random_starts(P1, P2, n=8))
        assert np.linalg.norm(d) > 0.0, name


def test_first_contact_distance_matches_coarse_check(paper_setup):
    state, _ = paper_setup
    # docs/model.md: a coarse check puts the first touch at a ring-face distance of ~0.083 m.
    assert state.d_contact == pytest.approx(0.083, abs=1e-3)


@pytest.mark.parametrize("seed", range(6))
def test_seeking_matches_scipy_on_random_poses(geom, seed):
    """Hierarchical grid + Newton finds the same couple as multi-start scipy."""
    rng = np.random.default_rng(seed)
    pairs = DockingScene(geom, "paper").pairs
    yaw, tilt = rng.uniform(-0.5, 0.5), rng.uniform(-0.2, 0.2)
    R = rot_z(yaw) @ rot_x(math.pi + tilt)
    p = np.array([*rng.uniform(-0.1, 0.1, 2), rng.uniform(0.05, 0.35)])
    poses = {"target_apds": (np.eye(3), np.zeros(3)), "chaser_apds": (R, p)}
    for pair in pairs:
        P1, P2 = posed(pair.patch1, *poses[pair.body1]), posed(pair.patch2, *poses[pair.body2])
        cp = seek_couple(P1, P2)
        _, _, d = scipy_closest(P1, P2, random_starts(P1, P2, n=12, seed=seed) + [cp.u])
        assert cp.distance <= np.linalg.norm(d) + 1e-9, pair.name


@pytest.mark.parametrize("seed", range(4))
def test_seeking_matches_brute_force_on_random_poses(geom, seed):
    """Random relative poses, all 12 pairs: the distance of the couple found equals that of
    dense sampling + scipy to 1e-9 m."""
    rng = np.random.default_rng(100 + seed)
    R = rot_z(rng.uniform(-0.6, 0.6)) @ rot_x(math.pi + rng.uniform(-0.3, 0.3))
    p = np.array([*rng.uniform(-0.15, 0.15, 2), rng.uniform(0.05, 0.3)])
    poses = {"target_apds": (np.eye(3), np.zeros(3)), "chaser_apds": (R, p)}
    for pair in DockingScene(geom, "paper").pairs:
        P1, P2 = posed(pair.patch1, *poses[pair.body1]), posed(pair.patch2, *poses[pair.body2])
        cp = seek_couple(P1, P2)
        _, _, d = brute_force_closest(P1, P2)
        assert abs(cp.distance - np.linalg.norm(d)) < 1e-9, pair.name


@pytest.mark.parametrize("kind", ["CS", "CC"])
def test_seeking_matches_brute_force_points(geom, kind):
    """Interior couples at a positive gap (the scenes of test_couple, random instants): the
    same couple as dense sampling + scipy, both points within 1e-9 m."""
    from couple_scenes import cc_scene, cs_scene
    _, c1, m1, c2, m2 = cs_scene(geom) if kind == "CS" else cc_scene(geom)
    for t in np.random.default_rng(7).uniform(0.0, 1.0, 4):
        P1, P2 = posed(c1, *m1.pose(t)), posed(c2, *m2.pose(t))
        cp = seek_couple(P1, P2)
        assert cp.interior and cp.distance > 1e-3
        u1, u2, _ = brute_force_closest(P1, P2)
        np.testing.assert_allclose(cp.p1, P1.position(u1), atol=1e-9)
        np.testing.assert_allclose(cp.p2, P2.position(u2), atol=1e-9)


@pytest.mark.parametrize("seed", range(4))
def test_far_pair_distance_mode_matches_brute_force(geom, seed):
    """The contact system's seeks of far pairs (`seek_couple` with ``distance_rtol``: the
    Newton finish stops once the distance has converged): never below the true distance, above
    it by at most 1e-4 of it, and exact to 1e-9 m for pairs nearer than ``rtol_beyond``."""
    rng = np.random.default_rng(200 + seed)
    R = rot_z(rng.uniform(-0.6, 0.6)) @ rot_x(math.pi + rng.uniform(-0.3, 0.3))
    p = np.array([*rng.uniform(-0.15, 0.15, 2), rng.uniform(0.01, 0.3)])
    poses = {"target_apds": (np.eye(3), np.zeros(3)), "chaser_apds": (R, p)}
    beyond = 0.02
    for pair in DockingScene(geom, "paper").pairs:
        P1, P2 = posed(pair.patch1, *poses[pair.body1]), posed(pair.patch2, *poses[pair.body2])
        cp = seek_couple(P1, P2, distance_rtol=1e-7, rtol_beyond=beyond)
        d = np.linalg.norm(brute_force_closest(P1, P2)[2])
        assert cp.distance >= d - 1e-9, pair.name
        assert cp.distance <= d * (1 + 1e-4) + 1e-9, pair.name
        if d < beyond:
            assert cp.distance == pytest.approx(d, abs=1e-9), pair.name
