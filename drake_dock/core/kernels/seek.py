"""The seek of Sect. 5.1 compiled: the hierarchical grid and the bounded Newton finish of
`drake_dock.core.seeking` (`hierarchical_seek`, `newton_closest`, `seek_couple`) over the
kernels' patch descriptions (`jets.patch_spec`), with the same steps and tolerances.

The grid distances are computed as |x1 - x2|^2 directly (the reference expands them), so a grid
tie may be broken differently; the Newton finish then converges to the same couple (tests
compare the couples and distances with the reference)."""
from __future__ import annotations

import math

import numpy as np
from numba import njit

from drake_dock.core.kernels.jets import PETAL, jet, patch_spec, petal_point, petal_row, position
from drake_dock.core.seeking import CLOSEST_MAX_ITER, CREEP_TOUCH, FLAT, Couple
from drake_dock.errors import SeekingError

EPS8 = 8 * np.finfo(float).eps


@njit(cache=True)
def _point(kind, prm, R, o, u0, u1):
    r = position(kind, prm, u0, u1)
    return (R[0, 0] * r[0] + R[0, 1] * r[1] + R[0, 2] * r[2] + o[0],
            R[1, 0] * r[0] + R[1, 1] * r[1] + R[1, 2] * r[2] + o[1],
            R[2, 0] * r[0] + R[2, 1] * r[1] + R[2, 2] * r[2] + o[2])


@njit(cache=True)
def _frame(R, o):
    """R and o as twelve scalars, read once for a grid's loop."""
    return (R[0, 0], R[0, 1], R[0, 2], R[1, 0], R[1, 1], R[1, 2], R[2, 0], R[2, 1], R[2, 2],
            o[0], o[1], o[2])


@njit(cache=True)
def _place(F, r, X, a):
    """X[a] = R r + o (Eq. 20) for the `_frame` F, as `_point` computes it."""
    X[a, 0] = F[0] * r[0] + F[1] * r[1] + F[2] * r[2] + F[9]
    X[a, 1] = F[3] * r[0] + F[4] * r[1] + F[5] * r[2] + F[10]
    X[a, 2] = F[6] * r[0] + F[7] * r[1] + F[8] * r[2] + F[11]


@njit(cache=True)
def _positions(kind, prm, R, o, U):
    """The points R r(u) + o (Eq. 20) at the rows u of U."""
    X = np.empty((U.shape[0], 3))
    F = _frame(R, o)
    two = U.shape[1] == 2
    for a in range(U.shape[0]):
        _place(F, position(kind, prm, U[a, 0], U[a, 1] if two else 0.0), X, a)
    return X


@njit(cache=True)
def _d2(X1, X2):
    D = np.empty((X1.shape[0], X2.shape[0]))
    for i in range(X1.shape[0]):
        for j in range(X2.shape[0]):
            a, b, c = X1[i, 0] - X2[j, 0], X1[i, 1] - X2[j, 1], X1[i, 2] - X2[j, 2]
            D[i, j] = a * a + b * b + c * c
    return D


@njit(cache=True)
def _argmin_d2(X1, X2):
    """(i, j) of np.argmin(_d2(X1, X2)) without the matrix: the first least entry, or the
    first NaN."""
    best, bi, bj = np.inf, 0, 0
    for i in range(X1.shape[0]):
        for j in range(X2.shape[0]):
            a, b, c = X1[i, 0] - X2[j, 0], X1[i, 1] - X2[j, 1], X1[i, 2] - X2[j, 2]
            d = a * a + b * b + c * c
            if d < best:
                best, bi, bj = d, i, j
            elif d != d:
                return i, j
    return bi, bj


@njit(cache=True)
def _local_axes(c, hw, lower, upper, periodic, n):
    """`seeking._local_grids` for one centre c, as its axes (dim, n): the grid's row a is
    (A[0, a // n], A[1, a % n]) (or A[0, a] for a curve)."""
    dim = c.shape[0]
    lo, hi = c - hw, c + hw
    for k in range(dim):
        if not periodic[k]:
            lo[k], hi[k] = max(lo[k], lower[k]), min(hi[k], upper[k])
    t = np.linspace(0.0, 1.0, n)
    A = np.empty((dim, n))
    for k in range(dim):
        for j in range(n):
            A[k, j] = lo[k] + (hi[k] - lo[k]) * t[j]
            if periodic[k]:
                span = upper[k] - lower[k]
                A[k, j] = lower[k] + np.mod(A[k, j] - lower[k], span)
    return A


@njit(cache=True)
def _axes_point(A, a):
    """Row a of the grid of the axes A (`_local_axes`)."""
    n = A.shape[1]
    if A.shape[0] == 1:
        return np.array([A[0, a]])
    return np.array([A[0, a // n], A[1, a % n]])


@njit(cache=True)
def _axes_positions(kind, prm, R, o, A):
    """`_positions` of the grid of the axes A; a petal's `petal_row` once per zeta."""
    dim, n = A.shape
    if kind != PETAL or dim == 1:
        U = np.empty((n ** dim, dim))
        for a in range(n ** dim):
            U[a] = _axes_point(A, a)
        return _positions(kind, prm, R, o, U)
    X = np.empty((n * n, 3))
    F = _frame(R, o)
    for j in range(n):
        row = petal_row(prm, A[1, j])
        for i in range(n):
            _place(F, petal_point(prm, A[0, i], A[1, j], row), X, i * n + j)
    return X


@njit(cache=True)
def _within(u, c, w):
    """All |u - c| <= w."""
    for k in range(u.shape[0]):
        if not abs(u[k] - c[k]) <= w[k]:
            return False
    return True


@njit(cache=True)
def hierarchical(k1, p1, R1, o1, lo1, hi1, per1, U1, k2, p2, R2, o2, lo2, hi2, per2, U2,
                 levels, n_fine, candidates):
    """`seeking.hierarchical_seek`: up to ``candidates`` start couples (C, dim1 + dim2), best
    first, from the coarse grids U1, U2."""
    n_coarse1 = round(U1.shape[0] ** (1.0 / U1.shape[1]))
    n_coarse2 = round(U2.shape[0] ** (1.0 / U2.shape[1]))
    h1 = (hi1 - lo1) / (n_coarse1 - 1)
    h2 = (hi2 - lo2) / (n_coarse2 - 1)
    d2 = _d2(_positions(k1, p1, R1, o1, U1), _positions(k2, p2, R2, o2, U2))
    dim1, dim2 = U1.shape[1], U2.shape[1]
    C1, C2 = np.empty((candidates, dim1)), np.empty((candidates, dim2))
    C = 0
    w1, w2 = 2 * h1, 2 * h2            # the candidates' exclusion half-widths
    for _ in range(candidates):
        best, bi, bj = np.inf, -1, -1
        for i in range(d2.shape[0]):
            for j in range(d2.shape[1]):
                if d2[i, j] < best:
                    best, bi, bj = d2[i, j], i, j
        if bi < 0:
            break
        C1[C], C2[C] = U1[bi], U2[bj]
        C += 1
        near2 = np.empty(d2.shape[1], dtype=np.bool_)
        for j in range(d2.shape[1]):
            near2[j] = _within(U2[j], U2[bj], w2)
        for i in range(d2.shape[0]):
            if _within(U1[i], U1[bi], w1):
                for j in range(d2.shape[1]):
                    if near2[j]:
                        d2[i, j] = np.inf
    g1, g2 = h1, h2
    for _ in range(levels):
        for c in range(C):
            A1 = _local_axes(C1[c].copy(), 2 * g1, lo1, hi1, per1, n_fine)
            A2 = _local_axes(C2[c].copy(), 2 * g2, lo2, hi2, per2, n_fine)
            i, j = _argmin_d2(_axes_positions(k1, p1, R1, o1, A1),
                              _axes_positions(k2, p2, R2, o2, A2))
            C1[c], C2[c] = _axes_point(A1, i), _axes_point(A2, j)
        g1, g2 = 4 * g1 / (n_fine - 1), 4 * g2 / (n_fine - 1)
    out = np.empty((C, dim1 + dim2))
    out[:, :dim1], out[:, dim1:] = C1[:C], C2[:C]
    return out


@njit(cache=True)
def _descent_step(H, g):
    """`seeking._descent_step`: -|H|^-1 g, eigenvalues made positive, as (Newton part, flat
    part)."""
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
def _gap(k1, p1, R1, o1, k2, p2, R2, o2, u, n1):
    x1 = _point(k1, p1, R1, o1, u[0], 0.0)
    x2 = _point(k2, p2, R2, o2, u[n1], u[n1 + 1] if u.shape[0] == n1 + 2 else 0.0)
    return (x1[0] - x2[0], x1[1] - x2[1], x1[2] - x2[2]), x1, x2


@njit(cache=True)
def newton(k1, p1, R1, o1, k2, p2, R2, o2, u, lower, upper, periodic, scale, tol, max_iter,
           distance_rtol, rtol_beyond):
    """`seeking.newton_closest` from u (patch 1 a curve): (u, iterations, status), status 0
    converged, 1 not converged (the reference raises `SeekingError`). ``distance_rtol`` < 0
    means none."""
    n1 = 1
    n = u.shape[0]
    u = u.copy()
    gfree = np.zeros(n)
    norm_J = norm_d = 0.0
    it = 0
    converged = False
    for it in range(1, max_iter + 1):
        j1 = jet(k1, p1, u[0], 0.0)
        j2 = jet(k2, p2, u[1], u[2] if n == 3 else 0.0)
        _, x1, x2 = _gap(k1, p1, R1, o1, k2, p2, R2, o2, u, n1)
        d = np.array([x1[0] - x2[0], x1[1] - x2[1], x1[2] - x2[2]])
        cols = np.empty((n, 3))
        cols[0] = R1 @ np.array(j1[1])
        cols[1] = -(R2 @ np.array(j2[1]))
        if n == 3:
            cols[2] = -(R2 @ np.array(j2[2]))
        g = cols @ d
        H = cols @ cols.T
        d1, d2 = R1.T @ d, R2.T @ d
        H[0, 0] += d1 @ np.array(j1[3])
        K2 = (np.array(j2[3]), np.array(j2[4]), np.array(j2[5]))
        if n == 2:
            H[1, 1] -= d2 @ K2[0]
        else:
            H[1, 1] -= d2 @ K2[0]
            H[1, 2] -= d2 @ K2[1]
            H[2, 1] -= d2 @ K2[1]
            H[2, 2] -= d2 @ K2[2]
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
            step[fi] = sf + cut * flat
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
def seek(k1, p1, R1, o1, lo1, hi1, per1, U1, k2, p2, R2, o2, lo2, hi2, per2, U2, levels, n_fine,
         candidates, distance_rtol, rtol_beyond):
    """The start couples of `hierarchical`, each finished by `newton` unless an earlier one
    started within 1e-9 of the spans (one finish serves both): the finished couples u (C, n),
    their iterations, statuses, points x1, x2 (C, 3) and whether they are interior
    (`seeking.is_interior` of both parts), in the order of the starts."""
    starts = hierarchical(k1, p1, R1, o1, lo1, hi1, per1, U1, k2, p2, R2, o2, lo2, hi2, per2, U2,
                          levels, n_fine, candidates)
    lower, upper = np.concatenate((lo1, lo2)), np.concatenate((hi1, hi2))
    periodic = np.concatenate((per1, per2))
    span = upper - lower
    scale = np.maximum(span, 1e-300)
    tol = 1e-9 * span
    C, n = starts.shape
    U, its, status = np.empty((C, n)), np.zeros(C, dtype=np.int64), np.zeros(C, dtype=np.int64)
    X1, X2 = np.empty((C, 3)), np.empty((C, 3))
    interior = np.zeros(C, dtype=np.bool_)
    started = np.zeros(C, dtype=np.bool_)
    m = 0
    for c in range(C):
        dup = False
        for s in range(c):
            dup = dup or (started[s] and _within(starts[c], starts[s], tol))
        if dup:
            continue
        started[c] = True
        u, its[m], status[m] = newton(k1, p1, R1, o1, k2, p2, R2, o2, starts[c], lower, upper,
                                      periodic, scale, 1e-14, CLOSEST_MAX_ITER, distance_rtol,
                                      rtol_beyond)
        _, x1, x2 = _gap(k1, p1, R1, o1, k2, p2, R2, o2, u, 1)
        U[m] = u
        X1[m, 0], X1[m, 1], X1[m, 2] = x1
        X2[m, 0], X2[m, 1], X2[m, 2] = x2
        interior[m] = True
        for k in range(n):
            # is_interior: min(u - lower, upper - u) > 1e-9 span unless periodic (NaN: not).
            inside = u[k] - lower[k] > 1e-9 * span[k] and upper[k] - u[k] > 1e-9 * span[k]
            if not (periodic[k] or inside):
                interior[m] = False
        m += 1
    return U[:m], its[:m], status[:m], X1[:m], X2[:m], interior[:m]


def _spec(patch):
    """(kind, parameters) of a patch, kept on it."""
    hit = patch.__dict__.get("_kernel_spec")
    if hit is None:
        hit = patch.__dict__["_kernel_spec"] = patch_spec(patch)
    return hit


def _domain(patch, n_coarse):
    """(lower, upper, periodic, coarse grid) of a patch as the kernels take them (writable,
    C-ordered: one compiled signature), kept on it."""
    cache = patch.__dict__.setdefault("_kernel_domain", {})
    hit = cache.get(n_coarse)
    if hit is None:
        hit = cache[n_coarse] = (np.array(patch.lower, dtype=float),
                                 np.array(patch.upper, dtype=float), np.array(patch.periodic),
                                 np.array(patch.grid_points(n_coarse)[0]))
    return hit


def supported(P1, P2) -> bool:
    """True when the compiled seek applies: patch 1 a curve, both patches with a kernel
    description."""
    return P1.patch.dim == 1 and _spec(P1.patch) is not None and _spec(P2.patch) is not None


def seek_couple(P1, P2, *, distance_rtol=None, rtol_beyond=0.0, n_coarse=12, levels=2,
                n_fine=21, candidates=3) -> Couple:
    """`drake_dock.core.seeking.seek_couple` compiled, for posed patches P1 (a curve) and P2
    with kernel descriptions (`supported`): one call of `seek`, then the nearest finished
    couple."""
    pa, pb = P1.patch, P2.patch
    (k1, q1), (k2, q2) = _spec(pa), _spec(pb)
    # Writable C-ordered copies: one compiled signature whatever the caller's arrays.
    R1, o1 = np.array(P1.R, dtype=float, order="C"), np.array(P1.p, dtype=float)
    R2, o2 = np.array(P2.R, dtype=float, order="C"), np.array(P2.p, dtype=float)
    U, its, status, X1, X2, interior = seek(k1, q1, R1, o1, *_domain(pa, n_coarse), k2, q2, R2, o2,
                                  *_domain(pb, n_coarse), levels, n_fine, candidates,
                                  -1.0 if distance_rtol is None else float(distance_rtol),
                                  float(rtol_beyond))
    # The nearest couple. A start whose Newton did not converge (it creeps: a nearly flat
    # valley, e.g. a ring's circle almost parallel to the other ring's face, or a circle that
    # touches or pierces a face, where the minima form a curve) counts where it is not the
    # nearest, or where it ended within CREEP_TOUCH of touching (the contact-form finish and
    # the modes then take it as a touch); else it is an error.
    best, dist = -1, np.inf
    for c in range(U.shape[0]):
        d = float(np.linalg.norm(X1[c] - X2[c]))
        if d < dist:
            best, dist = c, d
    if status[best] and dist > CREEP_TOUCH:
        raise SeekingError(f"closest-couple Newton did not converge in {CLOSEST_MAX_ITER} "
                           f"iterations (at distance {dist:.3g} m)")
    return Couple(U[best, :1], U[best, 1:], X1[best], X2[best], dist, int(its[best]),
                  bool(interior[best]))


def warm():
    """Compiles or loads the seek's kernels: a curve against a curve and against a surface."""
    from drake_dock.core.patches import Circle, PlaneRect, Segment, posed
    eye, z = np.eye(3), np.zeros(3)
    seg = posed(Segment((0.0, 0.0, 0.1), (1.0, 0.0, 0.1)), eye, z)
    seek_couple(seg, posed(Segment((0.5, -1.0, 0.0), (0.5, 1.0, 0.0)), eye, z))
    seek_couple(posed(Circle(0.3, 0.1), eye, z),
                posed(PlaneRect((-1, -1, 0), (2, 0, 0), (0, 2, 0)), eye, z))
