"""The hybrid decisions of a pair (drake_dock.core.hybrid), each against a hand-computed case, a
closed form or a second implementation. Runs without Drake."""
import math

import numpy as np
import pytest

from drake_dock.core import hybrid
from drake_dock.core.constraints import DETACH, SLIDE, STICK
from drake_dock.core.hybrid import Mode
from drake_dock.core.relations import relation

FAR, TRACKED, SLIDING, STICKING = Mode.FAR, Mode.TRACKED, Mode.SLIDING, Mode.STICKING


def test_mode_is_the_port_status_code():
    """The couple port's status code was status + stick with far 0, tracked 1, contact 2."""
    legacy = {(0, False): FAR, (1, False): TRACKED, (2, False): SLIDING, (2, True): STICKING}
    for (status, stick), mode in legacy.items():
        assert status + stick == int(mode)
        assert mode.in_contact == (status == 2)
    assert [Mode.of_selection(m) for m in (DETACH, SLIDE, STICK)] == [TRACKED, SLIDING, STICKING]


def test_sigma_and_crossing_by_hand():
    assert relation("CS").sigma(-1.0, 0.3) == -1.0          # declared
    assert relation("CC").sigma(None, -0.2) == -1.0
    assert relation("CC").sigma(None, 0.0) == 1.0
    assert relation("PC").sigma(None, -0.2) == 1.0       # a point-curve n is along d
    tol = 1e-8
    # A couple 1 cm apart on the side of n: the closest couple, not crossing.
    assert not hybrid.patches_cross(0.01, 0.01, 1.0, tol)
    # The same couple with the normal declared the other way: on the wrong side.
    assert hybrid.patches_cross(0.01, 0.01, -1.0, tol)
    # The contact-form couple is 5 cm apart while the patches are 1 cm apart: not the closest.
    assert hybrid.patches_cross(0.05, 0.01, 1.0, tol)
    # Round-off on either side of the tolerance.
    assert not hybrid.patches_cross(-0.5 * tol, 0.0, 1.0, tol)
    assert hybrid.patches_cross(-2 * tol, 0.0, 1.0, tol)
    # A failed contact-form finish at zero distance: a curve through a surface; at 1 mm, or a
    # finish that was not tried (a domain end), no crossing.
    assert hybrid.intersecting(1e-16, True, tol)
    assert not hybrid.intersecting(1e-3, True, tol)
    assert not hybrid.intersecting(0.0, False, tol)


@pytest.mark.parametrize("distance, usable, crossing, was_contact, expected", [
    (0.01, True, False, False, (TRACKED, None)),
    (0.01, True, False, True, (FAR, 0.005)),      # a contact that ran off a patch end
    (0.01, False, False, False, (FAR, 0.005)),    # at a domain end or not isolated
    (0.01, True, True, False, (FAR, 0.01)),       # crossing: half track_distance
    (0.05, True, False, False, (FAR, 0.04)),      # d - td / 2 = 0.04 > d / 2 = 0.025
    (0.03, True, False, False, (FAR, 0.02)),      # d - td / 2 = 0.02 > d / 2 = 0.015
    (0.025, True, False, False, (FAR, 0.015)),
    (1e-5, False, False, False, (FAR, 1e-4)),     # the re-seek floor
])
def test_after_seek_by_hand(distance, usable, crossing, was_contact, expected):
    mode, clearance = hybrid.after_seek(distance, usable, crossing, was_contact, 0.02, 1e-4)
    assert mode == expected[0]
    if expected[1] is None:
        assert clearance is None
    else:
        assert clearance == pytest.approx(expected[1], rel=1e-12)


@pytest.mark.parametrize("distance, usable, was_contact", [
    (0.0, False, True), (1e-5, False, False), (0.01, True, False), (0.05, True, False)])
def test_after_seek_carried_couple_keeps_half_track_distance(distance, usable, was_contact):
    """A couple carried by a linked pair (`drake_dock.core.handover`) is far with half
    track_distance of clearance at any distance, even a usable one: it is that pair's couple."""
    assert hybrid.after_seek(distance, usable, False, was_contact, 0.02, 1e-4,
                             carried=True) == (FAR, 0.01)


def test_far_clearance_never_lets_a_pair_touch_unseen():
    """A pair at distance d > reseek_floor cannot touch within its clearance of relative travel
    (the distance shrinks at most by the travel), and it keeps at least half of the smaller of
    d and track_distance in hand."""
    rng = np.random.default_rng(3)
    td, floor = 0.02, 1e-4
    for d in np.concatenate([10 ** rng.uniform(-3.9, 0.5, 500), [td, 2 * floor]]):
        mode, clearance = hybrid.after_seek(d, True, False, False, td, floor)
        if d < td:
            assert mode == TRACKED
            continue
        assert mode == FAR and clearance >= floor
        assert d - clearance >= min(0.5 * td, 0.5 * d) * (1 - 1e-12)


def test_impact_set_by_hand():
    modes = [FAR, TRACKED, TRACKED, SLIDING, STICKING, TRACKED]
    gap = [np.nan, 0.0, 5e-9, 0.0, 0.0, 1e-3]
    vn = [np.nan, -0.4, -0.1, 1e-7, 1e-6, -2.0]
    hit = hybrid.impact_hits(modes, gap, vn, 1e-8)
    assert hit == [1, 2]                      # couple 5 approaches but is 1 mm away
    # Closing speed 0.4: couples in contact with v_n <= 4e-7 join (3 does, 4 separates).
    assert hybrid.impact_set(hit, modes, vn) == [1, 2, 3]
    assert hybrid.closed_after_impact([0.0, 3e-7, 5e-7], 0.4) == [True, True, False]


def test_zeno_guard_ends_a_bounce_sequence_after_the_closed_form_count():
    """A ball bouncing with restitution e: approach speeds v0 e^k; with the guard the impact
    whose speed is first below zeno_speed is plastic, so the sequence has
    ceil(log(zeno_speed / v0) / log(e)) + 1 impacts."""
    for v0, e, zeno in [(1.0, 0.5, 1e-3), (0.3, 0.9, 1e-3), (2.0, 0.1, 0.05)]:
        v, n = v0, 0
        while v > 0.0:
            v *= hybrid.zeno_restitution(v, e, zeno)
            n += 1
            assert n < 10000
        assert n == math.ceil(math.log(zeno / v0) / math.log(e)) + 1
        assert hybrid.zeno_restitution(zeno, e, zeno) == e    # at the guard: still elastic


def test_contact_candidates_by_hand():
    modes = [FAR, TRACKED, SLIDING, STICKING, TRACKED, TRACKED]
    gap = [np.nan, 0.0, 0.0, 0.0, 0.0, 1e-6]
    vn = [np.nan, 0.0, 1e-7, 0.2, 1e-7, 0.0]
    # No impact: the couples in contact stay candidates, the resting tracked couples join.
    new, cand = hybrid.contact_candidates(modes, gap, vn, False, [], 1e-8, 1e-6)
    assert new == modes and cand == [1, 2, 3, 4]
    # After an impact that closed couples 1 and 2: the contact couple 3 left out of it is
    # tracked again; couple 4 rests and joins.
    new, cand = hybrid.contact_candidates(modes, gap, vn, True, [1, 2], 1e-8, 1e-6)
    assert new == [FAR, TRACKED, SLIDING, TRACKED, TRACKED, TRACKED]
    assert cand == [1, 2, 4]


def test_modes_left_by_hand():
    assert hybrid.modes_left(SLIDING, 0.0, [0.0, 0.0], 0.3) == (STICK, SLIDE)
    assert hybrid.modes_left(SLIDING, 2.0, [0.6, 0.0], 0.3) == ()
    assert hybrid.modes_left(STICKING, 2.0, [0.3, 0.4], 0.25) == (STICK,)   # |lt| = mu_s ln
    assert hybrid.modes_left(STICKING, 2.0, [0.3, 0.39], 0.25) == ()
    assert hybrid.modes_left(STICKING, -1.0, [0.0, 0.0], 0.25) == (STICK, SLIDE, STICK)


def test_velocity_projection_against_the_kkt_solution():
    """v+ minimises (v+ - v)^T M (v+ - v) / 2 subject to C^T v+ = 0: the KKT system
    [M C; C^T 0] [v+; mu] = [M v; 0]; the energy removed is the kinetic energy of v - v+
    (Pythagoras in the M metric)."""
    rng = np.random.default_rng(11)
    for n, k in [(6, 1), (6, 3), (12, 5)]:
        A = rng.normal(size=(n, n))
        M = A @ A.T + n * np.eye(n)
        C = rng.normal(size=(n, k))
        v = rng.normal(size=n)
        vp, removed = hybrid.project_velocity(M, np.linalg.inv(M), C, v)
        K = np.block([[M, C], [C.T, np.zeros((k, k))]])
        kkt = np.linalg.solve(K, np.concatenate([M @ v, np.zeros(k)]))[:n]
        np.testing.assert_allclose(vp, kkt, rtol=1e-10, atol=1e-12)
        np.testing.assert_allclose(C.T @ vp, 0.0, atol=1e-11)
        dv = v - vp
        assert removed == pytest.approx(0.5 * dv @ M @ dv, rel=1e-9)


def test_velocity_projection_of_a_particle_on_a_plane():
    """A particle of mass m with normal row e_z loses its normal velocity and m vz^2 / 2; a
    velocity already on the constraint is returned unchanged."""
    m = 3.0
    M = m * np.eye(3)
    C = np.array([[0.0], [0.0], [1.0]])
    vp, removed = hybrid.project_velocity(M, np.linalg.inv(M), C, np.array([1.0, 2.0, -0.5]))
    np.testing.assert_allclose(vp, [1.0, 2.0, 0.0], atol=1e-15)
    assert removed == pytest.approx(0.5 * m * 0.25, rel=1e-14)
    v = np.array([1.0, 2.0, 0.0])
    vp, removed = hybrid.project_velocity(M, np.linalg.inv(M), C, v)
    assert vp is v and removed == 0.0
