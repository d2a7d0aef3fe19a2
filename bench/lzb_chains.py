"""Work-precision of the LZB solver on ball chains.

For each chain case, prints the error of v_plus against a converged compliant reference
(the chain with force K delta^eta integrated in time by scipy's DOP853 at rtol 1e-13) and the
wall time (best of several runs, side by side in this run) of
- `solve_lzb` (adaptive 8th order, located events) at several rtol, and
- `solve_lzb_fixed_step` (the same equations, explicit Euler in fixed impulse steps dP, phase
  changes at step ends: first order in dP, like Siconos's MultipleImpact).

Run: .venv/bin/python bench/lzb_chains.py [--quick]
"""
import argparse
import time

import numpy as np
from scipy.integrate import solve_ivp

from drake_dock.impact import solve_lzb, solve_lzb_fixed_step


def chain(n):
    Wn = np.zeros((n, n - 1))
    for j in range(n - 1):
        Wn[j, j], Wn[j + 1, j] = -1.0, 1.0
    return np.eye(n), Wn


def compliant_reference(n, K, eta, v0):
    def rhs(t, y):
        x, v = y[:n], y[n:]
        d = x[:-1] - x[1:]
        f = K * np.maximum(d, 0.0) ** eta
        a = np.zeros(n)
        a[:-1] -= f
        a[1:] += f
        return np.concatenate([v, a])
    y = np.concatenate([np.zeros(n), v0])
    t = 0.0
    while True:
        sol = solve_ivp(rhs, (t, t + 1e-2), y, method="DOP853", rtol=1e-13, atol=1e-17)
        t, y = sol.t[-1], sol.y[:, -1]
        if np.all(y[:n - 1] - y[1:n] <= 0) and np.all(y[n:-1] - y[n + 1:] <= 0):
            return y[n:]


def best_time(f, repeat):
    best = np.inf
    for _ in range(repeat):
        t0 = time.perf_counter()
        out = f()
        best = min(best, time.perf_counter() - t0)
    return best, out


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
        ref = compliant_reference(n, K, eta, v0)
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
    if target:
        rtol, err, t = target
        print(f"\ntarget (1e-9 on the 3-ball Hertz chain in under 20 ms): rtol={rtol:.0e} gives "
              f"{err:.2e} in {t * 1e3:.1f} ms -> {'met' if t < 0.02 else 'NOT met'}")


if __name__ == "__main__":
    main()
