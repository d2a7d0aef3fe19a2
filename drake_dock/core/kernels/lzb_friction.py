"""Stick or slip of the loaded couples of a compiled LZB impact (`drake_dock.core.kernels.lzb`,
Eq. 27 and 53): the decisions taken at a couple's loading and at its friction events, and the
direction in which a couple starts to slide from rest. They set the phase arrays' ``stuck`` and
``slip_dir`` and log the events."""
from __future__ import annotations

import math

import numpy as np
from numba import njit

from drake_dock.core.kernels.lzb_forces import probe_loads, stick_rates
from drake_dock.core.kernels.lzb_records import REVERSAL, SLIP, STICK, log_event


@njit(cache=True, inline='always')
def _speed_scale(y, imp):
    """The largest |u| (at least 1e-300)."""
    scale = 1e-300
    for i in range(imp.s, imp.s + imp.nu):
        scale = max(scale, abs(y[i]))
    return scale


@njit(cache=True)
def rest_speed(imp, scale):
    """The tangential speed within which a couple is at rest: twice the speed at which a
    sliding couple's friction event fires (``settle``), or 1e-9 of the largest velocity
    ``scale``."""
    return max(1e-9 * scale, 2.0 * imp.settle)


@njit(cache=True, inline='always')
def _ut_norm(y, j, imp):
    o = 2 * imp.s + 2 * j
    return math.sqrt(y[o] ** 2 + y[o + 1] ** 2)


@njit(cache=True, inline='always')
def _known_rates(imp, ph, lam_n, skip, k):
    """The force rates (nu) with lambda_n = ``lam_n`` and the loaded couples neither in
    ``skip`` nor k sliding along their slip directions (Eq. 27); the other tangential rates
    zero."""
    s, nu, mu, slip_dir = imp.s, imp.nu, imp.mu, ph.slip_dir
    lam = np.zeros(nu)
    for j in range(s):
        lam[j] = lam_n[j]
        if lam_n[j] > 0.0 and not skip[j] and j != k:
            lam[s + 2 * j] = -mu[j] * lam_n[j] * slip_dir[j, 0]
            lam[s + 2 * j + 1] = -mu[j] * lam_n[j] * slip_dir[j, 1]
    return lam


@njit(cache=True, inline='always')
def _sticking_forces(imp, ph, lam_n, mask):
    """The tangential force rates (nu) that keep the couples ``mask`` at rest, the other
    loaded couples sliding along their slip directions."""
    lam = _known_rates(imp, ph, lam_n, mask, -1)
    stick_rates(imp, lam, mask)
    return lam


@njit(cache=True, inline='always')
def _tangential_response(imp, f, held, k):
    """u_t' of couple k (2) under the force rates ``f`` (nu; changed: the rates of the couples
    ``held``, kept at rest, solved by `stick_rates`)."""
    s, nu, G = imp.s, imp.nu, imp.G
    stick_rates(imp, f, held)
    out = np.zeros(2)
    for r in range(2):
        acc = 0.0
        for c in range(nu):
            acc += G[s + 2 * k + r, c] * f[c]
        out[r] = acc
    return out


@njit(cache=True, inline='always')
def _along(a, m, g00, g01, g11, c0, c1):
    """x = (a I + m G~)^-1 c (2 by 2) and |x| (inf where singular)."""
    p, q, r = a + m * g00, m * g01, a + m * g11
    det = p * r - q * q
    if det <= 0.0:
        return 0.0, 0.0, np.inf
    x0, x1 = (r * c0 - q * c1) / det, (p * c1 - q * c0) / det
    return x0, x1, math.sqrt(x0 * x0 + x1 * x1)


@njit(cache=True)
def _start_dir(c0, c1, g00, g01, g11, m):
    """The direction s (2) along which a couple starts to slide from rest (Eq. 27): its
    tangential acceleration c + G~ lambda_t with lambda_t = -m s (m = mu lambda_n, G~ its
    effective tangential Delassus block, c its acceleration without its own friction) lies
    along s: (alpha I + m G~) s = c, alpha > 0 the rate at which u_t grows, found by bisection
    of the decreasing |(alpha I + m G~)^-1 c| = 1 over [0, |c|] (at |c| the norm is at most 1,
    m G~ being positive semi-definite). Where no alpha > 0 gives it (the sticking force
    inside the sliding cone), the limit alpha = 0, along minus the sticking force. Zero for
    c = 0."""
    out = np.zeros(2)
    cn = math.sqrt(c0 * c0 + c1 * c1)
    if cn == 0.0:
        return out
    x0, x1, n = _along(0.0, m, g00, g01, g11, c0, c1)
    if n <= 1.0:
        out[0], out[1] = x0 / n, x1 / n
        return out
    lo, hi = 0.0, cn
    for _ in range(200):
        if hi - lo <= 1e-15 * cn:
            break
        a = 0.5 * (lo + hi)
        if _along(a, m, g00, g01, g11, c0, c1)[2] > 1.0:
            lo = a
        else:
            hi = a
    x0, x1, n = _along(hi, m, g00, g01, g11, c0, c1)
    out[0], out[1] = x0 / n, x1 / n
    return out


@njit(cache=True)
def _refine_start_dirs(imp, ph, lam_n, starting, held):
    """The slip directions of the couples ``starting`` (from rest, `_start_dir`) made
    consistent with each other, the couples ``held`` stuck and the other loaded couples
    sliding along theirs: sweeps until no direction moves by 1e-12 (at most 50)."""
    s, nu, mu, slip_dir = imp.s, imp.nu, imp.mu, ph.slip_dir
    for _ in range(50):
        moved = 0.0
        for k in range(s):
            if not starting[k]:
                continue
            # Its acceleration without its own friction, and the columns of G~.
            c = _tangential_response(imp, _known_rates(imp, ph, lam_n, held, k), held, k)
            unit = np.zeros(nu)
            unit[s + 2 * k] = 1.0
            g0 = _tangential_response(imp, unit, held, k)
            unit = np.zeros(nu)
            unit[s + 2 * k + 1] = 1.0
            g1 = _tangential_response(imp, unit, held, k)
            d = _start_dir(c[0], c[1], g0[0], 0.5 * (g0[1] + g1[0]), g1[1],
                           mu[k] * lam_n[k])
            if d[0] == 0.0 and d[1] == 0.0:
                continue
            moved = max(moved, abs(d[0] - slip_dir[k, 0]), abs(d[1] - slip_dir[k, 1]))
            slip_dir[k, 0], slip_dir[k, 1] = d[0], d[1]
        if moved <= 1e-12:
            break


@njit(cache=True)
def select_friction_modes(y, js, impulse, imp, ph, log, lam, starting):
    """Stick or slip (Eq. 27) of the couples ``js`` (a mask: loaded or loading), decided
    jointly with the couples that stick now, since their sticking forces depend on each
    other: a couple that moves tangentially slips along its motion; the couples at rest all
    stick if the tangential forces that keep them at rest lie in their static cones;
    otherwise the one furthest outside its cone starts to slide, and the rest are tested
    again with it sliding (at most s rounds). The couples that start to slide from rest
    (those and ``starting``, a mask of couples already starting, changed in place) slide
    along the directions their tangential accelerations point along, found together
    (`_refine_start_dirs`) after each round. Testing one couple at a time, with the others'
    loads not yet counted, made three feet landing together slip and stick in turn without
    end. Returns the log."""
    s, mu_s = imp.s, imp.mu_s
    stuck, slip_dir = ph.stuck, ph.slip_dir
    scale = _speed_scale(y, imp)
    lam_n = probe_loads(y, imp, ph, lam)
    was = stuck.copy()
    v_rest = rest_speed(imp, scale)
    cand = np.zeros(s, np.bool_)
    for j in range(s):
        if js[j]:
            nt = _ut_norm(y, j, imp)
            if nt > v_rest:
                o = 2 * s + 2 * j
                stuck[j] = False
                slip_dir[j, 0], slip_dir[j, 1] = y[o] / nt, y[o + 1] / nt
            else:
                cand[j] = True
    for j in range(s):
        if stuck[j] and (lam_n[j] > 0.0 or js[j]):
            cand[j] = True
    for j in range(s):
        if cand[j]:
            y[2 * s + 2 * j] = 0.0
            y[2 * s + 2 * j + 1] = 0.0
            stuck[j] = True
    lam_max = 1e-300
    for j in range(s):
        lam_max = max(lam_max, lam_n[j])
    if starting.any():
        _refine_start_dirs(imp, ph, lam_n, starting, cand)
    for _ in range(s):
        lt = _sticking_forces(imp, ph, lam_n, cand)
        k, worst = -1, -np.inf
        for j in range(s):
            if cand[j]:
                norm = math.sqrt(lt[s + 2 * j] ** 2 + lt[s + 2 * j + 1] ** 2)
                cone = mu_s[j] * lam_n[j]
                if cone > 0.0:
                    excess = norm - cone * (1.0 + 1e-12)
                else:       # a couple at zero load sticks only with zero force
                    excess = norm - 1e-12 * lam_max
                ratio = excess / max(cone, 1e-300)
                if ratio > worst:
                    k, worst = j, ratio
        if k < 0 or worst <= 0.0:
            break
        norm = math.sqrt(lt[s + 2 * k] ** 2 + lt[s + 2 * k + 1] ** 2)
        cand[k] = False
        stuck[k] = False
        starting[k] = True
        slip_dir[k, 0], slip_dir[k, 1] = -lt[s + 2 * k] / norm, -lt[s + 2 * k + 1] / norm
        _refine_start_dirs(imp, ph, lam_n, starting, cand)
    for j in range(s):
        if js[j] or was[j] != stuck[j]:
            if stuck[j] and not was[j]:
                log = log_event(log, impulse, STICK, j)
            elif not stuck[j] and _ut_norm(y, j, imp) <= 1e-12 * scale:
                log = log_event(log, impulse, SLIP if was[j] else REVERSAL, j)
    return log


@njit(cache=True)
def on_friction_event(y, j, impulse, imp, ph, log, lam):
    """Couple j's friction event: a stuck couple's force reached its static cone (it starts
    to slide; the others that stick are decided again with it), or a sliding
    couple's u_t along its slip direction fell to the speed of rest (within `rest_speed` it
    came to rest: decide; otherwise its direction turned: follow it)."""
    s, stuck, slip_dir = imp.s, ph.stuck, ph.slip_dir
    if stuck[j]:
        lam_n = probe_loads(y, imp, ph, lam)
        mask = np.zeros(s, np.bool_)
        for k in range(s):
            mask[k] = stuck[k] and (lam_n[k] > 0.0 or k == j)
        lt = _sticking_forces(imp, ph, lam_n, mask)
        a, b = lt[s + 2 * j], lt[s + 2 * j + 1]
        stuck[j] = False
        starting = np.zeros(s, np.bool_)
        norm = math.sqrt(a * a + b * b)
        if norm > 0.0:
            slip_dir[j, 0], slip_dir[j, 1] = -a / norm, -b / norm
            starting[j] = True
        log = log_event(log, impulse, SLIP, j)
        others = stuck.copy()
        if others.any():
            # Decided again with j starting to slide, their directions found together.
            return select_friction_modes(y, others, impulse, imp, ph, log, lam, starting)
        if starting[j]:
            _refine_start_dirs(imp, ph, lam_n, starting, others)
        return log
    nt = _ut_norm(y, j, imp)
    if nt <= rest_speed(imp, _speed_scale(y, imp)):
        js = np.zeros(s, np.bool_)
        js[j] = True
        return select_friction_modes(y, js, impulse, imp, ph, log, lam, np.zeros(s, np.bool_))
    o = 2 * s + 2 * j
    slip_dir[j, 0], slip_dir[j, 1] = y[o] / nt, y[o + 1] / nt
    return log


