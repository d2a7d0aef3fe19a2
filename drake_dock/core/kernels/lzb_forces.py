"""The force rates of a compiled LZB impact (`drake_dock.core.kernels.lzb`) and its
right-hand side, over the records of `drake_dock.core.kernels.lzb_records`: lambda_n on the
loading curve (Eq. 28), lambda_t of the sliding couples (Eq. 27), and the constraint force rates
of the *held* couples, locked (e = 0 after their maximal compression: u_n = 0 kept) or stuck
(u_t = 0 kept), solved for at every evaluation. Without held couples the force rates are
explicit (`_sliding_rhs`)."""
from __future__ import annotations

import math

import numpy as np
from numba import njit

from drake_dock.core.kernels.lzb_records import (COMPRESSION, EXPANSION, LOCKED, any_held,
                                                 any_locked)
from drake_dock.core.kernels.small_linalg import lstsq

_RCOND = 1e-12        # the constraint solves' cut-off (numpy's lstsq rcond)


@njit(cache=True, inline='always')
def slip_dir_of(y, j, imp, ph):
    """Couple j's slip direction: along u_t, or the one set at its start of sliding while
    |u_t| is below twice ``settle`` (the speed of rest): below it the direction of u_t turns
    faster than any step can follow, and following it makes the force chatter."""
    o = imp.s + imp.s + 2 * j
    a, b = y[o], y[o + 1]
    nt = math.sqrt(a * a + b * b)
    if nt > 2.0 * imp.settle:
        return a / nt, b / nt
    return ph.slip_dir[j, 0], ph.slip_dir[j, 1]


@njit(cache=True, inline='always')
def _solve_held(imp, lam, cols, rows, m):
    """lambda += B z with (G B)_R z = -(G lambda)_R (the constraint force rates), the first m
    columns of ``cols`` (nu, m) being B and ``rows`` R: least squares of least norm, cut off
    at `_RCOND` (the rows are those the columns hold at zero velocity)."""
    if m == 0:
        return
    G, nu = imp.G, imp.nu
    A = np.empty((m, m))
    r = np.empty(m)
    for a in range(m):
        i = rows[a]
        acc = 0.0
        for k in range(nu):
            acc += G[i, k] * lam[k]
        r[a] = -acc
        for c in range(m):
            acc = 0.0
            for k in range(nu):
                acc += G[i, k] * cols[k, c]
            A[a, c] = acc
    z = lstsq(A, r, _RCOND)
    for k in range(nu):
        acc = 0.0
        for c in range(m):
            acc += cols[k, c] * z[c]
        lam[k] += acc


@njit(cache=True, inline='always')
def _stick_columns(imp, lam, mask, cols, rows, m):
    """Appends to the unknowns (columns ``cols``, rows ``rows``, m so far) the tangential
    rates of the couples ``mask``, zeroed in ``lam``; returns their new number."""
    s = imp.s
    for j in range(s):
        if mask[j]:
            for k in (s + 2 * j, s + 2 * j + 1):
                lam[k] = 0.0
                cols[k, m] = 1.0
                rows[m] = k
                m += 1
    return m


@njit(cache=True, inline='always')
def _slide_rates(y, imp, ph, lam):
    """lambda_t = -mu lambda_n d (Eq. 27) into ``lam`` for the loaded couples neither stuck
    nor locked, d their slip direction (`slip_dir_of`); whether a loaded couple is stuck."""
    s, mu, phase, stuck = imp.s, imp.mu, ph.phase, ph.stuck
    some = False
    for j in range(s):
        if lam[j] > 0.0:
            if stuck[j]:
                some = True
            elif phase[j] != LOCKED:
                d0, d1 = slip_dir_of(y, j, imp, ph)
                lam[s + 2 * j] = -mu[j] * lam[j] * d0
                lam[s + 2 * j + 1] = -mu[j] * lam[j] * d1
    return some


@njit(cache=True)
def stick_rates(imp, lam, mask):
    """The tangential force rates that keep the couples ``mask`` at rest, into ``lam`` (whose
    other entries are the known rates; Eq. 27, second line): G_SS lambda_S =
    -(G lambda_known)_S."""
    cols = np.zeros((imp.nu, 2 * imp.s))
    rows = np.empty(2 * imp.s, np.int64)
    _solve_held(imp, lam, cols, rows, _stick_columns(imp, lam, mask, cols, rows, 0))


@njit(cache=True, inline='always')
def held_forces(y, imp, ph, lam):
    """The force rates with locked couples: the unknowns are the locked couples' normal
    force rates (a sliding locked couple carries -mu lambda_n along its slip direction) and
    the stuck loaded or locked couples' tangential ones; they keep u_n = 0 on the locked
    couples and u_t = 0 on the stuck ones. ``lam`` holds the loading curve's lambda_n, zero
    on the locked couples."""
    s, nu, friction, mu = imp.s, imp.nu, imp.friction, imp.mu
    phase, stuck = ph.phase, ph.stuck
    cols = np.zeros((nu, 3 * s))
    rows = np.empty(3 * s, np.int64)
    m = 0
    for j in range(s):
        if phase[j] == LOCKED:
            cols[j, m] = 1.0
            if friction and not stuck[j]:
                d0, d1 = slip_dir_of(y, j, imp, ph)
                cols[s + 2 * j, m] = -mu[j] * d0
                cols[s + 2 * j + 1, m] = -mu[j] * d1
            rows[m] = j
            m += 1
    if friction:
        _slide_rates(y, imp, ph, lam)
        mask = np.zeros(s, np.bool_)
        for j in range(s):
            mask[j] = stuck[j] and (lam[j] > 0.0 or phase[j] == LOCKED)
        m = _stick_columns(imp, lam, mask, cols, rows, m)
    _solve_held(imp, lam, cols, rows, m)


@njit(cache=True)
def forces(y, imp, ph, lam):
    """The force rates lambda (nu: normal, then the tangential pairs) at y into ``lam``:
    lambda_n = kappa max(x, 0)^eta (Eq. 28); a loaded sliding couple's lambda_t =
    -mu lambda_n d (Eq. 27); a stuck loaded couple's, the rate that keeps it at rest; with
    locked couples, `held_forces`."""
    s, nu, kappa, eta, friction = imp.s, imp.nu, imp.kappa, imp.eta, imp.friction
    phase, stuck = ph.phase, ph.stuck
    for j in range(s):
        lam[j] = kappa[j] * max(y[j], 0.0) ** eta[j]
    for k in range(s, nu):
        lam[k] = 0.0
    if any_locked(ph):
        for j in range(s):
            if phase[j] == LOCKED:
                lam[j] = 0.0
        held_forces(y, imp, ph, lam)
        return
    if friction and _slide_rates(y, imp, ph, lam):
        mask = np.zeros(s, np.bool_)
        for j in range(s):
            mask[j] = stuck[j] and lam[j] > 0.0
        stick_rates(imp, lam, mask)


@njit(cache=True)
def probe_loads(y, imp, ph, lam):
    """Normal force rates for a stick-slip decision (s): the current ones, or, when no couple
    is loaded yet (the instant of loading), their ratio as loading starts: couples closing at
    rates -u_n load as lambda = kappa (-u_n tau)^eta (Eq. 28). ``lam`` (nu) is work space."""
    s, kappa, eta, phase = imp.s, imp.kappa, imp.eta, ph.phase
    out = np.empty(s)
    if any_locked(ph):
        forces(y, imp, ph, lam)
        for j in range(s):
            out[j] = lam[j]
    else:
        for j in range(s):
            out[j] = kappa[j] * y[j] ** eta[j] if y[j] > 0.0 else 0.0
    for j in range(s):
        if out[j] > 0.0:
            return out
    for j in range(s):
        un = y[s + j]
        loading = y[j] >= 0.0 and un < 0.0 and phase[j] == COMPRESSION
        out[j] = kappa[j] * (-un) ** eta[j] if loading else 0.0
    return out


# The right-hand side -----------------------------------------------------------------------
@njit(cache=True)
def rhs(y, out, imp, ph, lam):
    """dy/dtau into ``out``, ``lam`` (nu) receiving lambda (`forces`): dx = -rate u_n (an
    unloaded couple in compression indents only while it approaches: the configuration is
    frozen, so there is no gap), du = G lambda, dP = lambda, the compression and expansion
    works -lambda_n u_n (Eq. 30-31) and the friction dissipation -lambda_t . u_t; u_n of a
    locked couple and u_t of a stuck loaded one are held at zero exactly."""
    if not any_held(ph):
        _sliding_rhs(y, out, imp, ph, lam)
        return
    s, nu, friction = imp.s, imp.nu, imp.friction
    phase, rate, stuck = ph.phase, ph.rate, ph.stuck
    forces(y, imp, ph, lam)
    ou, ow = s, s + 2 * nu
    for j in range(s):
        un = y[ou + j]
        dx = -rate[j] * un
        if phase[j] == COMPRESSION and y[j] <= 0.0 and dx < 0.0:
            dx = 0.0
        out[j] = dx
        power = lam[j] * un
        cf = 0.0 if phase[j] == EXPANSION else 1.0
        out[ow + j] = -power * cf
        out[ow + s + j] = power * (cf - 1.0)
        fp = 0.0
        if friction:
            o = 2 * s + 2 * j
            fp = -(lam[s + 2 * j] * y[o] + lam[s + 2 * j + 1] * y[o + 1])
        out[ow + 2 * s + j] = fp
    _velocity_and_impulse_rates(imp, lam, out)
    for j in range(s):
        if friction and stuck[j] and (lam[j] > 0.0 or phase[j] == LOCKED):
            out[ou + s + 2 * j] = 0.0
            out[ou + s + 2 * j + 1] = 0.0
        if phase[j] == LOCKED:
            out[ou + j] = 0.0


@njit(cache=True)
def _sliding_rhs(y, out, imp, ph, lam):
    """`rhs` with no couple held: lambda_t = -mu lambda_n d along the slip direction d of
    every loaded couple (`slip_dir_of`), its friction power mu lambda_n d . u_t, in fewer
    operations."""
    s, nu, kappa, eta, mu = imp.s, imp.nu, imp.kappa, imp.eta, imp.mu
    friction, phase, rate, slip_dir = imp.friction, ph.phase, ph.rate, ph.slip_dir
    v_dir = 2.0 * imp.settle
    for j in range(s):
        lam[j] = kappa[j] * max(y[j], 0.0) ** eta[j]
    ox, ou = 0, s
    ow = s + 2 * nu
    for j in range(s):
        un = y[ou + j]
        dx = -rate[j] * un
        if phase[j] == COMPRESSION and y[j] <= 0.0 and dx < 0.0:
            dx = 0.0     # an unloaded couple indents only while it approaches
        out[ox + j] = dx
        power = lam[j] * un
        cf = 0.0 if phase[j] == EXPANSION else 1.0
        out[ow + j] = -power * cf
        out[ow + s + j] = power * (cf - 1.0)
        out[ow + 2 * s + j] = 0.0
    if friction:
        for j in range(s):
            a, b = y[ou + s + 2 * j], y[ou + s + 2 * j + 1]
            nt = math.sqrt(a * a + b * b)
            if nt > v_dir:
                d0, d1 = a / nt, b / nt
            else:
                d0, d1 = slip_dir[j, 0], slip_dir[j, 1]
            ml = mu[j] * lam[j]
            lam[s + 2 * j] = -ml * d0
            lam[s + 2 * j + 1] = -ml * d1
            out[ow + 2 * s + j] = ml * (d0 * a + d1 * b)
    _velocity_and_impulse_rates(imp, lam, out)


@njit(cache=True, inline='always')
def _velocity_and_impulse_rates(imp, lam, out):
    """du/dtau = G lambda and dP/dtau = lambda into ``out`` (Eq. 35 in contact space)."""
    s, nu, G = imp.s, imp.nu, imp.G
    for i in range(nu):
        acc = 0.0
        for k in range(nu):
            acc += G[i, k] * lam[k]
        out[s + i] = acc
        out[s + nu + i] = lam[i]
