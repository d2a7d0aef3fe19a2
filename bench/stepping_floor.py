"""The floor of compiled stepping: what an evaluation would cost if the integrator ran in numba
around the evaluation kernel, beside what one costs in a run today.

Measured in one run, on one sample of the IDSS envelope plan (models/idss_envelope.yaml),
each the median of ``--repeats``:
1. the sample's run (`simulate`, start to end): its wall time over the evaluations it
   computed, all inclusive (Drake's integrator, the witnesses, the events, the step control,
   the recording);
2. the compiled evaluation kernel (`drake_dock.core.kernels.engine.evaluate`) called from
   Python at every recorded state of that run with its own modes and inputs (the mean per
   call), and at the recorded state with the most couples in contact, the costliest;
3. the same kernel inside a Dormand-Prince 5(4) loop compiled here (first same as last, six
   evaluations a step, error per component against ``accuracy * (1 + |x|)``, the step
   capped at the scenario's ``max_step_size``), from that costliest state with its modes and
   inputs held for ``--seconds`` of simulated time: no witnesses, no events, no recording.
   The motion so integrated is not the run's (modes held); only its cost per evaluation is
   read, and evaluations the kernel flags (`S_REPORT`: a failed mode solve, a lost couple)
   are counted and printed, since a flagged one may return early.

It prints the run's wall time by part (seeking, contact dynamics, impacts and the rest:
Drake's integrator, the witnesses, the step control and the recording), then the costs per
evaluation, the ratio of (1) to (3) (the cost per evaluation that compiled stepping would
leave, taken at the costliest state, so the run's average state costs less), and the share
of (1) that the kernel itself takes over the run's states; and the sample's projected wall
time with compiled stepping, twice: the run's seeking and impacts as measured (the contact
system's `timing`), everything else replaced by the run's evaluations at the cost of (3);
and the run's event handling as measured (every event's transitions, `_on_event`, and every
step start's seeks of far pairs, `reseek_far`, with the evaluations they make), the other
evaluations at the cost of (3), which is what compiled stepping with Python at the events
would leave. No target: the floor of a design not built.

    python bench/stepping_floor.py [--sample 6] [--seconds 0.1] [--repeats 3]
"""
import argparse
import math
import statistics
import time

import numpy as np
from numba import njit

from drake_dock.campaign.plan import load_plan
from drake_dock.campaign.points import sample_specs
from drake_dock.campaign.sample import sample_scenario
from drake_dock.core.kernels.engine import evaluate
from drake_dock.core.kernels.model import S_REPORT
from drake_dock.core.kernels.prepare import warm
from drake_dock.docking.model.diagram import DiagramSpec, build_docking_diagram
from drake_dock.docking.model.simulate import simulate
from drake_dock.docking.placement.place import PlacementCache, place
from drake_dock.docking.scenario.models_dir import MODELS_DIR
from drake_dock.systems.evaluation import SCALARS, XDOT

PLAN = MODELS_DIR / "idss_envelope.yaml"

# Dormand and Prince's 5(4) pair: the stages' coefficients, the fifth-order weights and the
# error weights (fifth minus fourth order).
A = ((1 / 5,), (3 / 40, 9 / 40), (44 / 45, -56 / 15, 32 / 9),
     (19372 / 6561, -25360 / 2187, 64448 / 6561, -212 / 729),
     (9017 / 3168, -355 / 33, 46732 / 5247, 49 / 176, -5103 / 18656))
B = (35 / 384, 0.0, 500 / 1113, 125 / 192, -2187 / 6784, 11 / 84)
E = (71 / 57600, 0.0, -71 / 16695, 71 / 1920, -17253 / 339200, 22 / 525, -1 / 40)
COEFFS = np.zeros((8, 7))
for i, row in enumerate(A):
    COEFFS[i, :len(row)] = row
COEFFS[5, :6], COEFFS[6, :7] = B, E


@njit(cache=False)
def _stage(mp, sp, x, tau, buf, xd, k):
    evaluate(mp, sp, x, tau, buf)
    k[:] = buf[xd:xd + k.shape[0]]
    return buf


@njit(cache=False)
def dormand_prince(mp, sp, x0, tau, size, xd, sc, t_end, h_max, accuracy, coeffs):
    """(evaluations, accepted steps, rejected steps, steps at the cap, time reached,
    evaluations the kernel flagged (`S_REPORT`)): the loop of the module docstring."""
    n = x0.shape[0]
    buf = np.empty(size)
    K = np.empty((7, n))
    x, xs = x0.copy(), np.empty(n)
    _stage(mp, sp, x, tau, buf, xd, K[0])
    evals, accepted, rejected, capped, flagged = 1, 0, 0, 0, 0
    t, h = 0.0, min(h_max, 1e-4)
    while t < t_end:
        hh = min(h, t_end - t)
        for s in range(1, 7):              # stages 2-6 and the fifth-order end (stage 7)
            row = coeffs[s - 1] if s < 6 else coeffs[5]
            for i in range(n):
                acc = 0.0
                for j in range(s):
                    acc += row[j] * K[j, i]
                xs[i] = x[i] + hh * acc
            _stage(mp, sp, xs, tau, buf, xd, K[s])
            flagged += buf[sc + S_REPORT] != 0.0
        evals += 6
        err = 0.0
        for i in range(n):
            e = 0.0
            for j in range(7):
                e += coeffs[6, j] * K[j, i]
            err = max(err, abs(hh * e) / (accuracy * (1.0 + abs(x[i]))))
        if not math.isfinite(err):
            break
        if err <= 1.0:
            t += hh
            accepted += 1
            capped += hh >= h_max * (1.0 - 1e-12)
            x[:] = xs
            K[0] = K[6]
        else:
            rejected += 1
        grow = 5.0 if err == 0.0 else min(5.0, max(0.2, 0.9 * err ** -0.2))
        h = min(h_max, hh * (min(grow, 1.0) if err > 1.0 else grow))
    return evals, accepted, rejected, capped, t, flagged


class EventTime:
    """The wall time and the evaluations computed inside the contact system's event handlers
    (`RigidContactSystem._on_event` and `reseek_far`) while ``with``: both are wrapped for
    the block (before the Diagram is built: the system registers its handlers then)."""

    def __enter__(self):
        from drake_dock.systems import contact_system as cs
        self.seconds, self.evaluations, self._cs = 0.0, 0, cs
        self._saved = cs.RigidContactSystem._on_event, cs.reseek_far

        def timed(f, engine_of):
            def run(*args, **kw):
                engine = engine_of(args)
                t0, n0 = time.perf_counter(), engine.evaluations
                try:
                    return f(*args, **kw)
                finally:
                    self.seconds += time.perf_counter() - t0
                    self.evaluations += engine.evaluations - n0
            return run
        cs.RigidContactSystem._on_event = timed(self._saved[0], lambda a: a[0].engine)
        cs.reseek_far = timed(self._saved[1], lambda a: a[0].eng)
        return self

    def __exit__(self, *exc):
        self._cs.RigidContactSystem._on_event, self._cs.reseek_far = self._saved

    def reset(self):
        self.seconds, self.evaluations = 0.0, 0


def _kernel_loop(mp, sp, x, tau, buf, n):
    for _ in range(n):
        evaluate(mp, sp, x, tau, buf)


def median_of(fn, repeats):
    """The median wall time of ``repeats`` calls of fn."""
    times = []
    for _ in range(repeats):
        t0 = time.perf_counter()
        fn()
        times.append(time.perf_counter() - t0)
    return statistics.median(times)


def _over_states(mp, prepared):
    for x, sp, tau, buf in prepared:
        evaluate(mp, sp, x, tau, buf)


def main():
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--sample", type=int, default=6, help="sample of the IDSS plan (default 6)")
    ap.add_argument("--seconds", type=float, default=0.1,
                    help="simulated seconds of the compiled loop (default 0.1)")
    ap.add_argument("--repeats", type=int, default=3, help="runs of the sample (default 3)")
    args = ap.parse_args()
    warm()
    plan, base, fields = load_plan(PLAN)
    (spec,) = sample_specs(plan, fields, [args.sample])
    scenario = sample_scenario(base, spec[2])
    runs, in_events = [], []
    with EventTime() as events:
        dd = build_docking_diagram(DiagramSpec.of(scenario))
        state = place(scenario, PlacementCache(dd.scene))
        for _ in range(args.repeats):
            events.reset()
            runs.append(simulate(scenario, state, dd=dd))
            in_events.append((events.seconds, events.evaluations))
    run = runs[0]
    per_run = statistics.median(r.wall_time / r.evaluations for r in runs)
    wall = statistics.median(r.wall_time for r in runs)
    print(f"sample {args.sample}: {run.outcome} at {run.end_time:.3f} s simulated, "
          f"{run.evaluations} evaluations computed, wall {wall:.3f} s (median of "
          f"{args.repeats})")
    shares = ", ".join(f"{k.replace('_', ' ')} {v:.0%}" for k, v in run.timing["shares"].items())
    print(f"the run's wall time by part (`RigidContactSystem.timing`): {shares}")

    rec, contact = run.record, dd.contact
    in_contact = [sum(m.pairs[i].mode.in_contact for i in m.index().near) for m in rec.modes]
    k = int(np.argmax(in_contact))
    x0, modes, tau = np.array(rec.states[k]), rec.modes[k], np.array(rec.tau[k])
    mp = contact.engine.packed
    sp, layout = contact.engine.prepared(modes)
    buf = np.empty(layout[-1])
    xd, sc = int(layout[XDOT]), int(layout[SCALARS])
    print(f"state: t = {rec.t[k]:.4f} s, {len(x0)} states, {len(modes.index().near)} pairs "
          f"not far, {in_contact[k]} in contact")

    n_calls, reps = 5000, args.repeats
    _kernel_loop(mp, sp, x0, tau, buf, 10)
    per_call = median_of(lambda: _kernel_loop(mp, sp, x0, tau, buf, n_calls), reps) / n_calls
    prepared = []
    for x, m, f in zip(rec.states, rec.modes, rec.tau):
        spm, lay = contact.engine.prepared(m)
        prepared.append((np.array(x), spm, np.array(f), np.empty(lay[-1])))
    _over_states(mp, prepared)
    per_state = median_of(lambda: _over_states(mp, prepared), reps) / len(prepared)
    cfg = scenario.simulator_config
    loop = (mp, sp, x0, tau, layout[-1], xd, sc)
    t0 = time.perf_counter()
    dormand_prince(*loop, 1e-3, cfg.max_step_size, cfg.accuracy, COEFFS)
    compile_s = time.perf_counter() - t0
    result = []
    t_loop = median_of(lambda: result.append(dormand_prince(
        *loop, args.seconds, cfg.max_step_size, cfg.accuracy, COEFFS)), reps)
    evals, accepted, rejected, capped, reached, flagged = result[-1]
    per_loop = t_loop / evals
    print(f"compiled Dormand-Prince loop (compiled in {compile_s:.1f} s): {reached:.3f} s in "
          f"{accepted} steps (+{rejected} rejected, {capped} at the step cap), {evals} "
          f"evaluations, {flagged} flagged by the kernel")
    print(f"us per evaluation: the run {per_run * 1e6:.1f}; the kernel called from Python "
          f"{per_state * 1e6:.1f} over the run's {len(prepared)} recorded states, "
          f"{per_call * 1e6:.1f} at the costliest; the compiled loop there {per_loop * 1e6:.1f}")
    if flagged or reached < args.seconds:
        print("ratio of the run to the compiled loop: not measured (the loop stopped early or "
              "the kernel flagged evaluations: try a shorter --seconds)")
    else:
        print(f"ratio of the run to the compiled loop: {per_run / per_loop:.1f}x per "
              f"evaluation; the kernel's share of the run's evaluation cost: "
              f"{per_state / per_run:.0%}")
        kept_of = [r.wall_time * (r.timing["shares"]["seeking"] + r.timing["shares"]["impacts"])
                   for r in runs]
        kept = statistics.median(kept_of)
        projected = statistics.median(k + r.evaluations * per_loop for k, r in zip(kept_of, runs))
        print(f"projected wall of the sample with compiled stepping: {projected:.3f} s (its "
              f"seeking and impacts as they are, {kept:.3f} s, and each of its evaluations at "
              f"the compiled loop's cost; medians over the runs), {wall / projected:.1f}x less "
              f"than the run")
        handled = statistics.median(s_ for s_, _ in in_events)
        with_events = statistics.median(s_ + (r.evaluations - n_) * per_loop
                                        for (s_, n_), r in zip(in_events, runs))
        print(f"projected wall with compiled stepping and the events in Python as they are: "
              f"{with_events:.3f} s (the event handling, {handled:.3f} s with the "
              f"{statistics.median(n_ for _, n_ in in_events):.0f} evaluations it makes, and "
              f"the other evaluations at the compiled loop's cost), {wall / with_events:.1f}x "
              f"less than the run")


if __name__ == "__main__":
    main()
