"""What the two interpenetration checks cost over one run: the scenario is simulated once, then
the analytic check (`drake_dock.docking.checks.penetration`) and the triangle-mesh check
(`drake_dock.docking.checks.mesh_check`, its meshes built afresh and counted) each go over the run's
timeseries. Prints the run's samples and wall time, each check's wall time and deepest
crossing, and the mesh check's time over the analytic one's.

    python bench/penetration_cost.py [models/idss_box_corner.yaml] [--duration SECONDS]
"""
import argparse
import time

from drake_dock.docking.checks.mesh_check import apds_meshes, deepest_penetration_mesh
from drake_dock.docking.checks.penetration import deepest_penetration
from drake_dock.docking.model.simulate import simulate
from drake_dock.docking.placement.place import place
from drake_dock.docking.report.results import timeseries
from drake_dock.docking.scenario.loading import load_scenario


def main(argv=None):
    ap = argparse.ArgumentParser(description=__doc__)
    ap.add_argument("scenario", nargs="?", default="models/idss_box_corner.yaml")
    ap.add_argument("--duration", type=float, default=None)
    args = ap.parse_args(argv)
    s = load_scenario(args.scenario)
    t0 = time.perf_counter()
    ts = timeseries(simulate(s, place(s), duration=args.duration))
    print(f"run: {len(ts['t'])} samples to t = {ts['t'][-1]:.3f} s, "
          f"{time.perf_counter() - t0:.1f} s", flush=True)
    run_args = (s.geometry, ts["t"], ts["R_WA"], ts["p_WA"], ts["apds_names"].tolist())
    walls = {}
    apds_meshes.cache_clear()
    for name, check in (("analytic", deepest_penetration), ("mesh", deepest_penetration_mesh)):
        t0 = time.perf_counter()
        found = check(*run_args)
        walls[name] = time.perf_counter() - t0
        print(f"{name} check: {walls[name]:.2f} s, {found.describe()}", flush=True)
    print(f"mesh / analytic: {walls['mesh'] / walls['analytic']:.2f}")


if __name__ == "__main__":
    main()
