"""The conditions sweep's first conditions, drake_dock against the plant alone, in one run.

For the first ``--runs`` random conditions of `drake-dock study conditions` (its seed, order and
contact set; the paper example's scenario unless one is given), prints per run drake_dock's
outcome, simulated time, derivative evaluations and wall time (`simulate`: the run, placement
and Diagram excluded, as the sweep's wall time without its outputs), and the wall time of the
same plant without contact (free flight with the Stewart element) integrated by Drake over the
same simulated time with the same `SimulatorConfig`, and their ratio; then
`median wall per condition: <S> s` and `ratio to the plant alone: <N>x` (the medians' ratio),
and the target of the issue (N <= 20).

    python bench/offnominal.py [--runs 8] [SCENARIO.yaml]
"""
import argparse
import sys
from pathlib import Path

import numpy as np

from drake_dock.core.kernels.prepare import warm
from drake_dock.docking.model.simulate import simulate
from drake_dock.docking.placement.place import place
from drake_dock.docking.scenario.loading import load_scenario
from drake_dock.docking.scenario.models_dir import PAPER_EXAMPLE
from drake_dock.errors import DrakeDockError
from drake_dock.studies.conditions import ConditionsPlan, conditions, with_condition

sys.path.insert(0, str(Path(__file__).parent))
from floors import free_flight  # noqa: E402  (a sibling bench module)

TARGET = 20.0     # the bound on the ratio to the plant alone


def main():
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("scenario", nargs="?", default=str(PAPER_EXAMPLE))
    ap.add_argument("--runs", type=int, default=8, help="the first N random conditions")
    a = ap.parse_args()
    warm()
    plan = ConditionsPlan(random=a.runs, corners=0)
    base = load_scenario(a.scenario)
    base.contact.pairs = plan.pairs
    simulate(base, place(base), duration=0.01)  # loads every kernel and Drake's code once
    rows = []
    print(f"{'condition':<11} {'outcome':<9} {'sim s':>6} {'evals':>7} {'drake_dock s':>13} "
          f"{'plant s':>8} {'ratio':>7}")
    for name, cond in conditions(plan):
        s = with_condition(base, cond)
        try:
            state = place(s)
            r = simulate(s, state)
        except DrakeDockError as e:
            print(f"{name:<11} error: {type(e).__name__} (left out)")
            continue
        plant, _ = free_flight(s, state, r.end_time)
        rows.append((r.wall_time, plant))
        print(f"{name:<11} {r.outcome:<9} {r.end_time:6.2f} {r.evaluations:7d} "
              f"{r.wall_time:13.3f} {plant:8.3f} {r.wall_time / plant:6.1f}x")
    if not rows:
        raise SystemExit("no condition ran")
    w, p = (float(np.median(c)) for c in zip(*rows))
    cfg = base.simulator_config
    print(f"median wall per condition: {w:.3f} s (the plant alone over the same simulated "
          f"time: {p:.3f} s; {cfg.integration_scheme}, accuracy {cfg.accuracy:g}, step cap "
          f"{cfg.max_step_size:g} s)")
    ratio = w / p
    print(f"ratio to the plant alone: {ratio:.1f}x")
    print(f"target: ratio to the plant alone <= {TARGET:g}x: "
          + ("met" if ratio <= TARGET else f"NOT met ({ratio / TARGET:.1f}x over)"))


if __name__ == "__main__":
    main()
