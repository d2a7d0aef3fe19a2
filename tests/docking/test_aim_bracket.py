"""The consistent aim's root finding on hand-made mismatches (`drake_dock.docking.placement.aim`):
the bracket that stops on a jump of the first contact (`_bracketed_height`, `JUMP_SLOPE`) and
the secant steps from the axial height (`_local_height`). Each is checked against a closed
form or against scipy's brentq."""
import math

import pytest
from scipy.optimize import brentq

from drake_dock.docking.placement.aim import (AIM_TOL, JUMP_SLOPE, LOCAL_STEPS, _bracketed_height,
                                              _local_height)


def _counted(f):
    calls = []

    def g(s):
        calls.append(s)
        return f(s)
    return g, calls


def _jump(s_jump, upper, lower):
    """A mismatch with a jump at s_jump: upper(s) below it, lower(s) from it on."""
    return lambda s: upper(s) if s < s_jump else lower(s)


@pytest.mark.parametrize("f", [
    lambda s: 0.3 - 2.0 * s,
    lambda s: 0.07 * (0.2 - s),
    lambda s: 9.0 * (0.2137 - s),                   # just under JUMP_SLOPE
    lambda s: math.tanh(40.0 * (0.31 - s)) / 5.0,   # slope 8 at the root, flat elsewhere
    lambda s: (0.25 - s) ** 3 + 0.01 * (0.25 - s),
])
def test_a_smooth_root_is_brentqs_to_the_bit(f):
    """Where every branch changes by less than JUMP_SLOPE per metre, the bracket never stops
    early: the result is scipy's brentq to 1e-10 m, bit for bit."""
    assert _bracketed_height(f, 0.0, 0.45) == brentq(f, 0.0, 0.45, xtol=1e-10)


@pytest.mark.parametrize("m_up, m_down, side", [(0.004, -0.02, -1), (0.03, -0.002, +1)])
def test_a_jump_is_left_at_the_end_with_the_smaller_miss(m_up, m_down, side):
    """Two branches of slope -0.9 and -1.1 whose roots lie beyond the jump at s* (irrational):
    no root exists. The bracket stops once its ends lie within the smaller |mismatch| /
    JUMP_SLOPE of each other, on the side of the jump with the smaller miss, and takes far
    fewer evaluations than brentq bisecting the jump down to 1e-10 m."""
    s_star = 0.2 + 1e-3 * math.sqrt(2.0)
    f = _jump(s_star, lambda s: m_up - 0.9 * (s - s_star), lambda s: m_down - 1.1 * (s - s_star))
    g, calls = _counted(f)
    x = _bracketed_height(g, 0.0, 0.45)
    assert (x - s_star) * side >= 0.0
    assert abs(x - s_star) < min(m_up, -m_down) / JUMP_SLOPE
    assert abs(f(x)) == pytest.approx(min(m_up, -m_down), abs=2e-3)
    h, full = _counted(f)
    brentq(h, 0.0, 0.45, xtol=1e-10)
    assert len(calls) < 0.6 * len(full)


@pytest.mark.parametrize("m_up, m_down, sign", [(0.004, -0.02, 1), (0.03, -0.002, 1),
                                               (0.004, -0.02, -1), (0.03, -0.002, -1)])
def test_the_bracket_stops_at_the_first_evaluation_that_shows_the_jump(m_up, m_down, sign):
    """The stop rule evaluated afresh on the points the bracket asked for, in their order: it
    first holds at the last of them (no evaluation after it, none missed before)."""
    s_star = 0.2 + 1e-3 * math.sqrt(2.0)
    f = _jump(s_star, lambda s: sign * (m_up - 0.9 * (s - s_star)),
              lambda s: sign * (m_down - 1.1 * (s - s_star)))
    g, calls = _counted(f)
    _bracketed_height(g, 0.0, 0.45)

    def shows_the_jump(points):
        xs = sorted(points)
        return any(f(a) * f(b) < 0 and (b - a) * JUMP_SLOPE < min(abs(f(a)), abs(f(b)))
                   for a, b in zip(xs, xs[1:]))
    shown = [shows_the_jump(calls[:k + 1]) for k in range(len(calls))]
    assert shown.index(True) == len(calls) - 1


def test_a_jump_of_equal_misses_is_left_at_its_higher_end():
    s_star = 0.2 + 1e-3 / math.pi
    assert _bracketed_height(lambda s: 0.01 if s < s_star else -0.01, 0.0, 0.45) > s_star


def test_a_root_next_to_a_jump_is_found_not_the_jump():
    """The upper branch reaches zero 49 mm before the jump: the bracket finds that root to
    1e-10 m rather than stopping on the jump."""
    f = _jump(0.2, lambda s: 0.001 - (s - 0.15), lambda s: -0.05)
    assert _bracketed_height(f, 0.0, 0.45) == pytest.approx(0.151, abs=1e-10)


def test_no_sign_change_is_a_value_error():
    with pytest.raises(ValueError):
        _bracketed_height(lambda s: 1.0 + s, 0.0, 0.45)


def test_the_secant_from_the_axial_height_finds_the_root_next_to_it():
    """mismatch(s) = 0.73 (r - s), r 58 um below s0 (random 4's numbers): the first step
    (slope -1) and one secant step meet r to AIM_TOL, in at most LOCAL_STEPS evaluations after
    s0."""
    s0, r = 0.2238155724, 0.2238155724 - 5.77e-5
    g, calls = _counted(lambda s: 0.73 * (r - s))
    x = _local_height(g, s0, 0.45)
    assert abs(x - r) <= AIM_TOL / 0.73
    assert len(calls) <= 1 + LOCAL_STEPS


def test_where_the_first_contact_is_flat_the_first_step_meets_the_root():
    """mismatch(s) = r - s (h_c constant): the first step, s0 + mismatch(s0), is r itself."""
    s0, r = 0.2029855606, 0.2029855606 - 3e-5
    g, calls = _counted(lambda s: r - s)
    assert abs(_local_height(g, s0, 0.45) - r) <= AIM_TOL and len(calls) == 2


def test_the_axial_height_is_taken_where_its_mismatch_is_within_aim_tol():
    g, calls = _counted(lambda s: 0.5 * AIM_TOL)
    assert _local_height(g, 0.2, 0.45) == 0.2 and calls == [0.2]


def test_a_jump_next_to_the_axial_height_is_bracketed():
    """mismatch +14.5 mm at s0 and a jump 9.4 mm above it to -9.2 mm (random 3's numbers):
    the first step crosses the jump, and the bracket between s0 and it stops on the jump's
    side with the smaller miss."""
    s0, s_star = 0.1906100308, 0.2000222750
    f = _jump(s_star, lambda s: 0.0058 - 0.93 * (s - s_star),
              lambda s: -0.0092 - 0.98 * (s - s_star))
    x = _local_height(f, s0, 0.45)
    assert x < s_star and s_star - x < 0.0058 / JUMP_SLOPE


def test_the_secant_takes_at_most_local_steps_steps():
    """Curved mismatches with a root r 1 mm below s0: 0.9 (r - s) - 30 (r - s)^2 is met to
    AIM_TOL by the third step; 0.5 (r - s) - 10 (r - s)^2 is not, and after LOCAL_STEPS
    evaluations the aim is left to the whole range."""
    r = 0.2
    g, calls = _counted(lambda s: 0.9 * (r - s) - 30.0 * (r - s) ** 2)
    assert abs(_local_height(g, r + 1e-3, 0.45) - r) < 2.0 * AIM_TOL
    assert len(calls) == 1 + LOCAL_STEPS
    g, calls = _counted(lambda s: 0.5 * (r - s) - 10.0 * (r - s) ** 2)
    assert _local_height(g, r + 1e-3, 0.45) is None and len(calls) == 1 + LOCAL_STEPS


def test_a_step_above_s_max_is_not_evaluated():
    g, calls = _counted(lambda s: 0.3)
    assert _local_height(g, 0.2, 0.45) is None and calls == [0.2]


def test_no_root_the_secant_can_reach_leaves_the_aim_to_the_whole_range():
    """A mismatch that grows with s: the secant steps leave [0, s_max] (or stall) and
    `_local_height` returns None."""
    assert _local_height(lambda s: 0.01 + s, 0.2, 0.45) is None
    assert _local_height(lambda s: 0.01, 0.2, 0.45) is None
