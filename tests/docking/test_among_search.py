"""The first-contact search's cheaper variants used by the consistent aim's bracket
(`drake_dock.docking.search`): among some pairs of the set, stopped at a travel, and the covers'
steps found chunk by chunk; and the placements they give on sweep conditions whose consistent
aim lies on a jump of the first contact. Checked against the search with the whole set, the
whole grid's covers, and the bracket with the whole set (`_bracketed_height`)."""
import dataclasses

import numpy as np
import pytest

from drake_dock.core.kernels import cover as compiled_cover
from drake_dock.docking import scene, search
from drake_dock.docking.scene import JUMP_SLOPE, Approach, contact_approach
from tests.docking.test_consistent_aim import _condition


def _aimed(name):
    """The condition's scenario and its approaches by s (`contact_approach`'s approach(s))."""
    s = _condition(name)
    ic = s.initial
    v = np.array([*ic.lateral_velocity, -ic.chaser_speed])
    direction = tuple((v / np.linalg.norm(v)).tolist())
    offset, slope = np.array(ic.lateral_offset), np.array(ic.lateral_velocity) / ic.chaser_speed
    yaw, tilt = np.radians(ic.target_yaw_deg), tuple(np.radians(ic.tilt_deg).tolist())
    return s, lambda x: Approach(float(yaw), tilt, tuple((offset + x * slope).tolist()),
                                 direction)


# Random 51 on both sides of its jump: a tip arc closes first below s = 0.18243, the guide
# side of C6 from there on.
@pytest.mark.parametrize("x", [0.18242, 0.18245])
def test_a_pair_closes_at_the_same_travel_among_some_pairs(x):
    """The closing pairs alone give the whole set's first contact to the bit; any other
    pairs give one no higher (or none)."""
    s, approach = _aimed("random 51")
    g, a = s.geometry, approach(x)
    lam, names = search.first_contact_or_faces(g, a, "complete")
    assert search.first_contact_or_faces(g, a, "complete", among=names) == (lam, names)
    both = ["cc_Tring_C6", "cc_Tring_Ctip1"]
    assert search.first_contact_or_faces(g, a, "complete", among=both) == (lam, names)
    others = [pr.name for pr in search.search_pairs(dataclasses.astuple(g), "complete")
              if pr.name not in names][:12]
    lam_o, names_o = search.first_contact_or_faces(g, a, "complete", among=others)
    assert not names_o or lam_o < lam - 1e-9


def test_a_search_stopped_above_its_first_contact_finds_none():
    """Random 33 at s = 0.20223, where C2's guide side closes first at a height of 0.149 m:
    a search stopped 0.1 mm above that finds none; one stopped 0.1 mm below, or further
    down, finds the whole search's first contact to the bit."""
    s, approach = _aimed("random 33")
    g, a = s.geometry, approach(0.2022298023810)
    lam, names = search.first_contact_or_faces(g, a, "complete")
    per_height = 1.0 / a.height(1.0)
    assert search.first_contact_above(g, a, "complete", lam + 1e-4 * per_height) == (None, [])
    assert search.first_contact_above(g, a, "complete", 0.2003 * per_height) == (None, [])
    for stop in (lam - 1e-4 * per_height, 0.1 * per_height):
        assert search.first_contact_above(g, a, "complete", stop) == (lam, names)
    # Stopped 0.1 mm above, the marches of the step holding the stop end there.
    key = (dataclasses.astuple(g), a, None, 1e-13, "complete")
    assert search._first_contact(*key, None, lam + 1e-4 * per_height)[2] < \
        search._first_contact(*key)[2]


def test_a_search_with_the_whole_set_is_remembered_once():
    """`first_contact_or_faces` and `first_contact_seeks` share the memo's entry."""
    s, approach = _aimed("random 33")
    a = approach(0.2)
    search._first_contact.cache_clear()
    search.first_contact_or_faces(s.geometry, a, "complete")
    search.first_contact_seeks(s.geometry, a, which="complete")
    info = search._first_contact.cache_info()
    assert (info.misses, info.hits) == (1, 1)


@pytest.mark.parametrize("chunk", [1, 7, search.TOUCH_CHUNK])
def test_the_covers_steps_chunk_by_chunk_are_the_whole_grids(monkeypatch, chunk):
    """Every step's booleans from `search._TouchSteps` (its first ``chunk`` steps, then the
    rest) equal the compiled touch test of each pair on the whole grid, on a tilted sideways
    approach."""
    monkeypatch.setattr(search, "TOUCH_CHUNK", chunk)
    s, approach = _aimed("corner 11")
    a = approach(0.2)
    pairs = search.search_pairs(dataclasses.astuple(s.geometry), "complete")
    grid = search.travel_grid(s.geometry, a)
    chunks = search._TouchSteps(pairs, a, grid)
    got = np.array([chunks.column(k) for k in range(len(grid) - 1)]).T
    whole = search._TouchSteps(pairs, a, grid)
    want = np.array([compiled_cover.touch_steps(m, f, whole.e, np.asarray(grid))
                     for m, f in whole.covers])
    assert got.any() and np.array_equal(got, want)


def _whole_searches(monkeypatch, s, bracket=None):
    """`contact_approach` (with ``bracket`` for `_among_height`), its memo cleared: its result
    and the number of searches it ran with the whole set."""
    searches, original = set(), search._first_contact
    original.cache_clear()

    def spy(*args):
        if len(args) < 6 or args[5] is None:        # the whole set, stopped or not
            searches.add(args)
        return original(*args)
    with monkeypatch.context() as m:
        m.setattr(search, "_first_contact", spy)
        if bracket is not None:
            m.setattr(scene, "_among_height", bracket)
        return contact_approach(s), len(searches)


@pytest.mark.parametrize("name", ["random 51", "random 3", "random 33"])
def test_a_jump_between_two_pairs_places_as_the_whole_sets_bracket(monkeypatch, name):
    """Where only the pairs closing at the bracket's ends close first inside it, the
    placement is the whole set's bracket's to the bit, with fewer searches of the whole set."""
    s = _condition(name)
    placed, whole_among = _whole_searches(monkeypatch, s)
    placed_whole, whole = _whole_searches(monkeypatch, s, scene._bracketed_height)
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
    s, approach = _aimed(name)
    ends = []
    original = scene._bracket_ends

    def spy(*args):
        ends.append(original(*args))
        return ends[-1]
    monkeypatch.setattr(scene, "_bracket_ends", spy)
    search._first_contact.cache_clear()
    a, lam, _ = contact_approach(s)
    end, other = ends[-1]

    def m(y):
        b = approach(y)
        return b.height(search.first_contact_or_faces(s.geometry, b, "complete")[0]) - y
    assert a == approach(end) and other is not None
    assert m(end) * m(other) < 0
    assert abs(end - other) * JUMP_SLOPE < min(abs(m(end)), abs(m(other)))
    assert abs(m(end)) < abs(m(other)) or (abs(m(end)) == abs(m(other)) and end > other)
