"""The point-curve pairs (kind "PC") in the contact system: the side witness and the re-seek
of a couple on the curve's convex side (docs/model.md, "The petal corner")."""
import math

import numpy as np
import pytest

from drake_dock.core.couple import evaluate_couple
from drake_dock.core.patches import Circle, Point

R_C = 0.4


def test_side_witness_is_armed_and_reseeks():
    """The contact system arms the side witness of a point-curve pair that is not far, and
    seeks its couple again once the point has reached the curve's convex side
    (`transitions._reseek`), the value `point_curve_side` in closed form changing sign."""
    from drake_dock.core.hybrid import Mode
    from drake_dock.systems.contact_types import ContactPair, PairState
    from drake_dock.systems.transitions import _reseek
    from drake_dock.systems.witnesses import armed
    states = [PairState(Mode.TRACKED), PairState(Mode.FAR), PairState(Mode.SLIDING)]
    got = armed(states, (), {0, 1, 2})
    assert (0, "side") in got and (2, "side") in got and (1, "side") not in got
    assert all(kind != "side" for _, kind in armed(states))
    ring, X = Circle(R_C), (np.eye(3), np.zeros(3))
    pair = ContactPair("pc", "PC", None, Point((0.0, 0.0, 0.0)), None, ring)
    for rho, due in ((R_C - 0.01, False), (R_C + 0.01, True)):
        point = Point((rho * math.cos(0.3), rho * math.sin(0.3), 0.02))
        ev = evaluate_couple("PC", point, X, (np.zeros(3),) * 2, ring, X, (np.zeros(3),) * 2,
                             [0.3], 1.0)
        assert _reseek(pair, ev, np.array([np.inf]), X[0], 1e-6) == due


def corner_in_ring(overlap, radius=1e-3, sigma=None):
    """A free body whose origin is a corner sphere of ``radius`` (kind "PC") against the fixed
    circle of radius R_C in z = 0 (no gravity), placed at rest in the circle's plane inside
    the passage (the concave side) with |d| = radius - overlap: the gap is -overlap. Returns
    the initialized `SmallRun`."""
    from pydrake.math import RigidTransform
    from pydrake.multibody.tree import RotationalInertia, SpatialInertia
    from drake_dock.studies.small_scenes import SmallRun, SmallScene, _plant
    from drake_dock.systems.contact_system import ContactLaw, ContactPair, RigidContactSystem
    plant = _plant([0.0, 0.0, 0.0])
    body = plant.AddRigidBody("corner", SpatialInertia.MakeFromCentralInertia(
        1.0, np.zeros(3), RotationalInertia(1e-3, 1e-3, 1e-3)))
    plant.Finalize()
    pair = ContactPair("pc", "PC", body.body_frame(), Point((0.0, 0.0, 0.0), radius),
                       plant.world_frame(), Circle(R_C), sigma=sigma)
    sc = SmallScene(plant, RigidContactSystem(plant, [pair], ContactLaw(mu=0.3)), body, {})
    rho = R_C - (radius - overlap)
    X = (np.eye(3), np.array([rho * math.cos(0.3), rho * math.sin(0.3), 0.0]))
    return SmallRun(sc.system, lambda root: sc.set_state(root, X, (np.zeros(3),) * 2))


def test_point_curve_seek_at_an_overlap_keeps_n_along_d():
    """A corner sphere seeked overlapping the circle by 1-4 nm (less than half
    ``impact_gap_tol`` = 10 nm, the crossing rule |g| > d + impact_gap_tol with the seek's
    signed distance d = g) is tracked, at rest in contact, with sigma = +1 and its gap is the
    overlap, |d| - r, not -|d| - r (about -2 r, a couple whose normal points into the ring); at
    6 nm it is a crossing and stays far."""
    from drake_dock.core.hybrid import Mode
    for overlap in (1e-9, 4e-9):
        run = corner_in_ring(overlap)
        c = run.couple("pc")
        assert c["status"] != Mode.FAR       # tracked (at rest on it: in contact)
        assert run.system.get_modes(run.ctx).pairs[0].sigma == 1.0
        np.testing.assert_allclose(c["gap"], -overlap, rtol=1e-4)
    assert corner_in_ring(6e-9).couple("pc")["status"] == Mode.FAR


def test_point_curve_pair_refuses_a_declared_sigma_of_minus_one():
    from drake_dock.errors import InputError
    with pytest.raises(InputError, match=r"pairs\[pc\]\.sigma = -1\.0 .*None or \+1"):
        corner_in_ring(0.0, sigma=-1.0)
