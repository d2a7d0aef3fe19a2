"""The consistent aim of a straight approach with a lateral velocity (docs/model.md, "Initial
conditions"): the ring-face distance s at first contact for which the approach aimed at
aim(s) = offset + s v_lateral / chaser_speed has its first contact at s (`aim_height`)."""
from __future__ import annotations

import numpy as np
from scipy.optimize import brentq

from drake_dock.docking.placement.search import Approach
from drake_dock.docking.placement.search import first_contact
from drake_dock.errors import SeekingError


def aim_height(cache, approach, axial: Approach, s_max: float) -> float | None:
    """The ring-face distance s in [0, s_max] at first contact of the consistent aim:
    ``approach(s)`` is the approach aimed at aim(s), ``axial`` the chaser lowered along the
    docking axis with its ring centre over the offset; the searches in ``cache`` (a
    `PlacementCache`). Its first try is `_axial_height`, the highest s any solution can have,
    taken where |h_c(aim(s)) - s| <= `AIM_TOL`; then secant steps from it (`_local_height`);
    otherwise (or where a seek on the way fails) a bracket over the whole range
    (`_consistent_height`). A bracket is closed among the pairs that close at its ends
    (`_among_height`). None where no s is found."""
    mismatch = _Mismatch(cache, approach)
    s = _axial_height(cache, axial)
    if s is not None:
        try:
            s = _local_height(mismatch, s, s_max, _among_height)
        except SeekingError:          # a shortcut: the whole-range bracket decides
            s = None
    if s is None:
        s = _consistent_height(mismatch, s_max, bracket=_among_height)
    return s


# The consistent aim's first try and secant steps are taken where |h_c(aim(s)) - s| is within this
# (m; `aim_height`): the ring centre at first contact then lies within AIM_TOL |slope| of the
# offset. Ten times `TOUCH_GAP`: a closing by touch
# (`drake_dock.docking.placement.search.march_root`) is resolved to about TOUCH_GAP over the gap's
# rate, or, where a seek next to the touch fails, to the bracket in which it failed.
AIM_TOL = 1e-8


def _axial_height(cache, axial: Approach) -> float:
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
        return axial.height(first_contact(cache, axial).travel())
    except SeekingError:
        return None


# Secant steps of the consistent aim from the axial height (`_local_height`).
LOCAL_STEPS = 3


class _Mismatch:
    """m(s) = h_c(aim(s)) - s of `aim_height` for the approaches ``approach(s)``, with the
    scene's whole contact set, or among some of its pairs (`among`); the searches in the
    placement's ``cache``."""

    def __init__(self, cache, approach):
        self.cache, self.approach = cache, approach

    def __call__(self, s):
        return self.among(s, None)[0]

    def among(self, s, names):
        """(m(s), the closing pairs) with only the pairs ``names`` sought (all where None)."""
        a = self.approach(s)
        found = first_contact(self.cache, a, among=names)
        return a.height(found.travel()) - s, list(found.closing)

    def below(self, s, T):
        """None where m(s) < -T (T < s): no pair closes at the height s - T or above, found
        by a search that stops there; otherwise (m(s), the closing pairs)."""
        a = self.approach(s)
        found = first_contact(self.cache, a, stop=(s - T) / a.height(1.0))
        return None if found.lam is None else (a.height(found.lam) - s, list(found.closing))


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
