"""Per-evaluation cost of the rigid contact system with three active couples (a three-footed
stool resting on a plane: three C-S couples sticking), side by side with the plant's own
derivative evaluation, and the split of one evaluation into its parts. Prints microseconds and
ratios measured in this run.

    python bench/contact_eval.py [--repeats N]
"""
import argparse
import time

import numpy as np
from pydrake.systems.analysis import SimulatorConfig

from drake_dock.core.constraints import STICK, solve_given_modes
from drake_dock.core.kernels import constraints as compiled
from drake_dock.core.hybrid import Mode
from drake_dock.studies.small_scenes import stool
from drake_dock.systems.simulator import make_simulator


def per_call(fn, repeats):
    fn()
    best = np.inf
    for _ in range(5):
        t0 = time.perf_counter()
        for _ in range(repeats):
            fn()
        best = min(best, (time.perf_counter() - t0) / repeats)
    return best * 1e6


def main():
    ap = argparse.ArgumentParser()
    ap.add_argument("--repeats", type=int, default=300)
    a = ap.parse_args()
    sc = stool()
    sys_ = sc.system
    sim = make_simulator(sys_, SimulatorConfig(), lambda ctx: sc.set_state(
        ctx, (np.eye(3), np.array([0, 0, 0.2 + sc.params["foot_radius"]])),
        (np.zeros(3), np.zeros(3))), witness_accuracy=1e-8)
    ctx = sim.get_mutable_context()
    sim.Initialize()
    sim.AdvanceTo(0.01)
    modes = sys_.get_modes(ctx)
    active = [p.mode for p in modes.pairs]
    assert active == [Mode.STICKING] * 3, active
    k = [0]

    def full():
        k[0] += 1
        ctx.SetTime(0.01 + 1e-12 * k[0])     # invalidates the cache entry
        sys_.EvalTimeDerivatives(ctx)

    pctx = sc.plant.CreateDefaultContext()
    sc.plant.SetPositions(pctx, ctx.get_continuous_state_vector().CopyToVector()[:7])
    pd = sc.plant.AllocateTimeDerivatives()

    def plant_only():
        sc.plant.CalcTimeDerivatives(pctx, pd)

    E = sys_.eval(ctx)
    x = ctx.get_continuous_state_vector().CopyToVector()
    q, v = x[:sys_.nq], x[sys_.nq:sys_.nq + sys_.nv]
    ev = sys_.evaluator
    sctx = ev.set_scratch(q, v)
    poses, twists = ev.frame_kinematics(sctx)
    u = x[sys_.nq + sys_.nv:sys_.ie]

    def couples():
        for i, st in enumerate(modes.pairs):
            ev.couple(i, u[ev.couple_slice(i)], poses, twists, st.sigma, 0.0, True)

    evs = [ev.couple(i, u[ev.couple_slice(i)], poses, twists, st.sigma, 0.0, True)
           for i, st in enumerate(modes.pairs)]

    def rows():
        return [ev.row(i, evs[i], poses, sctx) for i in range(3)]

    R = rows()

    def free():
        ev.free_acceleration(sctx, v, (None, []))

    M, Minv, a0, _, _ = ev.free_acceleration(sctx, v, (None, []))

    def solve():
        solve_given_modes(Minv, a0, R, [STICK] * 3, [None] * 3, omega=20.0)

    W, bias, gap, vn, _, mu, mu_s = compiled.pack_rows(R)
    codes, dirs = np.full(3, compiled.STICK), np.zeros((3, 2))

    def solve_compiled():
        compiled.solve_packed(Minv, a0, W, bias, gap, vn, mu, mu_s, codes, dirs, 20.0)

    n = a.repeats
    t_full = per_call(full, n)
    t_plant = per_call(plant_only, n)
    parts = {"frame kinematics": per_call(lambda: ev.frame_kinematics(sctx), n),
             "3 couples (Eq. 47, frame, bias)": per_call(couples, n),
             "3 rows W (Drake Jacobians)": per_call(rows, n),
             "M, free acceleration": per_call(free, n),
             "constraint solve (9 rows), Python": per_call(solve, n),
             "constraint solve (9 rows), compiled": per_call(solve_compiled, n)}
    print(f"contact system, 3 sticking couples: {t_full:8.1f} us per derivative evaluation")
    print(f"plant alone (free flight):          {t_plant:8.1f} us")
    print(f"ratio contact system / plant:       {t_full / t_plant:8.1f}x")
    for name, t in parts.items():
        print(f"  {name:34s} {t:8.1f} us  ({t / t_full:5.1%})")
    print(f"evaluations so far: {sys_.evaluations}; final lambda_n: {E.lam_n.round(6)}")


if __name__ == "__main__":
    main()
