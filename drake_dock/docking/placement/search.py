"""The first-contact search on a straight approach (docs/model.md, "Initial conditions"): the
chaser APDS's straight relative approach (`Approach`) and the travel at which the first pair of
a scene closes as it comes along that line from far away (`first_contact`), seeking each pair
only in the steps of the travel its covers can touch in; the pairs' signed gaps (`seek_gaps`)
and the march through a step (`march_root`). What a search finds is remembered in the caller's
`PlacementCache`."""
from __future__ import annotations

import dataclasses
import functools
import heapq

import numpy as np
from scipy.optimize import brentq

from drake_dock.core.kernels import cover as compiled_cover
from drake_dock.core.patches import posed
from drake_dock.core.seeking import contact_couple, seek_couple
from drake_dock.docking.geometry.pairs import CHASER_APDS, R_MATCHED, TARGET_APDS, PairSpec
from drake_dock.docking.geometry.rotations import rot_vec, rot_z
from drake_dock.docking.scenario.dimensions import ApdsGeometry
from drake_dock.errors import SeekingError
from drake_dock.systems.contact_types import ContactOptions


def coaxial_pose(yaw_rad: float, d: float):
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

    @functools.cached_property
    def _rotation(self):
        R = coaxial_pose(self.yaw, 0.0)[0]
        return rot_vec((*self.tilt, 0.0)) @ R if self.tilt != (0.0, 0.0) else R

    def pose(self, lam: float):
        R, p = self._rotation.copy(), np.array([0.0, 0.0, lam])
        if self.aim != (0.0, 0.0) or self.direction != (0.0, 0.0, -1.0):
            p = np.array([*self.aim, 0.0]) - lam * np.asarray(self.direction)
        return R, p

    def height(self, lam: float) -> float:
        """Ring-face distance along the axis at lam."""
        return -lam * self.direction[2]


@dataclasses.dataclass(frozen=True)
class FirstContact:
    """A search's result: the line parameter ``lam`` of the first contact (None where no pair
    closes on the approach down to a ring-face distance of -H, or above the search's stop), the
    names of the pairs that close within 1e-9 of it (sorted), the seeks the search took, and
    the travel it started from (`travel_grid`'s first point, where every pair is apart)."""

    lam: float | None
    closing: tuple = ()
    seeks: int = 0
    start: float = 0.0

    def travel(self) -> float:
        """``lam``, or 0 (the ring-face plane, where the rings' faces meet: docs/model.md,
        "Initial conditions") where no pair closes."""
        return 0.0 if self.lam is None else self.lam


def first_contact(cache, approach: Approach, *, among=None, stop=None,
                  step=None, xtol=1e-13) -> FirstContact:
    """The line parameter lam at which the first pair of the scene of ``cache`` (a
    `drake_dock.docking.placement.place.PlacementCache`) closes when the chaser comes along
    ``approach`` from far away, and the pairs that close with it. The search
    steps the ring-face distance by 1 cm, or by 1/100 of its start distance for a larger APDS
    (H > 0.475 m), so that it takes at most about 100 steps (``step``: another step of lam); a
    pair is sought only at the ends of the steps its patches can touch in (`pair_touch_steps`), and
    marched through a step whose travel its couple comes within
    (`march_root`); roots to ``xtol``.

    ``among`` (pair names): only those pairs of the scene are sought. Each pair's closing is
    the same to the bit as with the whole set (its seeks do not depend on the other pairs), so
    where one of them closes, the first contact among them is never higher than the set's.
    ``stop`` (a travel): the search ends on the step holding it, and no closing below it is
    reported. A pure function of its arguments and the scene: remembered in ``cache``."""
    key = (approach, None if among is None else tuple(sorted(among)), stop, step, xtol)
    found = cache.searches.get(key)
    if found is None:
        found = cache.searches[key] = _search(cache.scene, approach, *key[1:])
    return found


def _search(scene, approach, among, stop, step, xtol) -> FirstContact:
    pairs = scene.pairs
    if among is not None:
        pairs = tuple(pr for pr in pairs if pr.name in among)
    grid = travel_grid(scene.geometry, approach, step)
    touch = _TouchSteps(pairs, approach, grid)
    gaps = _Gaps(pairs, approach, grid)
    for k in range(len(grid) - 1):
        # A pair closes on the step when its gap is > `TOUCH_GAP` at grid[k] (apart, not
        # touching or cutting) and <= 0 at grid[k + 1]; otherwise a pair that comes within the
        # step's travel is marched (`march_root`).
        roots, travel, marched = {}, grid[k] - grid[k + 1], []
        for j in np.flatnonzero(touch.column(k)):
            if TOUCH_GAP < gaps.gap(j, k) < np.inf and gaps.gap(j, k + 1) <= 0:
                roots[j] = gaps.root(j, k, xtol)
            elif abs(gaps.distance(j, k)) < travel:
                marched.append(j)
        # On the step holding ``stop`` the marches stop there, as below a known closing.
        last = stop is not None and grid[k + 1] < stop
        best = max([*roots.values(), *([stop] if last else [])], default=None)
        roots.update(gaps.marches(marched, k, xtol, best))
        roots = {pairs[j].name: lam for j, lam in roots.items()}
        if roots and not (last and max(roots.values()) < stop):
            d_c = max(roots.values())
            names = tuple(sorted(n for n, r in roots.items() if r >= d_c - 1e-9))
            return FirstContact(d_c, names, gaps.seeks, grid[0])
        if last:
            break
    return FirstContact(None, (), gaps.seeks, grid[0])


def point_contact(scene, approach, found: FirstContact) -> bool:
    """True when a pair closing at the first contact ``found`` (on ``scene``'s pairs) has a
    usable couple there (interior and isolated by the contact system's rule, `contact_couple`
    with the default `ContactOptions.conditioning_min`): a point contact that the simulation
    follows, and past which the features cross. Coaxial arcs of one radius (a ring's inside
    circle at a tip arc, a tip arc on a tip arc) touch along an arc and have none."""
    R, p = approach.pose(found.lam)
    poses = {TARGET_APDS: (np.eye(3), np.zeros(3)), CHASER_APDS: (R, p)}
    for pr in scene.pairs:
        if pr.name in found.closing:
            X1, X2 = poses[pr.body1], poses[pr.body2]
            c = pair_couples([pr], poses)[0]
            f = contact_couple(pr.kind, pr.patch1, X1, pr.patch2, X2, c,
                               conditioning_min=ContactOptions.conditioning_min)
            if f.usable:
                return True
    return False


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
    """The covers of a pair's two patches (`COVER_CELLS`, `kernels.cover.patch_cover`)."""
    out = []
    for patch in (pr.patch1, pr.patch2):
        out.append(compiled_cover.patch_cover(patch, *COVER_CELLS[patch.dim]))
    return out


def pair_touch_steps(pairs, approach: Approach, grid):
    """Booleans (pairs, steps): the covers of pair j's patches can touch between grid[k] and
    grid[k + 1] (`drake_dock.core.kernels.cover.touch_steps`); elsewhere the pair is apart."""
    return _TouchSteps(pairs, approach, grid).chunk(0, len(grid) - 1)


# `_TouchSteps` finds the first this many steps of a search's grid, and the rest where the
# search goes on (a search ends at its first contact, and below it the covers overlap most).
TOUCH_CHUNK = 32


class _TouchSteps:
    """`pair_touch_steps` of a search's grid, found on demand: its first `TOUCH_CHUNK` steps, then
    the rest. A step's booleans depend on the grid only through that step's ends, so a
    chunk's are the whole grid's."""

    def __init__(self, pairs, approach: Approach, grid):
        self.pairs, self.grid = pairs, np.asarray(grid, dtype=float)
        R, p0 = approach.pose(0.0)
        self.e = -(approach.pose(1.0)[1] - p0)       # the chaser's points move by -lam e
        self.covers, placed = [], {}                 # the moving covers, each posed once
        for pr in pairs:
            c1, c2 = pair_covers(pr)
            moving, fixed = (c1, c2) if pr.body1 == CHASER_APDS else (c2, c1)
            patch = pr.patch1 if pr.body1 == CHASER_APDS else pr.patch2  # held by the pairs
            if id(patch) not in placed:
                placed[id(patch)] = moving.posed(R, p0)
            self.covers.append((placed[id(patch)], fixed))
        self.chunks = {}

    def chunk(self, k0, k1):
        """Booleans (pairs, k1 - k0) of the steps k0 to k1 - 1."""
        grid = self.grid[k0:k1 + 1]
        out = np.zeros((len(self.pairs), k1 - k0), dtype=bool)
        for j, (moving, fixed) in enumerate(self.covers):
            out[j] = compiled_cover.touch_steps(moving, fixed, self.e, grid)
        return out

    def column(self, k):
        """The pairs' booleans of step k."""
        k0 = 0 if k < TOUCH_CHUNK else TOUCH_CHUNK
        if k0 not in self.chunks:
            k1 = TOUCH_CHUNK if k0 == 0 else len(self.grid) - 1
            self.chunks[k0] = self.chunk(k0, min(k1, len(self.grid) - 1))
        return self.chunks[k0][:, k - k0]


def pair_couples(pairs, poses, **grid):
    """Seeks the closest couple of every pair (`seek_couple`); ``poses`` maps body name ->
    (R_WB, p_WB)."""
    out = []
    for pr in pairs:
        P1, P2 = posed(pr.patch1, *poses[pr.body1]), posed(pr.patch2, *poses[pr.body2])
        out.append(seek_couple(P1, P2, **grid))
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
    for pr, cp, ref in zip(pairs, pair_couples(pairs, poses), refs):
        dist.append(cp.distance)
        if not cp.interior:
            out.append(np.inf)
            dirs.append(None)
            continue
        v = cp.p1 - cp.p2
        if pr.sigma is not None and (pr.patch1.dim, pr.patch2.dim) == (1, 2):
            # A declared side (a ring's face, solid on one side): the side of the surface's
            # normal sigma N the curve's point lies on, as the contact system takes it.
            T = posed(pr.patch2, *poses[pr.body2]).first(cp.u2)
            s = 1.0 if pr.sigma * (v @ np.cross(T[:, 0], T[:, 1])) >= 0 else -1.0
            if cp.distance < TOUCH_GAP:
                # The curve cuts the surface (their least distance is zero there, to
                # round-off): it is through, past its first touch; the bisection finds that
                # touch.
                out.append(-2.0 * TOUCH_GAP)
                dirs.append(None)
                continue
        else:
            s = 1.0 if ref is None or v @ ref >= 0 else -1.0
        out.append(s * cp.distance)
        dirs.append(s * v / max(cp.distance, 1e-300))
    return np.array(out), dirs, np.array(dist)


# The march of `march_root` takes at most this many sub-steps per step of the grid.
MARCH_SUBSTEPS = 256
# Two features touch below this distance, their couple interior or not (m, `march_root`).
TOUCH_GAP = 1e-9
# The longest sub-step of a march through features that cut each other, in floors.
CUT_FLOORS = 16


def march_root(pair, approach, hi, start, lo, floor, xtol):
    """The first closing of the pair on the travel from hi down to lo, where the grid's two
    ends cannot see it: a couple that enters or leaves its domain inside the step (a ring
    crossing a tip arc next to a petal corner and handed over to the guide surface; a circle
    meeting a guide surface next to its edge leaves the domain as its gap reaches 0, since past
    it the circle cuts the surface). ``start`` = (gap, direction, distance) at hi. The chaser
    translates along the approach, so features a distance D apart cannot touch within a travel
    of D: each sub-step is max(D, ``floor``), the side continued; while the features cut each
    other (D within `TOUCH_GAP`) it doubles up to `CUT_FLOORS` floors, the side continued from
    before the cut (also where the couple leaves its domain in the cut). From an interior gap
    above `TOUCH_GAP`, the pair closes where the gap turns below -`TOUCH_GAP` (brentq) or
    where it falls into +-`TOUCH_GAP` (the circle cutting the surface: the first point within
    `TOUCH_GAP`, bisected to 1e-12 of the travel, `_touch`; a seek that fails next to the
    touch is taken as touching there). A seek that fails while the couple is outside its
    domain (a circle nearing a surface's edge, which the edge pairs model) is taken as a touch
    outside it (distance 0: marched as a cut). A couple that becomes interior already cutting the
    surface (its distance within `TOUCH_GAP`: a circle that came in over an edge, which the
    set's edge pairs, or none, model) does not close it. Returns (lam of the closing or None;
    (gap, direction, distance) at lo; seeks taken)."""
    steps = march_steps(pair, approach, hi, start, lo, floor, xtol)
    while True:
        try:
            next(steps)
        except StopIteration as done:
            return done.value


def march_steps(pair, approach, hi, start, lo, floor, xtol):
    """`march_root` one sub-step at a time: yields the travel each sub-step starts from;
    its return value (`StopIteration.value`) is `march_root`'s."""
    lam, (g, ref, dist), seeks, cut = hi, start, 0, 0
    while lam > lo:
        yield lam
        # While the features cut each other no closing can start: the sub-step doubles, up
        # to `CUT_FLOORS` floors (a separation and closing inside it are not seen).
        cut = cut + 1 if abs(dist) <= TOUCH_GAP else 0
        nxt = max(lam - max(abs(dist), floor * min(2 ** max(cut - 1, 0), CUT_FLOORS)), lo)
        seeks += 1
        try:
            g2, ref2, d2 = _seek(pair, approach, nxt, ref)
        except SeekingError:
            if not np.isfinite(g):        # outside its domain: a touch there cannot close it
                g2, ref2, d2 = np.inf, None, 0.0
            elif g > TOUCH_GAP:           # next to a tangent touch (`_touch`)
                root, more = _touch(pair, approach, lam, nxt, ref)
                return root, None, seeks + more
            else:
                raise
        if np.isfinite(g) and g > TOUCH_GAP and np.isfinite(g2):
            if g2 <= 0 and abs(d2) > TOUCH_GAP:
                calls = []

                def f(x, ref=ref):
                    calls.append(x)
                    return _seek(pair, approach, x, ref)[0]
                root = brentq(f, nxt, lam, xtol=xtol, rtol=1e-15)
                return root, None, seeks + len(calls)
            if abs(d2) <= TOUCH_GAP:
                root, more = _touch(pair, approach, lam, nxt, ref)
                return root, None, seeks + more
        # A cut's direction is round-off: the side is continued from before the cut.
        lam, g, ref, dist = nxt, g2, ref if abs(d2) <= TOUCH_GAP else ref2, d2
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
    """(signed gap, direction, distance) of one pair at lam (`seek_gaps`)."""
    gaps, dirs, dist = seek_gaps([pair], approach, lam, [ref])
    return gaps[0], dirs[0], dist[0]


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

    def marches(self, js, k, xtol, best=None):
        """The marches (`march_steps`) of the pairs ``js`` over the step from grid[k], in
        lockstep: the march whose sub-step starts highest goes next. Once a closing is known
        at ``best`` (or found by a march), a march whose next sub-step starts below
        best - 1e-9 cannot add to the closing pairs (`first_contact`) and stops.
        Returns {j: lam} of the closings found; a march that ends without one leaves its side
        at grid[k + 1] (a stopped one leaves none: the search ends on this step)."""
        hi, lo = self.grid[k], self.grid[k + 1]
        runs, heap, roots, taken = {}, [], {}, dict.fromkeys(js, 0)
        for j in js:
            runs[j] = march_steps(self.pairs[j], self.approach, hi, self._hit(j, k), lo,
                                  (hi - lo) / MARCH_SUBSTEPS, xtol)
            heapq.heappush(heap, (-next(runs[j]), j))
        while heap:
            lam, j = heapq.heappop(heap)
            if best is not None and -lam < best - 1e-9:
                self.seeks += sum(taken[i] for _, i in heap) + taken[j]   # stopped marches
                break
            try:
                taken[j] += 1                                     # one seek per sub-step
                heapq.heappush(heap, (-next(runs[j]), j))
            except StopIteration as done:
                root, end, seeks = done.value
                self.seeks += seeks
                if root is not None:
                    roots[j] = root
                    best = root if best is None else max(best, root)
                elif end is not None:
                    self.at[(j, k + 1)] = end
        return roots

