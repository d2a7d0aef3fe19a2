"""An interpenetration check of two APDS over a run, independent of the contact code.

Written from the paper's geometry (Sect. 4) with its own formulas; it uses no patch, couple or
seek of `drake_dock.core`. In an APDS's own frame (cylindrical rho, theta, zeta; e3 along the
docking axis, ring face at zeta = 0):
- petal k (k = 1..3) is a thin plate on the cone rho = R - zeta cot(alpha1) (Eq. 12) between its
  two guide sides (the angular inset theta_1 of Eq. 13), 0 <= zeta <= H. A point's signed
  distance s to the cone (positive away from the axis) and the foot of that distance give its
  side of the plate and whether it lies over the plate;
- the ring is a solid annulus Rs <= rho <= R, ``ring_depth`` deep behind the ring face.

The other APDS's features are sampled as material points: the ring's inside and outside circles
and its face, the six guide sides (Eq. 14) and the three petal tip arcs (zeta = H).

A thin plate has no inside, so a point *crosses* a petal when its s changes sign at a place
over the plate (its foot, interpolated to s = 0 between two sub-steps, inside the petal): a
point passing round a side or over the tip changes side without crossing. A point that has
crossed (an odd number of times) is inside while it is over the plate, at the depth of the
least motion that ends that: back through the plate (|s|) or off the plate past its nearest
free edge (the distance of its foot to the guide sides, the tip arc and the root: the root is
fixed to the ring, but the other APDS passes that ring's annulus in the paper's reading, so a
point may come to the plate from below its root). Near an edge the second is the smaller: a
guide side sliding on its partner's edge that rides up over the edge by 30 um lies 30 um deep,
however far it is above the plate. A point inside the other ring's solid (`ring_depth_of`)
lies at its distance to the nearest face. What is checked: `checked_features`.

Between two samples of the run the relative pose is interpolated (translation linearly,
rotation along its geodesic) in sub-steps that move no feature point more than ``max_travel``.
Every point starts on its own side (the initial configuration is checked by the scenario).
"""
from __future__ import annotations

import dataclasses
import math

import numpy as np
from scipy.spatial import cKDTree

from drake_dock.docking.checks.cone_reach import cone_distance, watched_on_translation
from drake_dock.docking.geometry.rotations import rot_vec

PETAL_FEATURES = ("ring inside circle", "guide side", "petal")     # name prefixes
RING_FEATURES = ("ring",)
ALL_FEATURES = ("ring", "guide side", "petal")


def checked_features(g) -> tuple:
    """(feature name prefixes checked against the other APDS's petals, against its ring).
    The paper's petals (Rp > Rs) pass the other ring's annulus (docs/model.md): petals and
    ring are not checked against each other. Petals on the inside circle (Rp = Rs) pass
    through its passage: every feature is checked against both."""
    if g.Rp <= g.Rs:
        return ALL_FEATURES, ALL_FEATURES
    return PETAL_FEATURES, RING_FEATURES


@dataclasses.dataclass
class Penetration:
    """The deepest point found: its depth (m; 0 when none), the time, and which feature of which
    APDS lay inside which solid of the other."""

    depth: float = 0.0
    time: float = math.nan
    feature: str = ""
    solid: str = ""

    def describe(self) -> str:
        if self.depth == 0.0:
            return "no interpenetration"
        return (f"{self.feature} {self.depth * 1e3:.3g} mm through {self.solid} at "
                f"t = {self.time:.6g} s")


def _inset(g, zeta):
    """Eq. (13): theta_1(zeta) = arcsin(R sin(alpha2) / rho(zeta)) - alpha2."""
    rho = g.Rp - zeta / math.tan(g.alpha1)
    return np.arcsin(np.clip(g.Rp * math.sin(g.alpha2) / rho, -1.0, 1.0)) - g.alpha2


def feature_points(g, *, n_circle=1440, n_side=80, n_arc=60, n_face=9):
    """{feature name: (M, 3) points in the APDS frame}."""
    th = np.linspace(0.0, 2 * math.pi, n_circle, endpoint=False)
    c, s = np.cos(th), np.sin(th)

    def circle(r, z=0.0):
        return np.stack([r * c, r * s, np.full_like(th, z)], -1)

    out = {"ring inside circle": circle(g.Rs), "ring outside circle": circle(g.R)}
    out["ring face"] = np.concatenate([circle(r)[::4] for r in np.linspace(g.Rs, g.R, n_face)])
    A, tan1 = g.Rp * math.sin(g.alpha2), math.tan(g.alpha1)
    end = float(_inset(g, g.H))
    for i in range(1, 7):                          # Eq. (14), sine form
        sigma = 1 if i % 2 else -1
        phi = (i - 1) * math.pi / 3 + sigma * g.inset     # the side's root
        t = phi + sigma * np.linspace(0.0, end, n_side)
        rho = A / np.sin(g.alpha2 + sigma * (t - phi))
        out[f"guide side {i}"] = np.stack([rho * np.cos(t), rho * np.sin(t),
                                           (g.Rp - rho) * tan1], -1)
    r_tip = g.Rp - g.H / tan1
    for k in (1, 2, 3):
        phi = (2 * k - 2) * math.pi / 3 + g.inset
        t = np.linspace(phi + end, phi + math.pi / 3 - 2 * g.inset - end, n_arc)
        out[f"petal {k} tip arc"] = np.stack([r_tip * np.cos(t), r_tip * np.sin(t),
                                              np.full_like(t, g.H)], -1)
    return out


def petal_coordinates(g, X, k):
    """For points X (M, 3) in the APDS frame and petal k: the signed distance s to the cone
    (positive away from the axis), the foot's fraction across the petal (0 and 1 on its guide
    sides) and the foot's height zeta. The foot is over the plate for 0 <= fraction <= 1 and
    0 <= zeta <= H."""
    s, fractions, zeta_f = petal_places(g, X, (k,))
    return s, fractions[0], zeta_f


def petal_places(g, X, petals=(1, 2, 3)):
    """`petal_coordinates` for several petals at once: (s, [fraction across each petal],
    zeta)."""
    s = cone_distance(g, X)
    zeta_f = X[:, 2] - s * math.cos(g.alpha1)
    inset = _inset(g, np.clip(zeta_f, 0.0, g.H))
    theta = np.arctan2(X[:, 1], X[:, 0])
    fractions = []
    for k in petals:
        phi = (2 * k - 2) * math.pi / 3 + g.inset        # side 2k - 1's root
        dth = np.mod(theta - phi + math.pi, 2 * math.pi) - math.pi
        fractions.append((dth - inset) / (math.pi / 3 - 2 * g.inset - 2 * inset))
    return s, fractions, zeta_f


def _over(g, frac, zeta_f, tol=1e-9):
    return (frac >= -tol) & (frac <= 1 + tol) & (zeta_f >= -tol) & (zeta_f <= g.H + tol)


def free_edges(g, n=4001) -> dict:
    """{petal k: (M, 3) polyline} of petal k's free edges in the APDS frame, fine enough that
    a chord lies within 1e-8 m of the curve: guide side 2k - 1 from its root to the tip, the
    tip arc, guide side 2k from the tip to its root (Eq. 14 and zeta = H), and the root back
    along the ring's outside circle (zeta = 0). The root is fixed to the ring, but the other
    APDS's features pass the ring's annulus in the paper's reading (docs/model.md), so they
    may reach the plate from there."""
    f = feature_points(g, n_side=n, n_arc=n)
    out = {}
    for k in (1, 2, 3):
        a, b = f[f"guide side {2 * k - 1}"], f[f"guide side {2 * k}"]
        th_a, th_b = math.atan2(a[0, 1], a[0, 0]), math.atan2(b[0, 1], b[0, 0])
        th = th_b + np.linspace(0.0, 1.0, n) * ((th_a - th_b + math.pi) % (2 * math.pi) - math.pi)
        root = np.column_stack([g.Rp * np.cos(th), g.Rp * np.sin(th), np.zeros(n)])
        out[k] = np.concatenate([a, f[f"petal {k} tip arc"], b[::-1], root])
    return out


def annulus_rim(g, X):
    """Which of the points X (M, 3), in their own APDS frame, lie on the ring's outside circle
    (rho = R, zeta = 0): the guide sides' roots, the outer edge of the annulus that the other
    APDS's petals pass in the paper's reading, so not checked against them. Only the root's
    own sample is left out; the next sample of a side (`feature_points`) lies 4 mm above the
    ring face."""
    return (np.abs(X[:, 2]) < 1e-12) & (np.abs(np.hypot(X[:, 0], X[:, 1]) - g.Rp) < 1e-9)


def foot_on_cone(g, X, s):
    """The feet of points X (M, 3) at signed distances s (M,) from the cone (Eq. 12)."""
    e = X[:, :2] / np.maximum(np.hypot(X[:, 0], X[:, 1]), 1e-300)[:, None]
    n = np.column_stack([math.sin(g.alpha1) * e, np.full(len(X), math.cos(g.alpha1))])
    return X - s[:, None] * n


def distance_to_polyline(F, P):
    """Distance of points F (M, 3) to the polyline P (N, 3): to the two segments beside each
    point's nearest vertex."""
    if len(F) > 64:                               # in blocks: M x N x 3 floats at once
        return np.concatenate([distance_to_polyline(F[i:i + 64], P)
                               for i in range(0, len(F), 64)])
    if len(F) == 0:
        return np.zeros(0)
    return _beside(F, P, np.argmin(((F[:, None, :] - P[None, :, :]) ** 2).sum(-1), axis=1))


_POLYLINES = {}


def edge_polylines(g) -> dict:
    """{petal k: its free edges (`free_edges`) as a `Polyline`}, kept per geometry."""
    key = (g.Rp, g.H, g.alpha1, g.alpha2, g.inset)
    hit = _POLYLINES.get(key)
    if hit is None:
        if len(_POLYLINES) > 8:
            _POLYLINES.clear()
        hit = _POLYLINES[key] = {k: Polyline(P) for k, P in free_edges(g).items()}
    return hit


class Polyline:
    """A polyline P (N, 3) with a k-d tree of its vertices: `distance_to_polyline`, the same
    values, without its M x N distances. The nearest vertex is the brute force's (the least
    squared distance, the first of equals): where the tree's two nearest are more than 1e-9
    apart relatively, its nearest; else the vertices within that of the least distance,
    compared as the brute force compares them."""

    def __init__(self, P):
        self.P = np.array(P, dtype=float)
        self.P.flags.writeable = False          # the tree keeps it
        self.tree = cKDTree(self.P)

    def distance(self, F):
        if len(F) == 0:
            return np.zeros(0)
        d, j = self.tree.query(F, k=2)
        j = j[:, 0].copy()
        close = np.flatnonzero(d[:, 1] <= d[:, 0] * (1.0 + 1e-9) + 1e-300)
        if len(close):
            balls = self.tree.query_ball_point(F[close], d[close, 0] * (1.0 + 1e-9) + 1e-300)
            for m, c in zip(close, balls):
                c = np.sort(np.asarray(c, dtype=np.intp))
                j[m] = c[np.argmin(((F[m] - self.P[c]) ** 2).sum(-1))]
        return _beside(F, self.P, j)


def _beside(F, P, j):
    """Distance of points F (M, 3) to the two segments of the polyline P beside vertex j (M,)."""
    best = np.full(len(F), np.inf)
    for a, b in ((np.maximum(j - 1, 0), j), (j, np.minimum(j + 1, len(P) - 1))):
        A, d = P[a], P[b] - P[a]
        u = np.clip(((F - A) * d).sum(-1) / np.maximum((d * d).sum(-1), 1e-300), 0.0, 1.0)
        best = np.minimum(best, np.linalg.norm(F - A - u[:, None] * d, axis=1))
    return best


def ring_depth_of(g, X, ring_depth):
    """Depth of points X (M, 3) inside the ring's solid (<= 0: outside): the annulus
    Rs <= rho <= R + zeta from its face (zeta = 0) to ``ring_depth`` behind it, its outer edge
    chamfered at 45 deg, so that another ring meets it only at its face and its rim, the
    features the contact pairs model (docs/model.md, "APDS geometry")."""
    rho = np.hypot(X[:, 0], X[:, 1])
    return np.minimum.reduce([-X[:, 2], X[:, 2] + ring_depth, rho - g.Rs,
                              (g.R + X[:, 2] - rho) * math.sqrt(0.5)])


def _rotvec(R):
    """Rotation vector of R (log map), for interpolation."""
    c = np.clip((np.trace(R) - 1.0) / 2.0, -1.0, 1.0)
    a = math.acos(c)
    w = np.array([R[2, 1] - R[1, 2], R[0, 2] - R[2, 0], R[1, 0] - R[0, 1]])
    if a < 1e-12:
        return 0.5 * w
    if a > math.pi - 1e-6:                          # near a half turn: from R + I
        k = np.sqrt(np.maximum((np.diag(R) + 1.0) / 2.0, 0.0))
        k *= np.where(np.sign(w) == 0, 1.0, np.sign(w))
        return a * k / np.linalg.norm(k)
    return a / (2.0 * math.sin(a)) * w


def relative_poses(R_WA, p_WA, a, b):
    """Pose (R, p) of APDS a in APDS b's frame at each sample."""
    Rb_T = np.swapaxes(R_WA[:, b], -1, -2)
    return Rb_T @ R_WA[:, a], np.einsum("nij,nj->ni", Rb_T, p_WA[:, a] - p_WA[:, b])


def sub_steps(t, R, p, reach, max_travel):
    """(t, R, p) at the first sample, then sub-steps between samples that move no point within
    ``reach`` of the origin more than ``max_travel``."""
    R0 = R[0]
    yield t[0], R0, p[0]
    for n in range(1, len(t)):
        turned = not np.array_equal(R0, R[n])       # else the sub-steps keep R0 (one object)
        r = _rotvec(R0.T @ R[n]) if turned else np.zeros(3)
        travel = np.linalg.norm(p[n] - p[n - 1]) + np.linalg.norm(r) * reach
        m = max(1, int(math.ceil(travel / max_travel)))
        for f in np.arange(1, m + 1) / m:
            yield (t[n - 1] + (t[n] - t[n - 1]) * f, R0 @ rot_vec(f * r) if turned else R0,
                   p[n - 1] + f * (p[n] - p[n - 1]))
        R0 = R[n] if turned else R0


@dataclasses.dataclass
class _PetalWatch:
    """One feature against the three petals of the other APDS: each point's last place X and
    cone distance s (the same for the three), and which petal it has crossed. The place on a
    petal (`petal_coordinates`) and the foot are computed only for the points that change side
    or have crossed."""

    solids: tuple              # the three petals' names
    edges: dict                # petal k: its free edges (`free_edges`) as a `Polyline`
    graze: float = 1e-6        # m: a crossing this close to a free edge passes round it
    X: np.ndarray = None
    s: np.ndarray = None
    crossed: np.ndarray = None  # (3, M)
    sparse: bool = False        # `steps`: find the rows to step first (`deepest_penetration`)

    def _crossings(self, g, X, s, flip):
        """Per petal k = 1, 2, 3: of the points ``flip`` that changed side, those whose
        crossing (s = 0, linearly between the sub-steps) lies on petal k, more than `graze`
        from its free edges."""
        on = self._on_petals(g, self.X[flip], self.s[flip], X[flip], s[flip])
        for k in (1, 2, 3):
            yield k, flip[on[k - 1]]

    def _on_petals(self, g, X0, s0, X1, s1):
        """(3, M): whether the crossing of each point from (X0, s0) to (X1, s1) (opposite
        sides) lies on petal k, more than `graze` from its free edges."""
        w, over = _crossing_over(g, X0, s0, X1, s1)
        out = np.zeros((3, len(s0)), dtype=bool)
        for k in (1, 2, 3):
            idx = np.flatnonzero(over[k - 1])
            if len(idx) and self.graze > 0.0:
                foot0 = foot_on_cone(g, X0[idx], s0[idx])
                at = foot0 + w[idx][:, None] * (foot_on_cone(g, X1[idx], s1[idx]) - foot0)
                idx = idx[self.edges[k].distance(at) > self.graze]
            out[k - 1, idx] = True
        return out

    def step(self, g, X, s):
        """Updates with the sub-step's points X and their cone distances s (`cone_distance`);
        yields (petal name, depth of each point) for the petals some point has crossed."""
        X_now, s_now = X, s
        if self.s is None:
            self.crossed = np.zeros((3, len(s)), dtype=bool)
        else:
            flip = np.flatnonzero(np.sign(s) * np.sign(self.s) < 0)
            for k, idx in self._crossings(g, X, s, flip) if len(flip) else ():
                self.crossed[k - 1, idx] = ~self.crossed[k - 1, idx]
            # A point exactly on the cone (s = 0) keeps its last side: the crossing is seen
            # at the next sub-step off the cone.
            on = s == 0.0
            if on.any():
                X, s = np.where(on[:, None], self.X, X), np.where(on, self.s, s)
        self.X, self.s = X, s
        for k in np.flatnonzero(self.crossed.any(axis=1)) + 1:
            held = np.flatnonzero(self.crossed[k - 1])
            _, frac, zeta = petal_coordinates(g, X[held], k)
            inside = held[_over(g, frac, zeta)]
            off = self.edges[k].distance(foot_on_cone(g, X_now[inside], s_now[inside]))
            depth = np.zeros(len(s))
            depth[inside] = np.minimum(np.abs(s_now[inside]), off)
            yield self.solids[k - 1], depth

    def steps(self, g, X, s):
        """`step` over a block of sub-steps, the rows of X (C, M, 3) and s (C, M); yields
        (row, petal name, depth of each point). A row where no point changes side or lies on
        the cone, after a row with none on it, and where no point has crossed, changes only
        the last place: such rows are passed over, their last one kept."""
        start = 0
        if self.s is None:
            for found in self.step(g, X[0], s[0]):
                yield (0, *found)
            start = 1
        if start == len(s):
            return
        prev = np.concatenate([self.s[None], s[start:-1]])
        on = (s[start:] == 0.0).any(axis=1)
        busy = on.copy()
        if self.sparse and not self.crossed.any():
            # A row is stepped where a crossing lies over a petal (`_over`), near its free
            # edges or not.
            X_prev = np.concatenate([self.X[None], X[start:-1]])
            rows, points = np.nonzero(_flips(g, X_prev, prev, X[start:], s[start:]))
            busy[rows[_crosses_over(g, X_prev[rows, points], prev[rows, points],
                                    X[start:][rows, points], s[start:][rows, points])]] = True
        else:
            busy |= (np.sign(s[start:]) * np.sign(prev) < 0).any(axis=1)
        busy[1:] |= on[:-1]
        busy[0] |= bool((self.s == 0.0).any())
        skipped, held = None, self.crossed.any()
        for c in range(start, len(s)):
            if not busy[c - start] and not held:
                skipped = c
                continue
            if skipped == c - 1:
                self.X, self.s = X[skipped], s[skipped]
            for found in self.step(g, X[c], s[c]):
                yield (c, *found)
            held = self.crossed.any()
        if skipped == len(s) - 1:
            self.X, self.s = X[skipped], s[skipped]


def _crossing_over(g, X0, s0, X1, s1):
    """For points that cross the cone from (X0, s0) to (X1, s1): the crossing's weight w
    (linear between the two) and, per petal k = 1, 2, 3, whether it lies over the petal."""
    w = s0 / (s0 - s1)
    (_, fr0, zeta0), (_, fr1, zeta1) = petal_places(g, X0), petal_places(g, X1)
    zeta = zeta0 + w * (zeta1 - zeta0)
    return w, [_over(g, f0 + w * (f1 - f0), zeta) for f0, f1 in zip(fr0, fr1)]


def _crosses_over(g, X0, s0, X1, s1):
    """Whether each crossing (`_crossing_over`) lies over some petal."""
    over = _crossing_over(g, X0, s0, X1, s1)[1]
    return over[0] | over[1] | over[2]


def _flips(g, X0, s0, X1, s1, margin=1e-6):
    """The points that change side of the cone from (X0, s0) to (X1, s1) at a height that can
    lie on a petal: the crossing, linear between the two, within ``margin`` of 0 <= z <= H
    (there z is the foot's zeta, which `_over` bounds to 1e-9)."""
    flip = np.sign(s1) * np.sign(s0) < 0
    at = np.nonzero(flip)
    w = s0[at] / (s0[at] - s1[at])
    z = X0[at][:, 2] + w * (X1[at][:, 2] - X0[at][:, 2])
    flip[at] = (z > -margin) & (z < g.H + margin)
    return flip


# Sub-steps taken at once by `deepest_penetration`.
BLOCK = 64


def _blocks(steps, size):
    block = []
    for step in steps:
        block.append(step)
        if len(block) == size:
            yield block
            block = []
    if block:
        yield block


def deepest_penetration(g, t, R_WA, p_WA, names, *, ring_depth=0.04, max_travel=1e-3,
                        features=None, graze=1e-6, sparse=False) -> Penetration:
    """The deepest interpenetration of the two APDS over the samples t (N,) with their frames'
    poses R_WA (N, 2, 3, 3), p_WA (N, 2, 3) (the timeseries fields), names the two APDS names;
    ``features`` replaces `feature_points` (a subset, for tests). A point crosses a petal where
    its foot lies on the plate and more than ``graze`` (m) from its free edges; closer, it grazes
    an edge and passes round it: an edge in contact with a petal's edge holds the two at
    distance 0, so each of its points that the contact slides past passes exactly through
    the other edge (the default, 1 um, is above the sub-steps' interpolation error, 0.1 um at
    1 mm travel; a real slicing of the plate is seen by the feature's points further in).
    With ``sparse`` (a path on which few sub-steps cross a petal: an approach, not a contact
    sliding on one) the sub-steps where a crossing lies over a petal are found for a whole
    block at once and only those are stepped; on a translation (one rotation at every
    sample) only the points whose path can cross a petal's plate are watched
    (`drake_dock.docking.checks.cone_reach`). The result is the same."""
    feats = feature_points(g) if features is None else features
    reach = max(float(np.linalg.norm(X, axis=1).max()) for X in feats.values())
    best, rank = Penetration(), None
    edges = edge_polylines(g)
    on_petals = {f: ~annulus_rim(g, X) for f, X in feats.items()}
    vs_petals, vs_ring = checked_features(g)
    for a, b in ((0, 1), (1, 0)):
        R, p = relative_poses(R_WA, p_WA, a, b)
        watches = {f: _PetalWatch(tuple(f"{names[b]} petal {k}" for k in (1, 2, 3)), edges,
                                  graze, sparse=sparse)
                   for f in feats if f.startswith(vs_petals)}
        moved = {}      # a translation: {feature: (X R^T, the watched points that can cross)}
        if sparse and all(np.array_equal(R[0], R_n) for R_n in R[1:]):
            for fname, X in feats.items():
                XR = X @ R[0].T
                Xw = XR[on_petals[fname]] if fname in watches else XR[:0]
                if len(Xw):
                    Xw = Xw[watched_on_translation(g, Xw, p, max_travel)]
                moved[fname] = XR, Xw
        row0 = 0
        for block in _blocks(sub_steps(t, R, p, reach, max_travel), BLOCK):
            C = len(block)
            Rz, pz = np.array([Rab[2] for _, Rab, _ in block]), np.array([q[2] for *_, q in block])
            for f, (fname, X) in enumerate(feats.items()):
                found = []                                  # (row, solid, depths)
                Y = None
                if fname in moved:          # the same sums as below, on fewer points
                    XR, Xw = moved[fname]
                    shift = np.array([q for *_, q in block])
                    if len(Xw):
                        Yp = Xw[None] + shift[:, None]
                        s = cone_distance(g, Yp.reshape(-1, 3)).reshape(C, -1)
                        found = list(watches[fname].steps(g, Yp, s))
                    low = XR[:, 2].min() + shift[:, 2] - 1e-9
                elif fname in watches:
                    if all(Rab is block[0][1] for _, Rab, _ in block):     # a translation
                        Y = (X @ block[0][1].T)[None] + np.array([q for *_, q in block])[:, None]
                    else:
                        Y = np.stack([X @ Rab.T + pab for _, Rab, pab in block])
                    Yp = Y[:, on_petals[fname]]
                    s = cone_distance(g, Yp.reshape(-1, 3)).reshape(C, -1)
                    found = list(watches[fname].steps(g, Yp, s))
                    low = Y[:, :, 2].min(axis=1)
                else:           # the ring's solid lies below its face: only rows reaching it
                    low = (X @ Rz.T + pz).min(axis=0) - 1e-9
                if fname.startswith(vs_ring):
                    rows = np.flatnonzero(low < 0.0)
                    if Y is None and len(rows):
                        Y = np.stack([X @ block[c][1].T + block[c][2] for c in rows])
                    elif len(rows):
                        Y = Y[rows]
                    if len(rows):
                        depth = ring_depth_of(g, Y.reshape(-1, 3), ring_depth).reshape(
                            len(rows), -1)
                        found += [(c, f"{names[b]} ring", depth[m]) for m, c in enumerate(rows)]
                for c, solid, depth in found:
                    # The deepest; of equals, the first in the order (direction, sub-step,
                    # feature, petals before the ring).
                    d = float(depth.max()) if len(depth) else 0.0
                    key = (a, row0 + c, f, solid.endswith(" ring"))
                    if d > best.depth or (d == best.depth and d > 0.0 and key < rank):
                        best = Penetration(d, float(block[c][0]), f"{names[a]} {fname}", solid)
                        rank = key
            row0 += C
    return best
