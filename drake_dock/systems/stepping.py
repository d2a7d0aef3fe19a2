"""Step control that lets Drake's witness isolation finish in one or two bisections.

Drake's `Simulator` isolates a witness zero inside a step [t0, tf] by re-integrating from t0 to
the midpoint c; when c does not trigger it ends the step at c with no event (simulator.cc,
IsolateWitnessTriggers). A zero is therefore only isolated by a step that *starts* within the
isolation window w of it; reaching that takes many steps, each bisecting down from its full
length (`bench/paper_example.py` prints the cost with and without this monitor).

`WitnessApproach` is a simulator monitor that shortens the next step instead: after each step it
predicts every witness's zero by the secant through its last two values and the parabola
through its last three (same epoch, see below; the earlier of the two) and caps the
integrator's step so that the step ends w/2 before the earliest predicted
zero; once within w, the step is capped at 1.9 w, so that it crosses the zero and a single
bisection (to 0.95 w, inside the window) isolates it. The secant converges superlinearly, so a zero is reached in a few
steps. Events, their times and the integration's error control are Drake's own; only the
maximum step size changes. Drake calls the monitor before it applies the events found at a
step's end: a source with ``add_event_listener`` tells `WitnessApproach.after_event` the state
an event leaves (``witness_now_after``), and the step after the event is capped from there.

Sources are systems with ``witness_now(context)``, which returns a `WitnessNow` (epoch, layout,
w, d, target): ``w`` the values of the witness functions they return now, all with direction
positive-then-non-positive, as an array; ``layout`` a value, compared with ==, that changes
whenever the set of witnesses changes; ``epoch`` a value that changes whenever an event changes
their state or modes (values from different epochs are not joined by a secant); ``d`` each
witness's time derivative where the source knows it, NaN elsewhere (a couple's gap); and
``target`` the time (s) from now at which a step should end, just past it, rather than isolate
a witness (the source's transition is taken at the next step's start; inf for none). A source
with rates may also give ``witness_second_rate_array(context, mask)`` (second derivatives of
the witnesses in ``mask``); those are also predicted by their Taylor parabola, the second
derivative taken from the last two rates, or asked for at the first point of an epoch (just
after an impact, where no history predicts the landing). The predictions are compiled
(`drake_dock.core.kernels.leads`), over all witnesses at once.
"""
import math

import numpy as np

from drake_dock.core.kernels.leads import earliest_zero, lead_jet as _lead_jet, push


class _History:
    """A source's last three points (times, values, rates) of one epoch and witness layout,
    in arrays the compiled predictions update in place (`leads.push`)."""

    __slots__ = ("key", "T", "W", "D", "n", "need", "zero", "target")

    def __init__(self, key, size):
        self.key = key
        self.T = np.full(3, np.nan)
        self.W = np.zeros((3, size))
        self.D = np.full((3, size), np.nan)
        self.n = 0
        self.need = np.zeros(size, dtype=np.bool_)
        self.zero = self.target = math.inf     # the predicted zero and the target (s)

    def add(self, t, w, d):
        """The point at t (replacing the last one at the same time or later)."""
        self.n = push(self.T, self.W, self.D, self.n, t, w, d)


class WitnessApproach:
    """Simulator monitor. ``window`` is Drake's witness isolation window (0.01 x the context's
    accuracy, in s, for error-controlled integration); ``max_step`` the configured maximum."""

    #: length of the step that crosses a zero, in isolation windows: below 2, so that Drake's
    #: one bisection leaves an interval shorter than the window (at exactly 2 the interval
    #: (a + b) / 2 - a is the window give or take a rounding, and a second bisection, which
    #: misses the zero half the time, ends the step with no event)
    cross = 1.9

    #: consecutive shortened steps after which one step of the configured maximum is allowed
    #: (a witness that hovers just above zero must not stall the run)
    max_shortened = 40

    def __init__(self, simulator, sources, max_step: float, window: float):
        self.sim = simulator
        self.sources = list(sources)
        self.max_step = float(max_step)
        self.window = float(window)
        self._hist = {}
        self._shortened = 0
        self._short = False            # whether the last step capped was shortened
        self._before = 0               # consecutive shortened steps before it
        self._last_event = None
        self.shortened_steps = 0
        for s in self.sources:
            if hasattr(s, "add_event_listener"):
                s.add_event_listener(self.after_event)

    def close(self):
        """Stops listening to the sources' events (a run's end)."""
        for s in self.sources:
            if hasattr(s, "remove_event_listener"):
                s.remove_event_listener(self.after_event)

    def predicted_zero(self, root) -> float:
        """Earliest predicted zero time (inf if none); updates the history."""
        return self.predicted(root)[0]

    def predicted(self, root) -> tuple[float, float]:
        """(earliest predicted zero time of the witnesses, of the step-end targets), inf
        where none is predicted; updates the histories."""
        t = root.get_time()
        hist = {}
        for s in self.sources:
            c = s.GetMyContextFromRoot(root)
            hist[id(s)] = self._point(self._hist.get(id(s)), t, s.witness_now(c),
                                      lambda mask, s=s, c=c: s.witness_second_rate_array(c,
                                                                                         mask))
        self._hist = hist
        return self._earliest()

    def _point(self, h, t, now, second_rates) -> _History:
        """The history h (None for none) with the point ``now`` (`WitnessNow`) at t, a new one
        when its epoch or layout changed, with its predicted zero and target kept on it."""
        epoch, layout, w, d, lead = now
        if h is None or h.key[0] != epoch or (h.key[1] is not layout and h.key[1] != layout):
            h = _History((epoch, layout), len(w))
        h.add(t, w, d)
        need = h.need
        best = earliest_zero(h.T, h.W, h.D, h.n, need)
        if np.count_nonzero(need):
            wdd = second_rates(need)
            for j in np.flatnonzero(need).tolist():
                # Without a second rate, the tangent.
                wdd_j = 0.0 if math.isnan(wdd[j]) else float(wdd[j])
                best = min(best, t + _lead_jet(float(w[j]), float(d[j]), wdd_j))
        h.zero, h.target = best, t + lead
        return h

    def _earliest(self) -> tuple[float, float]:
        return (min((h.zero for h in self._hist.values()), default=math.inf),
                min((h.target for h in self._hist.values()), default=math.inf))

    def after_event(self, source, context, t, x, modes):
        """Event listener (``source.add_event_listener``): Drake calls the monitor before it
        handles the events at a step's end, so the step after an event would be capped from
        the witnesses before it; this caps it again from those at the state the event leaves
        (a new epoch, whose first point predicts with the rates it has)."""
        key = (t, modes.mode_changes, modes.reseeks)
        if key == self._last_event:         # the same event, told once per triggered witness
            return
        self._last_event = key
        now, second_rates = source.witness_now_after(context, t, x, modes)
        self._hist[id(source)] = self._point(None, t, now, second_rates)
        self._set_step(t, *self._earliest(), again=True)

    def __call__(self, root):
        self._set_step(root.get_time(), *self.predicted(root))

    def _set_step(self, t, t_zero, t_target, again=False):
        """Caps the next step (the module docstring) from the earliest predicted zero and
        target; ``again``: the same step's cap set anew (after an event)."""
        if again:       # the monitor's count of this step undone, then counted as capped now
            self._shortened = self._before
            self.shortened_steps -= self._short
        else:
            self._before = self._shortened
        lead = t_zero - t
        step = self.max_step
        if lead < self.max_step + self.window and self._shortened < self.max_shortened:
            cross = self.cross * self.window
            step = lead - 0.5 * self.window if lead > self.window else cross
            step = max(step, cross)
        short = step < self.max_step
        if short:
            self._shortened += 1
            self.shortened_steps += 1
        else:
            self._shortened = 0
        self._short = short
        # A step-end target: the step ends just past it (its transition is taken at the next
        # step's start), never shorter than the crossing step.
        lead = t_target - t
        if lead < step:
            step = max(lead + self.window, self.cross * self.window)
        self.sim.get_mutable_integrator().set_maximum_step_size(min(step, self.max_step))
