"""The first-contact search (`first_contact`) against a full scan: every pair's signed gap
(`signed_gaps`) at every point of the travel grid, the pairs' sides continued from point to
point, and brentq on the first step where a positive gap turns <= 0 (or the march
between). The search seeks a pair only in the steps its covers can touch; the travel and the
closing pairs are the scan's, bit for bit, and where the scan finds none the search finds
none. Independently, the path down to the first contact is clear by the interpenetration check
(`drake_dock.docking.checks.penetration`)."""
import math

import numpy as np
import pytest
from scipy.optimize import brentq

from drake_dock.docking.geometry.scene import DockingScene
from drake_dock.docking.placement import search
from drake_dock.docking.placement.place import PlacementCache, contact_approach, place
from drake_dock.docking.placement.search import Approach
from drake_dock.docking.placement.search import (MARCH_SUBSTEPS, TOUCH_GAP, first_contact,
                                                 march_root, seek_gaps, signed_gaps, travel_grid)
from drake_dock.docking.scenario.dimensions import ApdsGeometry
from drake_dock.errors import NumericalError


def _first(g, approach, which="paper", **kw):
    """`first_contact` on a fresh cache of the scene (g, which)."""
    return first_contact(PlacementCache(DockingScene(g, which)), approach, **kw)


def full_scan(g, approach, xtol=1e-13, which="paper"):
    """(lam, names, seeks) of the scan of every pair at every grid point: a pair closes on the
    first step where its gap turns from above `TOUCH_GAP` to <= 0, or, failing that on a step
    it comes within the step's travel of, where `march_root` closes it."""
    pairs = DockingScene(g, which).pairs
    grid = travel_grid(g, approach)
    gaps, refs, dist = seek_gaps(pairs, approach, grid[0], [None] * len(pairs))
    seeks = len(pairs)
    for d, d_lo in zip(grid[:-1], grid[1:]):
        gaps_lo, refs_lo, dist_lo = seek_gaps(pairs, approach, d_lo, refs)
        seeks += len(pairs)
        roots = {}
        for j in range(len(pairs)):
            if TOUCH_GAP < gaps[j] < np.inf and gaps_lo[j] <= 0:
                roots[pairs[j].name] = brentq(
                    lambda x, j=j: signed_gaps([pairs[j]], approach, x, [refs[j]])[0][0],
                    d_lo, d, xtol=xtol, rtol=1e-15)
            elif abs(dist[j]) < d - d_lo:
                lam, end, more = march_root(pairs[j], approach, d, (gaps[j], refs[j], dist[j]),
                                            d_lo, (d - d_lo) / MARCH_SUBSTEPS, xtol)
                seeks += more
                if lam is not None:
                    roots[pairs[j].name] = lam
                elif end is not None:
                    gaps_lo[j], refs_lo[j], dist_lo[j] = end
        if roots:
            d_c = max(roots.values())
            return d_c, sorted(n for n, r in roots.items() if r >= d_c - 1e-9), seeks
        gaps, refs, dist = gaps_lo, refs_lo, dist_lo
    raise NumericalError(f"no pair closes on the approach {approach}")


APPROACHES = {
    "paper": Approach(math.radians(5.0)),
    "tilted, off axis": Approach(math.radians(-3.0), (0.05, -0.02), (0.07, -0.04),
                                 (0.3, 0.2, -0.932737905308882)),
    "ring first": Approach(math.radians(2.0), (-0.06, 0.03), (-0.08, 0.05), (0.0, 0.0, -1.0)),
    "no contact": Approach(0.0, (0.0, 0.0), (0.8, 0.8), (0.0, 0.0, -1.0)),
}


@pytest.mark.parametrize("name", APPROACHES)
def test_search_equals_the_full_scan(name):
    g = ApdsGeometry()
    approach = APPROACHES[name]
    found = _first(g, approach)
    try:
        expected = full_scan(g, approach)
    except NumericalError:
        assert found.lam is None and found.closing == ()
        return
    assert (found.lam, list(found.closing)) == expected[:2]
    assert found.seeks < expected[2]


def _random_approach(rng):
    """A straight approach inside the IDSS box's misalignments, weighted to its edges: roll and
    tilt within 4 deg, aim within 0.1 m, lateral rate up to 0.4 of the closing rate."""
    edge = lambda lim, n: lim * np.sign(rng.uniform(-1, 1, n)) * rng.uniform(0.5, 1.0, n) ** 0.5
    v = np.array([*edge(0.4, 2), -1.0])
    return Approach(float(edge(math.radians(4.0), 1)[0]),
                    tuple(edge(math.radians(4.0), 2).tolist()), tuple(edge(0.1, 2).tolist()),
                    tuple((v / np.linalg.norm(v)).tolist()))


@pytest.mark.parametrize("which, seed", [("paper", s) for s in range(6)]
                         + [("complete", s) for s in range(6, 9)])
def test_search_equals_the_full_scan_on_random_approaches(which, seed):
    """Seeded random approaches: the search (covers, pairs built once per geometry, the compiled
    seek) closes the full scan's pairs at its travel, bit for bit, in fewer seeks."""
    g = ApdsGeometry()
    approach = _random_approach(np.random.default_rng(seed))
    found = _first(g, approach, which)
    try:
        expected = full_scan(g, approach, which=which)
    except NumericalError:
        assert found.lam is None and found.closing == ()
        return
    assert (found.lam, list(found.closing)) == expected[:2]
    assert found.seeks < expected[2]


# Where no pair closes, and the placement's fixed point -----------------------------------------
def _scenario(**initial):
    from drake_dock.docking.scenario.loading import load_scenario
    s = load_scenario()
    for k, v in initial.items():
        setattr(s.initial, k, v)
    return s


def test_a_roll_of_zero_approaches_freely_and_is_captured_without_contact():
    """At a relative roll of 0 the petals pass between each other: no pair closes, the
    independent interpenetration check finds the way clear (the ring's inside circle grazes the
    petal tips, Rs = R - H cot(alpha1)), the chaser starts approach_travel before the ring faces
    meet and coasts: captured at (approach_travel - capture_distance) / chaser_speed, no impact."""
    from drake_dock.docking.model.simulate import simulate
    s = _scenario(target_yaw_deg=0.0)
    st = place(s)
    assert st.d_contact == 0.0 and st.closing_pairs == [] and st.d0 == s.initial.approach_travel
    r = simulate(s, st)
    t_free = (s.initial.approach_travel - s.simulation.capture_distance) / s.initial.chaser_speed
    assert r.outcome == "captured" and not r.impacts
    assert r.capture_time == pytest.approx(t_free, abs=1e-7)


def test_a_large_roll_that_meets_unmodelled_features_is_a_typed_error():
    """At 40 deg roll no paper pair closes, but the guide sides cut through the petals that are
    not their partners: NoPairCloses names the feature and the petal, before any simulation."""
    from drake_dock.docking.placement.path_check import NoPairCloses
    with pytest.raises(NoPairCloses, match=r"guide side \d passes through the \w+ petal \d"):
        place(_scenario(target_yaw_deg=40.0))


def test_a_tilted_tip_on_tip_approach_is_placed_on_a_point_contact():
    """Coaxial and level at 40 deg roll the tips meet along an arc (tests/docking/
    test_tip_on_tip.py); tilted by 2 deg the same approach is placed on a point contact, and
    the independent check finds its path clear."""
    from drake_dock.docking.checks.penetration import deepest_penetration
    s = _scenario(target_yaw_deg=40.0)
    s.contact.pairs = "complete"
    g = s.geometry
    s.initial.tilt_deg = [2.0, 0.0]
    a, lam_c, names = contact_approach(s)
    eye, zero = np.eye(3), np.zeros(3)
    (R0, p0), (R1, p1) = a.pose(0.45), a.pose(lam_c)
    found = deepest_penetration(g, np.array([0.0, 1.0]), np.array([[eye, R0], [eye, R1]]),
                                np.array([[zero, p0], [zero, p1]]), ("target", "chaser"),
                                graze=1e-6)
    assert names and found.depth <= 1e-6


@pytest.mark.parametrize("yaw, tilt, offset, pair", [
    (59.9, [1.0, 1.0], [0.03, 0.0], "cc_Ctip3_Ttip3"),
    (-59.9, [0.0, 1.0], [0.0, 0.03], "ps_Ccorner6_T1")])
def test_a_large_roll_with_tilt_is_placed_on_the_new_pairs(yaw, tilt, offset, pair):
    """Near the roll range's ends, tilted and offset: the first contact is a tip arc on a tip
    arc, or a chaser corner on a target guide surface, and the independent check finds the
    straight path down to it clear (within 1 nm)."""
    from drake_dock.docking.checks.penetration import deepest_penetration
    s = _scenario(target_yaw_deg=yaw, tilt_deg=tilt, lateral_offset=offset)
    s.contact.pairs = "complete"
    a, lam_c, names = contact_approach(s)
    assert names == [pair]
    # The pair's couple touches there (its seek's distance, from the geometry afresh).
    from drake_dock.docking.geometry.pairs import CHASER_APDS, TARGET_APDS
    from drake_dock.docking.placement.search import pair_couples
    spec, = [p for p in DockingScene(s.geometry, "complete").pairs if p.name == pair]
    c, = pair_couples([spec], {TARGET_APDS: (np.eye(3), np.zeros(3)),
                                CHASER_APDS: a.pose(lam_c)})
    assert c.interior and abs(c.distance) < 1e-9
    eye, zero = np.eye(3), np.zeros(3)
    (R0, p0), (R1, p1) = a.pose(0.45), a.pose(lam_c)
    found = deepest_penetration(s.geometry, np.array([0.0, 1.0]), np.array([[eye, R0], [eye, R1]]),
                                np.array([[zero, p0], [zero, p1]]), ("target", "chaser"),
                                graze=1e-6)
    assert found.depth <= 1e-9


def test_a_crossing_before_the_first_contact_is_a_missed_contact():
    """`check_path` asked to verify a first contact of the complete set 1 cm below the tips'
    meeting of a coaxial 40 deg approach (ring distance 2H - 1 cm): the petals crossed on the
    way, so `MissedContact` names the crossing before it; the paper's set is not checked past
    its closing pairs, and where no pair closes the same crossing is a `NoPairCloses`."""
    from drake_dock.docking.placement.path_check import MissedContact, NoPairCloses, check_path
    from drake_dock.docking.placement.search import FirstContact
    g = _scenario().geometry
    approach = Approach(math.radians(40.0))
    below = FirstContact(2 * g.H - 0.01, ("cc_T1_C5",), 0, 0.45)
    with pytest.raises(MissedContact, match=r"petal \d before its first contact"):
        check_path(PlacementCache(DockingScene(g, "complete")), approach, below)
    check_path(PlacementCache(DockingScene(g, "paper")), approach, below)
    with pytest.raises(NoPairCloses, match=r"petal \d"):
        check_path(PlacementCache(DockingScene(g, "paper")), approach,
                   FirstContact(None, (), 0, 0.45))


def _idss_sample(k):
    from pathlib import Path
    from drake_dock.campaign.plan import load_plan
    from drake_dock.campaign.sample import sample_scenario
    from drake_dock.campaign.points import sample_specs
    models = Path(__file__).resolve().parents[2] / "models"
    plan, base, fields = load_plan(models / "idss_envelope.yaml")
    (_, _, values), = sample_specs(plan, fields, [k])
    return sample_scenario(base, values)


def test_a_fast_sideways_approach_is_placed_at_its_consistent_first_contact():
    """IDSS sample 34 (lateral rate 0.8 of the closing rate): the first contact changes pairs
    with the aim, so a bracket over the whole range closes on a jump; the placement finds the
    root instead. Checked afresh: the path passes the lateral offset at the height of its first
    contact, and that contact is the first on the path (a full scan of every pair agrees)."""
    s = _idss_sample(34)
    a, lam, closing = contact_approach(s)
    ic = s.initial
    h = a.height(lam)
    aim = np.array(ic.lateral_offset) + h * np.array(ic.lateral_velocity) / ic.chaser_speed
    np.testing.assert_allclose(a.aim, aim, atol=1e-6)
    lam_scan, names, _ = full_scan(ApdsGeometry(), a, which=s.contact.pairs)
    assert lam == lam_scan and closing == names


def test_a_seek_that_fails_outside_its_domain_is_marched_as_a_touch_there(monkeypatch):
    """IDSS sample 694: on the straight approach through its axial pose, the chaser ring's
    circle nears the T1 guide surface with its couple outside the domain (distances 1e-2,
    9e-4, 8e-5 m); there its closest-couple Newton creeps (more than 50 iterations). Made to
    fail at that travel, the march takes the failure as a touch outside the domain and goes on
    to the first contact of the search whose seek converges there. The placement is
    consistent (the path passes the offset at its first contact to 1e-8 m |slope|), and its
    first contact is the full scan's, which seeks every pair at every grid point."""
    from drake_dock.errors import SeekingError
    s = _idss_sample(694)
    ic = s.initial
    offset = np.array(ic.lateral_offset)
    slope = np.array(ic.lateral_velocity) / ic.chaser_speed
    a, lam, closing = contact_approach(s)
    np.testing.assert_allclose(np.array(a.aim) - a.height(lam) * slope, offset, rtol=0,
                               atol=1e-8 * np.linalg.norm(slope))
    lam_scan, names, _ = full_scan(s.geometry, a, which=s.contact.pairs)
    assert lam == lam_scan and closing == names
    pair = DockingScene.of(s).pair("cs_Cring_T1")
    failing = Approach(a.yaw, a.tilt, (-0.052305884320687224, -0.09989067043207144),
                       a.direction)
    lam_fail = 0.23063723414045384
    gap, _, dist = seek_gaps([pair], failing, lam_fail, [None])
    assert gap[0] == np.inf and 0 < dist[0] < 1e-4
    converged = _first(s.geometry, failing, s.contact.pairs)
    original, failed = search._seek, []

    def seek(pr, approach, x, ref):
        if pr.name == pair.name and approach == failing and x == lam_fail:
            failed.append(x)
            raise SeekingError("a closest-couple Newton that does not converge")
        return original(pr, approach, x, ref)

    monkeypatch.setattr(search, "_seek", seek)
    again = _first(s.geometry, failing, s.contact.pairs)
    assert (again.lam, again.closing) == (converged.lam, converged.closing) and failed


def test_the_fixed_point_is_a_root_or_the_jump_the_bracket_closes_on():
    """`_consistent_height` on hand-made mismatches: a root where there is one (to xtol), the
    jump where the function jumps across zero (its side with the smaller miss, within that
    miss / `JUMP_SLOPE`), the largest sign change of the grid where the whole range has none,
    and None where nothing changes sign."""
    from drake_dock.docking.placement.aim import JUMP_SLOPE, _consistent_height
    assert _consistent_height(lambda s: 0.3 - 2.0 * s, 0.45) == pytest.approx(0.15, abs=1e-9)
    s_jump = 0.2 + 1e-3 / math.pi
    jump = _consistent_height(lambda s: 0.1 if s < s_jump else -0.05, 0.45)
    assert 0.0 <= jump - s_jump < 0.05 / JUMP_SLOPE
    inner = _consistent_height(lambda s: (s - 0.1) * (s - 0.3), 0.45)   # + - + over the range
    assert inner == pytest.approx(0.3, abs=1e-9)
    assert _consistent_height(lambda s: 1.0 + s, 0.45) is None


def _eager_grid_height(mismatch, s_max, cells=46):
    """The grid fallback of `_consistent_height` evaluated everywhere before the scan (a second
    implementation: the largest grid interval that changes sign, brentq on it)."""
    from scipy.optimize import brentq
    grid = np.linspace(0.0, s_max, cells + 1)
    f = [mismatch(x) for x in grid]
    changes = [k for k in range(cells) if f[k] == 0.0 or f[k] * f[k + 1] < 0]
    if not changes:
        return None
    k = changes[-1]
    return float(grid[k]) if f[k] == 0.0 else brentq(mismatch, grid[k], grid[k + 1], xtol=1e-10)


@pytest.mark.parametrize("a, b", [(0.105, 0.455), (0.1, 0.3), (0.003, 0.2)])
def test_the_grid_fallback_evaluates_from_the_top_and_stops_at_the_first_sign_change(a, b):
    """mismatch(s) = (s - a)(s - b), positive at both ends of [0, 0.46] (no sign change for the
    whole-range brentq): the fallback returns the upper root b (to xtol), the same bits as the
    eager scan, and with b in the top grid interval it evaluates fewer than cells + 1 times."""
    from drake_dock.docking.placement.aim import _consistent_height
    calls = []

    def mismatch(s):
        calls.append(s)
        return (s - a) * (s - b)

    s_max, cells = 0.46, 46
    got = _consistent_height(mismatch, s_max, cells)
    assert got == pytest.approx(b, abs=1e-9)
    assert got == _eager_grid_height(lambda s: (s - a) * (s - b), s_max, cells)
    if b > s_max * (cells - 1) / cells:
        assert len(calls) < cells + 1


def test_a_jump_of_the_first_contact_is_placed_and_its_offset_reported():
    """Random 33 of the conditions sweep (complete set): the first contact jumps next to the
    placement's height s (the mismatch m = h_c - s of the aimed path is 1.9 mm; within
    |m| / `JUMP_SLOPE` of s on one side the first contact lies more than 0.1 mm below the path's
    height, on the other more than 0.1 mm above), so no path near it has the contact at the
    requested offset: the path at the jump is taken, and the ring centre's offset at first
    contact (`contact_offset`, in summary.json) is reported, about a millimetre away. Checked
    afresh: the chosen path's first contact is the full scan's, and the offset is the path's
    lateral position at that contact's height."""
    from drake_dock.docking.placement.aim import JUMP_SLOPE
    from drake_dock.docking.scenario.loading import load_scenario
    from drake_dock.studies.conditions import ConditionsPlan, conditions, with_condition
    base = load_scenario()
    base.contact.pairs = "complete"
    s = with_condition(base, dict(conditions(ConditionsPlan(random=60, corners=16)))["random 33"])
    a, lam, closing = contact_approach(s)
    g = s.geometry
    lam_scan, names, _ = full_scan(g, a, which="complete")
    assert lam == lam_scan and closing == names
    ic = s.initial
    slope = np.array(ic.lateral_velocity) / ic.chaser_speed
    centre = np.array(a.aim) - a.height(lam) * slope
    st = place(s)
    np.testing.assert_allclose(st.contact_offset, centre, atol=1e-15)
    assert np.linalg.norm(centre - np.array(ic.lateral_offset)) > 1e-4
    aimed = (np.array(a.aim) - np.array(ic.lateral_offset)) @ slope / (slope @ slope)
    reach = abs(a.height(lam) - aimed) / JUMP_SLOPE
    assert 1e-5 < reach < 1e-3
    sides = []
    for x in (aimed - reach, aimed + reach):
        near = Approach(a.yaw, a.tilt, tuple((np.array(ic.lateral_offset) + x * slope).tolist()),
                        a.direction)
        sides.append(near.height(_first(g, near, "complete").travel()) - x)
    assert min(sides) < -1e-4 and max(sides) > 1e-4


def _path_depth(g, approach, lam_c):
    """The deepest crossing (`deepest_penetration`, 1 um grazing) on the straight path from the
    search's start down to the first contact."""
    from drake_dock.docking.checks.penetration import deepest_penetration
    (R0, p0), (R1, p1) = approach.pose(travel_grid(g, approach)[0]), approach.pose(lam_c)
    eye, zero = np.eye(3), np.zeros(3)
    return deepest_penetration(g, np.array([0.0, 1.0]), np.array([[eye, R0], [eye, R1]]),
                               np.array([[zero, p0], [zero, p1]]), ("target", "chaser"),
                               graze=1e-6).depth


@pytest.mark.parametrize("name", ["random 26", "random 38", "random 57"])
def test_the_path_to_the_first_contact_is_clear_where_a_pair_closes_inside_a_step(name):
    """Three conditions of the conditions sweep (complete set) whose first contact lies inside a
    step of the travel grid: the ring's inside circle crosses a tip arc next to a petal corner
    and is handed over to the guide surface before the step's end (57, 38), or touches a guide
    surface next to its edge and then cuts it (26). Checked by the independent interpenetration
    check, the straight path down to the placed first contact crosses nothing deeper than 1 um
    (random 26's circle cuts the surface next to a near-tangent touch, where the couple is
    degenerate and its Newton slow). The steps' ends alone miss these contacts: the pair that
    closes is apart (+inf) at one end of its step or the other."""
    from drake_dock.docking.scenario.loading import load_scenario
    from drake_dock.studies.conditions import ConditionsPlan, conditions, with_condition
    base = load_scenario()
    base.contact.pairs = "complete"
    s = with_condition(base, dict(conditions(ConditionsPlan(random=60, corners=16)))[name])
    a, lam, _ = contact_approach(s)
    assert _path_depth(s.geometry, a, lam) < 1e-6


@pytest.mark.parametrize("seed", range(6, 9))
def test_the_path_to_a_random_first_contact_is_clear(seed):
    """The seeded random approaches of the complete set: the path down to the first contact
    crosses nothing (independent interpenetration check)."""
    g = ApdsGeometry()
    approach = _random_approach(np.random.default_rng(seed))
    assert _path_depth(g, approach, _first(g, approach, "complete").lam) < 1e-6


@pytest.mark.parametrize("seed", [0, 14, 32])
def test_lockstep_marches_find_the_full_marches_closings(seed):
    """On the first contact's step of approaches where marches close, the lockstep marches
    (`search._Gaps.marches`, stopped once a march's next sub-step starts 1e-9 below the best closing)
    against each march run over the whole step alone (`march_root`): with no closing known,
    with the best given at the first contact or 5e-10 above it, and with one given below
    every march's closing, the closings within 1e-9 of the first contact are found, each
    equal, in no more seeks."""
    g = ApdsGeometry()
    approach = _random_approach(np.random.default_rng(seed))
    lam_c = _first(g, approach, "complete").lam
    pairs = DockingScene(g, "complete").pairs
    grid = travel_grid(g, approach)
    k = max(i for i in range(len(grid) - 1) if grid[i] >= lam_c)
    touch = search.pair_touch_steps(pairs, approach, grid)
    gaps = search._Gaps(pairs, approach, grid)
    marched = [j for j in np.flatnonzero(touch[:, k])
               if not (0 < gaps.gap(j, k) < np.inf and gaps.gap(j, k + 1) <= 0)
               and abs(gaps.distance(j, k)) < grid[k] - grid[k + 1]]
    full, full_seeks = {}, 0
    for j in marched:
        lam, _, seeks = march_root(pairs[j], approach, grid[k], gaps.at[(j, k)], grid[k + 1],
                                   (grid[k] - grid[k + 1]) / MARCH_SUBSTEPS, 1e-13)
        full_seeks += seeks
        if lam is not None:
            full[j] = lam
    assert full and max(full.values()) == lam_c
    must = {j for j, lam in full.items() if lam >= lam_c - 1e-9}
    for best in (None, lam_c, lam_c + 5e-10, min(full.values()) - 1e-4):
        lockstep = search._Gaps(pairs, approach, grid)
        found = lockstep.marches(marched, k, 1e-13, best)
        assert must <= set(found)
        assert all(found[j] == full[j] for j in found)
        assert lockstep.seeks - sum(1 for key in lockstep.at if key[1] == k) <= full_seeks


@pytest.mark.parametrize("k", [3, 6])
def test_a_march_through_a_cut_finds_the_floor_steps_first_contact_in_fewer_seeks(k):
    """The paper set on IDSS sample k's line, aimed 0.15 m up it: on the way a ring circle cuts
    a petal's guide surface (a crossing that no pair of the set models). Through the cut the
    march's sub-steps double (`CUT_FLOORS`), and the first contact is the one the march at
    1/256 of the step finds (CUT_FLOORS = 1), bit for bit, in less than half the seeks. The
    side is continued from before the cut: taken from the cut's round-off direction, the two
    differ on these lines."""
    from unittest import mock
    ic = _idss_sample(k).initial
    v = np.array([*ic.lateral_velocity, -ic.chaser_speed])
    aim = np.array(ic.lateral_offset) + 0.15 * np.array(ic.lateral_velocity) / ic.chaser_speed
    approach = Approach(math.radians(ic.target_yaw_deg),
                        tuple(math.radians(t) for t in ic.tilt_deg), tuple(aim.tolist()),
                        tuple((v / np.linalg.norm(v)).tolist()))
    g = ApdsGeometry()
    found = {}
    for floors in (search.CUT_FLOORS, 1):
        with mock.patch.object(search, "CUT_FLOORS", floors):
            found[floors] = _first(g, approach)
    cut = found[search.CUT_FLOORS]
    assert (cut.lam, cut.closing) == (found[1].lam, found[1].closing)
    assert 2 * cut.seeks < found[1].seeks


def test_a_seek_that_fails_next_to_a_touch_is_taken_as_touching(monkeypatch):
    """Random 26 of the conditions sweep closes by touch: the target ring's circle meets a
    chaser guide surface (`cs_Tring_C1`) and then cuts it (`search.march_root`). Made to fail
    wherever that pair's couple is interior and nearer than 1e-5 m, its seek is taken as touching there: the
    closing pair is the same, and the first contact moves up to the first point of the travel
    at which the distance falls to 1e-5 m (brentq on the distance less 1e-5 m, to 1e-11 m)."""
    from drake_dock.docking.scenario.loading import load_scenario
    from drake_dock.errors import SeekingError
    from drake_dock.studies.conditions import ConditionsPlan, conditions, with_condition
    base = load_scenario()
    base.contact.pairs = "complete"
    s = with_condition(base, dict(conditions(ConditionsPlan(random=60, corners=16)))["random 26"])
    a, lam, closing = contact_approach(s)
    assert closing == ["cs_Tring_C1"]
    pair, = [pr for pr in DockingScene(s.geometry, "complete").pairs if pr.name == closing[0]]
    original, failed, near = search._seek, [], 1e-5

    def seek(pr, approach, x, ref):
        hit = original(pr, approach, x, ref)
        if pr.name == pair.name and np.isfinite(hit[0]) and hit[2] < near:
            failed.append(x)
            raise SeekingError("a closest-couple Newton that does not converge")
        return hit

    monkeypatch.setattr(search, "_seek", seek)
    found = _first(s.geometry, a, "complete")
    lam_f, names = found.lam, list(found.closing)
    assert names == closing and failed and lam_f > lam
    want = brentq(lambda x: original(pair, a, x, None)[2] - near, lam, lam + 1e-2, xtol=1e-13)
    assert lam_f == pytest.approx(want, abs=1e-11)
