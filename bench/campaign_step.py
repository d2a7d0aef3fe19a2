"""The step cap of a campaign's samples against what they answer: speed beside accuracy.

Measured in one run: the first ``--samples`` samples of the IDSS envelope plan
(models/idss_envelope.yaml), each placed once and run as a campaign runs it (`simulate` with
``lean=True``, then the row's columns, `drake_dock.campaign.sample.measure`) at the plan's own
step cap and at each ``--caps`` value in turn, one after the other per sample. A coarser cap
gets ``simulation.output_period`` at the plan's cap, so that its record keeps the plan's
sample spacing (the peak loads are read from the record). Per cap it prints the wall time of
the samples (their sum, and its ratio to the plan's cap), the derivative evaluations (the same),
how many samples end in the plan's cap's outcome, the largest relative difference of the peak
contact force, the peak Stewart stroke and force and of the end time among those, and the
largest energy-ledger closure error (relative). No target: the chart a docking engineer reads
to choose ``simulator_config.max_step_size`` for a campaign (a plan's ``set:`` takes it, with
``simulation.output_period``).

    python bench/campaign_step.py [--samples 8] [--caps 0.005 0.01 0.02]
"""
import argparse
import copy
import time

from drake_dock.campaign.plan import load_plan
from drake_dock.campaign.points import sample_specs
from drake_dock.campaign.sample import diagram_for, measure, sample_scenario
from drake_dock.core.kernels.prepare import warm
from drake_dock.docking.model.diagram import DiagramSpec
from drake_dock.docking.model.simulate import simulate
from drake_dock.docking.placement.place import PlacementCache, place
from drake_dock.docking.scenario.models_dir import MODELS_DIR

PLAN = MODELS_DIR / "idss_envelope.yaml"
COMPARED = ("peak_contact_force", "peak_stewart_stroke", "peak_stewart_force", "end_time")


def at_cap(scenario, cap, period):
    """``scenario`` with the step cap ``cap`` and the output period ``period`` (s)."""
    s = copy.deepcopy(scenario)
    s.simulator_config.max_step_size = cap
    s.simulation.output_period = period
    return s


def run_one(scenario, state, dd):
    """(wall time, evaluations, row) of one sample's lean run and its row."""
    t0 = time.perf_counter()
    result = simulate(scenario, state, dd=dd, lean=True)
    row = measure(result)
    return time.perf_counter() - t0, result.evaluations, row


def largest_difference(pairs, key):
    """The largest relative difference of column ``key`` over the (row, plan's row) pairs."""
    return max((abs(a[key] - b[key]) / max(abs(a[key]), abs(b[key]), 1e-300)
                for a, b in pairs), default=0.0)


def main():
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--samples", type=int, default=8)
    ap.add_argument("--caps", type=float, nargs="+", default=[0.005, 0.01, 0.02])
    args = ap.parse_args()
    warm()
    plan, base, fields = load_plan(PLAN)
    own = base.simulator_config.max_step_size
    caps = [own] + [c for c in args.caps if c != own]
    runs = {c: [] for c in caps}
    for spec in sample_specs(plan, fields, list(range(args.samples))):
        scenario = sample_scenario(base, spec[2])
        dd = diagram_for(DiagramSpec.of(scenario))
        state = place(scenario, PlacementCache(dd.scene))
        for c in caps:
            runs[c].append(run_one(at_cap(scenario, c, None if c == own else own), state, dd))
    wall0 = sum(r[0] for r in runs[own])
    evals0 = sum(r[1] for r in runs[own])
    print(f"{args.samples} samples of {PLAN.name}; the plan's step cap {own:g} s")
    for c in caps:
        rs = runs[c]
        wall, evals = sum(r[0] for r in rs), sum(r[1] for r in rs)
        same = [(r[2], r0[2]) for r, r0 in zip(rs, runs[own])
                if r[2]["outcome"] == r0[2]["outcome"]]
        diffs = ", ".join(f"{k} {largest_difference(same, k):.1e}" for k in COMPARED)
        closure = max(abs(r[2]["energy_closure"]) for r in rs)
        print(f"step cap {c:g} s" + ("" if c == own else f" (output period {own:g} s)")
              + f": wall {wall:.1f} s ({wall / wall0:.2f} of the plan's cap), evaluations "
              f"{evals} ({evals / evals0:.2f}); the plan's cap's outcome {len(same)} of "
              f"{len(rs)}; largest relative difference among those: {diffs}; largest "
              f"energy-ledger closure {closure:.1e}", flush=True)


if __name__ == "__main__":
    main()
