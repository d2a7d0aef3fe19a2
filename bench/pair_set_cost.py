"""What the pairs of `complete` that only a large relative roll reaches cost where the motion
does not reach them (petal corner / guide surface, tip arc / tip arc, petal corner / tip
land): the first conditions of the conditions sweep (seed 2026,
inside the IDSS box, rolls within 4 deg), each run twice in this process with the same
placement, once with the `complete` set and once with those 42 pairs patched out of it
(`pairs.corner_surface_pairs`, `pairs.tip_tip_pairs`,
`pairs.corner_land_pairs`). The far pairs' screenings add events,
which change the step sequence; in a long jam with many impacts the two runs then part at
round-off and end differently, so the wall time per derivative evaluation is the measure
compared. A short run first loads the compiled kernels, so that neither version pays for
it. Prints, per run, each version's wall time, evaluations, impacts and end time, the
seeks of the left-out pair types, and the ratio of the wall time per evaluation; then the
median ratio.

    python bench/pair_set_cost.py [--conditions 4]
"""
import argparse
import time
from unittest import mock

import numpy as np

from drake_dock.docking.geometry import pairs as pair_sets
from drake_dock.docking.model.simulate import simulate
from drake_dock.docking.placement.place import place
from drake_dock.docking.report.cost import cost_by_pair_type
from drake_dock.docking.scenario.loading import load_scenario
from drake_dock.docking.scenario.models_dir import PAPER_EXAMPLE
from drake_dock.studies.conditions import ConditionsPlan, conditions, with_condition

LEFT_OUT = ("petal corner / guide surface", "tip arc / tip arc", "petal corner / tip land")


def run(s, state):
    t0 = time.perf_counter()
    r = simulate(s, state)
    return r, time.perf_counter() - t0


def main(argv=None):
    ap = argparse.ArgumentParser(description=__doc__)
    ap.add_argument("--conditions", type=int, default=4)
    args = ap.parse_args(argv)
    base = load_scenario(PAPER_EXAMPLE)
    base.contact.pairs = "complete"
    ratios = []
    warm = with_condition(base, conditions(ConditionsPlan())[0][1])
    warm.simulation.duration = 0.05
    simulate(warm, place(warm))
    for name, cond in conditions(ConditionsPlan())[:args.conditions]:
        s = with_condition(base, cond)
        state = place(s)                    # with the complete set, for both runs
        full, wall_full = run(s, state)
        with mock.patch.object(pair_sets, "corner_surface_pairs", lambda *a, **k: []), \
                mock.patch.object(pair_sets, "tip_tip_pairs", lambda *a, **k: []), \
                mock.patch.object(pair_sets, "corner_land_pairs", lambda *a, **k: []):
            less, wall_less = run(s, state)
        costs = cost_by_pair_type(full.timing, full.scene)
        seeks = {t: costs[t]["seeks"] for t in LEFT_OUT if t in costs}
        per = [wall / r.evaluations for wall, r in ((wall_full, full), (wall_less, less))]
        ratios.append(per[0] / per[1])
        print(f"{name}: complete ({full.timing['pairs_declared']} pairs) {wall_full:.1f} s, "
              f"{full.evaluations} evaluations, {len(full.impacts)} impacts, end "
              f"{full.end_time:.3f} s; without the three types ({less.timing['pairs_declared']} "
              f"pairs) {wall_less:.1f} s, {less.evaluations}, {len(less.impacts)}, "
              f"{less.end_time:.3f} s; their seeks {seeks}; wall per evaluation "
              f"{per[0] * 1e6:.0f} / {per[1] * 1e6:.0f} us, ratio {ratios[-1]:.2f}", flush=True)
    print(f"median ratio {np.median(ratios):.2f} over {len(ratios)} runs")


if __name__ == "__main__":
    main()
