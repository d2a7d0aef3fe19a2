"""The cost of one derivative evaluation of the contact system inside a run, side by side with an
empty Python LeafSystem in Drake's simulator (the least any Python system costs per evaluation),
for the paper's example and the IDSS box corner (`models/idss_box_corner.yaml`), with the
whole evaluation in one compiled call (`ContactOptions.engine`, the default) and with the plant
as calculator (``engine`` off), all in this run.

Per scene and path it prints the evaluations, `us per evaluation: <U>` (the contact system's
time in its evaluations, `Timing.contact_dynamics`, over their number) and `ratio to an empty
LeafSystem: <N>x`; then the whole run's wall time per evaluation (witnesses, events, outputs
and Drake's integrator included) and its ratio; and the outcome and capture time of both paths.
The target (issue: N <= 10 for the evaluation) is checked on the engine's line.

    python bench/evaluation.py [--box-seconds 2.0]
"""
import argparse
import dataclasses
import os
import sys

from drake_dock.core.kernels.prepare import warm
from drake_dock.docking.model.diagram import DiagramSpec, build_docking_diagram
from drake_dock.docking.model.simulate import simulate
from drake_dock.docking.placement.place import place
from drake_dock.docking.scenario.loading import MODELS_DIR, PAPER_EXAMPLE, load_scenario

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
from floors import empty_leaf_cost  # noqa: E402  (a sibling bench module)

TARGET = 10.0


def _run(scenario, engine, duration):
    """The `RunResult` with the engine on or off."""
    options = dataclasses.replace(DiagramSpec.of(scenario).contact_options(), engine=engine)
    dd = build_docking_diagram(DiagramSpec.of(scenario, options=options))
    assert (dd.contact.evaluator.engine is not None) == engine
    return simulate(scenario, place(scenario), dd=dd, duration=duration)


def _per_evaluation(r):
    """Seconds per evaluation in the contact system's evaluations (`Timing`)."""
    return r.timing["shares"]["contact_dynamics"] * r.wall_time / r.evaluations


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
        simulate(scenario, place(scenario), duration=0.01)   # every kernel and Drake's code loaded
        results = {}
        for engine in (True, False):
            r = results[engine] = _run(scenario, engine, duration)
            n = r.evaluations
            label = "engine (one compiled call)" if engine else "plant as calculator"
            u = _per_evaluation(r)
            print(f"{name}, {label}: {n} evaluations; us per evaluation: {u * 1e6:.1f}; "
                  f"ratio to an empty LeafSystem: {u / empty:.1f}x; whole run "
                  f"{r.wall_time:.3f} s, {r.wall_time / n * 1e6:.0f} us per evaluation "
                  f"({r.wall_time / n / empty:.0f}x)")
        e, p = results[True], results[False]
        ue, up = _per_evaluation(e), _per_evaluation(p)
        print(f"{name}: outcome {e.outcome} / {p.outcome}; capture time {e.capture_time} / "
              f"{p.capture_time}; impacts {len(e.impacts)} / {len(p.impacts)}; "
              f"evaluation speed-up of the engine: {up / ue:.1f}x")
        ratio = ue / empty
        print(f"{name}: target: evaluation ratio to an empty LeafSystem <= {TARGET:g}x: "
              f"{'met' if ratio <= TARGET else f'NOT met ({ratio / TARGET:.1f}x over)'}")


if __name__ == "__main__":
    main()
