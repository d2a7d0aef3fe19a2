"""The far pairs' travel bound against the actual displacement of every point of the patch."""
import math

import numpy as np
import pytest

from drake_dock.studies.small_scenes import stool
from drake_dock.core.hybrid import Mode
from drake_dock.systems.contact_system import PairState


def _random_rotation(rng, angle=None):
    q = rng.normal(size=4)
    if angle is not None:
        axis = q[1:] / np.linalg.norm(q[1:])
        q = np.concatenate([[math.cos(angle / 2)], math.sin(angle / 2) * axis])
    w, x, y, z = q / np.linalg.norm(q)
    return np.array([[1 - 2 * (y * y + z * z), 2 * (x * y - z * w), 2 * (x * z + y * w)],
                     [2 * (x * y + z * w), 1 - 2 * (x * x + z * z), 2 * (y * z - x * w)],
                     [2 * (x * z - y * w), 2 * (y * z + x * w), 1 - 2 * (x * x + y * y)]])


def test_far_pair_travel_bound_covers_every_point_of_the_patch():
    """The bound of each far pair (all pairs at once) is at least the largest displacement,
    relative to frame 2, of the points of patch 1 since the reference pose; a pair never
    sought has an infinite bound."""
    system = stool().system
    rng = np.random.default_rng(7)
    k = len(system.pairs)
    for trial in range(20):
        poses0 = [(_random_rotation(rng), rng.normal(size=3)) for _ in system.frames]
        scale = 10.0 ** rng.uniform(-4, 0)
        poses1 = [(_random_rotation(rng, scale * rng.uniform(0, 1)) @ R, p + scale
                   * rng.normal(size=3)) for R, p in poses0]
        states = []
        for i in range(k):
            a, b = system.fidx[i]
            (R1, p1), (R2, p2) = poses0[a], poses0[b]
            states.append(PairState(Mode.FAR, ref_X21=(R2.T @ R1, R2.T @ (p1 - p2))))
        far = system.far
        bounds = far.bounds(list(range(k)), poses1, states)
        for i, pair in enumerate(system.pairs):
            r = pair.patch1.position(pair.patch1.grid(61))
            a, b = system.fidx[i]
            moved = []
            for poses in (poses0, poses1):
                (R1, p1), (R2, p2) = poses[a], poses[b]
                moved.append((r @ R1.T + p1 - p2) @ R2)      # points in frame 2
            actual = np.linalg.norm(moved[1] - moved[0], axis=1).max()
            assert actual <= bounds[i]
            assert bounds[i] <= 3.0 * actual + 1e-12     # and not vacuous
            assert bounds[i] == pytest.approx(far.bound(i, poses1, states[i]),
                                              rel=1e-14)
    states[1] = PairState(Mode.FAR)
    assert math.isinf(far.bounds([0, 1, 2], poses1, states)[1])


@pytest.mark.parametrize("horizon", [0.0, 0.05, 1.0])
def test_a_far_pair_falls_due_within_the_reseek_horizon_by_its_bounds_rate(horizon):
    """A disk 0.5 m above a plane, sinking at 1 m/s, just sought: its travel bound is 0 and
    grows at the speed of its rim's centre, so it reaches ``reseek_early`` of the clearance c
    after 0.9 c / (1 m/s); the pair is due at this step's start iff that is within the horizon,
    and otherwise the step-end target is that time."""
    from pydrake.systems.analysis import Simulator

    from drake_dock.studies.small_scenes import disk_on_incline
    from drake_dock.systems.contact_system import ContactOptions
    options = ContactOptions(reseek_horizon=horizon)
    sc = disk_on_incline(0.0, options=options)
    sim = Simulator(sc.system)
    ctx = sim.get_mutable_context()
    sc.set_state(ctx, (np.eye(3), np.array([0.0, 0.0, sc.params["radius"] + 0.5])),
                 (np.zeros(3), np.array([0.0, 0.0, -1.0])))
    sim.Initialize()
    state = sc.system.get_modes(ctx).pairs[0]
    assert state.mode == Mode.FAR and state.clearance > 0.1
    E = sc.system.eval(ctx)
    t_due = options.reseek_early * state.clearance / 1.0
    assert E.bound[0] == pytest.approx(0.0, abs=1e-15)
    if t_due <= horizon:
        assert E.due and E.due_pairs.tolist() == [0] and math.isinf(E.far_early)
    else:
        assert not E.due and E.due_pairs.tolist() == []
        assert E.far_early == pytest.approx(t_due, rel=1e-12)


def test_the_reseek_horizon_is_checked():
    from drake_dock.errors import InputError
    from drake_dock.systems.contact_system import ContactOptions
    with pytest.raises(InputError, match="reseek_horizon"):
        ContactOptions(reseek_horizon=-1e-3)
