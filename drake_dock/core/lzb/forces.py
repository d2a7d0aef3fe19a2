"""Force rates of an LZB impact in contact space (Sect. 6): lambda = dP/dtau from the force law
(28) on the compliant couples, Coulomb's law (27) on the loaded ones, and the constraint force
rates of the couples held at rest (locked normally at e = 0, or stuck). Functions of an
`ImpactProblem` ``prob`` and a state y (`drake_dock.core.lzb.state.StateLayout`)."""
from __future__ import annotations

import numpy as np


def slip_dirs(prob, ut, which):
    """Slip directions of the couples ``which``, lambda_t = -mu lambda_n d (Eq. 27). Near
    |u_t| = 0 (slip just started from rest) the slip direction is the one set by the
    stick-to-slip transition: the direction of a round-off-sized u_t is noise, and following it
    makes the force chatter."""
    nt = np.linalg.norm(ut[which], axis=1)
    big = nt > prob.v_tiny
    return np.where(big[:, None], ut[which] / np.where(big, nt, 1.0)[:, None],
                    prob.slip_dir[which])


def tangential_pairs(prob, y):
    """u_t of each couple, (s, 2), a view into y."""
    return y[prob.layout.ut].reshape(prob.s, 2)


def forces(prob, y):
    """Normal and tangential force rates (lambda_n (s), lambda_t (s, 2)) at the state y."""
    s = prob.s
    lam_n = prob.kappa * np.maximum(y[prob.layout.x], 0.0) ** prob.eta_pow   # 0 where x <= 0
    lam_t = np.zeros((s, 2))
    if prob.locked.any():
        lam_n[prob.locked] = 0.0
        return constrained_forces(prob, y, lam_n, lam_t)
    if prob.friction:
        ut = tangential_pairs(prob, y)
        loaded = lam_n > 0
        slip = loaded & ~prob.stuck
        if slip.any():
            lam_t[slip] = -prob.mu[slip, None] * lam_n[slip, None] * slip_dirs(prob, ut, slip)
        stick = loaded & prob.stuck
        if stick.any():
            lam_t[stick] = stick_forces(prob, lam_n, lam_t, stick)
    return lam_n, lam_t


def force_rates(prob, y):
    """(lambda, friction power): the force rates stacked as the contact-space components of u
    (normal, then the tangential pairs with friction) and each couple's friction power
    -lambda_t . u_t (Eq. 27), for the right-hand side."""
    if not prob.friction:
        return forces(prob, y)[0], 0.0
    if not prob.stuck.any() and not prob.locked.any():
        return sliding_rates(prob, y)
    lam_n, lam_t = forces(prob, y)
    return (np.concatenate([lam_n, lam_t.ravel()]),
            -(lam_t * tangential_pairs(prob, y)).sum(axis=1))


def sliding_rates(prob, y):
    """`force_rates` when no couple sticks or is locked (most frictional impacts): the loaded
    couples slide, lambda_t = -mu lambda_n u_t/|u_t|, and their friction power is
    mu lambda_n |u_t|; the same equations in fewer numpy operations."""
    s = prob.s
    lam = np.empty(3 * s)
    lam_n = lam[:s]
    np.power(np.maximum(y[prob.layout.x], 0.0), prob.eta_pow, out=lam_n)
    lam_n *= prob.kappa
    ut = tangential_pairs(prob, y)
    nt = np.sqrt(np.einsum("ij,ij->i", ut, ut))
    big = nt > prob.v_tiny
    if big.all():
        d = ut / nt[:, None]
    else:
        d = np.where(big[:, None], ut / np.where(big, nt, 1.0)[:, None], prob.slip_dir)
    lam_t = lam[s:].reshape(s, 2)
    mu_lam = prob.mu * lam_n
    np.multiply(d, -mu_lam[:, None], out=lam_t)
    return lam, mu_lam * np.einsum("ij,ij->i", d, ut)


def stick_forces(prob, lam_n, lam_t, stick):
    """Tangential force rates that keep u_t = 0 on the sticking couples (Eq. 27, second
    line): G_SS lam_S = -(G_Sn lam_n + G_S,slip lam_slip)."""
    s = prob.s
    key = stick.tobytes()
    hit = prob.stick_cache.get(key)
    if hit is None:
        # Per set of sticking couples: the rows and the pseudo-inverse of G_SS (the
        # least-squares solution, as lstsq with rcond 1e-12), factored once.
        idx = np.concatenate([[s + 2 * j, s + 2 * j + 1] for j in np.flatnonzero(stick)])
        GS = prob.G[idx].copy()
        GS[:, idx] = 0.0
        hit = prob.stick_cache[key] = (-np.linalg.pinv(prob.G[np.ix_(idx, idx)],
                                                       rcond=1e-12) @ GS)
    return (hit @ np.concatenate([lam_n, lam_t.ravel()])).reshape(-1, 2)


def constrained_forces(prob, y, lam_n, lam_t):
    """Forces with locked couples (e = 0 after their maximal compression): the unknowns are
    the locked couples' normal force rates (a sliding locked couple carries -mu lambda_n
    along its slip direction) and the stuck couples' tangential ones; they keep u_n = 0 on
    the locked couples and u_t = 0 on the stuck ones: (G B z)_R = -(G lambda_known)_R."""
    s = prob.s
    nu = len(prob.G)
    ut = tangential_pairs(prob, y) if prob.friction else None
    cols, rows = [], []
    for j in np.flatnonzero(prob.locked):
        b = np.zeros(nu)
        b[j] = 1.0
        if prob.friction and not prob.stuck[j]:
            d = slip_dirs(prob, ut, np.arange(s) == j)[0]
            b[s + 2 * j: s + 2 * j + 2] = -prob.mu[j] * d
        cols.append(b)
        rows.append(j)
    if prob.friction:
        slip = (lam_n > 0) & ~prob.stuck & ~prob.locked
        if slip.any():
            lam_t[slip] = -prob.mu[slip, None] * lam_n[slip, None] * slip_dirs(prob, ut, slip)
        for j in np.flatnonzero(prob.stuck & ((lam_n > 0) | prob.locked)):
            for k in (s + 2 * j, s + 2 * j + 1):
                b = np.zeros(nu)
                b[k] = 1.0
                cols.append(b)
                rows.append(k)
    B = np.array(cols).T
    known = np.concatenate([lam_n, lam_t.ravel()]) if prob.friction else lam_n
    z = np.linalg.lstsq((prob.G @ B)[rows], -(prob.G @ known)[rows], rcond=1e-12)[0]
    lam = known + B @ z
    return lam[:s].copy(), (lam[s:].reshape(s, 2).copy() if prob.friction else lam_t)


def probe_loads(prob, y):
    """Normal forces for the friction-mode test: the current ones, or, when no couple is
    loaded yet (the instant of loading), their ratio as loading starts: couples closing at
    rates -u_n load as lambda = kappa (-u_n tau)^eta (Eq. 28)."""
    x, un = y[prob.layout.x], y[prob.layout.un]
    lam_n = forces(prob, y)[0] if prob.locked.any() else \
        np.where(x > 0, prob.kappa * np.maximum(x, 0.0) ** prob.eta, 0.0)
    if not (lam_n > 0).any():
        loading = (x >= 0) & (un < 0) & prob.comp
        lam_n = np.where(loading, prob.kappa * np.maximum(-un, 0.0) ** prob.eta, 0.0)
    return lam_n
