"""Per-evaluation cost of the rigid contact system with three active couples (a three-footed
stool resting on a plane: three C-S couples sticking), side by side with the plant's own
derivative evaluation, and the split of one evaluation into its parts: the whole derivative
through Drake's system interface, the engine's evaluation (the one compiled call and the Python
around it), the compiled call alone, and the events' calculators (kinematics, the couples, the
contact rows, M and the free acceleration). Prints microseconds and ratios measured in this
run, and the final lambda_n against its closed form m g / 3 per foot.

    python bench/contact_eval.py [--repeats N]
"""
import argparse
import time

import numpy as np
from pydrake.systems.analysis import SimulatorConfig

from drake_dock.core.hybrid import Mode
from drake_dock.core.kernels.engine import evaluate as evaluate_kernel
from drake_dock.core.kernels.prepare import warm
from drake_dock.studies.small_scenes import G, stool
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
    ap.add_argument("--repeats", type=int, default=2000)
    a = ap.parse_args()
    warm()
    sc = stool()
    sys_ = sc.system
    sim = make_simulator(sys_, SimulatorConfig(), lambda ctx: sc.set_state(
        ctx, (np.eye(3), np.array([0, 0, 0.2 + sc.params["foot_radius"]])),
        (np.zeros(3), np.zeros(3))), witness_accuracy=1e-8)
    ctx = sim.get_mutable_context()
    sim.Initialize()
    sim.AdvanceTo(0.01)
    modes = sys_.get_modes(ctx)
    assert [p.mode for p in modes.pairs] == [Mode.STICKING] * 3
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

    eng = sys_.engine
    x = ctx.get_continuous_state_vector().CopyToVector()
    q, v = x[:sys_.nq], x[sys_.nq:sys_.nq + sys_.nv]
    u = x[sys_.nq + sys_.nv:sys_.ie]
    tau = np.zeros(sys_.nv)
    packed, layout = eng.prepared(modes)
    buf = np.empty(layout[-1])
    kin = eng.kinematics(q, v)
    sigma = np.array([st.sigma for st in modes.pairs])
    couples = eng.couples(kin, u, sigma, [0, 1, 2])
    n = a.repeats
    t_full = per_call(full, n)
    t_plant = per_call(plant_only, n)
    parts = {"engine evaluation (Engine.evaluate)":
             per_call(lambda: eng.evaluate(0.0, x, modes, tau), n),
             "the compiled call alone": per_call(
                 lambda: evaluate_kernel(eng.packed, packed, x, tau, buf), n),
             "events: kinematics": per_call(lambda: eng.kinematics(q, v), n),
             "events: 3 couples (Eq. 47, frame, bias)": per_call(
                 lambda: eng.couples(kin, u, sigma, [0, 1, 2]), n),
             "events: 3 contact rows (Eq. 11, 52)": per_call(
                 lambda: [eng.row(i, couples[i], kin) for i in range(3)], n),
             "events: M, M^-1, free acceleration": per_call(
                 lambda: eng.dynamics(q, v, tau), n)}
    print(f"contact system, 3 sticking couples: {t_full:8.1f} us per derivative evaluation")
    print(f"plant alone (free flight):          {t_plant:8.1f} us")
    print(f"ratio contact system / plant:       {t_full / t_plant:8.1f}x")
    for name, t in parts.items():
        print(f"  {name:40s} {t:8.1f} us  ({t / t_full:5.1%})")
    E = sys_.eval(ctx)
    print(f"evaluations so far: {sys_.evaluations}; final lambda_n: {E.lam_n.round(6)} "
          f"(closed form m g / 3 = {sc.params['mass'] * G / 3:.6f} N)")


if __name__ == "__main__":
    main()
