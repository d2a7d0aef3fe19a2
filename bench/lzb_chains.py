"""Work-precision of the LZB solver on ball chains.

For each chain case, prints the error of v_plus against the continuous limit of the chain
(`drake_dock.core.lzb.limit`, integrated in time by scipy's DOP853 at rtol 1e-12) and the
wall time (best of several runs, side by side in this run) of
- `solve_lzb` (adaptive 8th order, located events) at several rtol, and
- `solve_lzb_fixed_step` (the same equations, explicit Euler in fixed impulse steps dP, phase
  changes at step ends: first order in dP, like Siconos's MultipleImpact).
Then a column over the restitution e for each law, so that a low-e regression shows at once.
Then the compiled LZB (`solve_lzb(..., compiled=True)`, `drake_dock.core.kernels.lzb`) beside
the reference in this run: per chain size its error against the continuous limit and
`compiled LZB speed-up: <N>x` at rtol 1e-10; and (without --quick) for the paper example's
impacts (their inputs recorded from a run of models/paper_example.yaml), and the paper example
run with `ContactOptions.lzb_compiled` on and off: both capture times and the whole-run wall
time ratio.

Run: .venv/bin/python bench/lzb_chains.py [--quick]
"""
import argparse
import time

import numpy as np

from drake_dock.core.lzb.inputs import check_inputs, per_couple
from drake_dock.core.lzb.limit import continuous_limit_chain
from drake_dock.core.lzb.problem import ImpactProblem
from drake_dock.core.lzb.solve import solve_lzb

E_GRID = (0.0, 0.05, 0.1, 0.2, 0.3, 0.5, 0.7, 0.9, 1.0)


def chain(n):
    Wn = np.zeros((n, n - 1))
    for j in range(n - 1):
        Wn[j, j], Wn[j + 1, j] = -1.0, 1.0
    return np.eye(n), Wn


def solve_lzb_fixed_step(M, Wn, v_minus, stiffness, eta, restitution, *, dP, law="paper"):
    """First-order reference variant (frictionless): the same equations and restitution laws
    as `solve_lzb`, advanced by explicit Euler steps of a fixed increment ``dP`` (N s) of the
    primary impulse P* (the couple of largest force, Eq. 32), with phase changes applied at the
    end of the step in which they occur (no event location). This is how fixed-step LZB codes
    (e.g. Siconos's MultipleImpact) integrate; it is first order in dP. For benchmarks.
    Returns v_plus."""
    M, L, Wn, v, _, n, s = check_inputs(M, Wn, v_minus, None)
    K = per_couple("stiffness", stiffness, s, positive=True)
    eta_ = per_couple("eta", eta, s, positive=True)
    e = per_couple("restitution", restitution, s, lo=0.0, hi=1.0)
    MinvW = np.linalg.solve(M, Wn)
    G = Wn.T @ MinvW
    u0 = Wn.T @ v
    if np.any(u0 > 0):
        raise ValueError("v_minus: a couple is already separating")
    zeros = np.zeros(s)
    prob = ImpactProblem(np.pad(G, ((0, 2 * s), (0, 2 * s))), np.concatenate([u0, np.zeros(2 * s)]),
                    K, eta_, e, zeros, zeros, law, zeros, False)
    y = prob.y0.copy()
    events = []
    g_old = prob.event_values(y)
    j0 = int(np.argmin(u0))
    # First step from zero energy (Eq. 33-34): the time in which the fastest couple's impulse
    # reaches dP, x = |u| t, P = K |u|^eta t^(eta+1) / (eta+1).
    t_step = (dP * (eta_[j0] + 1) / (K[j0] * abs(u0[j0]) ** eta_[j0])) ** (1 / (eta_[j0] + 1))
    for _ in range(50_000_000):
        if prob.finished(y) and _ > 0:
            break
        y = y + t_step * prob.rhs(0.0, y)
        g_new = prob.event_values(y)
        for kind, j in zip(*np.nonzero((g_old > 0) & (g_new <= 0))):
            prob.apply_event(y, kind, j, events, 0.0)
        g_old = prob.event_values(y)
        lam = K * np.maximum(y[prob.layout.x], 0.0) ** eta_
        if lam.max() > 0:
            t_step = dP / lam.max()
    P = y[prob.layout.P]
    return v + MinvW @ P


def best_time(f, repeat):
    best = np.inf
    for _ in range(repeat):
        t0 = time.perf_counter()
        out = f()
        best = min(best, time.perf_counter() - t0)
    return best, out


def restitution_column(quick):
    """Error of `solve_lzb` (rtol 1e-10) against the continuous limit of each law over e
    (e = 0: against the shared velocity of the balls moving together), so that a low-e
    regression shows at once; and the number of phase events."""
    chains = [("3 equal balls, eta 1.5", [1.0, 1.0, 1.0], [1e7, 1e7], 1.5),
              ("5 unequal balls, eta 1", [2.0, 0.5, 1.0, 3.0, 1.0], [1e7, 1e8, 3e6, 1e7], 1.0)]
    grid = E_GRID[:4] if quick else E_GRID
    print(f"\nerror against the continuous limit over e (rtol 1e-10), [events]")
    print(f"{'case':24s} {'law':6s} " + " ".join(f"{'e=%g' % e:>15s}" for e in grid))
    for name, m, K, eta in chains[:1] if quick else chains:
        M, Wn = chain(len(m))
        M = np.diag(m)
        v0 = np.zeros(len(m))
        v0[0] = 1.0
        for law in ("bi", "mono", "paper"):
            cells = []
            for e in grid:
                ref = (np.full(len(m), m[0] / sum(m)) if e == 0 else
                       continuous_limit_chain(m, v0, K, eta, e, law, max_step=1e-3))
                r = solve_lzb(M, Wn, v0, K, eta, e, law=law, rtol=1e-10)
                cells.append(f"{np.abs(r.v_plus - ref).max():9.1e} [{len(r.events):3d}]")
            print(f"{name:24s} {law:6s} " + " ".join(f"{c:>15s}" for c in cells))


def compiled_chains(quick):
    """The compiled LZB beside the reference on chains of 3 to 9 balls (Hertz, e = 1 and 0.5,
    rtol 1e-10): the error of each against the continuous limit and the speed-up."""
    print("\ncompiled LZB (Dormand-Prince 5(4) in numba) beside the reference (scipy's DOP853), "
          "rtol 1e-10")
    print(f"{'chain':24s} {'ref error':>10s} {'compiled error':>15s} {'ref [ms]':>9s} "
          f"{'compiled [ms]':>14s}")
    for n in (3, 5) if quick else (3, 5, 7, 9):
        for e in (1.0, 0.5):
            M, Wn = chain(n)
            K = np.full(n - 1, 1e8)
            v0 = np.zeros(n)
            v0[0] = 1.0
            ref = continuous_limit_chain(np.ones(n), v0, K, 1.5, e, "paper")
            solve_lzb(M, Wn, v0, K, 1.5, e, rtol=1e-10, compiled=True)     # compiled or loaded
            t_r, r = best_time(lambda: solve_lzb(M, Wn, v0, K, 1.5, e, rtol=1e-10), 3)
            t_c, c = best_time(lambda: solve_lzb(M, Wn, v0, K, 1.5, e, rtol=1e-10,
                                                 compiled=True), 5)
            name = f"{n} balls, Hertz, e = {e:g}"
            print(f"{name:24s} {np.abs(r.v_plus - ref).max():10.2e} "
                  f"{np.abs(c.v_plus - ref).max():15.2e} {t_r * 1e3:9.2f} {t_c * 1e3:14.3f}")
            print(f"{name}: compiled LZB speed-up: {t_r / t_c:.0f}x")


def paper_example_impacts():
    """The paper example's impacts (recorded from a run) solved by both, and the example run
    with the compiled LZB on and off."""
    import dataclasses
    from drake_dock.docking.model.diagram import DiagramSpec, build_docking_diagram
    from drake_dock.docking.model.simulate import simulate
    from drake_dock.docking.placement.place import place
    from drake_dock.docking.scenario.loading import load_scenario
    from drake_dock.docking.scenario.models_dir import PAPER_EXAMPLE
    from drake_dock.systems import transitions
    scenario = load_scenario(PAPER_EXAMPLE)
    state = place(scenario)
    calls = []

    def recorder(*args, **kw):
        calls.append((args, kw))
        return solve_lzb(*args, **kw)
    transitions.solve_lzb = recorder
    try:
        dd = build_docking_diagram(DiagramSpec.of(scenario))
        simulate(scenario, state=state, dd=dd)
    finally:
        transitions.solve_lzb = solve_lzb
    t_r = t_c = dv = 0.0
    for args, kw in calls:
        kw = dict(kw, compiled=False)
        solve_lzb(*args, **dict(kw, compiled=True))
        t1, r = best_time(lambda: solve_lzb(*args, **kw), 3)
        t2, c = best_time(lambda: solve_lzb(*args, **dict(kw, compiled=True)), 3)
        t_r, t_c = t_r + t1, t_c + t2
        dv = max(dv, np.abs(r.v_plus - c.v_plus).max() / np.abs(r.v_plus).max())
    print(f"\npaper example: {len(calls)} impacts, reference {t_r * 1e3:.1f} ms, compiled "
          f"{t_c * 1e3:.2f} ms in all; largest relative difference of v+ {dv:.1e}")
    print(f"paper example's impacts: compiled LZB speed-up: {t_r / t_c:.0f}x")
    runs = {}
    for on in (False, True):
        opts = dataclasses.replace(dd.contact.options, lzb_compiled=on)
        simulate(scenario, state, dd=build_docking_diagram(DiagramSpec.of(scenario, options=opts)))
        walls = []
        for _ in range(3):
            d = build_docking_diagram(DiagramSpec.of(scenario, options=opts))
            t0 = time.perf_counter()
            res = simulate(scenario, state=state, dd=d)
            walls.append(time.perf_counter() - t0)
        runs[on] = (res, float(np.median(walls)))
    (off, w_off), (on, w_on) = runs[False], runs[True]
    print(f"paper example capture time: lzb_compiled off {off.capture_time!r} s, on "
          f"{on.capture_time!r} s (difference {abs(on.capture_time - off.capture_time):.1e} s)")
    print(f"paper example whole run (median of 3): off {w_off:.3f} s, on {w_on:.3f} s; "
          f"wall ratio off/on {w_off / w_on:.2f}x")


def main():
    ap = argparse.ArgumentParser()
    ap.add_argument("--quick", action="store_true", help="fewer points (CI)")
    args = ap.parse_args()
    cases = [("3-ball Hertz (eta 1.5)", 3, 1.5, 1.0), ("3-ball linear (eta 1)", 3, 1.0, 1.0),
             ("3-ball Hertz, K2 = 10 K1", 3, 1.5, 10.0), ("5-ball Hertz (eta 1.5)", 5, 1.5, 1.0)]
    rtols = [1e-6, 1e-8, 1e-9, 3e-10, 1e-10, 1e-12]
    dPs = [1e-2, 1e-3] if args.quick else [1e-2, 1e-3, 1e-4]
    if args.quick:
        cases = cases[:1]
    target = None
    print(f"{'case':28s} {'method':24s} {'error':>10s} {'time [ms]':>10s}")
    for name, n, eta, ratio in cases:
        M, Wn = chain(n)
        K = np.full(n - 1, 1e8)
        K[1] *= ratio
        v0 = np.zeros(n)
        v0[0] = 1.0
        ref = continuous_limit_chain(np.ones(n), v0, K, eta, 1.0)
        for rtol in rtols:
            t, r = best_time(lambda: solve_lzb(M, Wn, v0, K, eta, 1.0, rtol=rtol), 5)
            err = np.abs(r.v_plus - ref).max()
            print(f"{name:28s} {'adaptive rtol=%.0e' % rtol:24s} {err:10.2e} {t * 1e3:10.2f}")
            if n == 3 and eta == 1.5 and ratio == 1.0 and err <= 1e-9 and target is None:
                target = (rtol, err, t)
        for dP in dPs:
            t, v = best_time(lambda: solve_lzb_fixed_step(M, Wn, v0, K, eta, 1.0, dP=dP), 1)
            err = np.abs(v - ref).max()
            print(f"{name:28s} {'fixed dP=%.0e' % dP:24s} {err:10.2e} {t * 1e3:10.2f}")
    restitution_column(args.quick)
    compiled_chains(args.quick)
    if not args.quick:
        paper_example_impacts()
    if target:
        rtol, err, t = target
        print(f"\ntarget (1e-9 on the 3-ball Hertz chain in under 20 ms): rtol={rtol:.0e} gives "
              f"{err:.2e} in {t * 1e3:.1f} ms -> {'met' if t < 0.02 else 'NOT met'}")


if __name__ == "__main__":
    main()
