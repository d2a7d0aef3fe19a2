"""The impact without collision (`drake_dock.core.iwc`) on one free rigid body touching fixed
surfaces at k couples, whose 3k rows are redundant for k >= 2 (rank 5 for k = 2, 6 for
k = 3): the impulse against the momentum balance M (v+ - v) = W P solved separately, the
stopped couples (W^T v+ = 0), the cone, the kinetic energy, and the cases the affine set of
impulses has, or has not, an admissible point that the closed form shows."""
import math

import numpy as np
import pytest
from scipy.spatial.transform import Rotation

from drake_dock.core.iwc import impact_without_collision

MASS, INERTIA, MU_S = 2.0, (0.1, 0.2, 0.25), 0.8
FEET = {2: [(0.3, 0.1, -0.3), (-0.2, -0.25, -0.3)],
        3: [(0.3, 0.0, -0.3), (-0.15, 0.26, -0.3), (-0.15, -0.26, -0.3)]}


def free_body(R, couples):
    """M and the rows (Wn, Wt) of a free body (velocity [w, v] about its mass centre, world
    frame; inertia diag(INERTIA) turned by R) with couples (r, n, ta, tb): the point r from the
    mass centre, the surface's normal n and tangents. A couple's row for a direction d is the
    generalized force of a unit impulse d at r: [r x d, d]."""
    M = np.zeros((6, 6))
    M[:3, :3] = R @ np.diag(INERTIA) @ R.T
    M[3:, 3:] = MASS * np.eye(3)
    row = lambda r, d: np.concatenate([np.cross(r, d), d])  # noqa: E731
    Wn = np.column_stack([row(np.asarray(r, float), np.asarray(n, float))
                          for r, n, _, _ in couples])
    Wt = np.column_stack([row(np.asarray(r, float), np.asarray(t, float))
                          for r, _, ta, tb in couples for t in (ta, tb)])
    return M, Wn, Wt


def on_floor(k, R):
    return free_body(R, [(r, (0, 0, 1), (1, 0, 0), (0, 1, 0)) for r in FEET[k]])


def check_sticking(res, M, Wn, Wt, v, mu):
    """The returned impulse stops every couple, pushes, lies in the cone, does not add kinetic
    energy, and is the momentum jump: M (v+ - v) = Wn P_n + Wt P_t."""
    P_n, P_t = res.P_n, res.P_t
    scale = max(np.abs(P_n).max(), np.abs(P_t).max())
    np.testing.assert_allclose(M @ (res.v_plus - v), Wn @ P_n + Wt @ P_t.ravel(),
                               atol=1e-12 * scale)
    rel = np.concatenate([Wn.T @ res.v_plus, Wt.T @ res.v_plus])
    assert np.abs(rel).max() <= 1e-10 * np.abs(v).max()
    assert (P_n >= -1e-12 * scale).all()
    assert (np.hypot(P_t[:, 0], P_t[:, 1]) <= mu * P_n + 1e-12 * scale).all()
    ke, ke_plus = 0.5 * v @ M @ v, 0.5 * res.v_plus @ M @ res.v_plus
    assert ke_plus <= ke * (1 + 1e-12)
    np.testing.assert_allclose(res.energy_lost, ke - ke_plus, rtol=1e-9)


@pytest.mark.parametrize("k", [2, 3])
def test_redundant_couples_get_an_admissible_sticking_impulse(k):
    """A free body on k = 2 or 3 feet moving down and sideways (within the cone: |v_t| =
    0.32 < mu_s |v_n|) at 40 random orientations of its inertia: the sticking impulse exists
    (the body stops, its feet pushing), whatever the split of the redundant impulses."""
    rng = np.random.default_rng(11)
    v = np.array([0.0, 0.0, 0.0, 0.3, 0.1, -1.0])
    for _ in range(40):
        R = Rotation.random(random_state=rng.integers(1 << 31)).as_matrix()
        M, Wn, Wt = on_floor(k, R)
        assert np.linalg.matrix_rank(np.hstack([Wn, Wt])) == (5 if k == 2 else 6)
        res = impact_without_collision(M, Wn, Wt, v, MU_S)
        assert res is not None
        check_sticking(res, M, Wn, Wt, v, MU_S)


def test_admissible_impulse_beyond_the_minimum_norm_one():
    """A body pinched between a floor (couple 1 at r = -a z, n = +z) and a ceiling (couple 2 at
    r = +a z, n = -z), moving up at 1 m/s: both points stop, so v+ = 0 (a spin about z is all
    they allow, and there is none), and the z momentum gives P_n2 - P_n1 = m. The minimum-norm
    split (-m/2, m/2) pulls at the floor; the squeeze (1, 1) is in the null space of W, and the
    admissible impulses are P_n1 >= 0, P_n2 = P_n1 + m, P_t = 0."""
    a = 0.2
    M, Wn, Wt = free_body(np.eye(3), [((0, 0, -a), (0, 0, 1), (1, 0, 0), (0, 1, 0)),
                                      ((0, 0, a), (0, 0, -1), (1, 0, 0), (0, -1, 0))])
    v = np.array([0.0, 0.0, 0.0, 0.0, 0.0, 1.0])
    res = impact_without_collision(M, Wn, Wt, v, MU_S)
    assert res is not None
    check_sticking(res, M, Wn, Wt, v, MU_S)
    np.testing.assert_allclose(res.v_plus, np.zeros(6), atol=1e-12)
    np.testing.assert_allclose(res.P_n[1] - res.P_n[0], MASS, rtol=1e-12)


def test_no_admissible_impulse_in_the_set_is_none():
    """Two feet on the floor with the mass centre above their midpoint, the body moving up at
    1 m/s: the only motion that keeps both feet still is a spin about the line through them,
    which moves the mass centre horizontally, so v+_z = 0 and the z momentum gives
    P_n1 + P_n2 = m (0 - 1) < 0 for every impulse of the set: one foot at least pulls. None."""
    feet = [(0.25, 0.1, -0.3), (-0.25, -0.1, -0.3)]
    M, Wn, Wt = free_body(Rotation.from_euler("xyz", [0.3, -0.2, 0.5]).as_matrix(),
                          [(r, (0, 0, 1), (1, 0, 0), (0, 1, 0)) for r in feet])
    v = np.array([0.0, 0.0, 0.0, 0.0, 0.0, 1.0])
    assert impact_without_collision(M, Wn, Wt, v, MU_S) is None
    # The same body moving down: the set's impulses push (P_n1 + P_n2 = m) and one is
    # admissible.
    res = impact_without_collision(M, Wn, Wt, -v, MU_S)
    assert res is not None
    check_sticking(res, M, Wn, Wt, -v, MU_S)
    np.testing.assert_allclose(res.P_n.sum(), MASS, rtol=1e-12)


@pytest.mark.parametrize("scale", [1.0, 1e-6, 1e-12])
def test_admissibility_does_not_depend_on_the_units(scale):
    """The sticking impulse is linear in v (W^T v+ = 0 is): one foot of a body rising and
    sliding (its impulse pulls) is refused at every speed, and one landing is accepted with
    the impulse scaled by the speed. An absolute tolerance (in N s) would accept a pulling
    impulse once it is small enough."""
    M, Wn, Wt = free_body(np.eye(3), [((0.1, 0.0, -0.3), (0, 0, 1), (1, 0, 0), (0, 1, 0))])
    up = np.array([0.0, 0.0, 0.0, 0.2, 0.0, 0.5])
    assert impact_without_collision(M, Wn, Wt, scale * up, MU_S) is None
    down = up * np.array([1, 1, 1, 1, 1, -1])
    ref = impact_without_collision(M, Wn, Wt, down, MU_S)
    res = impact_without_collision(M, Wn, Wt, scale * down, MU_S)
    assert ref is not None and res is not None
    np.testing.assert_allclose(res.P_n, scale * ref.P_n, rtol=1e-12)
    np.testing.assert_allclose(res.P_t, scale * ref.P_t, rtol=1e-12, atol=1e-15 * scale)
    assert math.isclose(res.energy_lost, scale ** 2 * ref.energy_lost, rel_tol=1e-9)
