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
maximum step size changes, and it returns to its configured value after each event.

Sources are systems with ``witness_values(context) -> {name: value}`` (the values of the
witness functions they return now, all with direction positive-then-non-positive) and
optionally ``witness_epoch(context)``, which changes whenever an event changes their state or
modes (values from different epochs are not joined by a secant), and ``witness_rates(context)
-> {name: dw/dt}`` with ``witness_second_rates(context, names) -> {name: d2w/dt2}`` for
witnesses whose derivatives they know (a couple's gap): those are also predicted by their
Taylor parabola, the second derivative taken from the last two rates, or asked for at the
first point of an epoch (just after an impact, where no history predicts the landing).
"""
import math


def _lead(pts) -> float:
    """Time from the last of ``pts`` [(t, w), ...] (up to three, w > 0 at the last) to the
    predicted zero of w: the earlier of the secant through the last two and of the parabola
    through the last three (a witness falling ever faster, such as the gap of a couple
    accelerating towards contact, is reached earlier than its secant says). inf if neither
    predicts a zero ahead."""
    lead = math.inf
    if len(pts) < 2:
        return lead
    (t1, w1), (t2, w2) = pts[-2], pts[-1]
    s12 = (w2 - w1) / (t2 - t1)
    if s12 < 0.0:
        lead = w2 / -s12
    if len(pts) == 3:
        t0, w0 = pts[0]
        s01 = (w1 - w0) / (t1 - t0)
        c = (s12 - s01) / (t2 - t0)            # w(t2 + h) = w2 + b h + c h^2
        b = s12 + c * (t2 - t1)
        if c != 0.0:
            disc = b * b - 4.0 * c * w2
            if disc >= 0.0:
                r = math.sqrt(disc)
                # roots h = (-b -+ r) / (2c), written without cancellation
                q = -0.5 * (b + math.copysign(r, b))
                roots = [h for h in (q / c, w2 / q if q != 0.0 else math.inf) if h > 0.0]
                if roots:
                    lead = min(lead, min(roots))
    return lead


def _lead_jet(w, wd, wdd) -> float:
    """Time to the first zero of w + wd h + wdd h^2 / 2 (the witness's own derivatives), inf if
    none ahead."""
    a, b, c = 0.5 * wdd, wd, w
    if a == 0.0:
        return -c / b if b < 0.0 else math.inf
    disc = b * b - 4.0 * a * c
    if disc < 0.0:
        return math.inf
    r = math.sqrt(disc)
    q = -0.5 * (b + math.copysign(r, b))
    roots = [h for h in (q / a, c / q if q != 0.0 else math.inf) if h > 0.0]
    return min(roots) if roots else math.inf


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
        self.shortened_steps = 0

    def _values(self, root):
        out, rates = {}, {}
        for s in self.sources:
            c = s.GetMyContextFromRoot(root)
            epoch = s.witness_epoch(c) if hasattr(s, "witness_epoch") else 0
            for k, w in s.witness_values(c).items():
                out[(id(s), k)] = (epoch, float(w))
            if hasattr(s, "witness_rates"):
                for k, wd in s.witness_rates(c).items():
                    rates[(id(s), k)] = float(wd)
        return out, rates

    def _second_rates(self, root, keys):
        out = {}
        for s in self.sources:
            names = [k for sid, k in keys if sid == id(s)]
            if names:
                c = s.GetMyContextFromRoot(root)
                out.update({(id(s), k): v for k, v in s.witness_second_rates(c, names).items()})
        return out

    def predicted_zero(self, root) -> float:
        """Earliest predicted zero time (inf if none); updates the history."""
        t = root.get_time()
        best = math.inf
        values, rates = self._values(root)
        hist = {}
        need = []      # witnesses with a rate but no earlier rate in this epoch
        for key, (epoch, w) in values.items():
            h = self._hist.get(key)
            pts = [p for p in h[1] if p[0] < t] if h is not None and h[0] == epoch else []
            pts = (pts + [(t, w, rates.get(key))])[-3:]
            hist[key] = (epoch, pts)
            if w > 0.0:
                best = min(best, t + _lead([p[:2] for p in pts]))
                if key in rates:
                    if len(pts) > 1 and pts[-2][2] is not None:
                        # The second derivative from the last two rates.
                        (t1, _, r1), (t2, _, r2) = pts[-2], pts[-1]
                        best = min(best, t + _lead_jet(w, r2, (r2 - r1) / (t2 - t1)))
                    else:
                        need.append(key)
        if need:
            for key, wdd in self._second_rates(root, need).items():
                best = min(best, t + _lead_jet(values[key][1], rates[key], wdd))
        self._hist = hist
        return best

    def __call__(self, root):
        t = root.get_time()
        t_zero = self.predicted_zero(root)
        lead = t_zero - t
        step = self.max_step
        if lead < self.max_step + self.window and self._shortened < self.max_shortened:
            cross = self.cross * self.window
            step = lead - 0.5 * self.window if lead > self.window else cross
            step = max(step, cross)
        if step < self.max_step:
            self._shortened += 1
            self.shortened_steps += 1
        else:
            self._shortened = 0
        self.sim.get_mutable_integrator().set_maximum_step_size(min(step, self.max_step))
