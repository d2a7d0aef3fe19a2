"""The consistent aim of a lateral approach (`contact_approach`): the straight path whose first
contact has the chaser's ring centre at `initial.lateral_offset`. Where several paths do, the
placement takes the highest: the one whose contact is where the chaser, lowered along the axis
over the offset, first touches. Checked against the full scan of every pair (the first
contact), the independent interpenetration check (nothing is crossed above it on the axis)
and the whole-range bracket, which finds another, lower solution."""
import math

import numpy as np
import pytest

from drake_dock.docking.checks.penetration import deepest_penetration
from drake_dock.docking.geometry.scene import DockingScene
from drake_dock.docking.placement.aim import _consistent_height
from drake_dock.docking.placement.place import PlacementCache, contact_approach
from drake_dock.docking.placement.search import Approach
from drake_dock.docking.placement.search import first_contact, travel_grid
from drake_dock.docking.scenario.loading import load_scenario
from drake_dock.studies.conditions import ConditionsPlan, conditions, with_condition
from tests.docking.test_placement import full_scan


def _condition(name):
    base = load_scenario()
    base.contact.pairs = "complete"
    return with_condition(base, dict(conditions(ConditionsPlan(random=60, corners=16)))[name])


def _depth_down_to(g, approach, lam):
    """The deepest crossing (1 um grazing) on the straight path from the search's start down
    to lam."""
    (R0, p0), (R1, p1) = approach.pose(travel_grid(g, approach)[0]), approach.pose(lam)
    eye, zero = np.eye(3), np.zeros(3)
    return deepest_penetration(g, np.array([0.0, 1.0]), np.array([[eye, R0], [eye, R1]]),
                               np.array([[zero, p0], [zero, p1]]), ("target", "chaser"),
                               graze=1e-6).depth


def _height(g, approach) -> float:
    """The height of the first contact of the complete set on ``approach`` (the ring-face
    plane's where none closes), by a search on a cache of its own."""
    found = first_contact(PlacementCache(DockingScene(g, "complete")), approach)
    return approach.height(found.travel())


def _mismatch(g, yaw, tilt, offset, slope, direction):
    """h_c(aim(x)) - x: the first contact's height on the line aimed at offset + x slope,
    less x (the complete set)."""
    def mismatch(x):
        return _height(g, Approach(yaw, tilt, tuple((offset + x * slope).tolist()),
                                   direction)) - x
    return mismatch


@pytest.mark.parametrize("name", ["corner 4", "random 39"])
def test_the_consistent_aim_is_the_highest_solution(name):
    s = _condition(name)
    g, ic = s.geometry, s.initial
    a, lam, closing = contact_approach(s)
    h = a.height(lam)
    offset = np.array(ic.lateral_offset)
    slope = np.array(ic.lateral_velocity) / ic.chaser_speed
    # Consistent: the path passes the offset at its first contact's height, and that contact
    # is the full scan's.
    np.testing.assert_allclose(np.array(a.aim) - h * slope, offset, rtol=0, atol=1e-10)
    lam_scan, names, _ = full_scan(g, a, which="complete")
    assert lam == lam_scan and closing == names
    # Highest: lowered along the axis over the offset, the chaser reaches the placed pose
    # crossing nothing (so no pose above it on that line touches, and no higher solution
    # exists).
    yaw, tilt = math.radians(ic.target_yaw_deg), tuple(math.radians(t) for t in ic.tilt_deg)
    axial = Approach(yaw, tilt, tuple(offset.tolist()))
    for placed, lowered in zip(a.pose(lam), axial.pose(h)):
        np.testing.assert_allclose(placed, lowered, rtol=0, atol=1e-12)
    assert _depth_down_to(g, axial, h) <= 1e-9

    mismatch = _mismatch(g, yaw, tilt, offset, slope, a.direction)
    # The whole-range bracket closes on another solution, more than 1 cm lower.
    lower = _consistent_height(mismatch, 2.0 * g.H + 0.05)
    assert lower < h - 0.01 and abs(mismatch(lower)) <= 1e-9


def _placed_and_axial(name):
    """The condition's geometry, offset, slope, placement (`contact_approach`), yaw and tilt
    (rad), and the height h_axial where the chaser, lowered along the axis over the offset,
    first touches."""
    s = _condition(name)
    g, ic = s.geometry, s.initial
    offset = np.array(ic.lateral_offset)
    slope = np.array(ic.lateral_velocity) / ic.chaser_speed
    yaw, tilt = math.radians(ic.target_yaw_deg), tuple(math.radians(t) for t in ic.tilt_deg)
    axial = Approach(yaw, tilt, tuple(offset.tolist()))
    h_axial = _height(g, axial)
    return g, offset, slope, contact_approach(s), yaw, tilt, h_axial


@pytest.mark.parametrize("name", ["random 4", "random 42"])
def test_an_axial_pose_the_approach_does_not_first_touch_is_not_taken(name):
    """Random 4 and 42 (a petal corner on a ring): the straight approach through the pose where
    the chaser, lowered along the axis over the offset, first touches does not first touch
    there (tens of micrometres away), so that pose is not the placement. The secant steps from
    it (`_local_height`) find a path that passes the offset at its first contact to
    1e-8 m |slope|, within twice that first miss of the axial height, and that contact is the
    full scan's."""
    g, offset, slope, (a, lam, closing), yaw, tilt, h_axial = _placed_and_axial(name)
    through = Approach(yaw, tilt, tuple((offset + h_axial * slope).tolist()), a.direction)
    h_through = _height(g, through)
    assert abs(h_through - h_axial) > 1e-6
    np.testing.assert_allclose(np.array(a.aim) - a.height(lam) * slope, offset, rtol=0,
                               atol=1e-8 * np.linalg.norm(slope))
    assert abs(a.height(lam) - h_axial) <= 2.0 * abs(h_through - h_axial)
    lam_scan, names, _ = full_scan(g, a, which="complete")
    assert lam == lam_scan and closing == names


@pytest.mark.parametrize("line", ["axial", "through"])
def test_a_failed_seek_on_a_shortcut_leaves_the_aim_to_the_bracket(monkeypatch, line):
    """The first try and the secant steps are a shortcut: where a seek fails (`SeekingError`)
    on the axial line, or on the straight approach through the axial pose (the first try's
    mismatch), the placement is the whole-range bracket's, to the bit, and still consistent to
    1e-10 m."""
    from drake_dock.docking.placement import search
    from drake_dock.errors import SeekingError
    g, offset, slope, (a0, _, _), yaw, tilt, h_axial = _placed_and_axial("random 2")
    failing = {"axial": Approach(yaw, tilt, tuple(offset.tolist())),
               "through": Approach(yaw, tilt, tuple((offset + h_axial * slope).tolist()),
                                   a0.direction)}[line]
    original = search._search

    def failing_on_the_line(scene, approach, *rest):
        if approach == failing:
            raise SeekingError("a closest-couple Newton that does not converge")
        return original(scene, approach, *rest)

    mismatch = _mismatch(g, yaw, tilt, offset, slope, a0.direction)
    expected = _consistent_height(mismatch, 2.0 * g.H + 0.05)
    monkeypatch.setattr(search, "_search", failing_on_the_line)
    a, lam, _ = contact_approach(_condition("random 2"))
    assert a.aim == tuple((offset + expected * slope).tolist())
    np.testing.assert_allclose(np.array(a.aim) - a.height(lam) * slope, offset, rtol=0,
                               atol=1e-10)


def test_a_closing_by_touch_is_placed_by_the_first_try():
    """Random 26 (the target ring's circle touching a chaser guide surface and then cutting
    it, `search.march_root`): the straight approach through the axial pose first touches within
    `AIM_TOL` of h_axial, so that pose is the placement: its aim is offset + h_axial slope, bit
    for bit. On the full scan (a second search) the mismatch next to h_axial is smooth in the
    aim: its slope over 2e-9 m agrees with its slope over 2e-7 m to 1 %, and its root lies
    within 1e-11 m of h_axial."""
    g, offset, slope, (a, _, _), yaw, tilt, h_axial = _placed_and_axial("random 26")
    assert a.aim == tuple((offset + h_axial * slope).tolist())
    m = {}
    for dx in (-1e-7, -1e-9, 0.0, 1e-9, 1e-7):
        x = h_axial + dx
        near = Approach(yaw, tilt, tuple((offset + x * slope).tolist()), a.direction)
        m[dx] = near.height(full_scan(g, near, which="complete")[0]) - x
    wide = (m[1e-7] - m[-1e-7]) / 2e-7
    narrow = (m[1e-9] - m[-1e-9]) / 2e-9
    assert abs(narrow / wide - 1.0) < 0.01
    assert abs(m[0.0] / wide) < 1e-11
