"""The step cap of a campaign's samples against what they answer: speed beside accuracy.

Measured in one run: the first ``--samples`` samples of the IDSS envelope plan
(models/idss_envelope.yaml), each run as a campaign runs it (`run_sample`: placement, lean run
and row) at the plan's own step cap and at each ``--caps`` value in turn, one after the other
per sample, the cap set as a plan's ``set:`` sets it (``simulator_config.max_step_size``). A
coarser cap also gets ``simulation.output_period`` at the plan's cap (unless the plan sets
one), so that its record, which the peak loads are read from, keeps the plan's sample spacing.
First sample 0 runs once at every cap, untimed (each cap's Diagram is built then). Per cap it
prints the samples' wall time (their sum, and its ratio to the plan's cap's), how many samples
end in the plan's cap's outcome, the largest relative difference of the peak contact force, the
peak Stewart stroke and force and the end time among those, and the largest energy-ledger
closure error (relative). No target: the table a docking engineer reads to choose a
campaign's ``simulator_config.max_step_size``.

    python bench/campaign_step.py [--samples 8] [--caps 0.005 0.01 0.02]
"""
import argparse

from drake_dock.campaign.plan import load_plan
from drake_dock.campaign.points import sample_specs
from drake_dock.campaign.sample import run_sample
from drake_dock.core.kernels.prepare import warm
from drake_dock.docking.scenario.models_dir import MODELS_DIR

PLAN = MODELS_DIR / "idss_envelope.yaml"
COMPARED = ("peak_contact_force", "peak_stewart_stroke", "peak_stewart_force", "end_time")


def at_cap(spec, cap, period):
    """The sample ``spec`` with the step cap ``cap`` and the output period ``period`` (s; None:
    the plan's)."""
    sample, seed, values = spec
    values = {**values, "simulator_config.max_step_size": cap}
    if period is not None:
        values["simulation.output_period"] = period
    return sample, seed, values


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
    own_period = base.simulation.output_period
    caps = list(dict.fromkeys([own, *args.caps]))

    def spec_at(spec, cap):
        return at_cap(spec, cap, own_period if cap == own else (own_period or own))

    specs = sample_specs(plan, fields, list(range(args.samples)))
    for c in caps:
        run_sample(base, spec_at(specs[0], c))
    rows = {c: [] for c in caps}
    for spec in specs:
        for c in caps:
            rows[c].append(run_sample(base, spec_at(spec, c)))
    wall0 = sum(r["wall_time"] for r in rows[own])
    print(f"{args.samples} samples of {PLAN.name}; the plan's step cap {own:g} s")
    for c in caps:
        rs = rows[c]
        wall = sum(r["wall_time"] for r in rs)
        same = [(r, r0) for r, r0 in zip(rs, rows[own])
                if r["outcome"] == r0["outcome"] and r["error"] is None]
        diffs = ", ".join(f"{k} {largest_difference(same, k):.1e}" for k in COMPARED)
        closure = max((abs(r["energy_closure"]) for r in rs
                       if r["energy_closure"] is not None), default=float("nan"))
        errors = sum(r["error"] is not None for r in rs)
        print(f"step cap {c:g} s" + ("" if c == own else
                                     f" (output period {own_period or own:g} s)")
              + f": wall {wall:.1f} s ({wall / wall0:.2f} of the plan's cap); the plan's "
              f"cap's outcome {len(same)} of {len(rs)}"
              + (f" ({errors} ended in an error)" if errors else "")
              + f"; largest relative difference among those: {diffs}; largest energy-ledger "
              f"closure {closure:.1e}", flush=True)


if __name__ == "__main__":
    main()
