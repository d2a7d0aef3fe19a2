"""The closest couple of two posed patches by means that share nothing with the project's seek
(Sect. 5.1): multi-start bounded L-BFGS on 0.5 |r1 - r2|^2 (scipy), from random starts or from
the best samples of a dense sampling of both patches."""
import numpy as np
from scipy.optimize import minimize


def scipy_closest(P1, P2, starts):
    """(u1, u2, r1 - r2) of the least distance found by bounded L-BFGS from ``starts``."""
    lo = np.concatenate([P1.patch.lower, P2.patch.lower])
    hi = np.concatenate([P1.patch.upper, P2.patch.upper])
    n1 = P1.patch.dim

    def f(u):
        d = P1.position(u[:n1]) - P2.position(u[n1:])
        J = np.concatenate([P1.first(u[:n1]), -P2.first(u[n1:])], axis=1)
        return 0.5 * d @ d, J.T @ d

    best = None
    for u0 in starts:
        r = minimize(f, u0, jac=True, method="L-BFGS-B", bounds=list(zip(lo, hi)),
                     options={"ftol": 1e-30, "gtol": 1e-16, "maxiter": 2000})
        if best is None or r.fun < best.fun:
            best = r
    u = best.x
    return u[:n1], u[n1:], P1.position(u[:n1]) - P2.position(u[n1:])


def random_starts(P1, P2, n=5, seed=0):
    """n uniform random points of the pair's parameter box."""
    rng = np.random.default_rng(seed)
    lo = np.concatenate([P1.patch.lower, P2.patch.lower])
    hi = np.concatenate([P1.patch.upper, P2.patch.upper])
    return [lo + (hi - lo) * rng.random(lo.size) for _ in range(n)]


def brute_force_closest(P1, P2, n_curve=400, n_surf=90, best=4):
    """Dense sampling of both patches, then `scipy_closest` from the ``best`` samples."""
    def samples(P):
        return P.patch.grid(n_curve if P.patch.dim == 1 else n_surf)
    U1, U2 = samples(P1), samples(P2)
    X1, X2 = P1.position(U1), P2.position(U2)
    d2 = (X1 ** 2).sum(1)[:, None] + (X2 ** 2).sum(1)[None, :] - 2 * X1 @ X2.T
    k = np.argsort(d2, axis=None)[:best]
    starts = [np.concatenate([U1[i], U2[j]]) for i, j in zip(*np.unravel_index(k, d2.shape))]
    return scipy_closest(P1, P2, starts)
