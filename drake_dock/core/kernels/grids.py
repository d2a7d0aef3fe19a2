"""The grids of the seek (Sect. 5.1, `drake_dock.core.kernels.seek`), compiled: the patches'
points posed in the world (Eq. 20) over a grid, the coarse grid's distinct best couples and their
refinement by finer local grids (`hierarchical`). The grids evaluate points only
(`jets.position`: the jet's r with the same operations)."""
from __future__ import annotations

from typing import NamedTuple

import numpy as np
from numba import njit

from drake_dock.core.kernels.copies import copy1, copy2
from drake_dock.core.kernels.jets import PETAL, petal_point, petal_row, position


class Placed(NamedTuple):
    """A patch placed in the world, x = R r(u) + o (Eq. 20): its kernel kind and parameters
    (`jets.patch_spec`; `seek.POINT` and the point's coordinates for a point), its frame's
    rotation R (3, 3) and origin o (3,)."""

    kind: int
    prm: np.ndarray
    R: np.ndarray
    o: np.ndarray


class Domain(NamedTuple):
    """A patch's parameters as the seek takes them (`Patch.kernel_domain`): the lower and
    upper bounds and periodic flags per parameter, and the coarse grid (a point a row)."""

    lower: np.ndarray
    upper: np.ndarray
    periodic: np.ndarray
    grid: np.ndarray


@njit(cache=True)
def _frame(R, o):
    """R and o as twelve scalars, read once for a grid's loop."""
    return (R[0, 0], R[0, 1], R[0, 2], R[1, 0], R[1, 1], R[1, 2], R[2, 0], R[2, 1], R[2, 2],
            o[0], o[1], o[2])


@njit(cache=True)
def _place(F, r, X, a):
    """X[a] = R r + o (Eq. 20) for the `_frame` F, as `seek.world_point` computes it."""
    X[a, 0] = F[0] * r[0] + F[1] * r[1] + F[2] * r[2] + F[9]
    X[a, 1] = F[3] * r[0] + F[4] * r[1] + F[5] * r[2] + F[10]
    X[a, 2] = F[6] * r[0] + F[7] * r[1] + F[8] * r[2] + F[11]


@njit(cache=True)
def positions(kind, prm, R, o, U):
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
    """The local grid of n points per parameter spanning c +- hw (clipped to the domain for
    bounded parameters, wrapped for periodic ones) for one centre c, as its axes (dim, n): the
    grid's row a is (A[0, a // n], A[1, a % n]) (or A[0, a] for a curve)."""
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
    """`positions` of the grid of the axes A; a petal's `petal_row` once per zeta."""
    dim, n = A.shape
    if kind != PETAL or dim == 1:
        U = np.empty((n ** dim, dim))
        for a in range(n ** dim):
            copy1(U[a], _axes_point(A, a))
        return positions(kind, prm, R, o, U)
    X = np.empty((n * n, 3))
    F = _frame(R, o)
    for j in range(n):
        row = petal_row(prm, A[1, j])
        for i in range(n):
            _place(F, petal_point(prm, A[0, i], A[1, j], row), X, i * n + j)
    return X


@njit(cache=True)
def within(u, c, w):
    """All |u - c| <= w."""
    for k in range(u.shape[0]):
        if not abs(u[k] - c[k]) <= w[k]:
            return False
    return True


@njit(cache=True)
def hierarchical(a, da, b, db, levels, n_fine, candidates):
    """Sect. 5.1's grids for the `Placed` patches a and b over their `Domain`s da and db: up to
    ``candidates`` start couples (C, dim1 + dim2), best first. The best couples of the coarse
    grids that lie more than two cells apart in one of the patches (a nearly flat distance, a
    ring almost coaxial with a cone, can put the best cell in the wrong valley), each refined
    by ``levels`` grids of ``n_fine`` points spanning +-2 cells of the previous level around
    its best point."""
    k1, p1, R1, o1 = a
    lo1, hi1, per1, U1 = da
    k2, p2, R2, o2 = b
    lo2, hi2, per2, U2 = db
    n_coarse1 = round(U1.shape[0] ** (1.0 / U1.shape[1]))
    n_coarse2 = round(U2.shape[0] ** (1.0 / U2.shape[1]))
    h1 = (hi1 - lo1) / (n_coarse1 - 1)
    h2 = (hi2 - lo2) / (n_coarse2 - 1)
    d2 = _d2(positions(k1, p1, R1, o1, U1), positions(k2, p2, R2, o2, U2))
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
        copy1(C1[C], U1[bi])
        copy1(C2[C], U2[bj])
        C += 1
        near2 = np.empty(d2.shape[1], dtype=np.bool_)
        for j in range(d2.shape[1]):
            near2[j] = within(U2[j], U2[bj], w2)
        for i in range(d2.shape[0]):
            if within(U1[i], U1[bi], w1):
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
            copy1(C1[c], _axes_point(A1, i))
            copy1(C2[c], _axes_point(A2, j))
        g1, g2 = 4 * g1 / (n_fine - 1), 4 * g2 / (n_fine - 1)
    out = np.empty((C, dim1 + dim2))
    copy2(out[:, :dim1], C1[:C])
    copy2(out[:, dim1:], C2[:C])
    return out
