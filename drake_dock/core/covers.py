"""Bounding-sphere and slab covers of patches (Definition 1) and where two covers can touch
along a straight relative translation: a lower bound on the distance of two patches that needs
no seek. This module holds the covers' record (`Cover`), their cell layout and `patch_cover`,
which builds any patch's cover from its Python jets (the kernels use it for patches they do
not describe); the compiled `drake_dock.core.kernels.cover` builds the others' and computes the
gaps and the touched steps below.

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
the distance of the two patches (`drake_dock.core.kernels.cover.cover_gap`): every point of a
patch lies in a sphere of its cover.
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
