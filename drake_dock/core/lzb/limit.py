"""The continuous-time limit of the LZB restitution laws on a chain of balls: an independent
reference for `drake_dock.core.lzb.solve.solve_lzb`, integrated in physical time by scipy's DOP853.

Balls 0..n-1 move on a line, ball j behind ball j + 1; contact j between them has the approach
speed a_j = v_j - v_(j+1) and an equivalent deformation s_j >= 0 carrying the force
K_j s_j^eta (Eq. 28). The configuration is frozen as in LZB: there is no gap, and a contact
whose deformation is zero is re-activated as soon as its balls approach again. The laws:

- ``"bi"``: ds/dt = a in compression and a / e^2 in expansion (after a maximum of s); a contact
  in expansion whose balls approach again compresses again from where it is.
- ``"mono"``: ds/dt = a in both phases; the contact ends (s dropped to zero) once the work it
  returned reaches e^2 times the work it received since it began (Eq. 36).
- ``"paper"``: ds/dt = a in both phases; at each maximum the stored energy drops by
  (1 - e^2) times the work received in that compression (Eq. 54); the contact ends at s = 0.

Written for the tests, the bench and the stability study, in a form independent of the
solver's (physical time, ball velocities, scipy's event location).
"""
from __future__ import annotations

import numpy as np
from scipy.integrate import solve_ivp

_COMP, _EXP = 0, 1


def continuous_limit_chain(masses, v0, K, eta, e, law="bi", *, rtol=1e-12, settle=1e-10,
                           max_step=np.inf, max_events=100_000):
    """Final velocities of the chain ``masses`` with initial velocities ``v0`` (touching, at
    zero deformation), contact stiffness ``K`` and restitution ``e`` (scalars or one per
    contact), exponent ``eta``, under ``law`` in its continuous limit. e = 0 has no continuous
    limit here (use the closed form: the balls move together). The chain has settled when
    no approach speed, nor the speed its stored energy could give, exceeds ``settle`` times the
    initial speed."""
    m = np.asarray(masses, float)
    n = len(m)
    K = np.broadcast_to(np.asarray(K, float), (n - 1,)).copy()
    e = np.broadcast_to(np.asarray(e, float), (n - 1,)).copy()
    if np.any(e <= 0):
        raise ValueError("e = 0 has no continuous limit; the closed form is the shared velocity")
    v = np.asarray(v0, float)
    status = np.full(n - 1, _COMP)
    e_start = np.zeros(n - 1)      # stored energy when the current compression began
    wc_open = np.zeros(n - 1)      # mono: compression work since the contact began
    s_end = np.zeros(n - 1)        # expansion ends at s = s_end
    rate = np.ones(n - 1)
    sep = np.zeros(n - 1, dtype=bool)   # unloaded and separating: waits for its approach
    ext_dir = np.zeros(n - 1)           # direction of the next extremum of a
    last = None                         # the last event (kind, contact)

    def energy(s, j):
        return K[j] * s ** (eta + 1) / (eta + 1)

    def deformation(E, j):
        return ((eta + 1) * max(E, 0.0) / K[j]) ** (1 / (eta + 1))

    def rhs(t, y):
        vel, s = y[:n], y[n:]
        f = K * np.maximum(s, 0.0) ** eta
        acc = np.zeros(n)
        acc[:-1] -= f
        acc[1:] += f
        a = vel[:-1] - vel[1:]
        ds = np.where((status == _COMP) & (s <= 0), np.maximum(a, 0.0), rate * a)
        return np.concatenate([acc / m, ds])

    def make_events(y, last):
        a = y[:n - 1] - y[1:n]
        s = y[n:]
        events = []
        for j in range(n - 1):
            def approach(t, y, j=j):
                return y[j] - y[j + 1]
            def distance_to_end(t, y, j=j):
                return y[n + j] - s_end[j]
            if status[j] == _EXP:
                evs = [(approach, +1, "recompress"), (distance_to_end, -1, "end")]
            elif s[j] <= 1e-12 * scale_s and (a[j] < -1e-12 * scale_v or sep[j]):
                evs = [(approach, +1, "approach")]
            else:
                evs = [(approach, -1, "max")]
            def rate_of_approach(t, y, j=j):
                d = rhs(t, y)
                return d[j] - d[j + 1]
            # Extrema of a split the steps: a cannot cross zero twice inside one step unseen.
            # The next extremum is the opposite of the last one, or set by da/dt's sign now.
            if last == ("extremum", j):
                ext_dir[j] = -ext_dir[j]
            else:
                ext_dir[j] = -np.sign(rate_of_approach(0.0, y))
            if ext_dir[j] != 0:
                evs.append((rate_of_approach, ext_dir[j], "extremum"))
            for f, direction, kind in evs:
                f.terminal, f.direction = True, direction
                events.append((f, j, kind))
        return events

    def apply(kind, j, y):
        s = y[n:]
        if kind == "approach":
            sep[j] = False
        elif kind == "max":
            if s[j] <= 1e-12 * scale_s:     # separating unloaded (round-off indentation)
                s[j] = 0.0
                sep[j] = True
                return
            E = energy(s[j], j)
            work = E - e_start[j]
            status[j] = _EXP
            if law == "bi":
                rate[j] = 1.0 / e[j] ** 2
            elif law == "paper":
                s[j] = deformation(E - (1 - e[j] ** 2) * work, j)
            else:
                wc_open[j] += work
                s_end[j] = deformation((1 - e[j] ** 2) * wc_open[j], j)
        elif kind == "recompress":
            status[j], rate[j] = _COMP, 1.0
            e_start[j] = energy(s[j], j)
        elif kind == "end":
            s[j] = 0.0
            status[j], rate[j] = _COMP, 1.0
            e_start[j] = wc_open[j] = s_end[j] = 0.0

    def turn_at_once(y):
        # A loaded contact at a = 0 (within round-off) takes the phase its motion starts:
        # a maximum if a falls, a new compression if a rises (after the paper law's drop of
        # force, or at a tangency of a with zero).
        for _ in range(2 * n):
            a = y[:n - 1] - y[1:n]
            d = rhs(0.0, y)
            dadt = d[:n - 1] - d[1:n]
            near = np.abs(a) <= 1e-12 * scale_v
            turn = near & (((status == _COMP) & (y[n:] > 1e-12 * scale_s) & (dadt < 0))
                           | ((status == _EXP) & (dadt > 0)))
            if not turn.any():
                return
            j = int(np.flatnonzero(turn)[0])
            apply("max" if status[j] == _COMP else "recompress", j, y)

    def done(y):
        a = y[:n - 1] - y[1:n]
        if np.all(y[n:] <= 0) and np.all(a <= 0) and np.all(status == _COMP):
            return True
        # Settled: no balls approach, nor could the stored energy move them, by more than
        # `settle` (the limit of an endless sequence of ever smaller re-compressions, as at
        # small e).
        stored = K * np.maximum(y[n:], 0.0) ** (eta + 1) / (eta + 1)
        return bool(a.max() <= settle * scale_v
                    and stored.sum() <= 0.5 * m.min() * (settle * scale_v) ** 2)

    scale_v = np.abs(v).max()
    scale_s = (m.min() * scale_v ** 2 / K.max()) ** (1 / (eta + 1))
    chunk = 20 * scale_s / scale_v
    atol = np.concatenate([np.full(n, 1e-16 * scale_v), np.full(n - 1, 1e-16 * scale_s)])
    y = np.concatenate([v, np.zeros(n - 1)])
    t = 0.0
    for _ in range(max_events):
        if done(y):
            return y[:n]
        events = make_events(y, last)
        last = None
        sol = solve_ivp(rhs, (t, t + chunk), y, method="DOP853", rtol=rtol, atol=atol,
                        max_step=max_step * chunk, events=[f for f, _, _ in events])
        if sol.status == -1:
            raise RuntimeError(f"reference integration failed: {sol.message}")
        if sol.status == 1 and sol.t[-1] <= t:
            # An event function exactly zero at the start (a contact at rest at its
            # threshold) stops without progress: step past it without events.
            sol = solve_ivp(rhs, (t, t + 1e-6 * chunk), y, method="DOP853", rtol=rtol,
                            atol=atol)
        t, y = sol.t[-1], sol.y[:, -1].copy()
        if sol.status == 1:
            k = next(i for i, te in enumerate(sol.t_events) if len(te))
            _, j, kind = events[k]
            last = (kind, j)
            y = sol.y_events[k][0].copy()
            apply(kind, j, y)
            y[n:] = np.maximum(y[n:], 0.0)
            turn_at_once(y)
    raise RuntimeError(f"reference did not finish within {max_events} events")
