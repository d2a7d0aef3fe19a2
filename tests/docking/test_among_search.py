"""The first-contact search's cheaper variants used by the consistent aim's bracket
(`drake_dock.docking.placement.search.first_contact`): among some pairs of the set, stopped at a
travel, and the covers' steps found chunk by chunk; the caller's cache; and the placements they
give on sweep conditions whose consistent aim lies on a jump of the first contact. Checked
against the search with the whole set, the whole grid's covers, and the bracket with the whole
set (`_bracketed_height`)."""
import numpy as np
import pytest

from drake_dock.core.kernels import cover as compiled_cover
from drake_dock.docking.geometry.scene import DockingScene
from drake_dock.docking.placement import aim
from drake_dock.docking.placement import search
from drake_dock.docking.placement.aim import JUMP_SLOPE
from drake_dock.docking.placement.place import PlacementCache, contact_approach
from drake_dock.docking.placement.search import Approach
from drake_dock.docking.placement.search import first_contact
from tests.docking.test_consistent_aim import _condition


def _aimed(name):
    """The condition's scenario, its approaches by s (`contact_approach`'s approach(s)) and a
    cache of its scene."""
    s = _condition(name)
    ic = s.initial
    v = np.array([*ic.lateral_velocity, -ic.chaser_speed])
    direction = tuple((v / np.linalg.norm(v)).tolist())
    offset, slope = np.array(ic.lateral_offset), np.array(ic.lateral_velocity) / ic.chaser_speed
    yaw, tilt = np.radians(ic.target_yaw_deg), tuple(np.radians(ic.tilt_deg).tolist())
    return s, lambda x: Approach(float(yaw), tilt, tuple((offset + x * slope).tolist()),
                                 direction), PlacementCache(DockingScene.of(s))


def _found(fc):
    return fc.lam, fc.closing


# Random 51 on both sides of its jump: a tip arc closes first below s = 0.18243, the guide
# side of C6 from there on.
@pytest.mark.parametrize("x", [0.18242, 0.18245])
def test_a_pair_closes_at_the_same_travel_among_some_pairs(x):
    """The closing pairs alone give the whole set's first contact to the bit; any other
    pairs give one no higher (or none)."""
    s, approach, cache = _aimed("random 51")
    a = approach(x)
    whole = _found(first_contact(cache, a))
    assert _found(first_contact(cache, a, among=whole[1])) == whole
    both = ["cc_Tring_C6", "cc_Tring_Ctip1"]
    assert _found(first_contact(cache, a, among=both)) == whole
    others = [pr.name for pr in cache.scene.pairs if pr.name not in whole[1]][:12]
    lam_o, names_o = _found(first_contact(cache, a, among=others))
    assert not names_o or lam_o < whole[0] - 1e-9


def test_a_search_stopped_above_its_first_contact_finds_none():
    """Random 33 at s = 0.20223, where C2's guide side closes first at a height of 0.149 m:
    a search stopped 0.1 mm above that finds none; one stopped 0.1 mm below, or further
    down, finds the whole search's first contact to the bit."""
    s, approach, cache = _aimed("random 33")
    a = approach(0.2022298023810)
    whole = first_contact(cache, a)
    lam = whole.lam
    per_height = 1.0 / a.height(1.0)
    above = first_contact(cache, a, stop=lam + 1e-4 * per_height)
    assert _found(above) == (None, ())
    assert _found(first_contact(cache, a, stop=0.2003 * per_height)) == (None, ())
    for stop in (lam - 1e-4 * per_height, 0.1 * per_height):
        assert _found(first_contact(cache, a, stop=stop)) == _found(whole)
    # Stopped 0.1 mm above, the marches of the step holding the stop end there.
    assert above.seeks < whole.seeks


def test_the_callers_cache_remembers_each_search_once(monkeypatch):
    """A search asked twice of one `PlacementCache` runs once and gives the same result; asked
    of another cache of an equal scene it runs again and gives an equal one."""
    s, approach, cache = _aimed("random 33")
    a = approach(0.2)
    runs, original = [], search._search
    monkeypatch.setattr(search, "_search", lambda *args: runs.append(args) or original(*args))
    first = first_contact(cache, a)
    assert first_contact(cache, a) is first and len(runs) == 1
    assert first_contact(PlacementCache(DockingScene.of(s)), a) == first and len(runs) == 2


@pytest.mark.parametrize("chunk", [1, 7, search.TOUCH_CHUNK])
def test_the_covers_steps_chunk_by_chunk_are_the_whole_grids(monkeypatch, chunk):
    """Every step's booleans from `search._TouchSteps` (its first ``chunk`` steps, then the
    rest) equal the compiled touch test of each pair on the whole grid, on a tilted sideways
    approach."""
    monkeypatch.setattr(search, "TOUCH_CHUNK", chunk)
    s, approach, cache = _aimed("corner 11")
    a = approach(0.2)
    pairs = cache.scene.pairs
    grid = search.travel_grid(s.geometry, a)
    chunks = search._TouchSteps(pairs, a, grid)
    got = np.array([chunks.column(k) for k in range(len(grid) - 1)]).T
    whole = search._TouchSteps(pairs, a, grid)
    want = np.array([compiled_cover.touch_steps(m, f, whole.e, np.asarray(grid))
                     for m, f in whole.covers])
    assert got.any() and np.array_equal(got, want)


def _whole_searches(monkeypatch, s, bracket=None):
    """`contact_approach` (with ``bracket`` for `_among_height`) on a fresh cache: its result
    and the number of searches it ran with the whole set."""
    searches, original = set(), search._search

    def spy(scene, approach, among, stop, step, xtol):
        if among is None:                           # the whole set, stopped or not
            searches.add((approach, stop, step, xtol))
        return original(scene, approach, among, stop, step, xtol)
    with monkeypatch.context() as m:
        m.setattr(search, "_search", spy)
        if bracket is not None:
            m.setattr(aim, "_among_height", bracket)
        return contact_approach(s), len(searches)


@pytest.mark.parametrize("name", ["random 51", "random 3", "random 33"])
def test_a_jump_between_two_pairs_places_as_the_whole_sets_bracket(monkeypatch, name):
    """Where only the pairs closing at the bracket's ends close first inside it, the
    placement is the whole set's bracket's to the bit, with fewer searches of the whole set."""
    s = _condition(name)
    placed, whole_among = _whole_searches(monkeypatch, s)
    placed_whole, whole = _whole_searches(monkeypatch, s, aim._bracketed_height)
    assert placed == placed_whole
    assert whole_among + 3 <= whole


JUMPS = ["random 1", "random 3", "random 29", "random 33", "random 48", "random 51",
         "corner 11", "corner 13"]


@pytest.mark.parametrize("name", JUMPS)
def test_a_placement_on_a_jump_keeps_the_rule_with_the_whole_set(monkeypatch, name):
    """The sweep's conditions placed on a jump of the first contact (a third pair closes first
    at points the bracket evaluates in random 1, random 48 and corner 11): at the bracket's
    last two points the whole set's mismatch has opposite signs, they are closer than the
    smaller |m| / JUMP_SLOPE, and the end taken has the smaller |m|."""
    s, approach, cache = _aimed(name)
    ends = []
    original = aim._bracket_ends

    def spy(*args):
        ends.append(original(*args))
        return ends[-1]
    monkeypatch.setattr(aim, "_bracket_ends", spy)
    a, lam, _ = contact_approach(s, cache)
    end, other = ends[-1]

    def m(y):
        b = approach(y)
        return b.height(first_contact(cache, b).travel()) - y
    assert a == approach(end) and other is not None
    assert m(end) * m(other) < 0
    assert abs(end - other) * JUMP_SLOPE < min(abs(m(end)), abs(m(other)))
    assert abs(m(end)) < abs(m(other)) or (abs(m(end)) == abs(m(other)) and end > other)
