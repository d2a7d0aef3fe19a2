"""Work-precision of the LZB solver on ball chains.

For each chain case, prints the error of v_plus against the continuous limit of the chain
(`drake_dock.core.lzb.limit`, integrated in time by scipy's DOP853 at rtol 1e-12) and the
wall time (best of several runs, side by side in this run) of
- `solve_lzb` (the compiled Dormand-Prince 5(4), located events) at several rtol, and
- `solve_lzb_fixed_step` (the same equations, explicit Euler in fixed impulse steps dP, phase
  changes at step ends: first order in dP, like Siconos's MultipleImpact).
Then a column over the restitution e for each law, so that a low-e regression shows at once.

Run: .venv/bin/python bench/lzb_chains.py [--quick]
"""
import argparse
import time

import numpy as np

from drake_dock.core.lzb.inputs import check_inputs, per_couple
from drake_dock.core.lzb.limit import continuous_limit_chain
from drake_dock.core.kernels import lzb_forces, lzb_phases as LP, lzb_records as LR
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
    imp = LR.ImpactConstants(s, s, np.ascontiguousarray(G), K, eta_, e, zeros, zeros, False,
                             LR.LAW_NAMES.index(law), 1e-10, 1e-10, 1e-12, 0, 1.0)
    ph = LR.new_phases(s)
    y = np.zeros(4 * s + 2 * s)
    y[s:2 * s] = u0
    dy, lam, g_old, g_new = np.empty_like(y), np.empty(s), np.empty((3, s)), np.empty((3, s))
    log = LR.EventLog(np.empty(16), np.empty(16, np.int64), np.empty(16, np.int64), np.int64(0))
    LP.event_values(y, g_old, imp, ph, lam)
    j0 = int(np.argmin(u0))
    # First step from zero energy (Eq. 33-34): the time in which the fastest couple's impulse
    # reaches dP, x = |u| t, P = K |u|^eta t^(eta+1) / (eta+1).
    t_step = (dP * (eta_[j0] + 1) / (K[j0] * abs(u0[j0]) ** eta_[j0])) ** (1 / (eta_[j0] + 1))
    for _ in range(50_000_000):
        if LP.finished(y, imp, ph) and _ > 0:
            break
        lzb_forces.rhs(y, dy, imp, ph, lam)
        y = y + t_step * dy
        LP.event_values(y, g_new, imp, ph, lam)
        for kind, j in zip(*np.nonzero((g_old > 0) & (g_new <= 0))):
            log = LP.apply_event(y, int(kind), int(j), 0.0, imp, ph, log, lam)
        LP.event_values(y, g_old, imp, ph, lam)
        lam_n = K * np.maximum(y[:s], 0.0) ** eta_
        if lam_n.max() > 0:
            t_step = dP / lam_n.max()
    return v + MinvW @ y[2 * s:3 * s]


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
    if target:
        rtol, err, t = target
        print(f"\ntarget (1e-9 on the 3-ball Hertz chain in under 20 ms): rtol={rtol:.0e} gives "
              f"{err:.2e} in {t * 1e3:.1f} ms -> {'met' if t < 0.02 else 'NOT met'}")


if __name__ == "__main__":
    main()
