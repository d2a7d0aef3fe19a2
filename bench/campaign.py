"""Campaign throughput on this machine, and the projected 10,000-sample IDSS campaign.

Measured in one run: the first ``--samples`` samples of the IDSS envelope plan
(models/idss_envelope.yaml) on a local Dask cluster of each ``--workers`` count in turn (1,
then 2). Prints each configuration's samples per minute (cluster start included), the
samples' own wall times (median and range) and their outcomes; then the throughput ratio of
the last configuration to the first (the ideal for 1 and 2 workers on 2 free cores is 2), the
projected wall time of 1,000 and 10,000 samples with the last configuration's workers, and
whether the target (10,000 samples on 2 cores in at most 2 h) is met; it is measured only
when the last ``--workers`` count is 2.

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


def measure(samples: int, workers: int, where: Path) -> dict:
    plan = plan_with(samples, where)
    out = where / f"out-{workers}"
    t0 = time.perf_counter()
    summary = run_campaign(plan, out, workers=workers, progress=CampaignProgress(io.StringIO()))
    wall = time.perf_counter() - t0
    rows = pq.read_table(out / "results.parquet").to_pylist()
    return {"workers": workers, "wall": wall, "rate": samples / wall * 60.0,
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
    print(f"throughput ratio {last['workers']} : {base['workers']} workers = "
          f"{last['rate'] / base['rate']:.2f}")
    for n in (1000, 10000):
        print(f"projected {n} samples with {last['workers']} workers: "
              f"{duration_text(n / last['rate'] * 60.0)}")
    hours = 10000 / last["rate"] / 60.0
    print(f"target: the 10,000-sample IDSS campaign on 2 cores in at most 2 h: "
          + ("met" if hours <= 2.0 and last["workers"] == 2
             else f"NOT met ({hours / 2.0:.1f}x over)" if last["workers"] == 2
             else "not measured (2 workers needed)"))


if __name__ == "__main__":
    main()
