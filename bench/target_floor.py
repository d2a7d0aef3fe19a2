"""What a 10x speed-up over Drake's compliant contact asks of drake_dock, measured in one run.

For each metric: the fastest coarse compliant configuration (point contact, SAP at the coarse
steps a Drake user tries first) within the tolerance of the rigid reference, the drake_dock
wall time 10x would need, and that time against drake_dock's run and a floor, both measured
here:

- drake_dock's fastest run within the tolerance (accuracy 1e-3, step cap 0.01 s; median of
  ``--repeats`` identical runs) and its derivative evaluations;
- the floor: the plant alone without contact over the same time and integrator settings,
  plus the same number of evaluations of an *empty* Python LeafSystem in Drake's simulator
  (drake_dock's architecture: a custom LeafSystem supplies the contact forces). No
  implementation in that architecture that needs as many evaluations runs below it.

Errors are relative to each metric's contact effect, as in the study
(`drake_dock.studies.docking_metrics`).

    python bench/target_floor.py [--repeats 5] [--tolerance 1e-3]
"""
import argparse
import copy
import sys
from pathlib import Path

import numpy as np

from drake_dock.docking.model.simulate import simulate
from drake_dock.docking.placement.place import place
from drake_dock.docking.scenario.loading import load_scenario
from drake_dock.docking.scenario.models_dir import PAPER_EXAMPLE
from drake_dock.studies.compliant import (CompliantConfig, hunt_crossley_dissipation,
                                          run_compliant)
from drake_dock.studies.docking_metrics import (METRICS, compliant_metrics, contact_effect,
                                                errors, rigid_metrics, scene_start)

sys.path.insert(0, str(Path(__file__).parent))
from floors import empty_leaf_cost, free_flight  # noqa: E402  (a sibling bench module)


def main():
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--repeats", type=int, default=5)
    ap.add_argument("--tolerance", type=float, default=1e-3)
    args = ap.parse_args()
    tol = args.tolerance
    scenario = load_scenario(PAPER_EXAMPLE)
    state = place(scenario)
    start = scene_start(scenario, state)
    sc = copy.deepcopy(scenario)
    sc.simulator_config.accuracy = 1e-8
    ref = rigid_metrics(simulate(sc, state=state), start)
    effect = contact_effect(ref, start)

    def err(m):
        return errors(m, ref, effect)

    fast = copy.deepcopy(scenario)
    fast.simulator_config.accuracy = 1e-3
    fast.simulator_config.max_step_size = 0.01
    runs = [simulate(fast, state=state) for _ in range(args.repeats)]
    t_dd = float(np.median([r.wall_time for r in runs]))
    evals = runs[0].evaluations
    e_dd = err(rigid_metrics(runs[0], start))
    d_hc = hunt_crossley_dissipation(scenario.contact.restitution,
                                     scenario.initial.chaser_speed)
    rows = []
    for k_c in (1e6, 1e7, 1e8):
        for h in (1e-2, 3e-3):
            cfg = CompliantConfig("point", k_c, h, dissipation=d_hc)
            r = run_compliant(scenario, state, cfg, t_max=2 * ref["capture_time"])
            m = compliant_metrics(r, start)
            rows.append((cfg.label(), r.wall_time, err(m) if r.captured else None))
    leaf = empty_leaf_cost(scenario.simulator_config.integration_scheme)
    t_free, _ = free_flight(fast, state, ref["capture_time"])
    print("coarse compliant runs (point contact, SAP), errors against drake_dock at 1e-8:")
    for label, wall, e in rows:
        es = ("no capture" if e is None else
              " ".join(f"{k}={e[k]:.1e}" for k in METRICS))
        print(f"  {label:<32s} {wall:.4f} s  {es}")
    print(f"drake_dock accuracy 1e-3, step cap 0.01 s: {t_dd:.3f} s (median of {len(runs)}), "
          f"{evals} evaluations; errors "
          + " ".join(f"{k}={e_dd[k]:.1e}" for k in METRICS))
    print(f"empty Python LeafSystem in Drake's simulator: {1e6 * leaf:.1f} us per evaluation; "
          f"x {evals} evaluations = {1e3 * leaf * evals:.2f} ms")
    print(f"the plant alone (no contact) to the capture time: {1e3 * t_free:.2f} ms")
    floor = t_free + leaf * evals
    print(f"floor: the plant alone + {evals} empty-LeafSystem evaluations = "
          f"{1e3 * floor:.2f} ms (drake_dock now: {t_dd / floor:.0f}x the floor)")
    for k in METRICS:
        ok = [(w, label) for label, w, e in rows if e is not None and e[k] <= tol]
        eff = f"; contact effect {effect[k]:.4g}"
        if not ok:
            print(f"target {k}: no coarse compliant run within {tol:g}{eff}")
            continue
        w, label = min(ok)
        need = w / 10
        print(f"target {k}: compliant {label} {w:.4f} s within {tol:g}; 10x needs drake_dock "
              f"at {1e3 * need:.2f} ms = {t_dd / need:.0f}x faster than now, "
              f"{need / floor:.2f}x the floor"
              + (" (below it: cannot be met)" if need < floor else "") + eff)


if __name__ == "__main__":
    main()
