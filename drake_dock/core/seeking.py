"""Seeking the couple of minimal distance between two patches (Sect. 5.1).

The paper's hierarchical grid: a coarse grid over both patches' parameters, then grids an order
finer around the best cell, finished here by a bounded Newton iteration on the closest-point
conditions (gradient of 0.5 |r1 - r2|^2 equal to zero, or its projection on active bounds).
Everything is vectorised over the grid; only the pair asked for is searched. `contact_couple`
finishes the couple on the contact form (Eq. 37-38) inside the domains, or says why it is not a
potential contact (docs/model.md, "Degenerate couples").
"""
from __future__ import annotations

import dataclasses
import math

import numpy as np

from drake_dock.core import vec3 as v3
from drake_dock.core.couple import closest_point_conditions, point_curve_side
from drake_dock.core.patches import Circle
from drake_dock.errors import SeekingError

# m: a Newton finish that creeps this near touching is a touch (`newton_closest`; the compiled
# seek keeps the same rule, `drake_dock.core.kernels.seek`).
CREEP_TOUCH = 1e-6


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


def _pairwise_d2(X1, X2):
    """|x1 - x2|^2 for every pair of rows of X1 (..., m1, 3) and X2 (..., m2, 3), without
    forming the difference tensor; leading axes are batched."""
    return (np.einsum("...ix,...ix->...i", X1, X1)[..., :, None]
            + np.einsum("...jx,...jx->...j", X2, X2)[..., None, :]
            - 2.0 * X1 @ np.swapaxes(X2, -1, -2))


def _distinct_best(d2, U1, U2, h1, h2, k):
    """The k best grid couples that lie more than 2 cells apart in one of the patches: the
    best, then the best of those not within 2 cells of a chosen one in both patches, ..."""
    d2 = d2.copy()
    chosen1, chosen2 = [], []
    for _ in range(k):
        i, j = np.unravel_index(np.argmin(d2), d2.shape)
        if not np.isfinite(d2[i, j]):
            break
        chosen1.append(U1[i])
        chosen2.append(U2[j])
        near1 = np.all(np.abs(U1 - U1[i]) <= 2 * h1, axis=1)
        near2 = np.all(np.abs(U2 - U2[j]) <= 2 * h2, axis=1)
        d2[np.ix_(near1, near2)] = np.inf
    return chosen1, chosen2


def _local_grids(patch, centres, half_width, n):
    """Around each row c of ``centres`` (C, dim), the tensor grid of n points per parameter
    spanning c +- half_width (clipped to the domain for bounded parameters, wrapped for
    periodic ones), in the order of ``meshgrid(..., indexing="ij")``: shape (C, n**dim, dim)."""
    lo, hi = centres - half_width, centres + half_width
    bounded = ~np.array(patch.periodic)
    lo = np.where(bounded, np.maximum(lo, patch.lower), lo)
    hi = np.where(bounded, np.minimum(hi, patch.upper), hi)
    axes = lo[:, :, None] + (hi - lo)[:, :, None] * np.linspace(0.0, 1.0, n)   # (C, dim, n)
    if patch.dim == 1:
        U = axes[:, 0, :, None]
    else:
        mesh = [np.broadcast_to(axes[:, k].reshape((-1,) + (1,) * k + (n,)
                                                   + (1,) * (patch.dim - 1 - k)),
                                (len(centres),) + (n,) * patch.dim).reshape(len(centres), -1)
                for k in range(patch.dim)]
        U = np.stack(mesh, axis=-1)
    return patch.wrap(U)


def hierarchical_seek(P1, P2, *, n_coarse=12, levels=2, n_fine=21, candidates=3):
    """Sect. 5.1: coarse grid, then ``levels`` grids of ``n_fine`` points spanning +-2 cells of
    the previous level around its best point. The ``candidates`` best coarse couples that are
    distinct (more than two cells apart) are refined, since a nearly flat distance (a ring
    almost coaxial with a cone) can put the best coarse cell in the wrong valley. Returns a list
    of (u1, u2), best first. The candidates are refined together (one batch per level), and
    the coarse grid's points are the patches' cached ones (`Patch.grid_points`) posed."""
    U1, r1 = P1.patch.grid_points(n_coarse)
    U2, r2 = P2.patch.grid_points(n_coarse)
    h1 = P1.patch.span / (n_coarse - 1)
    h2 = P2.patch.span / (n_coarse - 1)
    d2 = _pairwise_d2(r1 @ P1.R.T + P1.p, r2 @ P2.R.T + P2.p)
    c1, c2 = _distinct_best(d2, U1, U2, h1, h2, candidates)
    c1, c2 = np.array(c1), np.array(c2)
    C = len(c1)
    g1, g2 = h1, h2
    for _ in range(levels):
        G1 = _local_grids(P1.patch, c1, 2 * g1, n_fine)
        G2 = _local_grids(P2.patch, c2, 2 * g2, n_fine)
        m1, m2 = G1.shape[1], G2.shape[1]
        X1 = P1.position(G1.reshape(C * m1, -1)).reshape(C, m1, 3)
        X2 = P2.position(G2.reshape(C * m2, -1)).reshape(C, m2, 3)
        i, j = np.divmod(_pairwise_d2(X1, X2).reshape(C, -1).argmin(axis=1), m2)
        c1, c2 = G1[np.arange(C), i], G2[np.arange(C), j]
        g1, g2 = 4 * g1 / (n_fine - 1), 4 * g2 / (n_fine - 1)
    return list(zip(c1, c2))


def _chol_solve(A, b):
    """x = A^-1 b by Cholesky for a small symmetric matrix in floats, with det(A); None when
    A is not positive definite."""
    n = len(b)
    L = [[0.0] * n for _ in range(n)]
    det = 1.0
    for i in range(n):
        for j in range(i + 1):
            s = A[i][j] - sum(L[i][k] * L[j][k] for k in range(j))
            if i == j:
                if not s > 0.0:
                    return None
                L[i][i] = math.sqrt(s)
                det *= s
            else:
                L[i][j] = s / L[j][j]
    y = [0.0] * n
    for i in range(n):
        y[i] = (b[i] - sum(L[i][k] * y[k] for k in range(i))) / L[i][i]
    x = [0.0] * n
    for i in reversed(range(n)):
        x[i] = (y[i] - sum(L[k][i] * x[k] for k in range(i + 1, n))) / L[i][i]
    return x, det


# Eigenvalues of the descent step's Hessian below FLAT max(1, |w|max) are flat directions.
FLAT = 1e-10


def _descent_step(H, g):
    """The descent step -|H|^-1 g with the eigenvalues of H made positive, in two parts (lists):
    along the directions where |w| >= FLAT max(1, |w|max) (the Newton step where H is safely
    positive definite), and along the flat ones, where -(v.g) / |w| (|w| floored at 1e-16)
    is far too long and the caller caps it (`newton_closest`). A Cholesky solve where H is well
    conditioned (lambda_min >= det / tr^(n-1) is above FLAT max(1, tr)), the
    eigen-decomposition otherwise."""
    n = len(g)
    if n == 1:
        return [-g[0] / max(abs(H[0][0]), FLAT * max(1.0, abs(H[0][0])))], [0.0]
    fact = _chol_solve(H, g)
    if fact is not None:
        x, det = fact
        tr = sum(H[i][i] for i in range(n))
        if det / tr ** (n - 1) >= FLAT * max(1.0, tr):
            return [-a for a in x], [0.0] * n
    w, V = np.linalg.eigh(np.array(H))
    w = np.abs(w)
    top = max(1.0, w.max())
    c = -(V.T @ np.array(g)) / np.maximum(w, 1e-16 * top)
    flat = w < FLAT * top
    return (V @ np.where(flat, 0.0, c)).tolist(), (V @ np.where(flat, c, 0.0)).tolist()


# The closest-couple Newton's iteration limit (`newton_closest`). A crossing next to a
# tangency (a ring's circle cutting a guide surface it nearly osculates, next to the surface's
# edge) leaves J nearly singular, and the iteration walks the valley for about 90 iterations
# before it converges quadratically.
CLOSEST_MAX_ITER = 200


def newton_closest(P1, P2, u1, u2, *, tol=1e-14, max_iter=CLOSEST_MAX_ITER, distance_rtol=None,
                   rtol_beyond=0.0):
    """Bounded Newton on f(u) = 0.5 |r1(u1) - r2(u2)|^2 from (u1, u2).

    Returns (u1, u2, iterations). Parameters at a domain end with the gradient pushing outwards
    are held (active set); periodic parameters are wrapped. With ``distance_rtol`` the
    iteration also ends when a step shortens (or would shorten) the distance by less than that
    fraction of it: a caller that needs the distance, not the couple, stops early in a flat
    valley (a ring nearly coaxial with a cone), where the couple walks along the valley for
    many iterations while the distance changes in its seventh digit. This applies only while
    the distance exceeds ``rtol_beyond``; the distance is then converged to about 1e2
    distance_rtol (the valley's many small steps add up), not the couple.

    One point at a time in plain floats (the patches' jets, `drake_dock.core.vec3`)."""
    pa, pb = P1.patch, P2.patch
    n1 = pa.dim
    n = n1 + pb.dim
    u = [float(a) for a in u1] + [float(a) for a in u2]
    lower = [float(a) for a in pa.lower] + [float(a) for a in pb.lower]
    upper = [float(a) for a in pa.upper] + [float(a) for a in pb.upper]
    periodic = tuple(pa.periodic) + tuple(pb.periodic)
    scale = [max(float(a), 1e-300) for a in list(pa.span) + list(pb.span)]
    R1, o1 = P1.R.tolist(), tuple(P1.p.tolist())
    R2, o2 = P2.R.tolist(), tuple(P2.p.tolist())
    eps8 = 8 * np.finfo(float).eps
    idx = range(n)

    def gap_vector(u):
        return v3.sub(v3.add(v3.rot(R1, pa.jet(u[:n1])[0]), o1),
                      v3.add(v3.rot(R2, pb.jet(u[n1:])[0]), o2))

    gfree = [0.0] * n
    norm_J = norm_d = 0.0
    for it in range(1, max_iter + 1):
        r1, T1, K1 = pa.jet(u[:n1])
        r2, T2, K2 = pb.jet(u[n1:])
        x1, x2 = v3.add(v3.rot(R1, r1), o1), v3.add(v3.rot(R2, r2), o2)
        d = v3.sub(x1, x2)
        # J = [T1, -T2] (world tangents); g = J^T d; H = J^T J + diag(d.K1, -d.K2).
        cols = [v3.rot(R1, t) for t in T1] + [v3.mul(v3.rot(R2, t), -1.0) for t in T2]
        g = [v3.dot(c, d) for c in cols]
        H = [[v3.dot(cols[a], cols[b]) for b in idx] for a in idx]
        d1, d2 = v3.rot_t(R1, d), v3.rot_t(R2, d)     # d.(R K) = (R^T d).K
        for a in range(n1):
            for b in range(n1):
                H[a][b] += v3.dot(d1, K1[a][b])
        for a in range(n - n1):
            for b in range(n - n1):
                H[n1 + a][n1 + b] -= v3.dot(d2, K2[a][b])
        norm_J = math.sqrt(sum(v3.dot(c, c) for c in cols))     # Frobenius
        norm_d = math.sqrt(v3.dot(d, d))
        # Round-off of d = r1 - r2 is about eps (|r1| + |r2|): far from the world origin it,
        # not |d|, sets how small the gradient J^T d can get.
        d_roundoff = eps8 * (max(abs(a) for a in x1) + max(abs(a) for a in x2))
        # Active set with a band (Bertsekas' projected Newton): a parameter within a band
        # (at most 1e-3 of its span) from a bound that the gradient pushes outwards is moved
        # onto the bound and held; approaching the bound by clipped, backtracked steps
        # converges only linearly. The band shrinks with the coordinate's own Newton distance
        # |g_i| / H_ii, so that it vanishes at a minimum that lies inside the domain close to
        # a bound.
        step = [0.0] * n
        free = []
        on_bounds = True
        for i in idx:
            gi = g[i]
            band = min(1e-3 * scale[i], abs(gi) / max(abs(H[i][i]), 1e-300))
            if not periodic[i] and u[i] <= lower[i] + band and gi > 0:
                step[i] = lower[i] - u[i]
            elif not periodic[i] and u[i] >= upper[i] - band and gi < 0:
                step[i] = upper[i] - u[i]
            else:
                free.append(i)
                continue
            on_bounds = on_bounds and step[i] == 0.0
        gfree = [g[i] if i in free else 0.0 for i in idx]
        norm_gfree = math.sqrt(sum(a * a for a in gfree))
        # Converged when the projected gradient vanishes to round-off (this also ends a flat
        # valley, e.g. two coaxial arcs of equal radius where every couple is minimal).
        if on_bounds and norm_gfree <= norm_J * max(1e-13 * norm_d, d_roundoff):
            break
        # Touching to round-off (a tangent touch makes |d|^2 flat to fourth order, where
        # Newton on it only converges linearly): the contact form finishes it (couple.py).
        if on_bounds and norm_gfree <= 1e-15 * norm_J ** 2:
            break
        if free:
            # Newton step with the Hessian's eigenvalues made positive (|lambda|, floored), so
            # that the step always descends; unchanged near a strict minimum.
            sf, flat = _descent_step([[H[a][b] for b in free] for a in free],
                                     [g[a] for a in free])
            # Along a flat direction (a circle over a coaxial arc of its radius, a coaxial
            # circle along a surface of revolution) the step runs to a quarter of the domain,
            # or to the first domain end on its way: a valley that ends there is followed
            # to it (clipping one coordinate would leave the valley's floor).
            reach = max([abs(f) / scale[a] for a, f in zip(free, flat)])
            cut = 0.25 / reach if reach > 0.25 else 1.0
            for a, f in zip(free, flat):
                if f != 0.0 and not periodic[a]:
                    cut = min(cut, max(((upper[a] if f > 0 else lower[a]) - u[a]) / f, 0.0))
            for a, s, f in zip(free, sf, flat):
                step[a] = s + cut * f
            # A huge Newton step that backtracking would shrink by many trials: capped at a
            # quarter of the domain instead.
            reach = max(abs(s) / c for s, c in zip(step, scale))
            if reach > 0.25:
                step = [s * (0.25 / reach) for s in step]
        # Backtracking on f keeps the iteration a descent method far from the minimum; a step
        # that cannot decrease f at all means f is at its minimum to round-off.
        f0 = 0.5 * norm_d * norm_d
        slope = sum(a * b for a, b in zip(g, step))
        if -slope <= 1e-15 * f0:
            break
        # df = |d| d|d|: the predicted shortening of the distance by this step.
        far = distance_rtol is not None and on_bounds and 2.0 * f0 > rtol_beyond ** 2
        if far and -slope <= distance_rtol * 2.0 * f0:
            break
        t = 1.0
        while True:
            un = [a + t * s if periodic[i] else min(max(a + t * s, lower[i]), upper[i])
                  for i, (a, s) in enumerate(zip(u, step))]
            dn = gap_vector(un)
            fn = 0.5 * v3.dot(dn, dn)
            if fn <= f0 + 1e-4 * sum(gi * (b - a) for gi, a, b in zip(g, u, un)):
                break
            t *= 0.25
            if t < 1e-12:
                un = None
                break
        if un is None:
            break
        moved = max(abs(b - a) / c for a, b, c in zip(u, un, scale))
        u = un
        if moved < tol:
            break
        # The step just taken shortened the distance by less than distance_rtol of it.
        if far and f0 - fn <= distance_rtol * 2.0 * f0:
            break
    else:
        # A nearly flat valley (a ring almost coaxial with a cone) can keep the iteration
        # creeping at a gradient of 1e-13: a point whose projected gradient is 1e-10 of
        # |J| |d| is accepted (the distance is stationary there to second order), and so is
        # one within CREEP_TOUCH of touching (a circle that pierces a face near its edge, where
        # the minima form a curve: the contact-form finish and the modes take it as a touch).
        # Otherwise report with the residual so that the caller can name the couple.
        norm_gfree = math.sqrt(sum(a * a for a in gfree))
        if norm_gfree > 1e-10 * norm_J * norm_d and norm_d > CREEP_TOUCH:
            raise SeekingError(f"closest-couple Newton did not converge in {max_iter} iterations "
                               f"(projected gradient {norm_gfree:.3e})")
    u = np.array(u)
    return pa.wrap(u[:n1]), pb.wrap(u[n1:]), it


def seek_couple(P1, P2, *, distance_rtol=None, rtol_beyond=0.0, **grid_options) -> Couple:
    """The couple of minimal distance between posed patches P1 and P2 (Sect. 5.1); with
    ``distance_rtol`` the Newton finish ends once the distance has converged to that fraction,
    where it is beyond ``rtol_beyond`` (see `newton_closest`)."""
    if P1.patch.dim == 0:
        return (seek_point_curve(P1, P2) if P2.patch.dim == 1 else
                seek_point_surface(P1, P2, distance_rtol=distance_rtol, rtol_beyond=rtol_beyond))
    best = None
    tol = 1e-9 * np.concatenate([P1.patch.span, P2.patch.span])
    started = []
    for u1, u2 in hierarchical_seek(P1, P2, **grid_options):
        # Two candidates refined onto the same grid couple: one Newton finish serves both.
        u0 = np.concatenate([u1, u2])
        if any(np.all(np.abs(u0 - s) <= tol) for s in started):
            continue
        started.append(u0)
        u1, u2, it = newton_closest(P1, P2, u1, u2, distance_rtol=distance_rtol,
                                    rtol_beyond=rtol_beyond)
        p1, p2 = P1.position(u1), P2.position(u2)
        dist = float(np.linalg.norm(p1 - p2))
        if best is None or dist < best.distance:
            best = Couple(u1, u2, p1, p2, dist, it,
                          is_interior(P1.patch, u1) and is_interior(P2.patch, u2))
    if best is None or not math.isfinite(best.distance):
        raise SeekingError("no finite distance between the patches (a non-finite pose)")
    return best


def seek_point_curve(P1, P2, *, n_grid=64, max_iter=30) -> Couple:
    """The couple of a posed point P1 (`Point`, a sphere of radius r) and a posed curve P2:
    the s of least |p - c(s)|; the distance is |p - c(s)| - r. For a full `Circle` in closed
    form: s is the polar angle of p projected onto the circle's plane (in P2's frame), and with
    p on the axis (every s is closest) s = 0, a couple that is not isolated (its conditioning is
    0, `contact_couple` refuses it). Otherwise a grid of ``n_grid`` points over the domain,
    finished by Newton on F = t2 . d (Eq. 37 for a point) clipped to the domain. The couple is
    ``interior`` only inside the curve's domain and with p on its concave side (inside a
    circle's passage, `point_curve_side`): elsewhere it is not a potential contact."""
    pt, curve = P1.patch, P2.patch
    p = P1.position(np.zeros(0))
    q = P2.R.T @ (p - P2.p)                      # p in the curve's frame
    if type(curve) is Circle:
        rho = math.hypot(q[0], q[1])
        s = curve.wrap(np.array([math.atan2(q[1], q[0]) if rho > 0.0 else 0.0]))
        it = 0
    else:
        U = curve.grid(n_grid)
        d2 = ((curve.position(U) - q) ** 2).sum(axis=-1)
        s = U[int(np.argmin(d2))]
        it = 0
        for it in range(1, max_iter + 1):
            r, t, k = curve.position(s), curve.first(s)[:, 0], curve.second(s)[:, 0, 0]
            d = q - r
            Fu = k @ d - t @ t
            if not Fu < 0.0:                    # not a minimum of |d|: stop here
                break
            step = -(t @ d) / Fu
            s_new = curve.clip(s + step)
            done = abs(float(s_new[0] - s[0])) <= 1e-14 * (1.0 + float(curve.span[0]))
            s = s_new
            if done:
                break
        s = curve.wrap(s)
    p2 = P2.position(s)
    d = p - p2
    dist = float(np.linalg.norm(d)) - pt.radius
    if not math.isfinite(dist):
        raise SeekingError("no finite distance between the point and the curve (a non-finite "
                           "pose)")
    # A potential contact only on the curve's concave side (`point_curve_side`).
    concave = point_curve_side(curve, P2.R, s[0], d) > 0.0
    return Couple(np.zeros(0), s, p, p2, dist, it, is_interior(curve, s) and concave)


def seek_point_surface(P1, P2, *, n_grid=16, distance_rtol=None, rtol_beyond=0.0) -> Couple:
    """The couple of a posed point P1 (`Point`, a sphere of radius r) and a posed surface P2:
    the u of least |p - s(u)| (the distance is |p - s(u)| - r), from the nearest point of an
    ``n_grid`` x ``n_grid`` grid over the domain, finished by the bounded Newton of
    `newton_closest` (held on a domain end the gradient pushes outwards). The couple is
    ``interior`` only inside the surface's domain."""
    pt, surface = P1.patch, P2.patch
    p = P1.position(np.zeros(0))
    U, r = surface.grid_points(n_grid)
    u0 = U[int(np.argmin(((P2.p + r @ P2.R.T - p) ** 2).sum(axis=-1)))]
    _, u2, it = newton_closest(P1, P2, np.zeros(0), u0, distance_rtol=distance_rtol,
                               rtol_beyond=rtol_beyond)
    p2 = P2.position(u2)
    dist = float(np.linalg.norm(p - p2)) - pt.radius
    if not math.isfinite(dist):
        raise SeekingError("no finite distance between the point and the surface (a "
                           "non-finite pose)")
    return Couple(np.zeros(0), u2, p, p2, dist, it, is_interior(surface, u2))


def is_interior(patch, u, rtol=1e-9) -> bool:
    """True when u lies inside the patch's domain by more than rtol of its span. A couple on a
    domain end is not a potential contact of its pair: there the closest-point conditions (22)
    do not hold, and an edge or a tip touching is a contact of another pair (or none)."""
    return bool(np.all(patch.margin(u) > rtol * patch.span))


@dataclasses.dataclass
class ContactCouple:
    """The couple a seek hands to tracking: ``u`` solves the contact form (Eq. 37-38) when
    ``usable``; otherwise it is the seek's couple and ``reason`` says why it is not a potential
    contact (docs/model.md, "Degenerate couples"). ``finish_failed``: the couple was interior
    and isolated but its contact-form finish failed."""

    u: np.ndarray
    usable: bool
    reason: str = ""
    finish_failed: bool = False


def contact_couple(kind, patch1, X1, patch2, X2, c: Couple, *, conditioning_min,
                   max_iter=20) -> ContactCouple:
    """The seek's couple ``c`` of patches on body poses X_i = (R_i, p_i), finished by Newton on
    the contact form F(u) = 0 (Eq. 37-38; the distance's gradient is flat at a tangent touch).

    Rules: the couple must be interior (`is_interior`) and isolated (J's conditioning above
    10 ``conditioning_min``); every Newton iterate must stay interior with J regular
    (conditioning above ``conditioning_min``), and the iteration must converge within
    ``max_iter`` steps (F at its round-off floor, or steps below 1e-9 of the smallest span).
    Otherwise the couple is not usable and the seek's couple is returned with the reason; no
    patch is evaluated outside its domain and no singular J is solved."""
    u0 = c.u
    n1 = patch1.dim
    if not c.interior:
        return ContactCouple(u0, False, "the closest couple lies on a domain end (a point-curve "
                                        "couple: or on the curve's convex side)")
    _, _, cond = closest_point_conditions(kind, patch1, X1, patch2, X2, u0, conditioning=True)
    if not cond > 10 * conditioning_min:
        return ContactCouple(u0, False, f"the couple is not isolated (J conditioning "
                                        f"{cond:.2e}, Eq. 40)")
    uc = u0
    step = np.inf
    for _ in range(max_iter):
        F, Fu, cond = closest_point_conditions(kind, patch1, X1, patch2, X2, uc,
                                               conditioning=True)
        if not cond > conditioning_min:
            return ContactCouple(u0, False, f"J turns singular along the contact-form finish "
                                            f"(conditioning {cond:.2e})", True)
        un = uc - np.linalg.solve(Fu, F)
        if not (np.all(np.isfinite(un)) and is_interior(patch1, un[:n1])
                and is_interior(patch2, un[n1:])):
            return ContactCouple(u0, False, "the contact-form finish leaves the domain: no "
                                            "contact-form couple inside it near the seek's", True)
        step = np.abs(un - uc).max()
        uc = un
        if np.abs(F).max() <= 1e-15 * (1.0 + np.abs(Fu).max()):
            return ContactCouple(uc, True)
    # F stalled at its round-off (far from the origin |F| cannot reach the test above) while
    # the steps became negligible: converged.
    span = np.concatenate([patch1.span, patch2.span]).min()
    if step <= 1e-9 * span:
        return ContactCouple(uc, True)
    return ContactCouple(u0, False, f"the contact-form finish did not converge in {max_iter} "
                                    f"Newton steps", True)
