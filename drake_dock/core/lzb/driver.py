"""The reference driver of an LZB impact (`drake_dock.core.lzb.solve`, "Numerics"): scipy's
DOP853 from event to event, the events located on its dense output in the shape of scipy's
solve_ivp (find the active events of a step, solve each event equation on the dense output,
handle the first and those simultaneous with it). `drake_dock.core.lzb.compiled` shares the
event handling and the segments with sticking or locked couples."""
from __future__ import annotations

import numpy as np
from scipy.integrate import DOP853
from scipy.optimize import brentq

from drake_dock.core.lzb.problem import APPROACH, FRICTION, NORMAL
from drake_dock.errors import NumericalError

_INSIDE = np.arange(1, 32) / 32.0   # where a step's dense output is sampled for events
_CLEAR = 1e-14                      # scaled event values below this are round-off


def active_events(prob, dense, t0, t1, g0, g1):
    """The events of a step from t0 to t1 as (row, couple, ta, tb) with a sign change of the
    event function inside [ta, tb]. The normal rows are sampled inside the step as well, so
    that u_n crossing zero twice in one step (a brief separation or approach between two
    phases) is not missed, nor a crossing that follows a start at the threshold."""
    out = []
    for kind, j in zip(*np.nonzero((g0 > 0) & (g1 <= 0))):
        if kind == FRICTION or prob.locked[j]:     # friction, a locked couple's release
            out.append((kind, j, t0, t1))
    T = np.concatenate([[t0], t0 + _INSIDE * (t1 - t0), [t1]])
    inside = prob.normal_event_values(dense(T[1:-1]))
    for kind, G in ((NORMAL, inside[0]), (APPROACH, inside[1])):
        G = np.column_stack([g0[kind], G, g1[kind]])       # (s, samples)
        # Inside the step a crossing counts from a value clear of round-off.
        down = ((G[:, :-1] > _CLEAR) | ((G[:, :-1] > 0) & (np.arange(len(T) - 1) == 0))) \
            & (G[:, 1:] <= 0)
        for j in np.flatnonzero(down.any(axis=1) & ~prob.locked):
            i = int(np.argmax(down[j]))
            out.append((kind, j, T[i], T[i + 1]))
    return out


def event_time(prob, dense, kind, j, ta, tb):
    """The zero of couple j's event function of row ``kind`` in [ta, tb] on the step's dense
    output (ta itself when the function starts on the boundary)."""
    def f(tt):
        return prob.event_values(dense(tt))[kind, j]
    if f(ta) <= 0:
        return ta
    return brentq(f, ta, tb, xtol=1e-15 * max(1.0, abs(tb)), rtol=4 * np.finfo(float).eps)


def handle_events(prob, dense, brackets, events, impulse_scale):
    """Applies the first event of the step, and every other one at the same instant
    (symmetric couples: after the restart their functions would start at <= 0 and their
    crossings would never be seen again); then the couples at u_n = 0 take the phase their
    motion starts. Returns (t, y) there, the restart point. ``impulse_scale`` (m_s, v_s)."""
    roots = [(event_time(prob, dense, kind, j, ta, tb), kind, j) for kind, j, ta, tb in brackets]
    t_first, kind0, j0 = min(roots, key=lambda r: r[0])
    # Move to the zero's far side (within round-off) so the crossing is consumed.
    y = dense(t_first)
    m_s, v_s = impulse_scale
    impulse = y[prob.layout.P][:prob.s].sum() * m_s * v_s
    prob.apply_event(y, kind0, j0, events, impulse)
    same = 1e-12 * max(1.0, abs(t_first))
    for tr, kind, j in sorted(roots):
        if (kind, j) != (kind0, j0) and tr <= t_first + same \
                and prob.event_values(y)[kind, j] <= 0:
            prob.apply_event(y, kind, j, events, impulse)
    prob.turn_at_once(y, events, impulse)
    return t_first, y


def budget_error(max_steps, events):
    """The NumericalError of an impact that did not end within ``max_steps`` steps."""
    return NumericalError(f"LZB impact did not end within {max_steps} steps "
                          f"(events so far: {len(events)})",
                          couples=sorted({ev.couple for ev in events[-10:]}))


def _step(solver, steps, max_steps, events):
    """One accepted DOP853 step; the number of steps so far."""
    msg = solver.step()
    if solver.status == "failed":
        raise NumericalError(f"LZB integration failed: {msg}")
    steps += 1
    if steps > max_steps:
        raise budget_error(max_steps, events)
    return steps


def segment(prob, t, y, h, steps, history, events, *, rtol, max_steps, impulse_scale):
    """One DOP853 integration from (t, y), first step h (None: chosen by scipy), until the
    first event (applied; the restart point) or the end of the impact. Appends the normal
    impulses after each accepted step to ``history``; returns (t, y, h, steps)."""
    m_s, v_s = impulse_scale
    P = prob.layout.P
    solver = DOP853(prob.rhs, t, y, np.inf, rtol=rtol, atol=rtol * 1e-2, first_step=h)
    prob.classify(y)
    g_old = prob.event_values(y)
    while True:
        steps = _step(solver, steps, max_steps, events)
        g_new = prob.event_values(solver.y)
        h = solver.step_size
        dense = solver.dense_output()
        brackets = active_events(prob, dense, solver.t_old, solver.t, g_old, g_new)
        if brackets:
            t, y = handle_events(prob, dense, brackets, events, impulse_scale)
            history.append(y[P][:prob.s] * m_s * v_s)
            return t, y, h, steps
        y, t = solver.y, solver.t
        # A couple that separated unloaded waits for its approach (same rhs).
        g_old = prob.event_values(y) if prob.classify(y) else g_new
        history.append(y[P][:prob.s] * m_s * v_s)
        if prob.finished(y):
            return t, y, h, steps


def integrate(prob, y, events, *, rtol, max_steps, impulse_scale):
    """The driver: scipy's DOP853 from event to event until the impact ends
    (`ImpactProblem.finished`); restarted at each event. Returns (y, steps, the normal
    impulses after each accepted step)."""
    steps, history = 0, []
    t, h = 0.0, None
    while not prob.finished(y):
        t, y, h, steps = segment(prob, t, y, h, steps, history, events, rtol=rtol,
                                 max_steps=max_steps, impulse_scale=impulse_scale)
    return y, steps, history
