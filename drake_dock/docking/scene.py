"""The docking scene's initial configuration (Sect. 8.2): the chaser placed on its straight
approach at the scenario's travel before the first contact (`drake_dock.docking.search`),
with the consistent aim for a lateral velocity, and its path checked."""
from __future__ import annotations

import dataclasses
import math

import numpy as np
from scipy.optimize import brentq

from drake_dock.core.seeking import contact_couple
from drake_dock.docking.apds import ApdsGeometry
from drake_dock.docking.pairs import (CHASER_APDS, R_MATCHED, TARGET_APDS,  # noqa: F401
                                      PairSpec, apds_pairs)
from drake_dock.docking.path_check import (MissedContact, NoPairCloses,  # noqa: F401
                                           check_free_approach, check_path_to_contact)
from drake_dock.docking.rotations import rot_vec, rot_x, rot_z  # noqa: F401 (re-exported)
from drake_dock.docking.search import (COVER_CELLS, MARCH_SUBSTEPS,  # noqa: F401 (re-exported)
                                       TOUCH_GAP, Approach, first_contact,
                                       first_contact_above, first_contact_distance,
                                       first_contact_or_faces,
                                       first_contact_seeks, march_root, march_steps,
                                       pair_couples, pair_covers, relative_pose, search_pairs,
                                       seek_gaps, signed_gaps, touch_steps, travel_grid)
from drake_dock.errors import InputError, SeekingError
from drake_dock.systems.contact_types import ContactOptions


@dataclasses.dataclass
class InitialState:
    """World poses (R, p) and spatial velocities (w, v) of the three bodies at t = 0."""

    X_WB: dict
    V_WB: dict
    d_contact: float           # ring-face distance at first contact
    d0: float                  # initial ring-face distance
    closing_pairs: list
    contact_offset: tuple = (0.0, 0.0)   # the ring centre's lateral offset at first contact


def initial_state(scenario) -> InitialState:
    """Sect. 8.2 (docs/model.md): the target at the origin turned by yaw about its docking axis,
    its APDS at the Stewart element's equilibrium, the chaser coaxial at ring-face distance
    d_contact + approach_travel, moving at chaser_speed towards the target; all else at rest.
    Raises `InputError` for a capture distance not below that initial ring distance."""
    ic = scenario.initial
    if ic.approach_travel < 0:
        raise InputError("initial.approach_travel", ic.approach_travel,
                         ">= 0 m (a negative travel means initial interpenetration)")
    approach, d_c, closing = contact_approach(scenario)
    d0 = d_c + ic.approach_travel
    cap = scenario.simulation.capture_distance
    if not cap < d0:
        raise InputError("simulation.capture_distance", cap,
                         f"< the initial ring distance {d0:.6g} m (first contact at {d_c:.6g} m "
                         f"+ initial.approach_travel {ic.approach_travel:g} m)",
                         "capture would hold from t = 0 and never be detected: the rings would "
                         "pass through each other")
    yaw = math.radians(ic.target_yaw_deg)
    R_WT, p_WT = rot_z(yaw), np.zeros(3)
    p_TA = np.asarray(scenario.stewart.p_TA, dtype=float)
    R_WA, p_WA = R_WT, p_WT + R_WT @ p_TA
    R_AC, p_AC = approach.pose(d0)
    R_WCA, p_WCA = R_WA @ R_AC, p_WA + R_WA @ p_AC
    # Chaser body: its APDS frame sits at chaser_apds_offset in the body frame, same axes.
    p_C_CA = np.asarray(scenario.chaser_apds_offset, dtype=float)
    R_WC, p_WC = R_WCA, p_WCA - R_WCA @ p_C_CA
    zero = np.zeros(3)
    if ic.lateral_velocity == [0.0, 0.0] and ic.angular_velocity_deg_s == [0.0, 0.0, 0.0]:
        w_WC, v_WC = zero, -ic.chaser_speed * R_WA[:, 2]
    else:
        # The ring centre moves at (lateral_velocity, -chaser_speed); the chaser's mass centre
        # adds w x (p_WC - p_WCA).
        w_WC = R_WA @ np.radians(ic.angular_velocity_deg_s)
        v_ring = R_WA @ np.array([*ic.lateral_velocity, -ic.chaser_speed])
        v_WC = v_ring + np.cross(w_WC, p_WC - p_WCA)
    return InitialState(
        X_WB={"target": (R_WT, p_WT), "target_apds": (R_WA, p_WA), "chaser": (R_WC, p_WC)},
        V_WB={"target": (zero, zero), "target_apds": (zero, zero), "chaser": (w_WC, v_WC)},
        d_contact=d_c, d0=d0, closing_pairs=closing,
        contact_offset=tuple((np.array(approach.aim) - approach.height(d_c) * np.array(
            ic.lateral_velocity) / ic.chaser_speed).tolist()))


def contact_approach(scenario):
    """The scenario's straight approach and its first contact: (Approach, lam_c, closing
    pairs of the scenario's contact set; lam_c = 0 and none where no pair closes and the ring
    faces meet first). The lateral offset is the ring centre's at first contact. With a
    lateral velocity the aim point (where the path meets the target's ring-face plane) is
    aim = offset + s v_lateral / chaser_speed, where s, the ring-face distance at contact, solves
    s = h_c(aim(s)). Its first try is `_axial_height`, the highest s any solution can have,
    taken where |h_c(aim(s)) - s| <= `AIM_TOL`; then secant steps from it (`_local_height`);
    otherwise (or where a seek on the way fails) a bracket over the whole range
    (`_consistent_height`). A bracket is closed among the pairs that close at its ends
    (`_among_height`)."""
    ic = scenario.initial
    g = scenario.geometry
    which = scenario.contact.pairs
    yaw = math.radians(ic.target_yaw_deg)
    tilt = tuple(math.radians(t) for t in ic.tilt_deg)
    v = np.array([*ic.lateral_velocity, -ic.chaser_speed])
    direction = tuple((v / np.linalg.norm(v)).tolist()) if v[0] or v[1] else (0.0, 0.0, -1.0)
    offset = np.array(ic.lateral_offset, dtype=float)
    slope = np.array(ic.lateral_velocity) / ic.chaser_speed

    def approach(s):
        return Approach(yaw, tilt, tuple((offset + s * slope).tolist()), direction)

    s = 0.0
    if slope.any():
        s_max = 2.0 * g.H + 0.05
        mismatch = _Mismatch(g, which, approach)
        s = _axial_height(g, Approach(yaw, tilt, tuple(offset.tolist())), which)
        if s is not None:
            try:
                s = _local_height(mismatch, s, s_max, _among_height)
            except SeekingError:          # a shortcut: the whole-range bracket decides
                s = None
        if s is None:
            s = _consistent_height(mismatch, s_max, bracket=_among_height)
        if s is None:
            raise NoPairCloses(
                f"no straight approach at initial.lateral_velocity {ic.lateral_velocity} m/s "
                f"has its first contact (contact.pairs: {which}) at or before "
                f"initial.lateral_offset {ic.lateral_offset} m")
    a = approach(s)
    lam_c, closing = first_contact_or_faces(g, a, which)
    if not closing:
        check_free_approach(g, a, which, travel_grid(g, a)[0])
    elif which == "complete":
        check_path_to_contact(g, a, travel_grid(g, a)[0], lam_c,
                              line=not _isolated(g, a, lam_c, closing))
    return a, lam_c, closing


# The consistent aim's first try and secant steps are taken where |h_c(aim(s)) - s| is within
# this (m; `contact_approach`): the ring centre at first contact then lies within
# AIM_TOL |slope| of the offset. Ten times `TOUCH_GAP`: a closing by touch (`_touch`) is
# resolved to about TOUCH_GAP over the gap's rate, or, where a seek next to the touch fails,
# to the bracket in which it failed.
AIM_TOL = 1e-8


def _axial_height(g: ApdsGeometry, axial: Approach, which) -> float:
    """The ring-face distance at which the chaser, lowered along the docking axis with its ring
    centre over the offset (``axial``), first touches the target APDS (0 where the faces meet
    first; below 0 where a pair closes past the face plane). Above it the chaser touches
    nothing there, so no straight approach can have its first contact with the ring centre at
    the offset higher up: where the approach through this pose first touches at it, it is the
    highest solution of the consistent aim. (Highest as far as a closing does not depend on
    the line the pose is reached along: a couple that becomes interior already cutting a
    surface does not close.) None where a seek on that line fails (`SeekingError`): the try is
    a shortcut, and the whole-range bracket decides."""
    try:
        return axial.height(first_contact_or_faces(g, axial, which)[0])
    except SeekingError:
        return None


def _isolated(g: ApdsGeometry, approach: Approach, lam: float, names) -> bool:
    """True when a pair of ``names`` has a usable couple at lam (interior and isolated by the
    contact system's rule, `contact_couple` with the default `ContactOptions.conditioning_min`):
    a point contact that the simulation follows, and past which the features cross. Coaxial
    arcs of one radius (a ring's inside circle at a tip arc, a tip arc on a tip arc) touch
    along an arc and have none."""
    R, p = approach.pose(lam)
    poses = {TARGET_APDS: (np.eye(3), np.zeros(3)), CHASER_APDS: (R, p)}
    for pr in search_pairs(dataclasses.astuple(g), "complete"):
        if pr.name in names:
            X1, X2 = poses[pr.body1], poses[pr.body2]
            c = pair_couples([pr], poses)[0]
            f = contact_couple(pr.kind, pr.patch1, X1, pr.patch2, X2, c,
                               conditioning_min=ContactOptions.conditioning_min)
            if f.usable:
                return True
    return False


# Secant steps of the consistent aim from the axial height (`_local_height`).
LOCAL_STEPS = 3


class _Mismatch:
    """m(s) = h_c(aim(s)) - s of `contact_approach` for the approaches ``approach(s)``, with
    the whole contact set, or among some of its pairs (`among`)."""

    def __init__(self, g, which, approach):
        self.g, self.which, self.approach = g, which, approach

    def __call__(self, s):
        return self.among(s, None)[0]

    def among(self, s, names):
        """(m(s), the closing pairs) with only the pairs ``names`` sought (all where None)."""
        a = self.approach(s)
        lam, closing = first_contact_or_faces(self.g, a, self.which, names)
        return a.height(lam) - s, closing

    def below(self, s, T):
        """None where m(s) < -T (T < s): no pair closes at the height s - T or above, found
        by a search that stops there; otherwise (m(s), the closing pairs)."""
        a = self.approach(s)
        lam, closing = first_contact_above(self.g, a, self.which, (s - T) / a.height(1.0))
        return None if lam is None else (a.height(lam) - s, closing)


def _among_height(mismatch, a, b):
    """`_bracketed_height` on [a, b] with the mismatch among the pairs that close at a and b
    (each search a few pairs' cost), checked with the whole set. Where a pair among them
    closes, a first contact among them is never higher than the set's, so m >= m_among, equal
    where the set's first contact is one of them. The end taken is evaluated with the set; so
    is the jump's other end n where m_among(n) < 0 (where it is > 0, m(n) is too, and no
    smaller: the jump holds for m), as far as it must: m(n) < -|m(end)| leaves the jump
    (narrower than |m(end)| / `JUMP_SLOPE`) and the end taken as they are
    (`_Mismatch.below`). Where a check differs, its closing pairs join the names (the whole
    set where they add none) and the bracket is closed again; so it is with the whole set
    where a search among the names fails (`SeekingError`: such a search goes on below the
    set's first contact). The result is a root or a jump of m by `_bracketed_height`'s rule;
    where the set's first contact at every point the bracket evaluates is among the names, it
    is the bracket's with the set, and elsewhere it may lie at another jump."""
    ends = {a: mismatch.among(a, None), b: mismatch.among(b, None)}
    names = frozenset(ends[a][1]) | frozenset(ends[b][1])
    while True:
        try:
            end, other = _bracket_ends(
                lambda x: ends[x][0] if x in ends else mismatch.among(x, names)[0], a, b)
            checked = [(mismatch.among(end, None), mismatch.among(end, names)[0])]
            if other is not None:
                m_among, closing_among = mismatch.among(other, names)
                T = abs(checked[0][0][0])
                # T < n keeps the stop above the face plane; a positive m_among has a closing.
                if m_among < 0 and T < other:
                    checked.append((mismatch.below(other, T), m_among))
                elif not (m_among > 0 and closing_among):      # else m >= m_among > 0
                    checked.append((mismatch.among(other, None), m_among))
        except SeekingError:
            if names is None:
                raise
            names = None
            continue
        differ = [full for full, m in checked if full is not None and full[0] != m]
        if not differ or names is None:
            return end
        grown = names.union(*(full[1] for full in differ))
        names = grown if grown != names else None


def _local_height(mismatch, s0, s_max, bracket=None):
    """The consistent aim next to the axial height s0 (`_axial_height`): s0 where
    |mismatch(s0)| <= `AIM_TOL`; otherwise up to `LOCAL_STEPS` secant steps, the first with
    slope -1 (h_c flat: s1 = s0 + mismatch(s0)), each taken where |mismatch| <= `AIM_TOL` and
    bracketed (`_bracketed_height`) where the mismatch changes sign. None where they neither
    meet nor bracket a root, or a step leaves [0, s_max]: the whole-range bracket decides.
    Where mismatch(s0) > 0 the first step goes up, where no solution lies (`_axial_height`):
    a bracket there closes on the jump of the first contact nearest s0, which is taken. A root
    below s0 would lie between two sign changes of a mismatch positive at s0 and at 0, which
    no bracket finds. ``bracket`` closes a sign change (`_bracketed_height` where None)."""
    bracket = bracket or _bracketed_height
    m0 = mismatch(s0)
    if abs(m0) <= AIM_TOL:
        return s0
    s1 = s0 + m0
    for _ in range(LOCAL_STEPS):
        if not 0.0 <= s1 <= s_max:
            return None
        m1 = mismatch(s1)
        if abs(m1) <= AIM_TOL:
            return s1
        if m1 * m0 < 0:
            return bracket(mismatch, min(s0, s1), max(s0, s1))
        if m1 == m0:
            return None
        s0, m0, s1 = s1, m1, s1 - m1 * (s1 - s0) / (m1 - m0)
    return None


# A bracket of the mismatch narrower than min(|m(a)|, |m(b)|) / JUMP_SLOPE holds a jump of the
# first contact and no root, as far as no branch of h_c(aim(s)) - s changes by more than
# JUMP_SLOPE m per m of s (`_bracketed_height`).
JUMP_SLOPE = 10.0


class _Jump(Exception):
    """The bracket holds a jump (`JUMP_SLOPE`); args: the end taken and the other end."""


def _bracketed_height(mismatch, a, b):
    """brentq to 1e-10 m on [a, b], stopped on a jump: as soon as a point it evaluates and
    its neighbour of the other sign are closer than the smaller |mismatch| of the two over
    `JUMP_SLOPE`, neither end's branch can reach zero between them, and the one with the
    smaller |mismatch| is taken (the higher on a tie). ValueError where mismatch(a) and
    mismatch(b) have one sign."""
    return _bracket_ends(mismatch, a, b)[0]


def _bracket_ends(mismatch, a, b):
    """`_bracketed_height` and the jump's other end: (s, None) for a root, (s, n) for a jump
    left at s."""
    seen = {}

    def f(s):
        m = seen[s] = mismatch(s)
        xs = sorted(seen)
        i = xs.index(s)
        for n in xs[max(i - 1, 0):i] + xs[i + 1:i + 2]:
            if seen[n] * m < 0 and abs(n - s) * JUMP_SLOPE < min(abs(m), abs(seen[n])):
                end = min((s, n), key=lambda x: (abs(seen[x]), -x))
                raise _Jump(end, n if end == s else s)
        return m

    try:
        return brentq(f, a, b, xtol=1e-10), None
    except _Jump as jump:
        return jump.args


def _consistent_height(mismatch, s_max, cells=46, bracket=None):
    """The ring-face distance s in [0, s_max] with mismatch(s) = h_c(aim(s)) - s = 0, bracketed
    over the whole range (`_bracketed_height`); where that range has no sign change, on the
    largest sign change of a grid of ``cells`` intervals. The first contact h_c jumps where it
    passes from one pair or feature to another, so the bracket may close on a jump instead of a
    root: the path at the jump is taken, and the ring centre at first contact then misses the
    offset by |mismatch(s)| |v_lateral| / chaser_speed (`InitialState.contact_offset`). None
    where no grid interval changes sign. ``bracket`` closes a sign change
    (`_bracketed_height` where None)."""
    bracket = bracket or _bracketed_height
    try:
        return bracket(mismatch, 0.0, s_max)
    except ValueError:                                  # no sign change over the range
        pass
    grid = np.linspace(0.0, s_max, cells + 1)
    f_above = mismatch(grid[cells])                     # scanned from the top, evaluated lazily
    for k in range(cells - 1, -1, -1):
        f_k = mismatch(grid[k])
        if f_k == 0.0:
            return float(grid[k])
        if f_k * f_above < 0:
            return bracket(mismatch, grid[k], grid[k + 1])
        f_above = f_k
    return None
