"""Model no more than a scene needs: per scene, the pairs it declares, the pairs searched and
the seeks, and the share of the wall time spent seeking, in contact dynamics and in impacts
(`RigidContactSystem.timing`), all measured in this run.

    python bench/time_shares.py
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


def main():
    from drake_dock.docking.simulate import simulate
    from drake_dock.docking.scenario import PAPER_EXAMPLE, load_scenario
    r = simulate(load_scenario(PAPER_EXAMPLE))
    print(f"paper example (12 pairs): {time_shares_line(r.timing)}; wall {r.wall_time:.3f} s")
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
