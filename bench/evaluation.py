"""The cost of one derivative evaluation of the contact system inside a run, side by side with an
empty Python LeafSystem in Drake's simulator (the least any Python system costs per evaluation)
and with the plant's own evaluation, for the paper's example and the IDSS box corner
(`models/idss_box_corner.yaml`), all in this run.

Per scene it prints the integrator's derivative evaluations and the evaluations the contact
system computed on every path (derivatives, witnesses, outputs, events; a request with equal
inputs comes from its memo), `us per evaluation: <U>` (the contact system's time in
`RigidContactSystem._lookup`, the one path of its derivatives and of its cache entry: the
compiled call with its Python around it, memo hits included, over the evaluations it
computed; over the integrator's derivative evaluations, which the empty LeafSystem's figure is
per, it would be less) and `ratio to an empty LeafSystem: <N>x`; then the whole run's wall
time per evaluation (witnesses, events, step control, recording and Drake's integrator
included) and its ratio; and the outcome and capture time. The target (issue: N <= 10 for the
evaluation) is checked on each scene's line.

    python bench/evaluation.py [--box-seconds 2.0]
"""
import argparse
import os
import sys
import time

from drake_dock.core.kernels.prepare import warm
from drake_dock.docking.model.diagram import DiagramSpec, build_docking_diagram
from drake_dock.docking.model.simulate import simulate
from drake_dock.docking.placement.place import PlacementCache, place
from drake_dock.docking.scenario.loading import load_scenario
from drake_dock.docking.scenario.models_dir import MODELS_DIR, PAPER_EXAMPLE
from drake_dock.systems.contact_system import RigidContactSystem

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
from floors import empty_leaf_cost, free_flight  # noqa: E402  (a sibling bench module)

TARGET = 10.0


def timed_run(scenario, duration):
    """(the `RunResult`, seconds in the contact system's evaluation lookups, the number of
    evaluations computed, the number of derivative evaluations the integrator asked for): the
    class's lookup, evaluation and derivative wrapped with a clock and counters for this
    run."""
    spent, computed, asked = [0.0], [0], [0]
    lookup, evaluate = RigidContactSystem._lookup, RigidContactSystem._evaluate
    derivatives = RigidContactSystem.DoCalcTimeDerivatives

    def clocked(self, context):
        t0 = time.perf_counter()
        try:
            return lookup(self, context)
        finally:
            spent[0] += time.perf_counter() - t0

    def counted(self, *args):
        computed[0] += 1
        return evaluate(self, *args)

    def derivative(self, context, out):
        asked[0] += 1
        return derivatives(self, context, out)

    RigidContactSystem._lookup, RigidContactSystem._evaluate = clocked, counted
    RigidContactSystem.DoCalcTimeDerivatives = derivative
    try:
        dd = build_docking_diagram(DiagramSpec.of(scenario))
        r = simulate(scenario, place(scenario, PlacementCache(dd.scene)), dd=dd,
                     duration=duration)
    finally:
        RigidContactSystem._lookup, RigidContactSystem._evaluate = lookup, evaluate
        RigidContactSystem.DoCalcTimeDerivatives = derivatives
    return r, spent[0], computed[0], asked[0]


def main():
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("--box-seconds", type=float, default=2.0,
                    help="simulated seconds of the box corner (default 2.0)")
    args = ap.parse_args()
    warm()
    scenes = [("paper example", load_scenario(PAPER_EXAMPLE), None),
              ("idss_box_corner", load_scenario(MODELS_DIR / "idss_box_corner.yaml"),
               args.box_seconds)]
    empty = empty_leaf_cost(scenes[0][1].simulator_config.integration_scheme)
    print(f"empty Python LeafSystem: {empty * 1e6:.1f} us per evaluation")
    for name, scenario, duration in scenes:
        simulate(scenario, place(scenario), duration=0.01)   # every kernel and Drake's code
        r, spent, computed, asked = timed_run(scenario, duration)
        n = r.evaluations
        u = spent / n
        t_free, n_free = free_flight(scenario, r.initial, r.end_time)
        print(f"{name}: {asked} derivative evaluations, {computed} evaluations computed (on "
              f"every path: derivatives, witnesses, outputs, events); us per "
              f"evaluation: {u * 1e6:.1f}; ratio to an empty LeafSystem: {u / empty:.1f}x; "
              f"the plant's own evaluation {t_free / n_free * 1e6:.1f} us "
              f"({u / (t_free / n_free):.1f}x)")
        print(f"{name}: whole run {r.wall_time:.3f} s, {r.wall_time / n * 1e6:.0f} us per "
              f"evaluation ({r.wall_time / n / empty:.0f}x an empty LeafSystem's); outcome "
              f"{r.outcome}, capture time {r.capture_time}, impacts {len(r.impacts)}")
        ratio = u / empty
        print(f"{name}: target: evaluation ratio to an empty LeafSystem <= {TARGET:g}x: "
              f"{'met' if ratio <= TARGET else f'NOT met ({ratio / TARGET:.1f}x over)'}")


if __name__ == "__main__":
    main()
