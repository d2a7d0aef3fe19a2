"""A second interpenetration check of two APDS over a run, on triangle meshes: independent of the
contact code and of the analytic check (`drake_dock.docking.checks.penetration`), whose semantics it
follows and whose result type (`Penetration`) it returns.

Meshes, built here from the paper's equations in an APDS's own frame (cylindrical rho, theta,
zeta; e3 along the docking axis, ring face at zeta = 0):
- petal k (k = 1..3): a zero-thickness plate of triangles between its two guide sides,
  0 <= zeta <= H. Its vertices form a grid of ``across`` + 1 columns and ``up`` + 1 rows:
  s = j / across across the petal and zeta from the root (0) to the tip (H), at
  theta = phi_k + theta_1(zeta) + s (pi/3 - 2 theta_1(zeta)), theta_1(zeta) = arcsin(R
  sin(alpha2) / rho) - alpha2 (Eq. 13), rho = R - zeta cot(alpha1) (Eq. 12). Every vertex
  lies on the cone; the first and last columns on guide sides 2k - 1 and 2k (Eq. 14), the last
  row on the tip arc. The rows lie closer near the tip, where the guide sides bend most (each
  chord of a side then deviates from the side alike). Each quad is split along its shorter
  diagonal.
- ring: a closed solid, the annulus Rs <= rho <= R from its face (zeta = 0) to ``ring_depth``
  behind it: face and back as ``radial`` x ``around`` quads, inside and outside walls as
  ``deep`` x ``around`` quads.

The chord error, the largest distance of a triangle from the surface it stands for, is the
sagitta of the widest row: sin(alpha1) R (pi / (3 across))^2 / 8 on the petals (at the root)
and R (pi / around)^2 / 2 on the ring's outside wall (`MeshResolution.chord_errors`). With the
default resolution in the paper's geometry: 0.57 um on the petals, 0.71 um on the ring. The
petals' free edges are chords too: the root's lie 0.80 um inside the outside circle, the guide
sides' within 0.31 um of Eq. (14), the tip arcs' within 0.08 um of theirs, all under the 1 um
graze below (an edge sliding along a petal's edge still passes round it).

Moving features of the other APDS: its meshes' own boundary vertices, the ring's inside and
outside circles (``around`` points each: 1.2 and 1.8 mm apart by default), the ring face (its
vertices on the inner rows, every fourth around: 19 circles 1 cm apart, 512 points each), the
guide sides (the petals' first and last columns: 129 points, 1.7 to 3.7 mm apart) and the tip
arcs (their last rows: 321 points, 0.5 mm apart). Checked as in `penetration`: the guide
sides (but their roots, on the outside circle), the tip arcs and the ring's inside circle
against the other APDS's petals; the ring's circles and face against the other ring. A petal
passing the other ring's annulus is the paper's reading and is not checked.

A point *crosses* a petal when its path over a sub-step cuts a petal triangle more than
``graze`` from the petal's free edges (the mesh's boundary: guide sides, tip arc, root);
nearer, it passes round the edge. Per point and petal the crossings are counted odd or even;
a crossed point lies as deep as the least motion that frees it: its distance to the petal's
mesh, or the distance of its nearest mesh point to the free edges. A point inside the other
ring's solid (the parity of a ray's crossings) lies at its distance to the solid's surface.
Between samples the relative pose is interpolated as in `penetration` (`sub_steps`); a point
is tested against a mesh only when its motion since its last test may have reached the mesh (a
lower bound of its distance, from a k-d tree of the triangles' centroids).
"""
from __future__ import annotations

import dataclasses
import functools
import itertools
import math

import numpy as np
from scipy.spatial import cKDTree

from drake_dock.docking.checks.penetration import Penetration, relative_poses, sub_steps
from drake_dock.errors import InputError

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
SAME_PLACE = 1e-10      # m: hits this close on one path are one crossing (a shared edge)
MAX_TRIANGLES = 4e6     # of an APDS (the default: 0.44 million)


@dataclasses.dataclass(frozen=True)
class MeshResolution:
    """How finely the APDS are meshed: petal columns (``across``) and rows (``up``); ring
    segments around (``around``), face rows (``radial``) and wall rows (``deep``). The default
    keeps every chord within 1 um of its surface in the paper's geometry."""

    across: int = 320
    up: int = 128
    around: int = 2048
    radial: int = 20
    deep: int = 4

    def validate(self) -> "MeshResolution":
        for name, low in (("across", 2), ("up", 2), ("around", 12), ("radial", 1),
                          ("deep", 1)):
            v = getattr(self, name)
            if isinstance(v, bool) or not isinstance(v, int) or v < low:
                raise InputError(f"resolution.{name}", v, f"an integer >= {low}")
        n = 6 * self.across * self.up + 4 * self.around * (self.radial + self.deep)
        if n > MAX_TRIANGLES:
            raise InputError("resolution", self, f"at most {MAX_TRIANGLES:.0e} triangles",
                             f"{n} asked for")
        return self

    def chord_errors(self, g) -> dict:
        """The sagittas (m) of the widest rows: {"petal": from the cone, "petal root": from the
        ring's outside circle, "ring": from the ring's outside wall}."""
        root = g.Rp * (math.pi / (3 * self.across)) ** 2 / 8
        return {"petal": math.sin(g.alpha1) * root, "petal root": root,
                "ring": g.R * (math.pi / self.around) ** 2 / 2}


def petal_points(g, k, s, zeta):
    """Points of petal k's guide surface at fraction s across (0 and 1 on guide sides 2k - 1
    and 2k) and height zeta (Eq. 12, 13), in the APDS frame."""
    s, zeta = np.broadcast_arrays(np.asarray(s, float), np.asarray(zeta, float))
    rho = g.Rp - zeta / math.tan(g.alpha1)
    inset = np.arcsin(g.Rp * math.sin(g.alpha2) / rho) - g.alpha2
    th = (2 * k - 2) * math.pi / 3 + g.inset + inset + s * (math.pi / 3 - 2 * g.inset - 2 * inset)
    return np.stack([rho * np.cos(th), rho * np.sin(th), zeta], -1)


def petal_rows(g, up):
    """Row heights 0 = zeta_0 < ... < zeta_up = H: equal shares of the integral of
    sqrt(curvature) along guide side 1, so that its chords deviate from it alike (a chord of
    length L on a curve of curvature kappa lies kappa L^2 / 8 from it)."""
    z = np.linspace(0.0, g.H, 4001)
    seg = np.diff(petal_points(g, 1, 0.0, z), axis=0)
    ds = np.linalg.norm(seg, axis=1)
    u = seg / ds[:, None]
    kappa = np.arcsin(np.minimum(np.linalg.norm(np.cross(u[1:], u[:-1]), axis=1), 1.0))
    kappa /= 0.5 * (ds[1:] + ds[:-1])                  # at the inner points
    kappa = np.concatenate([kappa[:1], kappa, kappa[-1:]])
    w = np.sqrt(0.5 * (kappa[1:] + kappa[:-1])) * ds + 1e-12 * ds
    cum = np.concatenate([[0.0], np.cumsum(w)])
    rows = np.interp(np.linspace(0.0, cum[-1], up + 1), cum, z)
    rows[0], rows[-1] = 0.0, g.H
    return rows


def petal_grid(g, k, res):
    """Petal k's vertices (across + 1, up + 1, 3): columns across, rows up."""
    s = np.linspace(0.0, 1.0, res.across + 1)
    return petal_points(g, k, s[:, None], petal_rows(g, res.up)[None, :])


def grid_triangles(V, wrap=False):
    """Triangles (T, 3, 3) of the vertex grid V (n, m, 3), each quad split along its shorter
    diagonal; ``wrap``: the first axis closes on itself (around the ring)."""
    if wrap:
        V = np.concatenate([V, V[:1]], axis=0)
    a, b, c, d = V[:-1, :-1], V[1:, :-1], V[1:, 1:], V[:-1, 1:]
    ac = (np.linalg.norm(c - a, axis=-1) <= np.linalg.norm(d - b, axis=-1))[..., None]
    first = np.stack([a, b, np.where(ac, c, d)], -2)
    second = np.stack([np.where(ac, a, b), c, d], -2)
    return np.concatenate([first.reshape(-1, 3, 3), second.reshape(-1, 3, 3)])


def ring_grids(g, res, ring_depth):
    """The ring solid's four vertex grids (around, rows, 3): face, back, inside wall and the
    outer chamfer (rho = R + zeta, 45 deg; `penetration.ring_depth_of`). Shared rims are
    computed alike, so the solid closes exactly."""
    th = 2.0 * math.pi * np.arange(res.around) / res.around
    c, s = np.cos(th), np.sin(th)

    def grid(rho, z):
        rho, z = np.broadcast_arrays(np.atleast_1d(rho), np.atleast_1d(z))
        return np.stack([np.outer(c, rho), np.outer(s, rho), np.outer(np.ones_like(c), z)], -1)

    radii = np.linspace(g.Rs, g.R, res.radial + 1)
    depths = np.linspace(0.0, -ring_depth, res.deep + 1)
    back = np.linspace(g.Rs, g.R - ring_depth, res.radial + 1)
    return [grid(radii, 0.0), grid(back, -ring_depth), grid(g.Rs, depths),
            grid(g.R + depths, depths)]


def free_edges(V):
    """The closed boundary polyline of a petal grid V: guide side 2k - 1 up, the tip arc, guide
    side 2k down, the root back."""
    return np.concatenate([V[0, :], V[1:, -1], V[-1, -2::-1], V[-2::-1, 0]])


def mesh_features(g, res) -> dict:
    """{feature name: (M, 3) points in the APDS frame}: the meshes' boundary vertices."""
    face, _, inner, outer = ring_grids(g, res, 1.0)
    out = {"ring inside circle": inner[:, 0], "ring outside circle": outer[:, 0],
           "ring face": face[::4, 1:-1].reshape(-1, 3)}
    grids = [petal_grid(g, k, res) for k in (1, 2, 3)]
    for k, V in enumerate(grids, 1):
        out[f"guide side {2 * k - 1}"], out[f"guide side {2 * k}"] = V[0], V[-1]
    for k, V in enumerate(grids, 1):
        out[f"petal {k} tip arc"] = V[:, -1]
    return out


def closest_on_triangles(P, A, B, C):
    """The closest points of triangles ABC to points P (all (n, 3)), by the Voronoi regions of
    the vertices, edges and face (Ericson, Real-Time Collision Detection, 5.1.5)."""
    ab, ac = B - A, C - A

    def dots(X):
        return (ab * (P - X)).sum(1), (ac * (P - X)).sum(1)

    (d1, d2), (d3, d4), (d5, d6) = dots(A), dots(B), dots(C)
    va, vb, vc = d3 * d6 - d5 * d4, d5 * d2 - d1 * d6, d1 * d4 - d3 * d2
    with np.errstate(divide="ignore", invalid="ignore"):
        den = va + vb + vc
        Q = A + (vb / den)[:, None] * ab + (vc / den)[:, None] * ac
        regions = [   # edge BC, edge AC, vertex C, edge AB, vertex B, vertex A: later wins
            ((va <= 0) & (d4 >= d3) & (d5 >= d6),
             B + ((d4 - d3) / ((d4 - d3) + (d5 - d6)))[:, None] * (C - B)),
            ((vb <= 0) & (d2 >= 0) & (d6 <= 0), A + (d2 / (d2 - d6))[:, None] * ac),
            ((d6 >= 0) & (d5 <= d6), C),
            ((vc <= 0) & (d1 >= 0) & (d3 <= 0), A + (d1 / (d1 - d3))[:, None] * ab),
            ((d3 >= 0) & (d4 <= d3), B),
            ((d1 <= 0) & (d2 <= 0), A)]
        for where, X in regions:
            Q = np.where(where[:, None], X, Q)
    return Q


def polyline_distance(P, Q):
    """Distance of points P (n, 3) to the polyline through Q (m, 3)."""
    A, D = Q[:-1], np.diff(Q, axis=0)
    L2 = (D * D).sum(1)
    out = np.empty(len(P))
    for i in range(0, len(P), 128):
        W = P[i:i + 128, None, :] - A[None]
        u = np.clip((W * D).sum(-1) / L2, 0.0, 1.0)
        out[i:i + 128] = np.linalg.norm(W - u[..., None] * D, axis=-1).min(1)
    return out


def _pairs(lists):
    """(i, j) for every j in lists[i]."""
    n = np.fromiter(map(len, lists), int, len(lists))
    j = np.fromiter(itertools.chain.from_iterable(lists), int, int(n.sum()))
    return np.repeat(np.arange(len(lists)), n), j


class TriangleMesh:
    """Triangles (T, 3, 3) with a k-d tree of their centroids: which may lie near a point, where
    paths cross them, the closest point, and (closed meshes) which points lie inside."""

    def __init__(self, tri, edges=None):
        self.A, self.e1, self.e2 = tri[:, 0], tri[:, 1] - tri[:, 0], tri[:, 2] - tri[:, 0]
        self.n = np.cross(self.e1, self.e2)
        centre = tri.mean(axis=1)
        self.rmax = float(np.linalg.norm(tri - centre[:, None], axis=-1).max()) * (1 + 1e-9)
        self.tree = cKDTree(centre)
        self.lo, self.hi = tri.min(axis=(0, 1)), tri.max(axis=(0, 1))
        self.edges = edges             # the free edges (a polyline) of an open mesh
        self._centre = centre
        self._up = None

    def near(self, P, r):
        """Pairs (i, j): triangle j may come within r[i] of point P[i]."""
        if len(P) == 0:
            return np.zeros(0, int), np.zeros(0, int)
        return _pairs(self.tree.query_ball_point(P, r + self.rmax, return_sorted=False))

    def bound(self, P, cap=0.1):
        """A lower bound of each point's distance to the mesh: from its nearest centroid, or
        its distance to the mesh's bounding box."""
        d = self.tree.query(P, distance_upper_bound=cap)[0] if len(P) else np.zeros(0)
        box = np.linalg.norm(np.maximum(np.maximum(self.lo - P, P - self.hi), 0.0), axis=1)
        return np.maximum(np.minimum(d, cap) - self.rmax, box)

    def crossings(self, P0, P1, pairs=None):
        """Where the paths P0[i] -> P1[i] cross the mesh: (i, X), a row a crossing (the hits of
        one place on triangles that share an edge or a vertex count once). A point on a
        triangle's plane counts on its positive side."""
        if pairs is None:
            pairs = self.near(0.5 * (P0 + P1), 0.5 * np.linalg.norm(P1 - P0, axis=1))
        i, j = pairs
        A, n = self.A[j], self.n[j]
        d0, d1 = ((P0[i] - A) * n).sum(1), ((P1[i] - A) * n).sum(1)
        cut = (d0 >= 0.0) != (d1 >= 0.0)
        i, j, d0, d1 = i[cut], j[cut], d0[cut], d1[cut]
        f = d0 / (d0 - d1)
        X = P0[i] + f[:, None] * (P1[i] - P0[i])
        W, e1, e2 = X - self.A[j], self.e1[j], self.e2[j]
        d00, d01, d11 = (e1 * e1).sum(1), (e1 * e2).sum(1), (e2 * e2).sum(1)
        d20, d21 = (W * e1).sum(1), (W * e2).sum(1)
        den = d00 * d11 - d01 * d01
        v, w = (d11 * d20 - d01 * d21) / den, (d00 * d21 - d01 * d20) / den
        on = (v >= -1e-9) & (w >= -1e-9) & (v + w <= 1.0 + 1e-9)
        i, f, X = i[on], f[on], X[on]
        order = np.lexsort((f, i))
        i, X = i[order], X[order]
        again = np.zeros(len(i), dtype=bool)
        again[1:] = (i[1:] == i[:-1]) & (np.linalg.norm(X[1:] - X[:-1], axis=1) <= SAME_PLACE)
        return i[~again], X[~again]

    def nearest(self, P, up):
        """Each point's distance to the mesh and its closest point of the mesh, given up, an
        upper bound of the distance (the distance to a point of the mesh)."""
        i, j = self.near(P, up * (1 + 1e-9) + 1e-12)
        A = self.A[j]
        Q = closest_on_triangles(P[i], A, A + self.e1[j], A + self.e2[j])
        d = np.linalg.norm(P[i] - Q, axis=1)
        order = np.lexsort((d, i))
        _, first = np.unique(i[order], return_index=True)
        return d[order[first]], Q[order[first]]

    def deepest(self, P, floor, edges=None):
        """(depth, index) of the point of P deepest below the mesh if deeper than floor, else
        (floor, -1). Depth: the distance to the mesh; with ``edges``, the least of that and the
        distance of the closest mesh point to the polyline edges. Exact distances are taken
        only for the points whose upper bound (the distance to the triangle of their nearest
        centroid) exceeds the deepest found."""
        j = self.tree.query(P)[1]
        A = self.A[j]
        up = np.linalg.norm(P - closest_on_triangles(P, A, A + self.e1[j], A + self.e2[j]), axis=1)
        order, best, arg, start, size = np.argsort(-up), floor, -1, 0, 64
        while start < len(order):
            idx = order[start:start + size]
            idx = idx[up[idx] > best + 1e-12]
            if not len(idx):
                break
            d, Q = self.nearest(P[idx], up[idx])
            if edges is not None:
                d = np.minimum(d, polyline_distance(Q, edges))
            if d.max() > best:
                best, arg = float(d.max()), int(idx[d.argmax()])
            start, size = start + size, 2 * size
        return best, arg

    def inside(self, P):
        """Which points lie inside the mesh (closed): the parity of the crossings of a ray from
        each along +e3 to above the mesh (triangles along the ray are not crossed)."""
        if len(P) == 0:
            return np.zeros(0, dtype=bool)
        if self._up is None:          # the triangles seen along e3: a tree in (x, y)
            tri = self.A[:, None, :2] + np.stack([0 * self.e1, self.e1, self.e2], 1)[..., :2]
            r = np.linalg.norm(tri - self._centre[:, None, :2], axis=-1).max()
            self._up = (cKDTree(self._centre[:, :2]), float(r) * (1 + 1e-9) + 1e-12)
        tree, r = self._up
        P1 = P.copy()
        P1[:, 2] = self.hi[2] + 1e-3
        i, _ = self.crossings(P, P1, _pairs(tree.query_ball_point(P[:, :2], r,
                                                                  return_sorted=False)))
        return np.bincount(i, minlength=len(P)) % 2 == 1

    def within_box(self, P):
        """Which points lie in the mesh's bounding box."""
        return np.all((P >= self.lo) & (P <= self.hi), axis=1)


@functools.lru_cache(maxsize=4)
def apds_meshes(shape, res, ring_depth):
    """([petal 1, 2, 3], ring) `TriangleMesh`es of an APDS; shape = (R, Rs, H, alpha1,
    alpha2, Rp, inset), angles in rad."""
    g = _Shape(*shape)
    petals = []
    for k in (1, 2, 3):
        V = petal_grid(g, k, res)
        petals.append(TriangleMesh(grid_triangles(V), free_edges(V)))
    ring = np.concatenate([grid_triangles(V, wrap=True) for V in ring_grids(g, res, ring_depth)])
    return petals, TriangleMesh(ring)


@dataclasses.dataclass(frozen=True)
class _Shape:
    R: float
    Rs: float
    H: float
    alpha1: float
    alpha2: float
    Rp: float
    inset: float


class _Watch:
    """The features of one APDS (X, in its frame) against the meshes of the other, sub-step by
    sub-step: per point and petal the crossings' parity, per point whether it lies inside the
    ring, and lower bounds of the distances (slack) that spare the tests of far points."""

    def __init__(self, petals, ring, Xp, Xr, reach, graze):
        self.petals, self.ring, self.Xp, self.Xr = petals, ring, Xp, Xr
        self.reach, self.graze = reach, graze
        self.crossed = np.zeros((len(Xp), 3), dtype=bool)
        self.inside = np.zeros(len(Xr), dtype=bool)
        self.slack = self.slack_r = None
        self.last = None

    def step(self, R, p, floor):
        """[(depth, point, solid)] of points deeper than floor after moving to (R, p), the
        deepest last."""
        def at(X, idx, R=R, p=p):
            return X[idx] @ R.T + p

        if self.last is None:
            Yp, Yr = self.Xp @ R.T + p, self.Xr @ R.T + p
            self.slack = np.column_stack([m.bound(Yp) for m in self.petals]).reshape(-1, 3)
            self.slack_r = self.ring.bound(Yr)
            box = np.flatnonzero(self.ring.within_box(Yr))
            self.inside[box] = self.ring.inside(Yr[box])
        else:
            R0, p0 = self.last
            travel = np.linalg.norm(p - p0) + np.linalg.norm(R - R0) * self.reach + 1e-12
            self.slack -= travel
            self.slack_r -= travel
            near = self.slack <= 0.0
            act = np.flatnonzero(near.any(axis=1))
            if len(act):
                Y0, Y1 = at(self.Xp, act, R0, p0), at(self.Xp, act)
                for k, mesh in enumerate(self.petals):
                    sel = np.flatnonzero(near[act, k])
                    if len(sel):
                        self._cross(k, mesh, act[sel], Y0[sel], Y1[sel])
                        self.slack[act[sel], k] = mesh.bound(Y1[sel])
            act = np.flatnonzero(self.slack_r <= 0.0)
            if len(act):
                Y1 = at(self.Xr, act)
                box = self.ring.within_box(Y1)
                self.inside[act] = box
                self.inside[act[box]] = self.ring.inside(Y1[box])
                self.slack_r[act] = self.ring.bound(Y1)
        self.last = (R, p)
        found = []
        for k, mesh in enumerate(self.petals):
            c = np.flatnonzero(self.crossed[:, k])
            if len(c):
                depth, i = mesh.deepest(at(self.Xp, c), floor, mesh.edges)
                if i >= 0:
                    found.append((depth, int(c[i]), f"petal {k + 1}"))
                    floor = depth
        c = np.flatnonzero(self.inside)
        if len(c):
            depth, i = self.ring.deepest(at(self.Xr, c), floor)
            if i >= 0:
                found.append((depth, int(c[i]), "ring"))
        return found

    def _cross(self, k, mesh, idx, Y0, Y1):
        """Counts the crossings of petal k by the points idx moving from Y0 to Y1."""
        i, X = mesh.crossings(Y0, Y1)
        if len(i) and self.graze > 0.0:
            i = i[polyline_distance(X, mesh.edges) > self.graze]
        flip = np.bincount(i, minlength=len(idx)) % 2 == 1
        self.crossed[idx[flip], k] ^= True


def _check(t, R_WA, p_WA, names, ring_depth, max_travel, graze):
    t, R_WA, p_WA = (np.asarray(a, dtype=float) for a in (t, R_WA, p_WA))
    n = len(t) if t.ndim == 1 else -1
    for field, a, shape in (("t", t, (n,)), ("R_WA", R_WA, (n, 2, 3, 3)),
                            ("p_WA", p_WA, (n, 2, 3))):
        if n < 1 or a.shape != shape or not np.isfinite(a).all():
            raise InputError(field, a.shape, f"finite values of shape {shape} (N >= 1 samples)")
    if len(names) != 2:
        raise InputError("names", names, "the two APDS names")
    for field, v, low in (("ring_depth", ring_depth, 0.0), ("max_travel", max_travel, 0.0)):
        if not (isinstance(v, (int, float)) and math.isfinite(v) and v > low):
            raise InputError(field, v, "a finite length > 0 m")
    if not (isinstance(graze, (int, float)) and math.isfinite(graze) and graze >= 0.0):
        raise InputError("graze", graze, "a finite length >= 0 m")
    return t, R_WA, p_WA


def deepest_penetration_mesh(g, t, R_WA, p_WA, names, *, ring_depth=0.04, max_travel=1e-3,
                             graze=1e-6, resolution=None, features=None) -> Penetration:
    """The deepest interpenetration of the two APDS over the samples t (N,) with their frames'
    poses R_WA (N, 2, 3, 3), p_WA (N, 2, 3) (the timeseries fields), names the two APDS names,
    found on triangle meshes of the geometry g (`MeshResolution` ``resolution``, its default
    when None). ``features`` replaces `mesh_features` (a subset, for tests). Arguments as in
    `penetration.deepest_penetration`; bad ones raise `InputError`."""
    t, R_WA, p_WA = _check(t, R_WA, p_WA, names, ring_depth, max_travel, graze)
    res = (MeshResolution() if resolution is None else resolution)
    if not isinstance(res, MeshResolution):
        raise InputError("resolution", res, "a MeshResolution or None")
    res.validate()
    shape = (float(g.R), float(g.Rs), float(g.H), float(g.alpha1), float(g.alpha2),
             float(g.Rp), float(g.inset))
    petals, ring = apds_meshes(shape, res, float(ring_depth))
    feats = mesh_features(g, res) if features is None else features
    vs_petals, vs_ring = checked_features(g)
    on_petals = [(f, X[~((np.abs(X[:, 2]) < 1e-12)          # roots on the outside circle
                        & (np.abs(np.hypot(X[:, 0], X[:, 1]) - g.Rp) < 1e-9))])
                 for f, X in feats.items() if f.startswith(vs_petals)]
    on_ring = [(f, X) for f, X in feats.items() if f.startswith(vs_ring)]
    which = {kind: [f for f, X in group for _ in range(len(X))]
             for kind, group in (("petal", on_petals), ("ring", on_ring))}
    Xp, Xr = (np.concatenate([X for _, X in group] + [np.zeros((0, 3))])
              for group in (on_petals, on_ring))
    reach = max(float(np.linalg.norm(X, axis=1).max(initial=0.0)) for X in feats.values())
    best = Penetration()
    for a, b in ((0, 1), (1, 0)):
        R, p = relative_poses(R_WA, p_WA, a, b)
        watch = _Watch(petals, ring, Xp, Xr, reach, graze)
        for tt, Rab, pab in sub_steps(t, R, p, reach, max_travel):
            for depth, i, solid in watch.step(Rab, pab, best.depth):
                if depth > best.depth:
                    kind = "ring" if solid == "ring" else "petal"
                    best = Penetration(depth, float(tt), f"{names[a]} {which[kind][i]}",
                                       f"{names[b]} {solid}")
    return best
