"""Seeking the couple of minimal distance between two patches (Sect. 5.1).

The paper's hierarchical grid: a coarse grid over both patches' parameters, then grids an order
finer around the best cell, finished here by a bounded Newton iteration on the closest-point
conditions (gradient of 0.5 |r1 - r2|^2 equal to zero, or its projection on active bounds).
Everything is vectorised over the grid; only the pair asked for is searched.
"""
from __future__ import annotations

import dataclasses

import numpy as np

from drake_dock.errors import SeekingError


@dataclasses.dataclass
class Couple:
    """The couple of minimal distance (u1*, u2*) of a pair of posed patches."""

    u1: np.ndarray
    u2: np.ndarray
    p1: np.ndarray  # world point on patch 1
    p2: np.ndarray  # world point on patch 2
    distance: float
    newton_iterations: int
    interior: bool = True  # both points inside their domains (Eq. 22 holds)

    @property
    def u(self):
        return np.concatenate([self.u1, self.u2])


def _pairwise_d2(P1, P2, U1, U2):
    X1 = P1.position(U1)
    X2 = P2.position(U2)
    # |x1 - x2|^2 on the product grid without forming the full difference tensor.
    return (np.einsum("ix,ix->i", X1, X1)[:, None] + np.einsum("jx,jx->j", X2, X2)[None, :]
            - 2.0 * X1 @ X2.T)


def _pairwise_min(P1, P2, U1, U2):
    d2 = _pairwise_d2(P1, P2, U1, U2)
    i, j = np.unravel_index(np.argmin(d2), d2.shape)
    return U1[i], U2[j]


def _distinct_best(d2, U1, U2, h1, h2, k):
    """The k best grid couples that lie more than 2 cells apart in one of the patches."""
    order = np.argsort(d2, axis=None)
    chosen = []
    for flat in order:
        i, j = np.unravel_index(flat, d2.shape)
        if all(np.any(np.abs(U1[i] - U1[a]) > 2 * h1) or np.any(np.abs(U2[j] - U2[b]) > 2 * h2)
               for a, b in chosen):
            chosen.append((i, j))
            if len(chosen) == k:
                break
    return [(U1[i], U2[j]) for i, j in chosen]


def _local_grid(patch, centre, half_width, n):
    axes = []
    for k in range(patch.dim):
        lo, hi = centre[k] - half_width[k], centre[k] + half_width[k]
        if not patch.periodic[k]:
            lo, hi = max(lo, patch.lower[k]), min(hi, patch.upper[k])
        axes.append(np.linspace(lo, hi, n))
    mesh = np.meshgrid(*axes, indexing="ij")
    return patch.wrap(np.stack([m.ravel() for m in mesh], axis=-1))


def hierarchical_seek(P1, P2, *, n_coarse=12, levels=2, n_fine=21, candidates=3):
    """Sect. 5.1: coarse grid, then ``levels`` grids of ``n_fine`` points spanning +-2 cells of
    the previous level around its best point. The ``candidates`` best coarse couples that are
    distinct (more than two cells apart) are refined, since a nearly flat distance (a ring
    almost coaxial with a cone) can put the best coarse cell in the wrong valley. Returns a list
    of (u1, u2), best first."""
    U1, U2 = P1.patch.grid(n_coarse), P2.patch.grid(n_coarse)
    h1 = P1.patch.span / (n_coarse - 1)
    h2 = P2.patch.span / (n_coarse - 1)
    d2 = _pairwise_d2(P1, P2, U1, U2)
    out = []
    for u1, u2 in _distinct_best(d2, U1, U2, h1, h2, candidates):
        g1, g2 = h1, h2
        for _ in range(levels):
            u1, u2 = _pairwise_min(P1, P2, _local_grid(P1.patch, u1, 2 * g1, n_fine),
                                   _local_grid(P2.patch, u2, 2 * g2, n_fine))
            g1, g2 = 4 * g1 / (n_fine - 1), 4 * g2 / (n_fine - 1)
        out.append((u1, u2))
    return out


def newton_closest(P1, P2, u1, u2, *, tol=1e-14, max_iter=50, distance_rtol=None,
                   rtol_beyond=0.0):
    """Bounded Newton on f(u) = 0.5 |r1(u1) - r2(u2)|^2 from (u1, u2).

    Returns (u1, u2, iterations). Parameters at a domain end with the gradient pushing outwards
    are held (active set); periodic parameters are wrapped. With ``distance_rtol`` the
    iteration also ends when a step shortens (or would shorten) the distance by less than that
    fraction of it: a caller that needs the distance, not the couple, stops early in a flat
    valley (a ring nearly coaxial with a cone), where the couple walks along the valley for
    many iterations while the distance changes in its seventh digit. This applies only while
    the distance exceeds ``rtol_beyond``; the distance is then converged to about 1e2
    distance_rtol (the valley's many small steps add up), not the couple."""
    n1 = P1.patch.dim
    u = np.concatenate([u1, u2]).astype(float)
    lower = np.concatenate([P1.patch.lower, P2.patch.lower])
    upper = np.concatenate([P1.patch.upper, P2.patch.upper])
    periodic = np.array(P1.patch.periodic + P2.patch.periodic)
    scale = np.maximum(np.concatenate([P1.patch.span, P2.patch.span]), 1e-300)

    def world(P, u):
        r, T, K = P.patch.jet(u)
        R = P.R
        return (R @ r + P.p, R @ np.array(T).T,
                np.einsum("xy,aby->xab", R, np.array(K)) if K is not None else None)

    def parts(u, second=False):
        r1, T1, K1 = world(P1, u[:n1])
        r2, T2, K2 = world(P2, u[n1:])
        d = r1 - r2
        J = np.concatenate([T1, -T2], axis=1)
        if second:
            # Round-off of d = r1 - r2 is about eps (|r1| + |r2|): far from the world origin
            # it, not |d|, sets how small the gradient J^T d can get.
            return d, J, K1, K2, 8 * np.finfo(float).eps * (np.abs(r1).max() + np.abs(r2).max())
        return d, J

    for it in range(1, max_iter + 1):
        d, J, K1, K2, d_roundoff = parts(u, second=True)
        g = J.T @ d
        S1 = np.einsum("x,xab->ab", d, K1)
        S2 = np.einsum("x,xab->ab", d, K2)
        H = J.T @ J
        H[:n1, :n1] += S1
        H[n1:, n1:] -= S2
        # Active set with a band (Bertsekas' projected Newton): a parameter within a band
        # (at most 1e-3 of its span) from a bound that the gradient pushes outwards is moved
        # onto the bound and
        # held; approaching the bound by clipped, backtracked steps converges only linearly.
        # The band shrinks with the coordinate's own Newton distance |g_i| / H_ii, so that it
        # vanishes at a minimum that lies inside the domain close to a bound.
        band = np.minimum(1e-3 * scale, np.abs(g) / np.maximum(np.abs(np.diag(H)), 1e-300))
        at_lo = (~periodic) & (u <= lower + band) & (g > 0)
        at_hi = (~periodic) & (u >= upper - band) & (g < 0)
        free = ~(at_lo | at_hi)
        step = np.zeros_like(u)
        step[at_lo] = (lower - u)[at_lo]
        step[at_hi] = (upper - u)[at_hi]
        gfree = np.where(free, g, 0.0)
        # Converged when the projected gradient vanishes to round-off (this also ends a flat
        # valley, e.g. two coaxial arcs of equal radius where every couple is minimal).
        on_bounds = np.all(step[~free] == 0.0)
        if on_bounds and np.linalg.norm(gfree) <= np.linalg.norm(J) * max(
                1e-13 * np.linalg.norm(d), d_roundoff):
            break
        # Touching to round-off (a tangent touch makes |d|^2 flat to fourth order, where
        # Newton on it only converges linearly): the contact form finishes it (couple.py).
        if on_bounds and np.linalg.norm(gfree) <= 1e-15 * np.linalg.norm(J) ** 2:
            break
        if free.any():
            # Newton step with the Hessian's eigenvalues made positive (|lambda|, floored), so
            # that the step always descends; unchanged near a strict minimum.
            w, V = np.linalg.eigh(H[np.ix_(free, free)])
            w = np.maximum(np.abs(w), 1e-10 * max(1.0, np.abs(w).max()))
            step[free] = -V @ ((V.T @ g[free]) / w)
            # A nearly flat direction (a coaxial circle along a surface of revolution) gives a
            # huge step that backtracking would shrink by many trials: cap it at a quarter
            # of the domain instead.
            reach = np.max(np.abs(step) / scale)
            if reach > 0.25:
                step *= 0.25 / reach
        # Backtracking on f keeps the iteration a descent method far from the minimum; a step
        # that cannot decrease f at all means f is at its minimum to round-off.
        f0 = 0.5 * d @ d
        if -(g @ step) <= 1e-15 * f0:
            break
        # df = |d| d|d|: the predicted shortening of the distance by this step.
        far = distance_rtol is not None and on_bounds and 2.0 * f0 > rtol_beyond ** 2
        if far and -(g @ step) <= distance_rtol * 2.0 * f0:
            break
        t = 1.0
        while True:
            un = u + t * step
            un = np.where(periodic, un, np.clip(un, lower, upper))
            dn, _ = parts(un)
            fn = 0.5 * dn @ dn
            if fn <= f0 + 1e-4 * (g @ (un - u)):
                break
            t *= 0.25
            if t < 1e-12:
                un = None
                break
        if un is None:
            break
        moved = np.abs(un - u) / scale
        u = un
        if moved.max() < tol:
            break
        # The step just taken shortened the distance by less than distance_rtol of it.
        if far and f0 - fn <= distance_rtol * 2.0 * f0:
            break
    else:
        # A nearly flat valley (a ring almost coaxial with a cone) can keep the iteration
        # creeping at a gradient of 1e-13: a point whose projected gradient is 1e-10 of
        # |J| |d| is accepted (the distance is stationary there to second order). Otherwise
        # report with the residual so that the caller can name the couple.
        if np.linalg.norm(gfree) > 1e-10 * np.linalg.norm(J) * np.linalg.norm(d):
            raise SeekingError(f"closest-couple Newton did not converge in {max_iter} iterations "
                               f"(projected gradient {np.linalg.norm(gfree):.3e})")
    u = np.concatenate([P1.patch.wrap(u[:n1]), P2.patch.wrap(u[n1:])])
    return u[:n1], u[n1:], it


def seek_couple(P1, P2, *, distance_rtol=None, rtol_beyond=0.0, **grid_options) -> Couple:
    """The couple of minimal distance between posed patches P1 and P2 (Sect. 5.1); with
    ``distance_rtol`` the Newton finish ends once the distance has converged to that fraction,
    where it is beyond ``rtol_beyond`` (see `newton_closest`)."""
    best = None
    for u1, u2 in hierarchical_seek(P1, P2, **grid_options):
        u1, u2, it = newton_closest(P1, P2, u1, u2, distance_rtol=distance_rtol,
                                    rtol_beyond=rtol_beyond)
        p1, p2 = P1.position(u1), P2.position(u2)
        dist = float(np.linalg.norm(p1 - p2))
        if best is None or dist < best.distance:
            best = Couple(u1, u2, p1, p2, dist, it,
                          is_interior(P1.patch, u1) and is_interior(P2.patch, u2))
    return best


def is_interior(patch, u, rtol=1e-9) -> bool:
    """True when u lies inside the patch's domain by more than rtol of its span. A couple on a
    domain end is not a potential contact of its pair: there the closest-point conditions (22)
    do not hold, and an edge or a tip touching is a contact of another pair (or none)."""
    return bool(np.all(patch.margin(u) > rtol * patch.span))
