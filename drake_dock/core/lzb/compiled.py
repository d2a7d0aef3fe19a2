"""The driver of the compiled LZB impact (`drake_dock.core.kernels.lzb`): `solve_lzb` with
``compiled=True`` integrates by it instead of `drake_dock.core.lzb.driver.integrate`.

The kernel integrates the states where no couple sticks or is locked, events included, in one
call. An event it hands back (a stick-slip decision, a lock) is applied here by the
reference's `handle_events` on the kernel's dense output, and the states with sticking or
locked couples are integrated by the reference's `segment` (`drake_dock.core.lzb.driver`) (scipy's DOP853) up to their next
event; then the kernel takes over again. The kernel's statuses become the reference's typed
errors."""
from __future__ import annotations

import numpy as np

from drake_dock.core.kernels import lzb as kernel
from drake_dock.core.kernels.lzb_phases import KINDS, LAW_NAMES, ImpactConstants, Phases
from drake_dock.core.lzb.driver import active_events, budget_error, handle_events, segment
from drake_dock.core.lzb.state import COMPRESSION, EXPANSION, LOCKED, ImpactEvent
from drake_dock.errors import NumericalError


class DenseOutput:
    """The kernel's continuous extension of one step from t_old to t_new (`kernel.dense_at`),
    called as scipy's: a state (n,) at a scalar, states (n, k) at k times."""

    def __init__(self, rc, t_old, t_new):
        self.rc, self.t_old, self.h = rc, t_old, t_new - t_old

    def __call__(self, T):
        th = (np.asarray(T, dtype=float) - self.t_old) / self.h
        rc = self.rc if th.ndim == 0 else self.rc[:, :, None]
        th1 = 1.0 - th
        return rc[0] + th * (rc[1] + th1 * (rc[2] + th * (rc[3] + th1 * rc[4])))


def _sync(prob):
    """The phase flags of `ImpactProblem` from its phases, after the kernel changed them."""
    prob.comp[:] = prob.phase == COMPRESSION
    prob.comp_f[:] = np.where(prob.phase == EXPANSION, 0.0, 1.0)
    prob.locked[:] = prob.phase == LOCKED


def integrate_compiled(prob, y, events, *, rtol, max_steps, impulse_scale):
    """`drake_dock.core.lzb.driver.integrate` by the compiled kernel: the same events and
    outputs, (y, steps, the normal impulses after each accepted step)."""
    m_s, v_s = impulse_scale
    s = prob.s
    imp = ImpactConstants(s, prob.layout.nu, np.ascontiguousarray(prob.G), prob.kappa,
                          prob.eta, prob.e, prob.mu, bool(prob.friction),
                          LAW_NAMES.index(prob.law), prob.settle, rtol, rtol * 1e-2, max_steps,
                          m_s * v_s)
    ph = Phases(prob.phase, prob.sep, prob.rate, prob.x_end, prob.slip_dir, prob.wc,
                prob.e_start, prob.wc_open)       # the kernel changes these in place
    steps, history = 0, []
    t, h = 0.0, None
    while not prob.finished(y):
        if prob.stuck.any() or prob.locked.any():
            t, y, h, steps = segment(prob, t, y, h, steps, history, events, rtol=rtol,
                                     max_steps=max_steps, impulse_scale=impulse_scale)
            continue
        (status, t, y, h, steps, log, hist, nh, t_old, t_new, rc, g_old, g_new) = \
            kernel.lzb_impact(y, t, 0.0 if h is None else h, steps, imp, ph)
        _sync(prob)
        events.extend(ImpactEvent(float(log.impulse[i]), KINDS[log.kind[i]],
                                  int(log.couple[i])) for i in range(log.n))
        history.extend(hist[:nh])
        if status == kernel.BUDGET:
            raise budget_error(max_steps, events)
        if status == kernel.STEP_FAILED:
            raise NumericalError(f"LZB integration failed: step size {h:.3g} below the "
                                 f"smallest at tau = {t:.6g}")
        if status == kernel.NONFINITE:
            raise NumericalError(f"LZB integration failed: non-finite state at tau = {t:.6g}")
        if status == kernel.PYEVENT:
            dense = DenseOutput(rc, t_old, t_new)
            brackets = active_events(prob, dense, t_old, t_new, g_old, g_new)
            t, y = handle_events(prob, dense, brackets, events, impulse_scale)
            history.append(y[prob.layout.P][:s] * m_s * v_s)
    return y, steps, history

