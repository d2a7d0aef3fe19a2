"""Model no more than a scene needs: per scene, the pairs it declares, the pairs searched and
the seeks (and the far pairs the broad phase screened), and the share of the wall time spent
seeking, in contact dynamics and in impacts (`RigidContactSystem.timing`), all measured in this
run; the docking scenes with both contact sets (`contact.pairs`).

    python bench/time_shares.py [--quick]
"""
import math
import time

import numpy as np

from drake_dock.run import time_shares_line
from drake_dock.studies.small_scenes import G, SmallRun, disk_on_incline, stool


def small(name, sc, X, V, t_end):
    sc.system.timing.reset()
    t0 = time.perf_counter()
    run = SmallRun(sc.system, lambda c: sc.set_state(c, X, V))   # Initialize seeks
    run.sim.AdvanceTo(t_end)
    wall = time.perf_counter() - t0
    print(f"{name}: {time_shares_line(sc.system.timing.shares(wall))}; wall {wall:.3f} s")


def docking(name, path, pairs):
    """A docking scene with the contact set ``pairs``; the wall time per simulated second, as
    the two sets first close at different ring distances (docs/model.md)."""
    import yaml
    from drake_dock.docking.model.simulate import simulate
    from drake_dock.docking.placement.place import place
    from drake_dock.docking.scenario.loading import load_scenario
    with open(path) as f:
        data = yaml.safe_load(f)
    data.setdefault("contact", {})["pairs"] = pairs
    s = load_scenario(data=yaml.safe_dump(data))
    r = simulate(s, place(s))
    print(f"{name}, {pairs} ({r.timing['pairs_declared']} pairs): {time_shares_line(r.timing)};"
          f" wall {r.wall_time:.3f} s for {r.end_time:.4f} s simulated "
          f"({r.wall_time / r.end_time:.2f} s/s, {r.evaluations} evaluations, {r.outcome})")


def main(argv=None):
    import argparse
    from drake_dock.docking.scenario.models_dir import MODELS_DIR, PAPER_EXAMPLE
    ap = argparse.ArgumentParser(description=__doc__)
    ap.add_argument("--quick", action="store_true", help="the paper example only")
    args = ap.parse_args(argv)
    scenes = [("paper example", PAPER_EXAMPLE)]
    if not args.quick:
        scenes.append(("IDSS box corner", MODELS_DIR / "idss_box_corner.yaml"))
    for name, path in scenes:
        for pairs in ("paper", "complete"):
            docking(name, path, pairs)
    sc = stool()
    small("stool at rest (3 pairs)", sc, (np.eye(3), np.array([0, 0, 0.2 + 0.05])),
          (np.zeros(3), np.zeros(3)), 0.5)
    sc = disk_on_incline(math.radians(20), mu=0.3)
    small("disk sliding then rolling (1 pair)", sc, (np.eye(3), np.array([0, 0, 0.3])),
          (np.zeros(3), np.array([1.0, 0, 0])), 0.6)
    sc = disk_on_incline(0.0, restitution=0.5)
    small("bouncing disk, Zeno guard (1 pair)", sc, (np.eye(3), np.array([0, 0, 0.35])),
          (np.zeros(3), np.zeros(3)), math.sqrt(0.1 / G) * 3 + 0.05)


if __name__ == "__main__":
    main()
