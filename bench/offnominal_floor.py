"""The off-nominal conditions of the conditions sweep against the floor Drake's own plant sets,
measured side by side in one run.

For the first ``--runs`` random conditions of `drake-dock study conditions` (its seed and order;
the paper example's scenario otherwise), prints per run: drake_dock's outcome, simulated time,
derivative evaluations and wall time (`simulate`, build excluded, as the sweep's wall time
without its outputs), and the wall time of the same plant without contact (free flight with
the Stewart element) integrated by Drake over the same simulated time with the same
`SimulatorConfig`, and with the step cap lifted (``max_step_size`` = the run's length). The
medians follow, against the sweep's target of 0.1 s per run.

Two floors. The plant alone over the same simulated time and settings: no run of a contact
model built on it costs less. And the floor of drake_dock's architecture at its own number of
evaluations: each costs at least the plant's own evaluation (its wall time per derivative
evaluation without contact) plus an empty Python LeafSystem's (`floors.empty_leaf_cost`);
no implementation with a Python LeafSystem that needs as many evaluations runs below it.

    python bench/offnominal_floor.py [--runs 8] [SCENARIO.yaml]
"""
import argparse
import copy
import sys
from pathlib import Path

import numpy as np

from drake_dock.core.kernels.prepare import warm
from drake_dock.docking.model.simulate import simulate
from drake_dock.docking.placement.place import place
from drake_dock.docking.scenario.loading import PAPER_EXAMPLE, load_scenario
from drake_dock.errors import DrakeDockError
from drake_dock.studies.conditions import ConditionsPlan, conditions, with_condition

sys.path.insert(0, str(Path(__file__).parent))
from floors import empty_leaf_cost, free_flight  # noqa: E402  (a sibling bench module)

TARGET = 0.1      # s per run: the target for the sweep's median



def main():
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("scenario", nargs="?", default=str(PAPER_EXAMPLE))
    ap.add_argument("--runs", type=int, default=8, help="the first N random conditions")
    ap.add_argument("--lifted-cap", type=float, default=0.05,
                    help="also run drake_dock with this step cap (coarser outputs), 0 to skip")
    a = ap.parse_args()
    warm()
    base = load_scenario(a.scenario)
    leaf = empty_leaf_cost(base.simulator_config.integration_scheme)
    todo = conditions(ConditionsPlan(random=a.runs, corners=0))
    rows = []
    print(f"{'condition':<11} {'outcome':<9} {'sim s':>6} {'evals':>7} {'drake_dock s':>13} "
          f"{'plant s':>8} {'uncapped s':>11} {'floor s':>8} {'ratio':>6} "
          f"{'lifted: evals':>14} {'floor s':>8}")
    for name, cond in todo:
        s = with_condition(base, cond)
        try:
            state = place(s)
            r = simulate(s, state=state)
        except DrakeDockError as e:
            print(f"{name:<11} error: {type(e).__name__} (left out)")
            continue
        plant, n_plant = free_flight(s, state, r.end_time)
        s2 = copy.deepcopy(s)
        s2.simulator_config.max_step_size = max(r.end_time, 1e-3)
        uncapped, _ = free_flight(s2, state, r.end_time)
        floor = r.evaluations * (plant / n_plant + leaf)
        lifted = (np.nan, np.nan)
        if a.lifted_cap > 0:
            s3 = copy.deepcopy(s)
            s3.simulator_config.max_step_size = a.lifted_cap
            try:
                r3 = simulate(s3, state=state)
                lifted = (r3.evaluations, r3.evaluations * (plant / n_plant + leaf))
            except DrakeDockError as e:
                print(f"{name}: with the step cap {a.lifted_cap:g} s, {type(e).__name__} "
                      f"(left out of that median)")
        rows.append((r.wall_time, plant, uncapped, floor, plant / n_plant,
                     r.wall_time / r.evaluations, lifted[1]))
        print(f"{name:<11} {r.outcome:<9} {r.end_time:6.2f} {r.evaluations:7d} "
              f"{r.wall_time:13.3f} {plant:8.3f} {uncapped:11.4f} {floor:8.3f} "
              f"{r.wall_time / plant:5.1f}x {lifted[0]:14.0f} {lifted[1]:8.3f}")
    if not rows:
        raise SystemExit("no condition ran")
    w, p, u, f, e, d, fl = (float(np.median(c)) for c in zip(*rows))
    lifted_floors = [r[6] for r in rows if not np.isnan(r[6])]
    fl = float(np.median(lifted_floors)) if lifted_floors else np.nan
    cfg = base.simulator_config
    print(f"median wall time per run: drake_dock {w:.3f} s; the plant alone over the same "
          f"simulated time {p:.3f} s ({cfg.integration_scheme}, accuracy {cfg.accuracy:g}, "
          f"step cap {cfg.max_step_size:g} s), {u:.4f} s with the step cap lifted")
    print(f"target {TARGET:g} s per run: the plant alone is {p / TARGET:.2f}x the target "
          f"({'below the floor: cannot be met at these settings' if p > TARGET else 'above the floor'}); "
          f"drake_dock is {w / p:.1f}x the plant alone")
    print(f"floor of a Python LeafSystem at drake_dock's evaluations (the plant's own cost "
          f"per evaluation, median {1e6 * e:.1f} us, + an empty LeafSystem's {1e6 * leaf:.1f} us): "
          f"median {f:.3f} s per run, {f / TARGET:.2f}x the target; drake_dock is {w / f:.1f}x "
          f"that floor, {1e6 * d:.0f} us per evaluation (median)")
    if a.lifted_cap > 0:
        print(f"with the step cap (= output spacing) {a.lifted_cap:g} s: that floor at "
              f"drake_dock's evaluations, median {fl:.3f} s per run over the "
              f"{len(lifted_floors)} that ran, {fl / TARGET:.2f}x the target")


if __name__ == "__main__":
    main()
