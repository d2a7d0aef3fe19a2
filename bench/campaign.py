"""Campaign throughput on this machine, and the projected 10,000-sample IDSS campaign.

Measured in one run: the first ``--samples`` samples of the IDSS envelope plan
(models/idss_envelope.yaml) on a local Dask cluster of each ``--workers`` count in turn (1,
then 2), each a whole campaign (`run_campaign`). Prints each configuration's samples per
minute (the whole campaign), the samples' own wall times (median and range) and their
outcomes; then the throughput ratio of the last configuration to the first (the ideal for 1
and 2 workers on 2 free cores is 2). A campaign's wall time is a fixed part (reading the plan,
the cluster's start; then its shutdown, the results and figures, which grow a little with the
samples) and the samples' part, from the cluster's
start to the last batch saved (the campaign's progress, which also holds each worker's first
loads); the projected wall time of 1,000 and of 10,000 samples with the last configuration's
workers is the fixed part plus their samples at the samples' part's rate, beside the whole
campaign's plain rate (its fixed part spread over its few samples). The target (10,000
samples on 2 cores in at most 2 h) is checked on the projection; it is measured only when the
last ``--workers`` count is 2.

    python bench/campaign.py [--samples 8] [--workers 1 2]
"""
import argparse
import io
import statistics
import tempfile
import time
from pathlib import Path

import pyarrow.parquet as pq
import yaml

from drake_dock.campaign.campaign import run_campaign
from drake_dock.campaign.progress import CampaignProgress, duration_text
from drake_dock.docking.scenario.models_dir import MODELS_DIR

PLAN = MODELS_DIR / "idss_envelope.yaml"


def plan_with(samples: int, where: Path) -> Path:
    """The IDSS plan cut to its first ``samples`` samples (the same points: sample i of the
    edges sampler does not depend on the number of samples)."""
    raw = yaml.safe_load(PLAN.read_text())
    raw["samples"] = samples
    raw["scenario"] = str(MODELS_DIR / raw["scenario"])
    path = where / "plan.yaml"
    path.write_text(yaml.safe_dump(raw))
    return path


class Clock(CampaignProgress):
    """The campaign's progress, silent, with the time of its last batch saved (its start, the
    cluster connected, is the progress's own ``t0``)."""

    def __init__(self):
        super().__init__(io.StringIO())
        self.last_saved = None

    def update(self, rows):
        super().update(rows)
        self.last_saved = time.perf_counter()


def measure(samples: int, workers: int, where: Path) -> dict:
    plan = plan_with(samples, where)
    out = where / f"out-{workers}"
    clock = Clock()
    t0 = time.perf_counter()
    summary = run_campaign(plan, out, workers=workers, progress=clock)
    wall = time.perf_counter() - t0
    rows = pq.read_table(out / "results.parquet").to_pylist()
    running = clock.last_saved - clock.t0
    return {"workers": workers, "wall": wall, "rate": samples / wall * 60.0,
            "per_sample": running / samples, "fixed": wall - running,
            "sample_walls": [r["wall_time"] for r in rows if r["wall_time"] is not None],
            "outcomes": {k: v for k, v in summary["outcomes"].items() if v}}


def main():
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--samples", type=int, default=8)
    ap.add_argument("--workers", type=int, nargs="+", default=[1, 2])
    args = ap.parse_args()
    results = []
    with tempfile.TemporaryDirectory(prefix="drake_dock-bench-campaign-") as tmp:
        for w in args.workers:
            where = Path(tmp) / f"w{w}"
            where.mkdir()
            r = measure(args.samples, w, where)
            results.append(r)
            walls = r["sample_walls"]
            print(f"{w} worker(s): {args.samples} samples in {r['wall']:.1f} s = "
                  f"{r['rate']:.2f} samples/min; per sample median {statistics.median(walls):.2f}"
                  f" s (range {min(walls):.2f}-{max(walls):.2f} s); outcomes {r['outcomes']}",
                  flush=True)
    base, last = results[0], results[-1]
    w = last["workers"]
    print(f"throughput ratio {w} : {base['workers']} workers = "
          f"{last['rate'] / base['rate']:.2f}")
    print(f"{w} worker(s): the samples' part {last['per_sample'] * args.samples:.1f} s "
          f"({last['per_sample']:.2f} s a sample), the fixed part {last['fixed']:.1f} s")
    for n in (1000, 10000):
        print(f"projected {n} samples with {w} workers: "
              f"{duration_text(last['fixed'] + n * last['per_sample'])} (at the whole "
              f"campaign's plain rate: {duration_text(n / last['rate'] * 60.0)})")
    hours = (last["fixed"] + 10000 * last["per_sample"]) / 3600.0
    print(f"target: the 10,000-sample IDSS campaign on 2 cores in at most 2 h: "
          + ("met" if hours <= 2.0 and w == 2
             else f"NOT met ({hours / 2.0:.1f}x over)" if w == 2
             else "not measured (2 workers needed)"))


if __name__ == "__main__":
    main()
