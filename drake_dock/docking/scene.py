"""The docking scene as a configuration of the generic core: the 12 contact pairs of Sect. 2.2
and 8.1, the facing of the two APDSes and the initial configuration of Sect. 8.2."""
from __future__ import annotations

import dataclasses
import functools
import math

import numpy as np
from scipy.optimize import brentq

from drake_dock.core import covers
from drake_dock.core.kernels import cover as compiled_cover
from drake_dock.core.kernels import seek as compiled_seek
from drake_dock.core.patches import posed
from drake_dock.core.seeking import contact_couple, seek_couple
from drake_dock.docking.apds import ApdsGeometry
from drake_dock.docking.pairs import (CHASER_APDS, R_MATCHED, TARGET_APDS, PairSpec,
                                      apds_pairs)
from drake_dock.docking.path_check import (MissedContact, NoPairCloses,  # noqa: F401
                                           check_free_approach, check_path_to_contact)
from drake_dock.docking.rotations import rot_vec, rot_x, rot_z  # noqa: F401 (re-exported)
from drake_dock.errors import InputError, SeekingError
from drake_dock.systems.contact_types import ContactOptions

def relative_pose(yaw_rad: float, d: float):
    """Pose (R, p) of the chaser APDS in the target APDS frame: coaxial, ring faces d apart,
    the target (with its APDS) turned by yaw about the axis from the matched facing."""
    return rot_z(-yaw_rad) @ R_MATCHED, np.array([0.0, 0.0, d])


@dataclasses.dataclass(frozen=True)
class Approach:
    """A straight relative approach of the chaser APDS in the target APDS frame: turned by
    yaw about the axis and tilted by the rotation vector ``tilt`` (rad, x-y plane, through its
    ring centre) from the matched facing; its ring centre on the line aim - lam * direction,
    where ``direction`` is the unit relative velocity (z < 0) and ``aim`` lies in the target's
    ring-face plane. Coaxial along the axis: lam is the ring-face distance."""

    yaw: float
    tilt: tuple = (0.0, 0.0)
    aim: tuple = (0.0, 0.0)
    direction: tuple = (0.0, 0.0, -1.0)

    def pose(self, lam: float):
        R, p = relative_pose(self.yaw, lam)
        if self.tilt != (0.0, 0.0):
            R = rot_vec((*self.tilt, 0.0)) @ R
        if self.aim != (0.0, 0.0) or self.direction != (0.0, 0.0, -1.0):
            p = np.array([*self.aim, 0.0]) - lam * np.asarray(self.direction)
        return R, p

    def height(self, lam: float) -> float:
        """Ring-face distance along the axis at lam."""
        return -lam * self.direction[2]


def pair_couples(pairs, poses, **grid):
    """Seeks the closest couple of every pair; ``poses`` maps body name -> (R_WB, p_WB). The
    compiled seek (`drake_dock.core.kernels.seek`) where the patches have kernel descriptions."""
    out = []
    for pr in pairs:
        P1, P2 = posed(pr.patch1, *poses[pr.body1]), posed(pr.patch2, *poses[pr.body2])
        seek = compiled_seek.seek_couple if compiled_seek.supported(P1, P2) else seek_couple
        out.append(seek(P1, P2, **grid))
    return out


def signed_gaps(pairs, approach, d, refs):
    """Signed gaps of the pairs at ring-face distance d. A pair is a potential contact only
    while its couple is interior (see `is_interior`); otherwise its gap is +inf and its side
    reference is dropped. The sign is fixed by the side the couple lies on when the pair becomes
    potential (docs/model.md) and continued from ``refs`` (the previous unit directions)."""
    gaps, dirs, _ = seek_gaps(pairs, approach, d, refs)
    return gaps, dirs


def seek_gaps(pairs, approach, d, refs):
    """`signed_gaps` and the distance of each pair's couple, interior or not (the least
    distance of the two bounded features)."""
    R, p = approach.pose(d)
    poses = {TARGET_APDS: (np.eye(3), np.zeros(3)), CHASER_APDS: (R, p)}
    out, dirs, dist = [], [], []
    for cp, ref in zip(pair_couples(pairs, poses), refs):
        dist.append(cp.distance)
        if not cp.interior:
            out.append(np.inf)
            dirs.append(None)
            continue
        v = cp.p1 - cp.p2
        s = 1.0 if ref is None or v @ ref >= 0 else -1.0
        out.append(s * cp.distance)
        dirs.append(s * v / max(cp.distance, 1e-300))
    return np.array(out), dirs, np.array(dist)


def first_contact_distance(g: ApdsGeometry, yaw_deg: float, *, step=None, xtol=1e-13):
    """Ring-face distance d at which the first of the 12 pairs closes when the chaser moves
    along the axis from far away; returns (d, names of the pairs that close at d within 1e-9)."""
    return first_contact(g, Approach(math.radians(yaw_deg)), step=step, xtol=xtol)


def first_contact(g: ApdsGeometry, approach: Approach, *, step=None, xtol=1e-13,
                  which="paper"):
    """Line parameter lam at which the first of the pairs of the set ``which`` (`apds_pairs`)
    closes when the chaser comes along ``approach`` from far away; returns (lam, names of the
    pairs that close within 1e-9). The
    search steps the ring-face distance by 1 cm, or by 1/100 of its start distance for a larger
    APDS (H > 0.475 m), so that it takes at most about 100 steps; a pair is sought only at the
    ends of the steps its patches can touch in (`touch_steps`), and marched through a step
    whose travel its couple comes within (`march_root`). Remembered per geometry and approach
    (a pure function of them)."""
    lam_c, names, _ = _first_contact(dataclasses.astuple(g), approach, step, xtol, which)
    if lam_c is None:
        raise NoPairCloses(f"no pair closes on the approach {approach}")
    return lam_c, list(names)


def first_contact_or_faces(g: ApdsGeometry, approach: Approach, which="paper"):
    """`first_contact`, or, when no pair of the set closes on the approach, where the rings'
    faces meet (lam = 0, the ring-face plane; no closing pair): docs/model.md, "Initial
    conditions"."""
    lam_c, names, _ = _first_contact(dataclasses.astuple(g), approach, None, 1e-13, which)
    return (0.0, []) if lam_c is None else (lam_c, list(names))


def first_contact_seeks(g: ApdsGeometry, approach: Approach, *, step=None, xtol=1e-13,
                        which="paper") -> int:
    """The number of seeks `first_contact` takes (or took) for this geometry and approach."""
    return _first_contact(dataclasses.astuple(g), approach, step, xtol, which)[2]


def travel_grid(g: ApdsGeometry, approach: Approach, step=None):
    """The search's travel points lam_0 > lam_1 > ... (lam_{k+1} = lam_k - step), from the
    height 2 H + 0.05 where every pair is apart (petals do not overlap axially) to the first
    point at a height of -H or below."""
    per_height = 1.0 / approach.height(1.0)
    d = (2.0 * g.H + 0.05) * per_height
    step = max(1e-2, (2.0 * g.H + 0.05) / 100) * per_height if step is None else step
    grid = [d]
    while approach.height(d) > -g.H:
        d = d - step
        grid.append(d)
    return grid


# Covers of the search (`drake_dock.core.covers`): cells per parameter and per block.
COVER_CELLS = {0: (1, 1), 1: (256, 16), 2: (32, 8)}


def pair_covers(pr: PairSpec):
    """The covers of a pair's two patches (`COVER_CELLS`), compiled where the patches have
    kernel descriptions."""
    out = []
    for patch in (pr.patch1, pr.patch2):
        cells = COVER_CELLS[patch.dim]
        out.append(compiled_cover.patch_cover(patch, *cells) or covers.patch_cover(patch, *cells))
    return out


def touch_steps(pairs, approach: Approach, grid):
    """Booleans (pairs, steps): the covers of pair j's patches can touch between grid[k] and
    grid[k + 1] (`drake_dock.core.covers.touch_steps`); elsewhere the pair is apart."""
    R, p0 = approach.pose(0.0)
    e = -(approach.pose(1.0)[1] - p0)            # the chaser's points move by -lam e
    grid = np.asarray(grid, dtype=float)
    out = np.zeros((len(pairs), len(grid) - 1), dtype=bool)
    for j, pr in enumerate(pairs):
        c1, c2 = pair_covers(pr)
        moving, fixed = (c1, c2) if pr.body1 == CHASER_APDS else (c2, c1)
        out[j] = compiled_cover.touch_steps(moving.posed(R, p0), fixed, e, grid)
    return out


class _Gaps:
    """The signed gaps and distances (`seek_gaps`) of the pairs at the travel grid's points,
    sought on demand and counted. A pair's side is continued from the grid point before when
    it was sought there; otherwise the pair was apart since its last seek and keeps the side
    it lies on."""

    def __init__(self, pairs, approach, grid):
        self.pairs, self.approach, self.grid = pairs, approach, grid
        self.at = {}                                   # (j, k) -> (gap, direction, distance)
        self.seeks = 0

    def _hit(self, j, k):
        hit = self.at.get((j, k))
        if hit is None:
            before = self.at.get((j, k - 1))
            ref = None if before is None else before[1]
            hit = self.at[(j, k)] = _seek(self.pairs[j], self.approach, self.grid[k], ref)
            self.seeks += 1
        return hit

    def gap(self, j, k):
        return self._hit(j, k)[0]

    def distance(self, j, k):
        return self._hit(j, k)[2]

    def root(self, j, k, xtol):
        """brentq on the step from grid[k] down to grid[k + 1] for pair j, its side from
        grid[k]; the two ends are the grid's gaps."""
        ref = self.at[(j, k)][1]
        ends = {self.grid[k]: self.gap(j, k), self.grid[k + 1]: self.gap(j, k + 1)}

        def f(dd):
            if dd in ends:
                return ends[dd]
            self.seeks += 1
            return signed_gaps([self.pairs[j]], self.approach, dd, [ref])[0][0]

        return brentq(f, self.grid[k + 1], self.grid[k], xtol=xtol, rtol=1e-15)

    def march(self, j, k, xtol):
        """`march_root` over the step from grid[k]; the side at grid[k + 1] is the march's."""
        hi, lo = self.grid[k], self.grid[k + 1]
        lam, end, seeks = march_root(self.pairs[j], self.approach, hi, self._hit(j, k), lo,
                                     (hi - lo) / MARCH_SUBSTEPS, xtol)
        self.seeks += seeks
        if end is not None:
            self.at[(j, k + 1)] = end
        return lam


# The march of `march_root` takes at most this many sub-steps per step of the grid.
MARCH_SUBSTEPS = 256
# Two features touch below this distance, their couple interior or not (m, `march_root`).
TOUCH_GAP = 1e-9


def march_root(pair, approach, hi, start, lo, floor, xtol):
    """The first closing of the pair on the travel from hi down to lo, where the grid's two
    ends cannot see it: a couple that enters or leaves its domain inside the step (a ring
    crossing a tip arc next to a petal corner and handed over to the guide surface; a circle
    meeting a guide surface next to its edge leaves the domain as its gap reaches 0, since past
    it the circle cuts the surface). ``start`` = (gap, direction, distance) at hi. The chaser
    translates along the approach, so features a distance D apart cannot touch within a travel
    of D: each sub-step is max(D, ``floor``), the side continued. From an interior gap above
    `TOUCH_GAP`, the pair closes where the gap turns below -`TOUCH_GAP` (brentq) or where
    it falls into +-`TOUCH_GAP` (the circle cutting the surface: the first point within
    `TOUCH_GAP`, bisected to 1e-12 of the travel, `_touch`; a seek that fails next to the
    touch is taken as touching there). A couple that becomes interior already cutting the
    surface (its distance within `TOUCH_GAP`: a circle that came in over an edge, which the
    set's edge pairs, or none, model) does not close it. Returns (lam of the closing or None; (gap,
    direction, distance) at lo; seeks taken)."""
    lam, (g, ref, dist), seeks = hi, start, 0
    while lam > lo:
        nxt = max(lam - max(abs(dist), floor), lo)
        seeks += 1
        try:
            g2, ref2, d2 = _seek(pair, approach, nxt, ref)
        except SeekingError:              # next to a tangent touch (`_touch`)
            if not (np.isfinite(g) and g > TOUCH_GAP):
                raise
            root, more = _touch(pair, approach, lam, nxt, ref)
            return root, None, seeks + more
        if np.isfinite(g) and g > TOUCH_GAP and np.isfinite(g2):
            if g2 <= 0 and abs(d2) > TOUCH_GAP:
                def f(x, ref=ref):
                    return _seek(pair, approach, x, ref)[0]
                return brentq(f, nxt, lam, xtol=xtol, rtol=1e-15), None, seeks
            if abs(d2) <= TOUCH_GAP:
                root, more = _touch(pair, approach, lam, nxt, ref)
                return root, None, seeks + more
        lam, g, ref, dist = nxt, g2, ref2, d2
    return None, (g, ref, dist), seeks


def _touch(pair, approach, hi, lo, ref):
    """The features are apart at hi and touch at lo < hi (`march_root`): the first point
    within `TOUCH_GAP` (about TOUCH_GAP / the gap's rate above the touch itself), bisected to
    1e-12 of the travel. Next to the touch the circle is tangent to the surface and
    the closest couple degenerate: where its Newton does not converge the features are taken
    to touch (the root moves up by at most the bracket). Returns (its lam, seeks)."""
    seeks = 0
    while hi - lo > 1e-12:
        mid = 0.5 * (hi + lo)
        try:
            g = _seek(pair, approach, mid, ref)[0]
        except SeekingError:
            g = 0.0
        seeks += 1
        if g <= TOUCH_GAP:
            lo = mid
        else:
            hi = mid
    return hi, seeks


def _seek(pair, approach, lam, ref):
    gaps, dirs, dist = seek_gaps([pair], approach, lam, [ref])
    return gaps[0], dirs[0], dist[0]


@functools.lru_cache(maxsize=16)
def search_pairs(geometry: tuple, which: str) -> tuple:
    """The pairs of the set ``which`` for the geometry ``dataclasses.astuple(g)``, built once
    per geometry and set: what their patches keep (covers, coarse grids, kernel descriptions)
    serves every approach the search is asked about."""
    return tuple(apds_pairs(ApdsGeometry(*geometry), which))


@functools.lru_cache(maxsize=64)
def _first_contact(geometry: tuple, approach: Approach, step, xtol, which):
    g = ApdsGeometry(*geometry)
    pairs = search_pairs(geometry, which)
    grid = travel_grid(g, approach, step)
    touch = touch_steps(pairs, approach, grid)
    gaps = _Gaps(pairs, approach, grid)
    for k in range(len(grid) - 1):
        # A pair closes on the step when its gap is > 0 at grid[k] and <= 0 at grid[k + 1];
        # otherwise a pair that comes within the step's travel is marched (`march_root`).
        roots, travel = {}, grid[k] - grid[k + 1]
        for j in np.flatnonzero(touch[:, k]):
            lam = None
            if 0 < gaps.gap(j, k) < np.inf and gaps.gap(j, k + 1) <= 0:
                lam = gaps.root(j, k, xtol)
            elif abs(gaps.distance(j, k)) < travel:
                lam = gaps.march(j, k, xtol)
            if lam is not None:
                roots[pairs[j].name] = lam
        if roots:
            d_c = max(roots.values())
            names = tuple(sorted(n for n, r in roots.items() if r >= d_c - 1e-9))
            return d_c, names, gaps.seeks
    return None, (), gaps.seeks


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
    faces meet first). The lateral offset is the ring centre's at first
    contact. With a lateral velocity
    the aim point (where the path meets the target's ring-face plane) is
    aim = offset + s v_lateral / chaser_speed, where s, the ring-face distance at contact, solves
    s = h_c(aim(s)) (brentq to 1e-10 m; `_consistent_height`)."""
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

    def mismatch(s):
        a = approach(s)
        return a.height(first_contact_or_faces(g, a, which)[0]) - s

    s = 0.0
    if slope.any():
        s = _consistent_height(mismatch, 2.0 * g.H + 0.05)
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


def _consistent_height(mismatch, s_max, cells=46):
    """The ring-face distance s in [0, s_max] with mismatch(s) = h_c(aim(s)) - s = 0, by brentq
    over the whole range; where that range has no sign change, on the largest sign change of a
    grid of ``cells`` intervals. The first contact h_c jumps where it passes from one pair or
    feature to another, so the bracket may close on a jump instead of a root: the path at the
    jump is taken, and the ring centre at first contact then misses the offset by
    |mismatch(s)| |v_lateral| / chaser_speed (`InitialState.contact_offset`). None where no
    grid interval changes sign."""
    try:
        return brentq(mismatch, 0.0, s_max, xtol=1e-10)
    except ValueError:                                  # no sign change over the range
        pass
    grid = np.linspace(0.0, s_max, cells + 1)
    f_above = mismatch(grid[cells])                     # scanned from the top, evaluated lazily
    for k in range(cells - 1, -1, -1):
        f_k = mismatch(grid[k])
        if f_k == 0.0:
            return float(grid[k])
        if f_k * f_above < 0:
            return brentq(mismatch, grid[k], grid[k + 1], xtol=1e-10)
        f_above = f_k
    return None
