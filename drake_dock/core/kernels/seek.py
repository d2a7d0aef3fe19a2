"""The seek of Sect. 5.1 compiled, over the kernels' patch descriptions (`jets.patch_spec`;
`drake_dock.core.seeking.seek_couple` packs them and reads the result):

- a curve against a curve or a surface (`seek`): the paper's hierarchical grid (`hierarchical`:
  a coarse grid over both patches' parameters, then grids an order finer around the best
  cells), each start finished by a bounded Newton iteration on the closest-point conditions
  (`newton`: the gradient of 0.5 |r1 - r2|^2 zero, or its projection on the active bounds);
- a point against a surface (`point_surface`): the nearest point of a grid, then `newton`;
- a point against a curve (`point_curve`): for a full circle in closed form (the polar angle
  of the point in the circle's frame; 0 on the axis, where every parameter is closest), else
  the nearest point of a grid finished by Newton on F = t2 . d (Eq. 37 for a point), clipped
  to the domain; and the curve's side the point lies on.

docs/algorithms.md, "The seek's Newton finish", gives the rules for flat valleys, domain ends
and creeping iterations that `newton` follows.
"""
from __future__ import annotations

import math
from typing import NamedTuple

import numpy as np
from numba import njit

from drake_dock.core.kernels.copies import copy1
from drake_dock.core.kernels.grids import Domain, Placed, hierarchical, positions, within
from drake_dock.core.kernels.jets import CIRCLE, jet, position

# A point patch (patch 1 of a point pair): its parameters are the point's coordinates.
POINT = -1
EPS8 = 8 * np.finfo(float).eps
# Eigenvalues of the descent step's Hessian below FLAT max(1, |w|max) are flat directions.
FLAT = 1e-10
# The closest-couple Newton's iteration limit (`newton`). A crossing next to a tangency (a
# ring's circle cutting a guide surface it nearly osculates, next to the surface's edge) leaves
# J nearly singular, and the iteration walks the valley for about 90 iterations before it
# converges quadratically.
CLOSEST_MAX_ITER = 200
# m: a Newton finish that creeps this near touching is a touch (`newton`'s status).
CREEP_TOUCH = 1e-6
# The further iterations of the nearest start of a curve's seek whose Newton has not converged
# in CLOSEST_MAX_ITER beyond CREEP_TOUCH (`creep_on`). A circle nearly parallel to a face, its
# nearest point near the face's edge, leaves a valley of minima that is flat along the circle
# and curved in the parameters: each straight step descends but runs off the valley's curve
# after a few mrad, and the iteration creeps to the minimum in a few hundred iterations.
CREEP_MAX_ITER = 2000


@njit(cache=True)
def _descent_step(H, g):
    """The descent step -|H|^-1 g with the eigenvalues of H made positive, in two parts: along
    the directions where |w| >= FLAT max(1, |w|max) (the Newton step where H is safely
    positive definite), and along the flat ones, where -(v . g) / |w| (|w| floored at 1e-16)
    is far too long and the caller caps it. A Cholesky solve where H is well conditioned
    (det / tr^(n-1) above FLAT max(1, tr)), the eigen-decomposition otherwise."""
    n = g.shape[0]
    if n == 1:
        return np.array([-g[0] / max(abs(H[0, 0]), FLAT * max(1.0, abs(H[0, 0])))]), np.zeros(1)
    L = np.zeros((n, n))
    det = 1.0
    ok = True
    for i in range(n):
        for j in range(i + 1):
            s = H[i, j]
            for k in range(j):
                s -= L[i, k] * L[j, k]
            if i == j:
                if not s > 0.0:
                    ok = False
                    break
                L[i, i] = math.sqrt(s)
                det *= s
            else:
                L[i, j] = s / L[j, j]
        if not ok:
            break
    if ok:
        tr = 0.0
        for i in range(n):
            tr += H[i, i]
        if det / tr ** (n - 1) >= FLAT * max(1.0, tr):
            y = np.zeros(n)
            for i in range(n):
                s = g[i]
                for k in range(i):
                    s -= L[i, k] * y[k]
                y[i] = s / L[i, i]
            x = np.zeros(n)
            for i in range(n - 1, -1, -1):
                s = y[i]
                for k in range(i + 1, n):
                    s -= L[k, i] * x[k]
                x[i] = s / L[i, i]
            return -x, np.zeros(n)
    w, V = np.linalg.eigh(H)
    w = np.abs(w)
    top = max(1.0, w.max())
    c = -(V.T @ g) / np.maximum(w, 1e-16 * top)
    flat = w < FLAT * top
    return V @ np.where(flat, 0.0, c), V @ np.where(flat, c, 0.0)


@njit(cache=True)
def world_point(kind, prm, R, o, u0, u1):
    """R r(u) + o (Eq. 20); a `POINT`'s r is its coordinates."""
    r = (prm[0], prm[1], prm[2]) if kind == POINT else position(kind, prm, u0, u1)
    return (R[0, 0] * r[0] + R[0, 1] * r[1] + R[0, 2] * r[2] + o[0],
            R[1, 0] * r[0] + R[1, 1] * r[1] + R[1, 2] * r[2] + o[1],
            R[2, 0] * r[0] + R[2, 1] * r[1] + R[2, 2] * r[2] + o[2])


class Bounds(NamedTuple):
    """A couple's parameters as `newton` takes them: lower and upper bounds, periodic flags
    and scales (the spans, floored at 1e-300)."""

    lower: np.ndarray
    upper: np.ndarray
    periodic: np.ndarray
    scale: np.ndarray


@njit(cache=True)
def _gap(k1, p1, R1, o1, k2, p2, R2, o2, u, n1):
    """(x1 - x2, x1, x2) at the couple u of two placed patches (the fields of their `Placed`,
    read once by the caller: `newton` calls this at every iteration), patch 1 a curve (n1 = 1)
    or a `POINT` (n1 = 0)."""
    x1 = world_point(k1, p1, R1, o1, u[0], 0.0)
    x2 = world_point(k2, p2, R2, o2, u[n1], u[n1 + 1] if u.shape[0] == n1 + 2 else 0.0)
    return (x1[0] - x2[0], x1[1] - x2[1], x1[2] - x2[2]), x1, x2


@njit(cache=True)
def newton(pa, pb, u, bounds, tol, max_iter, distance_rtol, rtol_beyond):
    """Bounded Newton on f(u) = 0.5 |r1(u1) - r2(u2)|^2 from u, for the `Placed` patches pa
    and pb (patch 1 a curve or a `POINT`) within the `Bounds` of their couple:
    (u, iterations, status), status 0 converged, 1 not converged with the projected gradient
    above 1e-10 |J| |d| (the caller names the couple). Parameters at a domain end with the
    gradient pushing outwards are held (an active set with a band, Bertsekas' projected
    Newton), periodic ones wrapped; the step descends (the Hessian's eigenvalues made
    positive), runs along a flat direction to a quarter of the domain or the first domain end
    on its way, and is backtracked on f. With ``distance_rtol`` >= 0 (< 0: none) the iteration
    also ends when a step shortens the distance by less than that fraction of it, while the
    distance exceeds ``rtol_beyond``."""
    k1, p1, R1, o1 = pa
    k2, p2, R2, o2 = pb
    lower, upper, periodic, scale = bounds
    n1 = 0 if k1 == POINT else 1
    n = u.shape[0]
    n2 = n - n1
    u = u.copy()
    gfree = np.zeros(n)
    norm_J = norm_d = 0.0
    it = 0
    converged = False
    for it in range(1, max_iter + 1):
        j2 = jet(k2, p2, u[n1], u[n1 + 1] if n2 == 2 else 0.0)
        _, x1, x2 = _gap(k1, p1, R1, o1, k2, p2, R2, o2, u, n1)
        d = np.array([x1[0] - x2[0], x1[1] - x2[1], x1[2] - x2[2]])
        # J = [T1, -T2] (world tangents); g = J^T d; H = J^T J + diag(d . K1, -d . K2).
        cols = np.empty((n, 3))
        k1d = 0.0
        if n1 == 1:
            j1 = jet(k1, p1, u[0], 0.0)
            copy1(cols[0], R1 @ np.array(j1[1]))
            k1d = (R1.T @ d) @ np.array(j1[3])
        copy1(cols[n1], -(R2 @ np.array(j2[1])))
        if n2 == 2:
            copy1(cols[n1 + 1], -(R2 @ np.array(j2[2])))
        g = cols @ d
        H = cols @ cols.T
        d2 = R2.T @ d
        if n1 == 1:
            H[0, 0] += k1d
        K2 = (np.array(j2[3]), np.array(j2[4]), np.array(j2[5]))
        if n2 == 1:
            H[n1, n1] -= d2 @ K2[0]
        else:
            H[n1, n1] -= d2 @ K2[0]
            H[n1, n1 + 1] -= d2 @ K2[1]
            H[n1 + 1, n1] -= d2 @ K2[1]
            H[n1 + 1, n1 + 1] -= d2 @ K2[2]
        norm_J = math.sqrt(np.sum(cols * cols))
        norm_d = math.sqrt(d @ d)
        d_roundoff = EPS8 * (max(abs(x1[0]), max(abs(x1[1]), abs(x1[2])))
                             + max(abs(x2[0]), max(abs(x2[1]), abs(x2[2]))))
        step = np.zeros(n)
        free = np.zeros(n, dtype=np.bool_)
        on_bounds = True
        for i in range(n):
            gi = g[i]
            band = min(1e-3 * scale[i], abs(gi) / max(abs(H[i, i]), 1e-300))
            if not periodic[i] and u[i] <= lower[i] + band and gi > 0:
                step[i] = lower[i] - u[i]
            elif not periodic[i] and u[i] >= upper[i] - band and gi < 0:
                step[i] = upper[i] - u[i]
            else:
                free[i] = True
                continue
            on_bounds = on_bounds and step[i] == 0.0
        gfree = np.where(free, g, 0.0)
        norm_gfree = math.sqrt(gfree @ gfree)
        if on_bounds and norm_gfree <= norm_J * max(1e-13 * norm_d, d_roundoff):
            converged = True
            break
        if on_bounds and norm_gfree <= 1e-15 * norm_J ** 2:
            converged = True
            break
        fi = np.flatnonzero(free)
        if fi.shape[0] > 0:
            sf, flat = _descent_step(np.ascontiguousarray(H[fi][:, fi]), g[fi])
            reach = np.max(np.abs(flat) / scale[fi])
            cut = 0.25 / reach if reach > 0.25 else 1.0
            for m in range(fi.shape[0]):
                a, f = fi[m], flat[m]
                if f != 0.0 and not periodic[a]:
                    room = ((upper[a] if f > 0 else lower[a]) - u[a]) / f
                    cut = min(cut, max(room, 0.0))
            for m in range(fi.shape[0]):
                step[fi[m]] = sf[m] + cut * flat[m]
            reach = np.max(np.abs(step) / scale)
            if reach > 0.25:
                step = step * (0.25 / reach)
        f0 = 0.5 * norm_d * norm_d
        slope = g @ step
        if -slope <= 1e-15 * f0:
            converged = True
            break
        far = distance_rtol >= 0.0 and on_bounds and 2.0 * f0 > rtol_beyond ** 2
        if far and -slope <= distance_rtol * 2.0 * f0:
            converged = True
            break
        t = 1.0
        un = u.copy()
        fn = 0.0
        accepted = False
        while True:
            for i in range(n):
                a = u[i] + t * step[i]
                un[i] = a if periodic[i] else min(max(a, lower[i]), upper[i])
            dn = _gap(k1, p1, R1, o1, k2, p2, R2, o2, un, n1)[0]
            fn = 0.5 * (dn[0] * dn[0] + dn[1] * dn[1] + dn[2] * dn[2])
            if fn <= f0 + 1e-4 * (g @ (un - u)):
                accepted = True
                break
            t *= 0.25
            if t < 1e-12:
                break
        if not accepted:
            converged = True
            break
        moved = np.max(np.abs(un - u) / scale)
        u = un
        if moved < tol:
            converged = True
            break
        if far and f0 - fn <= distance_rtol * 2.0 * f0:
            converged = True
            break
    status = 0
    if not converged and math.sqrt(gfree @ gfree) > 1e-10 * norm_J * norm_d:
        status = 1
    for i in range(n):
        if periodic[i]:
            span = upper[i] - lower[i]
            u[i] = lower[i] + np.mod(u[i] - lower[i], span)
    return u, it, status


@njit(cache=True)
def _couple_domain(da, db):
    """The `Bounds` of a couple from its two patches' `Domain`s."""
    lower, upper = np.concatenate((da.lower, db.lower)), np.concatenate((da.upper, db.upper))
    return Bounds(lower, upper, np.concatenate((da.periodic, db.periodic)),
                  np.maximum(upper - lower, 1e-300))


@njit(cache=True)
def seek(a, da, b, db, levels, n_fine, candidates, distance_rtol, rtol_beyond):
    """A curve's seek, of the `Placed` patches a (a curve) and b (a curve or a surface) over
    their `Domain`s da and db: the start couples of `hierarchical`, each finished by `newton`
    unless an earlier one started within 1e-9 of the spans (one finish serves both): the
    finished couples u (C, n),
    their iterations, statuses, points x1, x2 (C, 3) and whether they are interior
    (`seeking.is_interior` of both parts), in the order of the starts."""
    bounds = _couple_domain(da, db)
    lower, upper, periodic, scale = bounds
    k1, p1, R1, o1 = a
    k2, p2, R2, o2 = b
    tol = 1e-9 * (upper - lower)
    starts = hierarchical(a, da, b, db, levels, n_fine, candidates)
    C, n = starts.shape
    U, its, status = np.empty((C, n)), np.zeros(C, dtype=np.int64), np.zeros(C, dtype=np.int64)
    X1, X2 = np.empty((C, 3)), np.empty((C, 3))
    interior = np.zeros(C, dtype=np.bool_)
    started = np.zeros(C, dtype=np.bool_)
    m = 0
    for c in range(C):
        dup = False
        for s in range(c):
            dup = dup or (started[s] and within(starts[c], starts[s], tol))
        if dup:
            continue
        started[c] = True
        u, its[m], status[m] = newton(a, b, starts[c], bounds, 1e-14, CLOSEST_MAX_ITER,
                                      distance_rtol, rtol_beyond)
        _, x1, x2 = _gap(k1, p1, R1, o1, k2, p2, R2, o2, u, 1)
        copy1(U[m], u)
        X1[m, 0], X1[m, 1], X1[m, 2] = x1
        X2[m, 0], X2[m, 1], X2[m, 2] = x2
        interior[m] = True
        interior[m] = _interior(u, lower, upper, periodic)
        m += 1
    return U[:m], its[:m], status[:m], X1[:m], X2[:m], interior[:m]


@njit(cache=True)
def creep_on(a, da, b, db, u, distance_rtol, rtol_beyond):
    """`newton` continued from a finished couple u of `seek` (its arguments) that did not
    converge, with the seek's bounds, scales and tolerances, for at most CREEP_MAX_ITER further
    iterations: (u, iterations, status, x1 (3,), x2 (3,), interior), as one couple of `seek`."""
    bounds = _couple_domain(da, db)
    lower, upper, periodic, scale = bounds
    u, it, status = newton(a, b, u, bounds, 1e-14, CREEP_MAX_ITER, distance_rtol, rtol_beyond)
    _, x1, x2 = _gap(a.kind, a.prm, a.R, a.o, b.kind, b.prm, b.R, b.o, u, 1)
    return (u, it, status, np.array([x1[0], x1[1], x1[2]]), np.array([x2[0], x2[1], x2[2]]),
            _interior(u, lower, upper, periodic))


@njit(cache=True)
def _interior(u, lower, upper, periodic):
    """min(u - lower, upper - u) > 1e-9 span for every bounded parameter (NaN: not)."""
    for k in range(u.shape[0]):
        span = upper[k] - lower[k]
        inside = u[k] - lower[k] > 1e-9 * span and upper[k] - u[k] > 1e-9 * span
        if not (periodic[k] or inside):
            return False
    return True


@njit(cache=True)
def point_surface(a, b, db, distance_rtol, rtol_beyond):
    """The couple of the `Placed` point a (kind `POINT`: its frame's coordinates first in its
    parameters) and the `Placed` surface b over its `Domain` db: the nearest point of the
    domain's grid, finished by `newton`. Returns (u (2,), iterations, status, x1, x2 (3,),
    interior)."""
    k2, p2, R2, o2 = b
    lo2, hi2, per2, U2 = db
    X2 = positions(k2, p2, R2, o2, U2)
    x = world_point(POINT, a.prm, a.R, a.o, 0.0, 0.0)
    best, i_best = np.inf, 0
    for i in range(X2.shape[0]):
        e0, e1, e2 = X2[i, 0] - x[0], X2[i, 1] - x[1], X2[i, 2] - x[2]
        dd = e0 * e0 + e1 * e1 + e2 * e2
        if dd < best:
            best, i_best = dd, i
    bounds = Bounds(lo2, hi2, per2, np.maximum(hi2 - lo2, 1e-300))
    u, it, status = newton(a, b, U2[i_best].copy(), bounds, 1e-14, CLOSEST_MAX_ITER,
                           distance_rtol, rtol_beyond)
    _, x1, x2 = _gap(POINT, a.prm, a.R, a.o, k2, p2, R2, o2, u, 0)
    return (u, it, status, np.array([x1[0], x1[1], x1[2]]), np.array([x2[0], x2[1], x2[2]]),
            _interior(u, lo2, hi2, per2))


@njit(cache=True)
def point_curve(x, b, db, max_iter):
    """The couple of the world point x and the `Placed` curve b over its `Domain` db: the s of least
    |x - c(s)|, for a full circle (a periodic CIRCLE) its polar angle in the curve's frame (0 on
    the axis), else from the nearest point of the grid U by Newton on F = t2 . d, clipped to the
    domain, for at most ``max_iter`` steps (stopping where F' >= 0, not a minimum). Returns (s,
    iterations, x2 (3,), concave): ``concave`` where the point lies on the curve's concave side
    (d along its curvature direction; true where the curve is straight)."""
    k2, p2, R2, o2 = b
    lo, hi, periodic, U = db
    e = (x[0] - o2[0], x[1] - o2[1], x[2] - o2[2])
    q = (R2[0, 0] * e[0] + R2[1, 0] * e[1] + R2[2, 0] * e[2],
         R2[0, 1] * e[0] + R2[1, 1] * e[1] + R2[2, 1] * e[2],
         R2[0, 2] * e[0] + R2[1, 2] * e[1] + R2[2, 2] * e[2])
    span = hi[0] - lo[0]
    it = 0
    if k2 == CIRCLE and periodic[0]:
        s = math.atan2(q[1], q[0]) if math.hypot(q[0], q[1]) > 0.0 else 0.0
    else:
        best, s = np.inf, U[0, 0]
        for a in range(U.shape[0]):
            r = position(k2, p2, U[a, 0], 0.0)
            dd = (r[0] - q[0]) ** 2 + (r[1] - q[1]) ** 2 + (r[2] - q[2]) ** 2
            if dd < best:
                best, s = dd, U[a, 0]
        for it in range(1, max_iter + 1):
            r, t, _, k, _, _ = jet(k2, p2, s, 0.0)
            d = (q[0] - r[0], q[1] - r[1], q[2] - r[2])
            Fu = (k[0] * d[0] + k[1] * d[1] + k[2] * d[2]) - (t[0] * t[0] + t[1] * t[1]
                                                                + t[2] * t[2])
            if not Fu < 0.0:
                break
            s_new = s - (t[0] * d[0] + t[1] * d[1] + t[2] * d[2]) / Fu
            if periodic[0]:
                s_new = lo[0] + np.mod(s_new - lo[0], span)
            else:
                s_new = min(max(s_new, lo[0]), hi[0])
            done = abs(s_new - s) <= 1e-14 * (1.0 + span)
            s = s_new
            if done:
                break
    if periodic[0]:
        s = lo[0] + np.mod(s - lo[0], span)
    x2 = world_point(k2, p2, R2, o2, s, 0.0)
    k = jet(k2, p2, s, 0.0)[3]
    kw = (R2[0, 0] * k[0] + R2[0, 1] * k[1] + R2[0, 2] * k[2],
          R2[1, 0] * k[0] + R2[1, 1] * k[1] + R2[1, 2] * k[2],
          R2[2, 0] * k[0] + R2[2, 1] * k[1] + R2[2, 2] * k[2])
    side = ((x[0] - x2[0]) * kw[0] + (x[1] - x2[1]) * kw[1] + (x[2] - x2[2]) * kw[2])
    straight = kw[0] * kw[0] + kw[1] * kw[1] + kw[2] * kw[2] == 0.0
    return s, it, np.array([x2[0], x2[1], x2[2]]), straight or side > 0.0


def warm():
    """Compiles or loads the seek's kernels with the argument types of
    `drake_dock.core.seeking.seek_couple`: a curve against a curve and against a surface, a
    point against a surface and against a circle and an arc."""
    from drake_dock.core.patches import Arc, Circle, PlaneRect, Segment
    from drake_dock.core.kernels.jets import patch_spec
    eye, z = np.eye(3), np.zeros(3)

    seg = Segment((0.0, 0.0, 0.1), (1.0, 0.0, 0.1))
    plane = PlaneRect((-1, -1, 0), (2, 0, 0), (0, 2, 0))
    def placed(patch):
        return Placed(*patch_spec(patch), eye, z)

    for c1, c2 in ((seg, Segment((0.5, -1.0, 0.0), (0.5, 1.0, 0.0))), (Circle(0.3, 0.1), plane)):
        args = (placed(c1), Domain(*c1.kernel_domain(12)), placed(c2),
                Domain(*c2.kernel_domain(12)))
        U = seek(*args, 2, 21, 3, -1.0, 0.0)[0]
        creep_on(*args, U[0], -1.0, 0.0)
    pt = np.array([0.1, 0.2, 0.3, 0.01, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0])
    point_surface(Placed(POINT, pt, eye, z), placed(plane), Domain(*plane.kernel_domain(16)),
                  -1.0, 0.0)
    for curve in (Circle(0.3), Arc(0.3, 0.0, (0.2, 1.4))):
        point_curve(z, placed(curve), Domain(*curve.kernel_domain(64)), 30)
