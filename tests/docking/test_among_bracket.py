"""The consistent aim's bracket closed among the pairs that close at its ends
(`drake_dock.docking.placement.aim._among_height`), on hand-made scenes of a few pairs whose closing
heights are closed forms: checked against the bracket with the whole set
(`_bracketed_height`), bit for bit where no other pair shows, and against the jump's rule
where one does."""
import math

import pytest

from drake_dock.docking.placement.aim import JUMP_SLOPE, _among_height, _bracketed_height
from drake_dock.errors import SeekingError


class _Scene:
    """A mismatch as `aim._Mismatch` gives it: ``pairs`` maps a name to s -> the height at
    which the pair closes on the approach s (None: it does not close). Counts the searches
    with the whole set, and those that stop at a height (`below`)."""

    def __init__(self, pairs):
        self.pairs, self.whole, self.stopped = pairs, [], []

    def _first(self, s, names):
        hs = {n: self.pairs[n](s) for n in names}
        hs = {n: h for n, h in hs.items() if h is not None}
        if not hs:
            return 0.0 - s, []                       # the faces meet first
        h = max(hs.values())
        return h - s, sorted(n for n, x in hs.items() if x >= h - 1e-9)

    def __call__(self, s):
        return self._first(s, self.pairs)[0]

    def among(self, s, names):
        if names is None:
            self.whole.append(s)
        return self._first(s, self.pairs if names is None else names)

    def below(self, s, T):
        """As a search stopped at the height s - T (`first_contact`'s ``stop``): None where no
        pair closes there or above (none closing at all included)."""
        self.stopped.append(s)
        hs = [h for h in (f(s) for f in self.pairs.values()) if h is not None]
        return None if not hs or max(hs) < s - T else self._first(s, self.pairs)


S_STAR = 0.21 + 1e-3 * math.sqrt(2.0)      # an irrational jump


def test_a_jump_between_two_pairs_is_the_whole_sets_bracket_to_the_bit():
    """The tip closes first up to S_STAR (mismatch +0.02 there), a guide side from it on
    (-0.05): the end taken is the tip's, bit for bit the bracket's with the whole set; the
    whole set is searched at the two ends given and at the end taken only, and the jump's
    other end (negative) by a search that stops at the height the rule needs."""
    pairs = {"tip": lambda s: s + 0.02 if s < S_STAR else None, "side": lambda s: s - 0.05}
    scene = _Scene(pairs)
    full = _bracketed_height(_Scene(pairs), 0.1, 0.3)
    x = _among_height(scene, 0.1, 0.3)
    assert x == full and x < S_STAR
    assert sorted(set(scene.whole)) == sorted({0.1, 0.3, x})
    assert len(scene.stopped) == 1 and abs(scene.stopped[0] - S_STAR) < abs(scene(x)) / JUMP_SLOPE


def test_a_jump_whose_other_end_is_positive_needs_no_search_there():
    """The guide side's miss is the smaller (-0.004 against +0.03): the end taken is the
    side's, the bracket's with the whole set to the bit; the tip's end, positive among the
    two pairs, is positive with the whole set too and is not searched."""
    pairs = {"tip": lambda s: s + 0.03 if s < S_STAR else None, "side": lambda s: s - 0.004}
    scene = _Scene(pairs)
    x = _among_height(scene, 0.1, 0.3)
    assert x == _bracketed_height(_Scene(pairs), 0.1, 0.3) and x > S_STAR
    assert sorted(set(scene.whole)) == sorted({0.1, 0.3, x}) and scene.stopped == []


def test_a_smooth_root_is_the_whole_sets_to_the_bit():
    """One pair whose mismatch crosses zero with slope -0.9 (another pair far below): the
    root is the whole set's brentq, bit for bit, with the set searched at the ends and the
    root only."""
    pairs = {"side": lambda s: 0.2 + 0.1 * (s - 0.2), "far": lambda s: 0.05}
    scene = _Scene(pairs)
    x = _among_height(scene, 0.1, 0.3)
    assert x == _bracketed_height(_Scene(pairs), 0.1, 0.3)
    assert abs(x - 0.2) < 1e-10 and sorted(set(scene.whole)) == sorted({0.1, 0.3, x})


def test_a_third_pair_at_the_jump_is_found_and_taken():
    """A corner closes with the miss -0.018 just past the jump (s in [S_STAR, 0.24]),
    above the guide side: among the tip and the side the jump is +0.02 / -0.05 and the tip's
    end would be taken; the search at the other end, stopped at the tip's miss, finds the
    corner, which joins the names, and the end taken is the corner's (miss -0.018), the whole
    set's bracket to the bit."""
    pairs = {"tip": lambda s: s + 0.02 if s < S_STAR else None,
             "side": lambda s: s - 0.05,
             "corner": lambda s: s - 0.018 if S_STAR <= s <= 0.24 else None}
    scene = _Scene(pairs)
    x = _among_height(scene, 0.1, 0.3)
    assert x == _bracketed_height(_Scene(pairs), 0.1, 0.3)
    assert x > S_STAR and scene(x) == pytest.approx(-0.018, abs=1e-12) and scene.stopped
    assert len(set(scene.whole)) <= 4          # a, b and one end per pass


def test_a_third_pair_at_the_end_taken_is_found_and_taken():
    """A corner closes above the tip just before the jump (s in [0.2, S_STAR]): the end taken
    among the tip and the side is checked with the whole set, the corner joins the names, and
    the result is the whole set's bracket, bit for bit."""
    pairs = {"tip": lambda s: s + 0.02 if s < S_STAR else None,
             "side": lambda s: s - 0.05,
             "corner": lambda s: s + 0.03 if 0.2 <= s < S_STAR else None}
    scene = _Scene(pairs)
    x = _among_height(scene, 0.1, 0.3)
    assert x == _bracketed_height(_Scene(pairs), 0.1, 0.3)
    assert scene(x) == pytest.approx(0.03, abs=1e-12)
    assert len(set(scene.whole)) <= 4


def test_a_third_pair_away_from_the_jump_leaves_a_jump_of_the_whole_set():
    """A corner that closes first only inside the bracket (s in [0.12, 0.205], away from the
    jump) changes the points the bracket evaluates, not the rule: the end taken and the
    whole set's mismatch just across the jump have opposite signs, closer than the smaller
    |miss| / JUMP_SLOPE, and the end is on the side of the smaller miss."""
    pairs = {"tip": lambda s: s + 0.02 if s < S_STAR else None,
             "side": lambda s: s - 0.05,
             "corner": lambda s: s + 0.04 if 0.12 <= s <= 0.205 else None}
    scene = _Scene(pairs)
    x = _among_height(scene, 0.1, 0.3)
    assert x < S_STAR and scene(x) == pytest.approx(0.02, abs=1e-12)
    assert S_STAR - x < min(abs(scene(x)), abs(scene(S_STAR))) / JUMP_SLOPE


def test_a_pair_closing_below_the_face_plane_leaves_a_jump_of_the_whole_set():
    """A pair that closes only below the ring-face plane (height -0.01) just past the jump:
    among the tip and the side no pair closes there (the faces: m = -s), higher than the
    whole set's first contact. The end taken is the tip's, and the whole set's mismatch at the
    jump's far side is below -|m(end)|."""
    pairs = {"tip": lambda s: s + 0.02 if s < S_STAR else None,
             "side": lambda s: s - 0.05 if s >= S_STAR + 0.01 else None,
             "deep": lambda s: -0.01 if S_STAR <= s < S_STAR + 0.01 else None}
    scene = _Scene(pairs)
    x = _among_height(scene, 0.1, 0.3)
    assert x < S_STAR and scene(x) == pytest.approx(0.02, abs=1e-12)
    assert S_STAR - x < 0.02 / JUMP_SLOPE and scene(S_STAR) < -0.02


def test_a_failed_search_among_the_names_leaves_the_bracket_to_the_whole_set():
    """Where a search among the names fails (`SeekingError`; such a search goes on below the
    whole set's first contact), the bracket is closed with the whole set."""
    pairs = {"tip": lambda s: s + 0.02 if s < S_STAR else None, "side": lambda s: s - 0.05}

    class Failing(_Scene):
        def among(self, s, names):
            if names is not None and 0.15 < s < 0.25:
                raise SeekingError("a march below the first contact")
            return super().among(s, names)

    assert _among_height(Failing(pairs), 0.1, 0.3) == _bracketed_height(_Scene(pairs), 0.1, 0.3)


def test_a_check_that_no_name_explains_falls_back_to_the_whole_set():
    """Where the whole set's first contact differs from the pairs' own though it names only
    them (not a property of the search; a guard), the bracket ends with the whole set and
    returns its result instead of looping."""
    pairs = {"tip": lambda s: s + 0.02 if s < S_STAR else None, "side": lambda s: s - 0.05}

    class Odd(_Scene):
        def among(self, s, names):
            m, closing = super().among(s, names)
            return (m + 1e-3, closing) if names is None else (m, closing)

        def below(self, s, T):
            m, closing = self.among(s, None)
            return m - 5e-4, closing          # differs even from the whole set's

    x = _among_height(Odd(pairs), 0.1, 0.3)
    assert x == _bracketed_height(lambda s: Odd(pairs).among(s, None)[0], 0.1, 0.3)
