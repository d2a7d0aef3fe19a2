"""Wall time of the paper's example to capture, against the plant alone, and its targets.

The paper's example (Sect. 8.2) to capture, build excluded, side by side with the same plant
integrated by Drake alone (free flight with the Stewart element, no contact) over the same
simulated time and with the same integrator settings. Prints the wall time (the median of
``--repeats`` identical runs on fresh diagrams, each printed; the plant alone likewise, its runs
alternating with them), the real-time factor (simulated s per wall s), the derivative
evaluations and the share of them spent isolating witness events (steps of more than 50
evaluations), and the ratio of the two runs, all measured in this run; and the same example with
Drake's plain witness isolation (`simulate(..., witness_approach=False)`), for the ratio of the
step shortening; and with a coarser step cap (``--coarse-step``) for its cost; and with one witness function per transition instead of the
joint one (`ContactOptions.joint_witness` off; median of as many runs); and, per evaluation,
drake_dock's time against the plant's own and an empty Python LeafSystem's. Also the set-up (the initial state: the first-contact
placement, its seeks, and their number; and that of another approach of the same geometry) and
the kernels' cold and warm start (a fresh process that compiles them into an empty cache
directory, then one that loads them from it). Then the targets, each `met` or `NOT met`: the
ratio to the plant alone <= 10x (5x the aim), the set-up <= 0.02 s, under 0.5 s of wall time.

    python bench/paper_example.py [SCENARIO.yaml] [--repeats 5] [--coarse-step 0.01]
        [--compare-scheme bogacki_shampine3] [--skip-plain] [--skip-cold]
"""
import argparse
import copy
import dataclasses
import os
import subprocess
import sys
import tempfile
import time

import numpy as np

from drake_dock.core.kernels.prepare import warm
from drake_dock.docking.geometry.scene import DockingScene
from drake_dock.docking.model.diagram import DiagramSpec, build_docking_diagram
from drake_dock.docking.model.simulate import simulate
from drake_dock.docking.placement.place import PlacementCache, contact_approach, place
from drake_dock.docking.placement.search import first_contact
from drake_dock.docking.scenario.loading import load_scenario
from drake_dock.docking.scenario.models_dir import PAPER_EXAMPLE

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
from floors import empty_leaf_cost, free_flight  # noqa: E402  (a sibling bench module)


def kernel_start(cache_dir):
    """Wall time of a fresh process importing and readying the compiled kernels with the numba
    cache in ``cache_dir`` (empty: a cold start, compiling; filled: a warm one, loading)."""
    code = ("import time; t = time.perf_counter(); "
            "from drake_dock.core.kernels.prepare import warm; warm(); "
            "print(time.perf_counter() - t)")
    env = dict(os.environ, NUMBA_CACHE_DIR=cache_dir)
    out = subprocess.run([sys.executable, "-c", code], env=env, check=True,
                         capture_output=True, text=True)
    return float(out.stdout.split()[-1])


def main():
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("scenario", nargs="?", default=str(PAPER_EXAMPLE))
    ap.add_argument("--skip-plain", action="store_true",
                    help="skip the side-by-side run with Drake's plain witness isolation")
    ap.add_argument("--coarse-step", type=float, default=0.01,
                    help="also run with this step cap (samples at its step ends), 0 to skip")
    ap.add_argument("--repeats", type=int, default=5,
                    help="runs of the example; the wall time printed is their median")
    ap.add_argument("--compare-scheme", default="bogacki_shampine3",
                    help="also run with this integration scheme ('' to skip)")
    ap.add_argument("--skip-cold", action="store_true",
                    help="skip the kernels' cold and warm start (two fresh processes)")
    args = ap.parse_args()
    starts = None
    if not args.skip_cold:
        with tempfile.TemporaryDirectory() as cache:
            starts = kernel_start(cache), kernel_start(cache)
    scenario = load_scenario(args.scenario)
    warm()      # the kernels loaded (their start is measured above), the set-up on its own
    t0 = time.perf_counter()
    scene = DockingScene.of(scenario)
    cache = PlacementCache(scene)
    state = place(scenario, cache)
    t_state = time.perf_counter() - t0
    # The set-up of another approach of the same scene (the roll 1 deg more), on the same
    # cache: the pairs' covers and coarse grids are kept on the scene's patches.
    other_roll = copy.deepcopy(scenario)
    other_roll.initial.target_yaw_deg += 1.0
    t0 = time.perf_counter()
    place(other_roll, cache)
    t_state_warm = time.perf_counter() - t0
    seeks = first_contact(cache, contact_approach(scenario, cache)[0]).seeks
    t0 = time.perf_counter()
    dd = build_docking_diagram(DiagramSpec.of(scenario, scene=scene))
    t_build = time.perf_counter() - t0
    steps = []
    r = simulate(scenario, state=state, dd=dd,
                 progress=lambda t, T, frac: steps.append(dd.contact.evaluations))
    de = np.diff([0] + steps)
    iso = int(de[de > 50].sum())
    # The same run again on fresh diagrams: the wall time is the median of the runs (the first
    # run in a process also pays Python's warm-up; the machines are shared and noisy).
    # The plant alone is timed beside each run, the two alternating, and its wall time is the
    # median of as many runs (one run of a few ms alone is at the mercy of the machine's noise).
    runs, frees = [r], [free_flight(scenario, state, r.end_time)]
    for _ in range(args.repeats - 1):
        runs.append(simulate(scenario, state,
                             dd=build_docking_diagram(DiagramSpec.of(scenario))))
        frees.append(free_flight(scenario, state, r.end_time))
    if any(x.capture_time != r.capture_time or x.evaluations != r.evaluations for x in runs):
        raise SystemExit("repeated runs differ: the simulation is not deterministic")
    walls = [x.wall_time for x in runs]
    wall = float(np.median(walls))
    t_free, n_free = float(np.median([f[0] for f in frees])), frees[0][1]
    t_leaf = empty_leaf_cost(scenario.simulator_config.integration_scheme)
    # One witness function per transition instead of the joint one, alternating as above.
    each_options = dataclasses.replace(dd.contact.options, joint_witness=False)
    each = [simulate(scenario, state, dd=build_docking_diagram(
        DiagramSpec.of(scenario, options=each_options))) for _ in range(args.repeats)]
    plain = None
    if not args.skip_plain:
        dd2 = build_docking_diagram(DiagramSpec.of(scenario))
        plain = simulate(scenario, state=state, dd=dd2, witness_approach=False)
    coarse = None
    if args.coarse_step > 0:
        sc2 = copy.deepcopy(scenario)
        sc2.simulator_config.max_step_size = args.coarse_step
        coarse = simulate(sc2, state=state, dd=build_docking_diagram(DiagramSpec.of(sc2)))
    other = None
    if args.compare_scheme and args.compare_scheme != scenario.simulator_config.integration_scheme:
        sc3 = copy.deepcopy(scenario)
        sc3.simulator_config.integration_scheme = args.compare_scheme
        other = simulate(sc3, state=state, dd=build_docking_diagram(DiagramSpec.of(sc3)))
    print(f"scenario: {args.scenario}")
    if starts is not None:
        print(f"compiled kernels: cold start {starts[0]:.2f} s (compiling into an empty cache), "
              f"warm start {starts[1]:.2f} s (loading it), each a fresh process")
    print(f"set-up: {t_state:.4f} s (another approach of the same geometry: "
          f"{t_state_warm:.4f} s)")
    print(f"set-up seeks: {seeks} (the first-contact search on its final approach)")
    print(f"diagram build (excluded): {t_build:.2f} s")
    print(f"simulated {r.end_time:.4f} s (captured: {r.captured}); impacts {len(r.impacts)}; "
          f"mode changes {r.mode_changes}")
    print(f"drake_dock wall time: {wall:.3f} s (median of {len(walls)} identical runs: "
          + ", ".join(f"{w:.3f}" for w in walls) + f"); real-time factor "
          f"{r.end_time / wall:.4f}")
    print(f"derivative evaluations: {r.evaluations} ({1e3 * wall / r.evaluations:.3f} ms "
          f"each); {iso} ({iso / r.evaluations:.0%}) in witness isolation")
    if plain is not None:
        print(f"with Drake's plain witness isolation (no step shortening): {plain.wall_time:.3f} s, "
              f"{plain.evaluations} evaluations; capture {plain.capture_time:.6f} s vs "
              f"{r.capture_time:.6f} s; speed-up of the step shortening "
              f"{plain.wall_time / wall:.1f}x")
    if coarse is not None:
        print(f"with the step cap {args.coarse_step:g} s (samples at step ends) instead of "
              f"{scenario.simulator_config.max_step_size:g} s: {coarse.wall_time:.3f} s, "
              f"{coarse.evaluations} evaluations, {len(coarse.record.t)} samples instead of "
              f"{len(r.record.t)}; capture {coarse.capture_time:.9f} s vs {r.capture_time:.9f} s; "
              f"ratio {wall / coarse.wall_time:.2f}x")
    if other is not None:
        print(f"with {args.compare_scheme} instead of {scenario.simulator_config.integration_scheme}: "
              f"{other.wall_time:.3f} s, {other.evaluations} evaluations, "
              f"{len(other.record.t)} samples; capture {other.capture_time:.9f} s vs "
              f"{r.capture_time:.9f} s; ratio {other.wall_time / wall:.2f}x")
    wall_each = float(np.median([x.wall_time for x in each]))
    print(f"with one witness function per transition (joint_witness off) instead of the joint "
          f"one: {wall_each:.3f} s (median of {len(each)} runs), {each[0].evaluations} "
          f"evaluations; capture {each[0].capture_time!r} s vs {r.capture_time!r} s "
          f"(difference {abs(each[0].capture_time - r.capture_time):.1e} s); ratio "
          f"{wall_each / wall:.2f}x")
    print(f"same plant without contact (Drake alone): {t_free:.4f} s (median of {len(frees)} "
          "runs, each beside one of drake_dock's: " + ", ".join(f"{f[0]:.4f}" for f in frees)
          + ")")
    print(f"ratio to the plant alone: {wall / t_free:.1f}x")
    print(f"per evaluation: drake_dock {1e6 * wall / r.evaluations:.1f} us (whole run), the "
          f"plant alone {1e6 * t_free / n_free:.1f} us ({n_free} evaluations), an empty Python "
          f"LeafSystem {1e6 * t_leaf:.1f} us")
    ratio = wall / t_free
    print("target: ratio to the plant alone <= 10x (5x the aim): "
          + ("met" + (" (and the aim)" if ratio <= 5 else " (not the aim of 5x)")
             if ratio <= 10 else f"NOT met ({ratio / 10:.1f}x over)"))
    print(f"target: set-up <= 0.02 s: "
          + ("met" if t_state <= 0.02 else f"NOT met ({t_state / 0.02:.1f}x over)"))
    print(f"target: under 0.5 s of wall time: "
          + ("met" if wall < 0.5 else f"NOT met ({wall / 0.5:.2f}x over)"))


if __name__ == "__main__":
    main()
