"""Bounding-sphere and slab covers of patches (Definition 1) and where two covers can touch
along a straight relative translation: a lower bound on the distance of two patches that needs
no seek.

A cover splits the parameter box into n cells per parameter. Cell c, centre u_c and half-widths
h, is enclosed by the sphere about r(u_c) of radius

    rho_c = sum_k h_k (|T_k(u_c)| + sum_l h_l |K_kl(u_c)|),

the mean-value bound |r(u) - r(u_c)| <= sum_k h_k max_cell |T_k| with |T_k| grown from the
centre by the second derivatives K over the half-cell (twice the quadratic Taylor term, which
holds the cubic remainder of cells much smaller than the curvature radii). Cells are grouped in
blocks, each enclosed by a coarse sphere about the mean of its cells' centres, so that a pair of
covers is screened block by block before cell by cell.

Along a translation x(lam) = x(0) - lam e of the cover of patch 1, a sphere pair (centres
c1, c2, radii rho1 + rho2 = r) can touch only for lam in the interval

    |w - lam e| <= r,  w = c1(0) - c2:  lam in [(b - sqrt(D)) / |e|^2, (b + sqrt(D)) / |e|^2],
    b = w . e,  D = b^2 - |e|^2 (|w|^2 - r^2) >= 0;

outside the union of these intervals the patches are apart.

A surface's cell is also enclosed by a slab about its tangent plane: with n_c the unit normal
T_0 x T_1 / |T_0 x T_1| at u_c, |n_c . (r(u) - r(u_c))| <= kappa_c = sum_kl h_k h_l |K_kl(u_c)|
over the cell (n_c . T = 0, so only the quadratic Taylor term is left; twice it, as for rho_c).
A sphere (centre c1, radius rho1) can then touch the cell only where
|n_c . (w - lam e)| <= rho1 + kappa_c, w = c1(0) - c2: an interval of lam (all or none when
n_c . e = 0), intersected with the spheres'. Where a curve passes close to a surface but on one
side of it (a ring just inside a petal's cone), the slab is far thinner than the sphere.

At a fixed pose the least of |c1 - c2| - (rho1 + rho2) over the sphere pairs is a lower bound of
the distance of the two patches (`cover_gap`): every point of a patch lies in a sphere of its
cover.
"""
from __future__ import annotations

import dataclasses

import numpy as np


@dataclasses.dataclass(frozen=True)
class Cover:
    """Cell spheres (``centres`` (n, 3), ``radii`` (n,)) and block spheres (``block_centres``
    (m, 3), ``block_radii`` (m,)); ``blocks`` (m, b) lists each block's cells. A surface's
    cells also have slabs: unit ``normals`` (n, 3) and half-thicknesses ``flat`` (n,); a
    curve's ``flat`` is +inf (no slab)."""

    centres: np.ndarray
    radii: np.ndarray
    block_centres: np.ndarray
    block_radii: np.ndarray
    blocks: np.ndarray
    normals: np.ndarray
    flat: np.ndarray

    @classmethod
    def from_cells(cls, centres, radii, blocks, normals=None, flat=None) -> "Cover":
        """The cover of the cell spheres (and slabs, if given) with each block enclosed about
        its cells' mean."""
        cells = centres[blocks]                              # (m, b, 3)
        block_centres = cells.mean(axis=1)
        block_radii = (np.linalg.norm(cells - block_centres[:, None], axis=-1)
                       + radii[blocks]).max(axis=1)
        if normals is None:
            normals, flat = np.zeros_like(centres), np.full(len(radii), np.inf)
        return cls(centres, radii, block_centres, block_radii, blocks, normals, flat)

    def posed(self, R, p) -> "Cover":
        """The cover of the patch placed by the body pose (R, p), Eq. (20)."""
        R, p = np.asarray(R, dtype=float), np.asarray(p, dtype=float)
        return dataclasses.replace(self, centres=self.centres @ R.T + p,
                                   block_centres=self.block_centres @ R.T + p,
                                   normals=self.normals @ R.T)


def block_layout(patch, n: int, block: int):
    """The cells of a cover with n cells per parameter in blocks of ``block`` per parameter
    (block divides n): centres U (n^dim, dim) ordered block by block, the half-widths (dim,)
    and the blocks' cells (n^dim / block^dim, block^dim)."""
    half = (patch.upper - patch.lower) / (2 * n)
    axes = [patch.lower[k] + half[k] * (2 * np.arange(n) + 1) for k in range(patch.dim)]
    nb = n // block
    if patch.dim == 1:
        U = axes[0].reshape(-1, 1)
    else:
        A, Z = np.broadcast_arrays(axes[0].reshape(nb, 1, block, 1),
                                   axes[1].reshape(1, nb, 1, block))
        U = np.stack([A.ravel(), Z.ravel()], axis=-1)
    return U, half, np.arange(n ** patch.dim).reshape(nb ** patch.dim, block ** patch.dim)


def cell_radii(patch, U, half):
    """rho_c of the module docstring at the cell centres U (N, dim) with half-widths ``half``."""
    T = patch.first(U)                                  # (N, 3, dim)
    K = patch.second(U)                                 # (N, 3, dim, dim)
    grow = np.linalg.norm(T, axis=1) + np.einsum("nkl,l->nk", np.linalg.norm(K, axis=1), half)
    return grow @ half


def cell_slabs(patch, U, half):
    """(n_c, kappa_c) of the module docstring at a surface's cell centres U (N, 2)."""
    T = patch.first(U)                                  # (N, 3, 2)
    K = patch.second(U)                                 # (N, 3, 2, 2)
    n = np.cross(T[..., 0], T[..., 1])
    n = n / np.linalg.norm(n, axis=-1, keepdims=True)
    return n, np.einsum("nkl,k,l->n", np.linalg.norm(K, axis=1), half, half)


def patch_cover(patch, n: int, block: int) -> Cover:
    """The cover of ``patch`` with n cells per parameter in blocks of ``block`` per parameter
    (`block_layout`), with slabs for a surface (a point: its sphere); kept on the patch."""
    cache = patch.__dict__.setdefault("_covers", {})
    hit = cache.get((n, block))
    if hit is None and patch.dim == 0:
        # A `Point` (a sphere of radius ``radius``): one cell, the sphere itself.
        hit = cache[(n, block)] = Cover.from_cells(patch.position(np.zeros((1, 0))),
                                                   np.array([patch.radius]),
                                                   np.zeros((1, 1), dtype=np.int64))
    if hit is None:
        U, half, blocks = block_layout(patch, n, block)
        slabs = cell_slabs(patch, U, half) if patch.dim == 2 else (None, None)
        hit = cache[(n, block)] = Cover.from_cells(patch.position(U), cell_radii(patch, U, half),
                                                   blocks, *slabs)
    return hit


def cover_gap(a: Cover, b: Cover) -> float:
    """The least |c_a - c_b| - (rho_a + rho_b) over the cell sphere pairs of the posed covers a
    and b: a lower bound of the distance of their patches (negative where spheres overlap)."""
    d = np.linalg.norm(a.centres[:, None, :] - b.centres[None, :, :], axis=-1)
    return float((d - a.radii[:, None] - b.radii[None, :]).min())


def _intervals(w, r, e):
    """Per sphere pair (rows of w = c1(0) - c2, summed radii r): the interval of lam where
    |w - lam e| <= r, as (lo, hi, ok); ok False where there is none."""
    ee = e @ e
    b = w @ e
    D = b * b - ee * (np.einsum("...k,...k->...", w, w) - r * r)
    ok = D >= 0.0
    s = np.sqrt(np.where(ok, D, 0.0))
    return (b - s) / ee, (b + s) / ee, ok


def _slab_intervals(w, r, n, flat, e):
    """Per cell pair (rows of w = c1(0) - c2, the other cell's radius r, a slab's normal n and
    half-thickness flat): the interval of lam where |n . (w - lam e)| <= r + flat, as
    (lo, hi); (-inf, inf) for no slab (flat inf) and an empty one (inf, -inf) for none."""
    nw = np.einsum("...k,...k->...", n, w)
    ne = n @ e
    t = r + flat
    with np.errstate(divide="ignore", invalid="ignore"):
        a, b = (nw - t) / ne, (nw + t) / ne
    lo, hi = np.minimum(a, b), np.maximum(a, b)
    flat_e = ne == 0.0
    lo = np.where(flat_e, np.where(np.abs(nw) <= t, -np.inf, np.inf), lo)
    hi = np.where(flat_e, np.where(np.abs(nw) <= t, np.inf, -np.inf), hi)
    free = np.isinf(flat)
    return np.where(free, -np.inf, lo), np.where(free, np.inf, hi)


def touch_set(moving: Cover, fixed: Cover, e, lam_lo, lam_hi, slack=1e-9):
    """(lo, hi) arrays: intervals of lam in [lam_lo, lam_hi] outside whose union the patches of
    the two posed covers are apart, ``moving`` translated by -lam e. Blocks first, then the cells
    of the block pairs that can touch in the range, each cell pair's sphere interval cut by the
    cells' slabs; each interval widened by ``slack``."""
    e = np.asarray(e, dtype=float)
    w = moving.block_centres[:, None, :] - fixed.block_centres[None, :, :]
    lo, hi, ok = _intervals(w, moving.block_radii[:, None] + fixed.block_radii[None, :], e)
    I, J = np.nonzero(ok & (lo <= lam_hi + slack) & (hi >= lam_lo - slack))
    ci, cj = np.broadcast_arrays(moving.blocks[I][:, :, None], fixed.blocks[J][:, None, :])
    ci, cj = ci.ravel(), cj.ravel()
    w = moving.centres[ci] - fixed.centres[cj]
    lo, hi, ok = _intervals(w, moving.radii[ci] + fixed.radii[cj], e)
    for n, flat, r in ((fixed.normals[cj], fixed.flat[cj], moving.radii[ci]),
                       (moving.normals[ci], moving.flat[ci], fixed.radii[cj])):
        slo, shi = _slab_intervals(w, r, n, flat, e)
        lo, hi = np.maximum(lo, slo), np.minimum(hi, shi)
    ok &= lo <= hi + 2 * slack
    lo, hi = lo[ok] - slack, hi[ok] + slack
    keep = (lo <= lam_hi) & (hi >= lam_lo)
    return lo[keep], hi[keep]


def touched_steps(lo, hi, grid):
    """Booleans (K,): step k of the decreasing travel grid (from grid[k] to grid[k + 1], K + 1
    points) meets one of the intervals [lo, hi]."""
    K = len(grid) - 1
    neg = -np.asarray(grid, dtype=float)
    first = np.maximum(np.searchsorted(neg, -hi, "left") - 1, 0)
    last = np.minimum(np.searchsorted(neg, -lo, "right") - 1, K - 1)
    ok = first <= last
    marks = np.zeros(K + 1, dtype=int)
    np.add.at(marks, first[ok], 1)
    np.add.at(marks, last[ok] + 1, -1)
    return np.cumsum(marks[:K]) > 0


def touch_steps(moving: Cover, fixed: Cover, e, grid, slack=1e-9):
    """Booleans (K,): the steps of the decreasing travel grid (K + 1 points) in which the posed
    covers can touch, ``moving`` translated by -lam e (`touch_set`, `touched_steps`)."""
    lo, hi = touch_set(moving, fixed, e, grid[-1], grid[0], slack)
    return touched_steps(lo, hi, grid)
