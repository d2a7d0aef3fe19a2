"""The phases of a compiled LZB impact (`drake_dock.core.kernels.lzb`) over the records of
`drake_dock.core.kernels.lzb_records`: the event functions, the end test and every phase event
(maximal compression with the restitution law, end of expansion, separation, re-compression,
re-loading, lock and release at e = 0; the friction events and stick-slip decisions of
`drake_dock.core.kernels.lzb_friction`). The rules are stated in `drake_dock.core.lzb.solve`'s
docstring. A couple is *held* when it is locked or stuck (`drake_dock.core.kernels.lzb_forces`);
its event functions then need the force rates.
"""
from __future__ import annotations

import math

import numpy as np
from numba import njit

from drake_dock.core.kernels.lzb_forces import forces, probe_loads
from drake_dock.core.kernels.lzb_friction import on_friction_event, select_friction_modes
from drake_dock.core.kernels.lzb_records import (APPROACH, COMPRESSION, END, EXPANSION,
                                                 FRICTION, LOCK, LOCKED, MAXC, NORMAL, RECOMP,
                                                 REIMPACT, RELEASE, any_held, any_locked,
                                                 log_event, set_phase, stored_energy,
                                                 unloading)


# Event functions ---------------------------------------------------------------------------
@njit(cache=True)
def normal_value(y, kind, j, imp, ph):
    """Row NORMAL or APPROACH of couple j (`event_value`) but a locked couple's release (inf):
    they need no forces, so a step's dense output is sampled with them."""
    s, phase, sep, x_end = imp.s, ph.phase, ph.sep, ph.x_end
    x, un = y[j], y[s + j]
    if kind == NORMAL:
        if phase[j] == COMPRESSION and not sep[j]:
            return -un
        if phase[j] == EXPANSION:
            return x - x_end[j]
        return np.inf
    if phase[j] == EXPANSION or sep[j]:
        return un
    return np.inf


@njit(cache=True)
def event_value(y, kind, j, imp, ph, lam):
    """Couple j's function of row ``kind`` whose crossing from > 0 to <= 0 is a phase event:
    NORMAL, maximal compression (-u_n), the end of expansion (x - x_end) or a locked couple's
    release (its lambda_n); FRICTION, a loaded sliding couple's u_t along its slip direction
    down to ``settle``, the speed of rest (it came to rest, or turned), or a stuck loaded
    couple's force at its static cone (mu_s lambda_n - |lambda_t|); APPROACH, re-compression
    in expansion or the re-loading of a separated couple (u_n). ``lam`` (nu): work space."""
    if kind == APPROACH or (kind == NORMAL and ph.phase[j] != LOCKED):
        return normal_value(y, kind, j, imp, ph)
    if kind == FRICTION and not imp.friction:
        return np.inf
    held = any_held(ph)
    if held:
        forces(y, imp, ph, lam)
    return _force_value(y, kind, j, imp, ph, lam, held)


@njit(cache=True, inline='always')
def _force_value(y, kind, j, imp, ph, lam, held):
    """`event_value` of a FRICTION row, or a locked couple's NORMAL row, ``lam`` holding the
    force rates at y where couples are ``held``."""
    s, settle, mu_s, stuck, slip_dir = imp.s, imp.settle, imp.mu_s, ph.stuck, ph.slip_dir
    o = 2 * s + 2 * j
    if not held:
        if y[j] > 0.0:      # a loaded couple slides
            return y[o] * slip_dir[j, 0] + y[o + 1] * slip_dir[j, 1] - settle
        return np.inf
    if kind == NORMAL:
        return lam[j]
    if lam[j] <= 0.0:
        return np.inf
    if not stuck[j]:
        return y[o] * slip_dir[j, 0] + y[o + 1] * slip_dir[j, 1] - settle
    return mu_s[j] * lam[j] - math.sqrt(lam[s + 2 * j] ** 2 + lam[s + 2 * j + 1] ** 2)


@njit(cache=True)
def event_values(y, g, imp, ph, lam):
    """Every row of every couple (`event_value`) into g (3, s), the forces solved once."""
    s, friction, phase = imp.s, imp.friction, ph.phase
    held = any_held(ph)
    if held:
        forces(y, imp, ph, lam)
    for j in range(s):
        g[NORMAL, j] = normal_value(y, NORMAL, j, imp, ph) if phase[j] != LOCKED else \
            _force_value(y, NORMAL, j, imp, ph, lam, held)
        g[APPROACH, j] = normal_value(y, APPROACH, j, imp, ph)
        g[FRICTION, j] = _force_value(y, FRICTION, j, imp, ph, lam, held) if friction \
            else np.inf


@njit(cache=True)
def classify(y, imp, ph):
    """Marks the unloaded couples in compression that separate (x = 0, u_n > 0 beyond
    round-off), whose next event is their approach; True where one was marked."""
    s, phase, sep = imp.s, ph.phase, ph.sep
    changed = False
    for j in range(s):
        if phase[j] == COMPRESSION and not sep[j] and y[j] <= 0.0 and y[s + j] > 1e-12:
            sep[j] = True
            changed = True
    return changed


@njit(cache=True)
def finished(y, imp, ph):
    """Every couple unloaded and none approaching (a locked couple aside), or the bodies
    settled: no couple approaches, nor could the stored energy move one, by more than
    ``settle`` times the impact's velocity scale (u is scaled by the largest approach speed: a
    residual approach of 1e-12 of it, the round-off left when symmetric couples end together,
    does not start a new impact)."""
    s, kappa, eta, phase, settle = imp.s, imp.kappa, imp.eta, ph.phase, imp.settle
    done = True
    for j in range(s):
        if y[j] > 0.0 or phase[j] == EXPANSION or (y[s + j] < -1e-12 and phase[j] != LOCKED):
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



@njit(cache=True, inline='always')
def _lock(y, j, impulse, imp, ph, log, lam):
    """e = 0: the stored energy is lost and the couple is held at u_n = 0 by a constraint
    force rate lambda_n >= 0 (the limit e -> 0 of every law, which otherwise re-impacts
    without end); a couple whose constraint force would pull, or that nothing presses, is
    released instead (`_released`)."""
    y[j] = 0.0
    ph.e_start[j] = ph.wc_open[j] = 0.0
    set_phase(ph, j, LOCKED, 0.0)
    log = _released(y, impulse, imp, ph, log, lam, j)
    return log_event(log, impulse, LOCK if ph.phase[j] == LOCKED else END, j)


@njit(cache=True, inline='always')
def release_pulled(y, impulse, imp, ph, log, lam):
    """After the events of an instant: a locked couple whose constraint force rate would pull,
    or is zero (nothing presses it), is released and separates (`_released`); an event
    elsewhere can change a locked couple's force rate at once, past the zero its release
    event would find. Returns the log."""
    return _released(y, impulse, imp, ph, log, lam, -1)


@njit(cache=True, inline='always')
def _released(y, impulse, imp, ph, log, lam, locking):
    """The locked couples whose constraint force rate is not positive released, the one
    pulled most first and the others tested again; each separates and is logged, but the
    couple ``locking`` (-1 for none), whose lock is being decided. Returns the log."""
    phase, sep = ph.phase, ph.sep
    while any_locked(ph):
        lam_n = probe_loads(y, imp, ph, lam)
        k = -1
        for i in range(imp.s):
            if phase[i] == LOCKED and (k < 0 or lam_n[i] < lam_n[k]):
                k = i
        if lam_n[k] > 0.0:
            break
        set_phase(ph, k, COMPRESSION, 1.0)
        if k != locking:
            sep[k] = True
            log = log_event(log, impulse, RELEASE, k)
    return log


@njit(cache=True)
def apply_event(y, kind, j, impulse, imp, ph, log, lam):
    """Couple j's event function of row ``kind`` crossed zero at the state y: the phases
    changed in place; returns the log with the events."""
    s, friction, kappa, eta, e, law = imp.s, imp.friction, imp.kappa, imp.eta, imp.e, imp.law
    phase, sep, x_end = ph.phase, ph.sep, ph.x_end
    wc, e_start, wc_open = ph.wc, ph.e_start, ph.wc_open
    if kind == FRICTION:
        return on_friction_event(y, j, impulse, imp, ph, log, lam)
    if kind == APPROACH:
        if phase[j] == EXPANSION:
            # Approaching again during expansion: compression resumes on the loading curve
            # from the energy stored now.
            set_phase(ph, j, COMPRESSION, 1.0)
            e_start[j] = stored_energy(kappa[j], eta[j], y[j])
            return log_event(log, impulse, RECOMP, j)
        # A separated couple approaches again: it re-loads from zero indentation.
        sep[j] = False
        y[j] = 0.0
        log = log_event(log, impulse, REIMPACT, j)
        if friction:
            js = np.zeros(s, np.bool_)
            js[j] = True
            log = select_friction_modes(y, js, impulse, imp, ph, log, lam,
                                        np.zeros(s, np.bool_))
        return log
    if phase[j] == COMPRESSION and y[j] > 0.0:
        # Maximal compression: the work of this compression, W = E - E_start, enters W_c
        # (Eq. 36) and the law sets the expansion.
        E = stored_energy(kappa[j], eta[j], y[j])
        work = E - e_start[j]
        wc[j] += work
        wc_open[j] += work
        log = log_event(log, impulse, MAXC, j)
        if e[j] == 0.0:
            return _lock(y, j, impulse, imp, ph, log, lam)
        x_start, x_end[j], r = unloading(law, kappa[j], eta[j], e[j], E, work, wc_open[j])
        if not math.isnan(x_start):
            y[j] = x_start
        set_phase(ph, j, EXPANSION, r)
        return log
    if phase[j] == COMPRESSION:
        # u_n turned positive at zero indentation: the couple separates unloaded.
        sep[j] = True
        return log
    if phase[j] == LOCKED:
        # A locked couple's force rate reached zero: it is released and separates.
        set_phase(ph, j, COMPRESSION, 1.0)
        sep[j] = True
        return log_event(log, impulse, RELEASE, j)
    # The end of expansion (mono drops the remaining (1 - e^2) W_c here).
    y[j] = 0.0
    set_phase(ph, j, COMPRESSION, 1.0)
    x_end[j] = 0.0
    e_start[j] = wc_open[j] = 0.0
    ph.stuck[j] = False
    return log_event(log, impulse, END, j)
