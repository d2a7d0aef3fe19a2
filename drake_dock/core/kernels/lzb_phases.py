"""The phases of a compiled LZB impact (`drake_dock.core.kernels.lzb`) over plain arrays: the
right-hand side, the event functions, the end test and the events the kernel applies, as
`drake_dock.core.lzb.problem.ImpactProblem` has them for states with no couple stuck or
locked; the restitution laws of `drake_dock.core.lzb.laws` by code.

The functions take the impact's constants as an `ImpactConstants`, the couples' phase arrays
(which the events change in place) as a `Phases` and the event log as an `EventLog`: typed
records (NamedTuples) that numba passes as structures of arrays and scalars. Each function
reads the fields it uses at its top: a record still in use further down holds a reference to
each of its arrays, taken and released on every call."""
from __future__ import annotations

import math
from typing import NamedTuple

import numpy as np
from numba import njit
from drake_dock.core.kernels.copies import copy1

# Phases (`drake_dock.core.lzb.state`) and event rows (`drake_dock.core.lzb.problem`).
COMPRESSION, EXPANSION, LOCKED = 0, 1, 2
NORMAL, FRICTION, APPROACH = 0, 1, 2
# Event kinds logged by the kernel, as codes into KINDS.
KINDS = ("max_compression", "recompression", "end", "re_impact")
MAXC, RECOMP, END, REIMPACT = 0, 1, 2, 3
# Restitution laws, as codes into LAW_NAMES.
LAW_NAMES = ("paper", "mono", "bi")
_V_TINY = 1e-12       # `ImpactProblem.v_tiny`


# The records -------------------------------------------------------------------------------
class ImpactConstants(NamedTuple):
    """The constants of one impact (`ImpactProblem`'s, nondimensional): s couples and nu force
    components (s, or 3 s with friction); the Delassus matrix G (nu, nu) in contact space; per
    couple the stiffness kappa and exponent eta of Eq. (28), the energetic restitution e of
    Eq. (36) and the sliding friction mu of Eq. (27); ``friction``; ``law``, a code into
    LAW_NAMES; ``settle``, the relative velocity below which the impact has ended and the
    sliding speed at which a couple has come to rest; the integration's rtol, atol and step
    budget; ``imp_scale`` (m_s v_s), the impulses' unit."""
    s: int
    nu: int
    G: np.ndarray
    kappa: np.ndarray
    eta: np.ndarray
    e: np.ndarray
    mu: np.ndarray
    friction: bool
    law: int
    settle: float
    rtol: float
    atol: float
    max_steps: int
    imp_scale: float


class Phases(NamedTuple):
    """The couples' phase arrays (`ImpactProblem`'s of the same names), changed in place by
    the events: the phase, ``sep`` (unloaded and separating), ``rate`` (dx/dtau = -rate u_n),
    ``x_end`` (the indentation at which expansion ends), ``slip_dir`` (s, 2), the compression
    work ``wc`` summed over episodes, ``e_start`` (the stored energy when the current
    compression began) and ``wc_open`` (the compression work since the contact began)."""
    phase: np.ndarray
    sep: np.ndarray
    rate: np.ndarray
    x_end: np.ndarray
    slip_dir: np.ndarray
    wc: np.ndarray
    e_start: np.ndarray
    wc_open: np.ndarray


class EventLog(NamedTuple):
    """The events applied, as `ImpactEvent`: the first n entries of the total normal impulse,
    the kind (a code into KINDS) and the couple; n an int64."""
    impulse: np.ndarray
    kind: np.ndarray
    couple: np.ndarray
    n: int


# The problem -------------------------------------------------------------------------------
@njit(cache=True)
def stored_energy(kappa, eta, x):
    """Eq. (28) integrated (`laws.stored_energy`)."""
    return kappa * max(x, 0.0) ** (eta + 1.0) / (eta + 1.0)


@njit(cache=True)
def indentation(kappa, eta, E):
    """The inverse of `stored_energy` (`laws.indentation`)."""
    return ((eta + 1.0) * max(E, 0.0) / kappa) ** (1.0 / (eta + 1.0))


@njit(cache=True)
def rhs(y, out, imp, ph, lam):
    """dy/dtau into ``out`` (`ImpactProblem.rhs` with `forces.sliding_rates`: no couple stuck
    or locked): lambda_n = kappa max(x, 0)^eta (Eq. 28), lambda_t = -mu lambda_n d along the
    slip direction d (Eq. 27), du = G lambda, dP = lambda, the works of Eq. (30-31); ``lam``
    (nu) receives lambda."""
    s, nu, G, kappa, eta, mu = imp.s, imp.nu, imp.G, imp.kappa, imp.eta, imp.mu
    friction, phase, rate, slip_dir = imp.friction, ph.phase, ph.rate, ph.slip_dir
    for j in range(s):
        lam[j] = kappa[j] * max(y[j], 0.0) ** eta[j]
    ox, ou, oP = 0, s, s + nu
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
            if nt > _V_TINY:
                d0, d1 = a / nt, b / nt
            else:
                d0, d1 = slip_dir[j, 0], slip_dir[j, 1]
            ml = mu[j] * lam[j]
            lam[s + 2 * j] = -ml * d0
            lam[s + 2 * j + 1] = -ml * d1
            out[ow + 2 * s + j] = ml * (d0 * a + d1 * b)
    for i in range(nu):
        acc = 0.0
        for k in range(nu):
            acc += G[i, k] * lam[k]
        out[ou + i] = acc
        out[oP + i] = lam[i]


@njit(cache=True)
def event_value(y, kind, j, imp, ph):
    """Row ``kind`` of couple j of `ImpactProblem.event_values` (no couple stuck or locked; a
    sliding couple's u_t along its slip direction down to ``imp.settle``, the speed of rest)."""
    s, friction, v_rest = imp.s, imp.friction, imp.settle
    phase, sep, x_end, slip_dir = ph.phase, ph.sep, ph.x_end, ph.slip_dir
    x, un = y[j], y[s + j]
    if kind == NORMAL:
        if phase[j] == COMPRESSION and not sep[j]:
            return -un
        if phase[j] == EXPANSION:
            return x - x_end[j]
        return np.inf
    if kind == APPROACH:
        if phase[j] == EXPANSION or sep[j]:
            return un
        return np.inf
    if friction and x > 0.0:
        o = 2 * s + 2 * j
        return y[o] * slip_dir[j, 0] + y[o + 1] * slip_dir[j, 1] - v_rest
    return np.inf


@njit(cache=True)
def event_values(y, g, imp, ph):
    """Every row of every couple (`event_value`) into g (3, s)."""
    for kind in range(3):
        for j in range(imp.s):
            g[kind, j] = event_value(y, kind, j, imp, ph)


@njit(cache=True)
def classify(y, imp, ph):
    """`ImpactProblem.classify`: True where a couple was marked separating."""
    s, phase, sep = imp.s, ph.phase, ph.sep
    changed = False
    for j in range(s):
        if phase[j] == COMPRESSION and not sep[j] and y[j] <= 0.0 and y[s + j] > 1e-12:
            sep[j] = True
            changed = True
    return changed


@njit(cache=True)
def finished(y, imp, ph):
    """`ImpactProblem.finished` (no couple locked)."""
    s, kappa, eta, phase, settle = imp.s, imp.kappa, imp.eta, ph.phase, imp.settle
    done = True
    for j in range(s):
        if y[j] > 0.0 or phase[j] == EXPANSION or y[s + j] < -1e-12:
            done = False
    if done:
        return True
    for j in range(s):
        if y[s + j] < -settle:
            return False
    stored = 0.0
    for j in range(s):
        stored += stored_energy(kappa[j], eta[j], y[j])
    return stored <= 0.5 * settle * settle


# Events ------------------------------------------------------------------------------------
@njit(cache=True)
def _log(log, impulse, kind, j):
    """``log`` with the event (impulse, kind, j) appended, its arrays doubled when full."""
    ev_imp, ev_kind, ev_couple, n = log
    if n >= len(ev_kind):
        m = 2 * len(ev_kind)
        a, b, c = np.empty(m), np.empty(m, np.int64), np.empty(m, np.int64)
        copy1(a[:n], ev_imp[:n])
        copy1(b[:n], ev_kind[:n])
        copy1(c[:n], ev_couple[:n])
        ev_imp, ev_kind, ev_couple = a, b, c
    ev_imp[n], ev_kind[n], ev_couple[n] = impulse, kind, j
    return EventLog(ev_imp, ev_kind, ev_couple, n + 1)


@njit(cache=True)
def apply_event(y, kind, j, impulse, imp, ph, log):
    """`ImpactProblem.apply_event` for the events the kernel takes, the phases changed in
    place: (True, the log with the event), or (False, the log) with nothing changed for one
    that needs Python: a stick-slip decision or a lock. A sliding couple's friction event is a
    rest (`friction.on_friction_event`) where |u_t| <= max(2 settle, 1e-9 of the largest
    velocity), else a turn of its direction."""
    s, nu, friction, kappa, eta, e = imp.s, imp.nu, imp.friction, imp.kappa, imp.eta, imp.e
    law, v_rest = imp.law, imp.settle
    phase, sep, rate, x_end, slip_dir = ph.phase, ph.sep, ph.rate, ph.x_end, ph.slip_dir
    wc, e_start, wc_open = ph.wc, ph.e_start, ph.wc_open
    if kind == FRICTION:
        o = 2 * s + 2 * j
        nt = math.sqrt(y[o] ** 2 + y[o + 1] ** 2)
        scale = 0.0
        for i in range(s, s + nu):
            scale = max(scale, abs(y[i]))
        if nt <= max(1e-9 * scale, 2.0 * v_rest):     # `friction.rest_speed`
            return False, log           # came to rest: `select_impact_friction_modes`
        slip_dir[j, 0], slip_dir[j, 1] = y[o] / nt, y[o + 1] / nt
        return True, log
    if kind == APPROACH:
        if phase[j] == EXPANSION:
            phase[j], rate[j] = COMPRESSION, 1.0
            e_start[j] = stored_energy(kappa[j], eta[j], y[j])
            return True, _log(log, impulse, RECOMP, j)
        if friction:
            return False, log           # a re-impact decides stick or slip
        sep[j] = False
        y[j] = 0.0
        return True, _log(log, impulse, REIMPACT, j)
    if phase[j] == COMPRESSION and y[j] > 0.0:
        if e[j] == 0.0:
            return False, log           # a lock
        E = stored_energy(kappa[j], eta[j], y[j])
        work = E - e_start[j]
        wc[j] += work
        wc_open[j] += work
        log = _log(log, impulse, MAXC, j)
        r, xe = 1.0, 0.0
        if law == 0:        # paper, Eq. (54)
            y[j] = indentation(kappa[j], eta[j], E - (1.0 - e[j] * e[j]) * work)
        elif law == 1:      # mono
            xe = indentation(kappa[j], eta[j], (1.0 - e[j] * e[j]) * wc_open[j])
        else:               # bi
            r = 1.0 / (e[j] * e[j])
        phase[j], rate[j], x_end[j] = EXPANSION, r, xe
        return True, log
    if phase[j] == COMPRESSION:
        sep[j] = True
        return True, log
    if phase[j] == LOCKED:
        return False, log
    y[j] = 0.0
    phase[j], rate[j], x_end[j] = COMPRESSION, 1.0, 0.0
    e_start[j] = 0.0
    wc_open[j] = 0.0
    return True, _log(log, impulse, END, j)
