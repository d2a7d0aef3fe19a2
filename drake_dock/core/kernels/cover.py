"""The covers of `drake_dock.core.covers` (its docstring states the bounds) compiled: the cell
spheres and slabs from the patches' jets (`jets.jet`), the least gap of two posed covers and
the steps of a travel grid in which two covers can touch (tests/core/test_covers.py checks them
against sampled points of the patches, a brute force over every sphere pair and the seek)."""
from __future__ import annotations

import math
from typing import NamedTuple

import numpy as np
from numba import njit

from drake_dock.core import covers
from drake_dock.core.kernels.jets import jet, patch_spec


@njit(cache=True)
def _norm(v):
    return math.sqrt(v[0] * v[0] + v[1] * v[1] + v[2] * v[2])


@njit(cache=True)
def cell_spheres(kind, prm, U, half):
    """Centres r(u_c) (N, 3) and radii rho_c (N,) of the cells centred at U (N, dim) with
    half-widths ``half`` (`drake_dock.core.covers.cell_radii`), and for a surface the slabs'
    normals (N, 3) and half-thicknesses (N,) (`covers.cell_slabs`; zeros and inf for a
    curve)."""
    n, dim = U.shape
    C, rho = np.empty((n, 3)), np.empty(n)
    N, flat = np.zeros((n, 3)), np.full(n, np.inf)
    for c in range(n):
        r, T0, T1, K00, K01, K11 = jet(kind, prm, U[c, 0], U[c, 1] if dim == 2 else 0.0)
        C[c, 0], C[c, 1], C[c, 2] = r
        h0 = half[0]
        if dim == 1:
            rho[c] = h0 * (_norm(T0) + h0 * _norm(K00))
        else:
            h1 = half[1]
            rho[c] = (h0 * (_norm(T0) + h0 * _norm(K00) + h1 * _norm(K01))
                      + h1 * (_norm(T1) + h0 * _norm(K01) + h1 * _norm(K11)))
            x = (T0[1] * T1[2] - T0[2] * T1[1], T0[2] * T1[0] - T0[0] * T1[2],
                 T0[0] * T1[1] - T0[1] * T1[0])
            m = _norm(x)
            N[c, 0], N[c, 1], N[c, 2] = x[0] / m, x[1] / m, x[2] / m
            flat[c] = h0 * h0 * _norm(K00) + 2.0 * h0 * h1 * _norm(K01) + h1 * h1 * _norm(K11)
    return C, rho, N, flat


@njit(cache=True)
def _interval(c1, c2, r, e, ee):
    """The interval of lam where the sphere pair (centres c1, c2, summed radii r) touches,
    |w - lam e| <= r with w = c1 - c2 and ee = e . e, as (lo, hi, ok); ok False where there is
    none."""
    w0, w1, w2 = c1[0] - c2[0], c1[1] - c2[1], c1[2] - c2[2]
    b = w0 * e[0] + w1 * e[1] + w2 * e[2]
    D = b * b - ee * (w0 * w0 + w1 * w1 + w2 * w2 - r * r)
    if not D >= 0.0:
        return 0.0, 0.0, False
    s = math.sqrt(D)
    return (b - s) / ee, (b + s) / ee, True


@njit(cache=True)
def _slab(n, w0, w1, w2, t, e, lo, hi):
    """[lo, hi] cut by the lam where |n . (w - lam e)| <= t, t the half-thickness of the slab
    of normal n plus the other cell's radius; an empty interval (inf, -inf) for none."""
    nw = n[0] * w0 + n[1] * w1 + n[2] * w2
    ne = n[0] * e[0] + n[1] * e[1] + n[2] * e[2]
    if ne == 0.0:
        return (lo, hi) if abs(nw) <= t else (np.inf, -np.inf)
    a, b = (nw - t) / ne, (nw + t) / ne
    return max(lo, min(a, b)), min(hi, max(a, b))


@njit(cache=True)
def touched_steps(moving, fixed, e, grid, slack):
    """The steps of the decreasing grid in which the `CoverCells` ``moving``, translated by
    -lam e, can touch the `CoverCells` ``fixed``: blocks first, then the cells of the block
    pairs that can touch in the grid's range, each cell pair's sphere interval cut by the
    cells' slabs and widened by ``slack``; a step is touched where one of the intervals meets
    it."""
    mc, mr, mn, mflat, mbc, mbr, mblocks = moving
    fc, fr, fn, fflat, fbc, fbr, fblocks = fixed
    K = grid.shape[0] - 1
    neg = -grid
    marks = np.zeros(K + 1, dtype=np.int64)
    ee = e[0] * e[0] + e[1] * e[1] + e[2] * e[2]
    lam_lo, lam_hi = grid[K], grid[0]
    for I in range(mbc.shape[0]):
        for J in range(fbc.shape[0]):
            # Block spheres that cannot meet in the grid's range (grown by 1e-12 relative and
            # absolute, far above round-off) hold no cells that can: the steps a cell marks do
            # not depend on the range, so a part of the grid marks the whole grid's steps.
            lo, hi, ok = _interval(mbc[I], fbc[J], (mbr[I] + fbr[J]) * (1.0 + 1e-12) + 1e-12,
                                   e, ee)
            if not ok or lo > lam_hi + slack or hi < lam_lo - slack:
                continue
            # A moving cell whose sphere cannot meet block J's (grown likewise) in the range
            # meets none of its cells there.
            grown = fbr[J] * (1.0 + 1e-12) + 1e-12
            for a in mblocks[I]:
                lo, hi, ok = _interval(mc[a], fbc[J], mr[a] + grown, e, ee)
                if not ok or lo > lam_hi + slack or hi < lam_lo - slack:
                    continue
                for b in fblocks[J]:
                    lo, hi, ok = _interval(mc[a], fc[b], mr[a] + fr[b], e, ee)
                    if not ok:
                        continue
                    w0, w1, w2 = mc[a, 0] - fc[b, 0], mc[a, 1] - fc[b, 1], mc[a, 2] - fc[b, 2]
                    if fflat[b] < np.inf:
                        lo, hi = _slab(fn[b], w0, w1, w2, mr[a] + fflat[b], e, lo, hi)
                    if mflat[a] < np.inf:
                        lo, hi = _slab(mn[a], w0, w1, w2, fr[b] + mflat[a], e, lo, hi)
                    if not lo <= hi + 2 * slack:
                        continue
                    first = max(np.searchsorted(neg, -(hi + slack)) - 1, 0)
                    last = min(np.searchsorted(neg, -(lo - slack), side="right") - 1, K - 1)
                    if first <= last:
                        marks[first] += 1
                        marks[last + 1] -= 1
    out = np.empty(K, dtype=np.bool_)
    acc = 0
    for k in range(K):
        acc += marks[k]
        out[k] = acc > 0
    return out


class CoverCells(NamedTuple):
    """A `covers.Cover` as the kernels take it: its cells' sphere centres (N, 3) and radii,
    their slabs' normals (N, 3) and half-widths (inf: no slab), and its blocks' sphere centres
    (m, 3), radii and cells (m, b)."""

    centres: np.ndarray
    radii: np.ndarray
    normals: np.ndarray
    flat: np.ndarray
    block_centres: np.ndarray
    block_radii: np.ndarray
    blocks: np.ndarray


def cells_of(cover) -> CoverCells:
    """The `CoverCells` of a `covers.Cover`."""
    return CoverCells(cover.centres, cover.radii, cover.normals, cover.flat, cover.block_centres,
                      cover.block_radii, cover.blocks)


@njit(cache=True)
def _sphere_gap(c1, r1, c2, r2):
    d0, d1, d2 = c1[0] - c2[0], c1[1] - c2[1], c1[2] - c2[2]
    return math.sqrt(d0 * d0 + d1 * d1 + d2 * d2) - r1 - r2


@njit(cache=True)
def least_gap(a, b, below):
    """The least |c_a - c_b| - (rho_a + rho_b) over the cell sphere pairs of the posed
    `CoverCells` a and b, a lower bound of their patches' distance: the block pairs in
    increasing order of their spheres' gap, each one's cells only while that gap is below the
    least cell gap found (a block's sphere holds its cells' spheres). Stops at the first cell
    gap below ``below``, returning it (a gap known to be below that is all a screen needs); -inf
    for the least gap itself."""
    ac, ar, _an, _aflat, abc, abr, ablocks = a
    bc, br, _bn, _bflat, bbc, bbr, bblocks = b
    m, k = abc.shape[0], bbc.shape[0]
    lower = np.empty(m * k)
    for I in range(m):
        for J in range(k):
            lower[I * k + J] = _sphere_gap(abc[I], abr[I], bbc[J], bbr[J])
    best = np.inf
    for IJ in np.argsort(lower):
        if lower[IJ] >= best:
            break
        I, J = IJ // k, IJ % k
        for a in ablocks[I]:
            for b in bblocks[J]:
                g = _sphere_gap(ac[a], ar[a], bc[b], br[b])
                if g < best:
                    best = g
                    if best < below:
                        return best
    return best


def cover_gap(a, b, below: float = -np.inf) -> float:
    """The least gap of the posed covers a and b (`least_gap`); with ``below``, any gap of
    two cells below it once one is found (the least gap when it is not below)."""
    return float(least_gap(cells_of(a), cells_of(b), float(below)))


def patch_cover(patch, n: int, block: int):
    """`drake_dock.core.covers.patch_cover` from the compiled jets, or that Python one for
    a patch no kernel describes (a `Point`, say); kept on the patch."""
    cache = patch.__dict__.setdefault("_compiled_covers", {})
    hit = cache.get((n, block))
    if hit is None:
        spec = patch_spec(patch)
        if spec is None:
            hit = covers.patch_cover(patch, n, block)
        else:
            U, half, blocks = covers.block_layout(patch, n, block)
            centres, radii, normals, flat = cell_spheres(spec[0], spec[1], U, half)
            hit = covers.Cover.from_cells(centres, radii, blocks, normals, flat)
        cache[(n, block)] = hit
    return hit


def touch_steps(moving, fixed, e, grid, slack=1e-9):
    """Booleans (K,): the steps of ``grid`` in which the posed covers can touch."""
    return touched_steps(cells_of(moving), cells_of(fixed), np.asarray(e, dtype=float),
                         np.asarray(grid, dtype=float), float(slack))


def warm():
    """Compiles or loads the covers' kernels: a curve and a surface against each other."""
    from drake_dock.core.patches import Circle, PlaneRect
    plane = patch_cover(PlaneRect((-1, -1, 0), (2, 0, 0), (0, 2, 0)), 4, 2)
    circle = patch_cover(Circle(0.3, 0.1), 4, 2)
    touch_steps(circle, plane, np.array([0.0, 0.0, -1.0]), np.array([0.3, 0.2, 0.1, 0.0]))
    cover_gap(circle, plane)
