"""An LZB impact (Sect. 6) compiled, in one call per impact: du/dtau = G lambda in contact
space with G = W^T M^-1 W, the force law Eq. (28), Coulomb friction Eq. (27) sliding or
sticking, locked couples at e = 0, the works Eq. (30-31) and (36) and the restitution laws
(Eq. 54 and two alternatives, `lzb_records.unloading`), integrated by an embedded
Runge-Kutta pair with dense output and event location, over plain arrays. The model and its
rules are stated in `drake_dock.core.lzb.solve`'s docstring; the phases (force rates,
right-hand side, event functions, events and stick-slip decisions) are in
`drake_dock.core.kernels.lzb_phases` (with `lzb_forces`, `lzb_friction` and `lzb_records`).

The integrator is the Dormand-Prince 5(4) pair (Dormand and Prince, J. Comput. Appl. Math. 6,
1980; the continuous extension of Hairer, Norsett and Wanner, *Solving ODEs I*, Sect. II.6),
local extrapolation (the 5th-order solution is kept), error in the root-mean-square norm
scaled by atol + rtol max(|y|, |y_new|), step factor 0.9 err^(-1/5) within [0.2, 10]. The
events of each step are found on its dense output (`active_events`: the normal rows sampled
inside the step too) and located by Brent's method (`event_time`); the integration restarts
at the first.

The impact's constants come as an `lzb_records.ImpactConstants`, the couples' phase arrays,
which the kernel changes in place, as an `lzb_records.Phases`; the step's event brackets are a
`Brackets`.
"""
from __future__ import annotations

import math
from typing import NamedTuple

import numpy as np
from numba import njit

from drake_dock.core.kernels.copies import copy1, copy2
from drake_dock.core.kernels.lzb_forces import rhs
from drake_dock.core.kernels.lzb_friction import select_friction_modes
from drake_dock.core.kernels.lzb_phases import (apply_event, classify, event_value,
                                                event_values, finished, normal_value,
                                                release_pulled)
from drake_dock.core.kernels.lzb_records import (APPROACH, COMPRESSION, EXPANSION, FRICTION,
                                                 LOCKED, NORMAL, EventLog, ImpactConstants,
                                                 new_phases)

# Statuses.
DONE, BUDGET, STEP_FAILED, NONFINITE = 0, 1, 2, 3
_CLEAR = 1e-14        # scaled event values below this are round-off
_N_INSIDE = 31        # samples inside a step: k / 32, k = 1..31

# Dormand-Prince 5(4): nodes, coupling coefficients, 5th-order weights (= the last row),
# error weights (5th minus 4th order) and the dense-output coefficients d.
C2, C3, C4, C5 = 1.0 / 5.0, 3.0 / 10.0, 4.0 / 5.0, 8.0 / 9.0
A21 = 1.0 / 5.0
A31, A32 = 3.0 / 40.0, 9.0 / 40.0
A41, A42, A43 = 44.0 / 45.0, -56.0 / 15.0, 32.0 / 9.0
A51, A52, A53, A54 = 19372.0 / 6561.0, -25360.0 / 2187.0, 64448.0 / 6561.0, -212.0 / 729.0
A61, A62, A63, A64, A65 = (9017.0 / 3168.0, -355.0 / 33.0, 46732.0 / 5247.0, 49.0 / 176.0,
                           -5103.0 / 18656.0)
B1, B3, B4, B5, B6 = 35.0 / 384.0, 500.0 / 1113.0, 125.0 / 192.0, -2187.0 / 6784.0, 11.0 / 84.0
E1, E3, E4, E5, E6, E7 = (71.0 / 57600.0, -71.0 / 16695.0, 71.0 / 1920.0, -17253.0 / 339200.0,
                          22.0 / 525.0, -1.0 / 40.0)
D1, D3, D4, D5, D6, D7 = (-12715105075.0 / 11282082432.0, 87487479700.0 / 32700410799.0,
                          -10690763975.0 / 1880347072.0, 701980252875.0 / 199316789632.0,
                          -1453857185.0 / 822651844.0, 69997945.0 / 29380423.0)


class Brackets(NamedTuple):
    """The event brackets of a step (`active_events`), entry b: row kind[b] of couple
    couple[b] crosses zero in [ta[b], tb[b]]."""
    kind: np.ndarray
    couple: np.ndarray
    ta: np.ndarray
    tb: np.ndarray


# Dense output and root finding ---------------------------------------------------------------
@njit(cache=True)
def dense_at(rc, t_old, h, t, out, lo, hi):
    """Components lo..hi-1 of the continuous extension at t."""
    th = (t - t_old) / h
    th1 = 1.0 - th
    for i in range(lo, hi):
        out[i] = rc[0, i] + th * (rc[1, i] + th1 * (rc[2, i] + th * (rc[3, i]
                                                                      + th1 * rc[4, i])))


@njit(cache=True, inline='always')
def _root_value(rc, t_old, h, t, tmp, kind, j, imp, ph, lam):
    """Row ``kind`` of couple j's event function at t on the dense output (tmp: the state)."""
    dense_at(rc, t_old, h, t, tmp, 0, len(tmp))
    return event_value(tmp, kind, j, imp, ph, lam)


@njit(cache=True)
def event_time(rc, t_old, h, kind, j, ta, tb, tmp, imp, ph, lam):
    """The zero in [ta, tb] of couple j's event function of row ``kind`` on the dense output
    (ta when it starts on the boundary): Brent's method (Brent, *Algorithms for Minimization
    without Derivatives*, 1973, ch. 4), to xtol 1e-15 max(1, |tb|) and rtol 4 eps."""
    fa = _root_value(rc, t_old, h, ta, tmp, kind, j, imp, ph, lam)
    if fa <= 0.0:
        return ta
    fb = _root_value(rc, t_old, h, tb, tmp, kind, j, imp, ph, lam)
    if fb > 0.0:
        return tb
    xtol, rtol = 1e-15 * max(1.0, abs(tb)), 4.0 * 2.220446049250313e-16
    a, b = ta, tb
    c, fc = a, fa
    d = e = b - a
    for _ in range(200):
        if (fb > 0.0) == (fc > 0.0):
            c, fc = a, fa
            d = e = b - a
        if abs(fc) < abs(fb):
            a, b, c = b, c, b
            fa, fb, fc = fb, fc, fb
        tol = 2.0 * rtol * abs(b) + 0.5 * xtol
        m = 0.5 * (c - b)
        if abs(m) <= tol or fb == 0.0:
            return b
        if abs(e) >= tol and abs(fa) > abs(fb):
            sr = fb / fa
            if a == c:                      # secant
                p, q = 2.0 * m * sr, 1.0 - sr
            else:                           # inverse quadratic interpolation
                qq, rr = fa / fc, fb / fc
                p = sr * (2.0 * m * qq * (qq - rr) - (b - a) * (rr - 1.0))
                q = (qq - 1.0) * (rr - 1.0) * (sr - 1.0)
            if p > 0.0:
                q = -q
            else:
                p = -p
            if 2.0 * p < min(3.0 * m * q - abs(tol * q), abs(e * q)):
                e, d = d, p / q
            else:
                d = e = m
        else:
            d = e = m
        a, fa = b, fb
        b += d if abs(d) > tol else (tol if m > 0.0 else -tol)
        fb = _root_value(rc, t_old, h, b, tmp, kind, j, imp, ph, lam)
    return b


@njit(cache=True)
def active_events(rc, t_old, t_new, g0, g1, tmp, imp, ph, br):
    """The events of a step from t_old to t_new into ``br``, entries (row, couple, ta, tb)
    with a sign change of the event function inside [ta, tb]; their number. First the
    releases of locked couples and the friction rows, from the step's ends; then the normal
    and approach rows of the other couples, sampled inside the step as well (at k / 32), so
    that u_n crossing zero twice in one step (a brief separation or approach between two
    phases) is not missed, nor a crossing that follows a start at the threshold."""
    s, phase = imp.s, ph.phase
    br_kind, br_j, br_a, br_b = br
    nb = 0
    h = t_new - t_old
    for kind in (NORMAL, FRICTION):
        for j in range(s):
            if (kind == FRICTION or phase[j] == LOCKED) and g0[kind, j] > 0.0 \
                    and g1[kind, j] <= 0.0:
                br_kind[nb], br_j[nb], br_a[nb], br_b[nb] = kind, j, t_old, t_new
                nb += 1
    T = np.empty(_N_INSIDE + 2)
    T[0], T[-1] = t_old, t_new
    for k in range(1, _N_INSIDE + 1):
        T[k] = t_old + (k / 32.0) * h
    samples = np.empty((_N_INSIDE, 2, s))
    for k in range(_N_INSIDE):
        dense_at(rc, t_old, h, T[k + 1], tmp, 0, 2 * s)
        for j in range(s):
            samples[k, 0, j] = normal_value(tmp, NORMAL, j, imp, ph)
            samples[k, 1, j] = normal_value(tmp, APPROACH, j, imp, ph)
    for r in range(2):
        kind = NORMAL if r == 0 else APPROACH
        for j in range(s):
            if phase[j] == LOCKED:
                continue
            prev = g0[kind, j]
            for i in range(_N_INSIDE + 1):
                nxt = g1[kind, j] if i == _N_INSIDE else samples[i, r, j]
                if (prev > _CLEAR or (prev > 0.0 and i == 0)) and nxt <= 0.0:
                    br_kind[nb], br_j[nb], br_a[nb], br_b[nb] = kind, j, T[i], T[i + 1]
                    nb += 1
                    break
                prev = nxt
    return nb


# The driver --------------------------------------------------------------------------------
@njit(cache=True)
def _rms(v, sc):
    acc = 0.0
    for i in range(len(v)):
        acc += (v[i] / sc[i]) ** 2
    return math.sqrt(acc / len(v))


@njit(cache=True)
def lzb_impact(y, decide, imp, ph):
    """Integrates the impact of constants ``imp`` (an `ImpactConstants`) from the state y at
    tau = 0, the phase arrays ``ph`` (a `Phases`, updated in place) at the impact's start,
    until it ends (`DONE`), the step budget is exceeded (`BUDGET`), the step size underflows
    (`STEP_FAILED`) or the state is not finite (`NONFINITE`). With friction, the couples
    ``decide`` (a mask: loaded or approaching) first take stick or slip
    (`select_friction_modes`). Returns (status, tau, y, the last step, the steps taken, the
    events as an `EventLog`, the normal impulses after each accepted step and their number).

    Each step's events are located on its dense output (`active_events`, `event_time`); the
    first is applied there, with every other one at the same instant (symmetric couples: after
    the restart their functions would start at <= 0 and their crossings would never be seen
    again); then the couples at u_n = 0 take the phase their motion starts (a loaded couple in
    compression whose u_n grows reaches its maximal compression at once, one in expansion
    whose u_n falls approaches again at once: after Eq. 54's drop of force, or at a tangency
    of u_n with zero), a locked couple left pulling is released (`release_pulled`), and the
    integration restarts there."""
    s, nu, rtol, atol, max_steps = imp.s, imp.nu, imp.rtol, imp.atol, imp.max_steps
    imp_scale, phase = imp.imp_scale, ph.phase
    N = len(y)
    y = y.copy()
    t, h, steps = 0.0, 0.0, 0
    lam = np.empty(nu)
    k1, k2, k3, k4 = np.empty(N), np.empty(N), np.empty(N), np.empty(N)
    k5, k6, k7 = np.empty(N), np.empty(N), np.empty(N)
    ys, yn, sc, tmp, err = np.empty(N), np.empty(N), np.empty(N), np.empty(N), np.empty(N)
    rc = np.empty((5, N))
    g0, g1 = np.empty((3, s)), np.empty((3, s))
    nbmax = 3 * s
    br = Brackets(np.empty(nbmax, np.int64), np.empty(nbmax, np.int64), np.empty(nbmax),
                  np.empty(nbmax))
    br_kind, br_j, br_a, br_b = br
    roots = np.empty(nbmax)
    order = np.empty(nbmax, np.int64)
    # The event log; its count an int64, not the literal 0, so that apply_event and _log
    # are compiled for one type of it.
    log = EventLog(np.empty(16), np.empty(16, np.int64), np.empty(16, np.int64), np.int64(0))
    hist = np.empty((64, s))
    nh = 0
    if imp.friction and decide.any():
        log = select_friction_modes(y, decide, 0.0, imp, ph, log, lam,
                                    np.zeros(s, np.bool_))
    while not finished(y, imp, ph):
        classify(y, imp, ph)
        event_values(y, g0, imp, ph, lam)
        rhs(y, k1, imp, ph, lam)
        if h <= 0.0:
            # The initial step (Hairer, Norsett and Wanner, Sect. II.4).
            for i in range(N):
                sc[i] = atol + rtol * abs(y[i])
            d0, d1 = _rms(y, sc), _rms(k1, sc)
            h0 = 1e-6 if d0 < 1e-5 or d1 < 1e-5 else 0.01 * d0 / d1
            for i in range(N):
                ys[i] = y[i] + h0 * k1[i]
            rhs(ys, k2, imp, ph, lam)
            for i in range(N):
                tmp[i] = k2[i] - k1[i]
            d2 = _rms(tmp, sc) / h0
            if d1 <= 1e-15 and d2 <= 1e-15:
                h1 = max(1e-6, h0 * 1e-3)
            else:
                h1 = (0.01 / max(d1, d2)) ** 0.2
            h = min(100.0 * h0, h1)
        ended = False
        fac = 1.0
        h_used = h
        while True:
            # One accepted step.
            rejected = False
            while True:
                min_step = 10.0 * abs(np.nextafter(t, np.inf) - t)
                if h < min_step:
                    return (STEP_FAILED, t, y, h, steps, log, hist, nh)
                for i in range(N):
                    ys[i] = y[i] + h * A21 * k1[i]
                rhs(ys, k2, imp, ph, lam)
                for i in range(N):
                    ys[i] = y[i] + h * (A31 * k1[i] + A32 * k2[i])
                rhs(ys, k3, imp, ph, lam)
                for i in range(N):
                    ys[i] = y[i] + h * (A41 * k1[i] + A42 * k2[i] + A43 * k3[i])
                rhs(ys, k4, imp, ph, lam)
                for i in range(N):
                    ys[i] = y[i] + h * (A51 * k1[i] + A52 * k2[i] + A53 * k3[i] + A54 * k4[i])
                rhs(ys, k5, imp, ph, lam)
                for i in range(N):
                    ys[i] = y[i] + h * (A61 * k1[i] + A62 * k2[i] + A63 * k3[i] + A64 * k4[i]
                                        + A65 * k5[i])
                rhs(ys, k6, imp, ph, lam)
                for i in range(N):
                    yn[i] = y[i] + h * (B1 * k1[i] + B3 * k3[i] + B4 * k4[i] + B5 * k5[i]
                                        + B6 * k6[i])
                rhs(yn, k7, imp, ph, lam)
                finite = True
                for i in range(N):
                    err[i] = h * (E1 * k1[i] + E3 * k3[i] + E4 * k4[i] + E5 * k5[i]
                                  + E6 * k6[i] + E7 * k7[i])
                    sc[i] = atol + rtol * max(abs(y[i]), abs(yn[i]))
                    if not (math.isfinite(yn[i]) and math.isfinite(k7[i])):
                        finite = False
                if not finite:
                    return (NONFINITE, t, y, h, steps, log, hist, nh)
                en = _rms(err, sc)
                if en <= 1.0:
                    fac = 10.0 if en == 0.0 else min(10.0, 0.9 * en ** -0.2)
                    if rejected:
                        fac = min(1.0, fac)
                    break
                h *= max(0.2, 0.9 * en ** -0.2)
                rejected = True
            steps += 1
            if steps > max_steps:
                return (BUDGET, t, y, h, steps, log, hist, nh)
            t_old, t_new = t, t + h
            for i in range(N):
                dy = yn[i] - y[i]
                bspl = h * k1[i] - dy
                rc[0, i] = y[i]
                rc[1, i] = dy
                rc[2, i] = bspl
                rc[3, i] = dy - h * k7[i] - bspl
                rc[4, i] = h * (D1 * k1[i] + D3 * k3[i] + D4 * k4[i] + D5 * k5[i]
                                + D6 * k6[i] + D7 * k7[i])
            h_used = h
            event_values(yn, g1, imp, ph, lam)
            nb = active_events(rc, t_old, t_new, g0, g1, tmp, imp, ph, br)
            if nb > 0:
                first = 0
                for b in range(nb):
                    roots[b] = event_time(rc, t_old, h_used, br_kind[b], br_j[b], br_a[b],
                                          br_b[b], tmp, imp, ph, lam)
                    if roots[b] < roots[first]:
                        first = b
                t_first = roots[first]
                dense_at(rc, t_old, h_used, t_first, y, 0, N)
                impulse = 0.0
                for j in range(s):
                    impulse += y[s + nu + j]
                impulse *= imp_scale
                log = apply_event(y, br_kind[first], br_j[first], impulse, imp, ph, log, lam)
                # The others at the same instant, in the order (time, row, couple).
                for b in range(nb):
                    order[b] = b
                for a in range(1, nb):
                    b = a
                    while b > 0:
                        p, q = order[b - 1], order[b]
                        if _after(roots[p], br_kind[p], br_j[p], roots[q], br_kind[q], br_j[q]):
                            order[b - 1], order[b] = q, p
                            b -= 1
                        else:
                            break
                same = 1e-12 * max(1.0, abs(t_first))
                for a in range(nb):
                    b = order[a]
                    if b != first and roots[b] <= t_first + same and event_value(
                            y, br_kind[b], br_j[b], imp, ph, lam) <= 0.0:
                        log = apply_event(y, br_kind[b], br_j[b], impulse, imp, ph, log, lam)
                # The couples at u_n = 0 take the phase their motion starts.
                for _ in range(2 * s):
                    near = False
                    for j in range(s):
                        near = near or abs(y[s + j]) <= 1e-12
                    if not near:
                        break
                    rhs(y, tmp, imp, ph, lam)
                    jt = -1
                    for j in range(s):
                        if abs(y[s + j]) <= 1e-12 and (
                                (phase[j] == COMPRESSION and y[j] > 0.0 and tmp[s + j] > 0.0)
                                or (phase[j] == EXPANSION and tmp[s + j] < 0.0)):
                            jt = j
                            break
                    if jt < 0:
                        break
                    kind = NORMAL if phase[jt] == COMPRESSION else APPROACH
                    log = apply_event(y, kind, jt, impulse, imp, ph, log, lam)
                log = release_pulled(y, impulse, imp, ph, log, lam)
                t = t_first
                h = h_used
                nh = _history(hist, nh, y, imp)
                hist = _grown(hist, nh)
                break
            copy1(y, yn)
            t = t_new
            copy1(k1, k7)                   # first same as last
            if classify(y, imp, ph):
                event_values(y, g0, imp, ph, lam)
            else:
                copy2(g0, g1)
            nh = _history(hist, nh, y, imp)
            hist = _grown(hist, nh)
            h = h_used * fac
            if finished(y, imp, ph):
                ended = True
                break
        if ended:
            h = h_used
            break
    return (DONE, t, y, h, steps, log, hist, nh)


@njit(cache=True)
def _after(ta, ka, ja, tb, kb, jb):
    """(ta, ka, ja) > (tb, kb, jb) in lexicographic order."""
    if ta != tb:
        return ta > tb
    if ka != kb:
        return ka > kb
    return ja > jb


@njit(cache=True)
def _history(hist, nh, y, imp):
    """The normal impulses of y as row nh of hist; nh + 1."""
    s, nu, imp_scale = imp.s, imp.nu, imp.imp_scale
    for j in range(s):
        hist[nh, j] = y[s + nu + j] * imp_scale
    return nh + 1


@njit(cache=True)
def _grown(hist, nh):
    if nh < len(hist):
        return hist
    out = np.empty((2 * len(hist), hist.shape[1]))
    copy2(out[:nh], hist[:nh])
    return out


def warm():
    """Compiles (or loads) the kernel: two balls meeting at unit speed with friction and
    e = 0, at rest tangentially (the couple sticks and locks)."""
    s, nu = 1, 3
    G = np.array([[2.0, 0.0, 0.0], [0.0, 2.0, 0.0], [0.0, 0.0, 2.0]])
    y = np.zeros(4 * s + 2 * nu)
    y[s] = -1.0
    one = np.ones(s)
    imp = ImpactConstants(s, nu, G, one, 1.5 * one, 0.0 * one, 0.3 * one, 0.3 * one,
                          friction=True, law=0, settle=1e-8, rtol=1e-8, atol=1e-10,
                          max_steps=10_000, imp_scale=1.0)
    lzb_impact(y, np.ones(s, np.bool_), imp, new_phases(s))
