"""Bounding-sphere covers of patches (Definition 1) and where two covers can touch along a
straight relative translation: a lower bound on the distance of two patches that needs no seek.

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
    (m, 3), ``block_radii`` (m,)); ``blocks`` (m, b) lists each block's cells."""

    centres: np.ndarray
    radii: np.ndarray
    block_centres: np.ndarray
    block_radii: np.ndarray
    blocks: np.ndarray

    @classmethod
    def from_cells(cls, centres, radii, blocks) -> "Cover":
        """The cover of the cell spheres with each block enclosed about its cells' mean."""
        cells = centres[blocks]                              # (m, b, 3)
        block_centres = cells.mean(axis=1)
        block_radii = (np.linalg.norm(cells - block_centres[:, None], axis=-1)
                       + radii[blocks]).max(axis=1)
        return cls(centres, radii, block_centres, block_radii, blocks)

    def posed(self, R, p) -> "Cover":
        """The cover of the patch placed by the body pose (R, p), Eq. (20)."""
        R, p = np.asarray(R, dtype=float), np.asarray(p, dtype=float)
        return dataclasses.replace(self, centres=self.centres @ R.T + p,
                                   block_centres=self.block_centres @ R.T + p)


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


def patch_cover(patch, n: int, block: int) -> Cover:
    """The cover of ``patch`` with n cells per parameter in blocks of ``block`` per parameter
    (`block_layout`); kept on the patch."""
    cache = patch.__dict__.setdefault("_covers", {})
    hit = cache.get((n, block))
    if hit is None:
        U, half, blocks = block_layout(patch, n, block)
        hit = cache[(n, block)] = Cover.from_cells(patch.position(U), cell_radii(patch, U, half),
                                                   blocks)
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


def touch_set(moving: Cover, fixed: Cover, e, lam_lo, lam_hi, slack=1e-9):
    """(lo, hi) arrays: intervals of lam in [lam_lo, lam_hi] outside whose union the patches of
    the two posed covers are apart, ``moving`` translated by -lam e. Blocks first, then the cells
    of the block pairs that can touch in the range; each interval widened by ``slack``."""
    e = np.asarray(e, dtype=float)
    w = moving.block_centres[:, None, :] - fixed.block_centres[None, :, :]
    lo, hi, ok = _intervals(w, moving.block_radii[:, None] + fixed.block_radii[None, :], e)
    I, J = np.nonzero(ok & (lo <= lam_hi + slack) & (hi >= lam_lo - slack))
    ci, cj = np.broadcast_arrays(moving.blocks[I][:, :, None], fixed.blocks[J][:, None, :])
    ci, cj = ci.ravel(), cj.ravel()
    lo, hi, ok = _intervals(moving.centres[ci] - fixed.centres[cj],
                            moving.radii[ci] + fixed.radii[cj], e)
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
