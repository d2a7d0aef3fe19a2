"""A whole campaign: the plan loaded and checked, the directory opened (resuming what it holds),
the missing samples run on Dask in batches, each finished batch saved as a part, then
``results.parquet``, ``summary.json``, the figures and the worst samples' scenarios."""
from __future__ import annotations

import json
from pathlib import Path

import yaml
from pydrake.common.yaml import yaml_dump_typed

from drake_dock.campaign.execute import dask_client, run_on_dask, threads
from drake_dock.campaign.figures import capture_probability_figure, histograms_figure
from drake_dock.campaign.plan import figure_axes, load_plan
from drake_dock.campaign.progress import CampaignProgress
from drake_dock.campaign.report import summarize
from drake_dock.campaign.sample import run_batch
from drake_dock.campaign.points import sample_specs
from drake_dock.campaign.store import CampaignStore, atomic_write
from drake_dock.errors import InputError

MAX_WORKERS = 1024
FIGURES = ("capture_probability.png", "histograms.png")


def plan_identity(plan, base) -> dict:
    """What makes two campaigns the same (plan.json): the samples, seed, sampler,
    distributions and the whole base scenario; not the batch size, the figure's axes or the
    plan's file name, which change no row."""
    ident = {"samples": plan.samples, "seed": plan.seed, "sampler": plan.sampler,
             "vary": {p: {d.kind: getattr(d, d.kind)} for p, d in sorted(plan.vary.items())},
             "scenario": yaml.safe_load(yaml_dump_typed(base))}
    return json.loads(json.dumps(ident))


def batch_size(batch: int, samples: int, workers: int) -> int:
    """The plan's batch, smaller when there are too few samples to give every worker four
    batches (no row depends on it)."""
    return max(1, min(batch, -(-samples // (4 * workers))))


def _check_options(workers, scheduler):
    if workers is not None and (isinstance(workers, bool) or not 1 <= workers <= MAX_WORKERS):
        raise InputError("--workers", workers, f"1 <= N <= {MAX_WORKERS}")
    if workers is not None and scheduler is not None:
        raise InputError("--workers", workers, "not given with --scheduler (the cluster's "
                         "workers are started with `dask worker`)")


def run_campaign(plan_file, out, *, workers=None, scheduler=None, resume=False, progress=None,
                 runner=run_batch, window=None, ready=None) -> dict:
    """Runs (or resumes) the campaign of ``plan_file`` into ``out``; returns the summary.
    ``runner(base, specs) -> rows`` is the Dask task (`run_batch`); ``ready()``, if given, is
    called once the plan and ``out`` are checked, before the cluster starts, when samples are
    to run (the command line's: the kernels compiled meanwhile, loaded from the cache by the
    local workers)."""
    _check_options(workers, scheduler)
    plan, base, fields = load_plan(plan_file)
    store = CampaignStore(out, plan_identity(plan, base),
                          [c for f in fields for c in f.columns]).check(resume=resume)
    progress = progress or CampaignProgress()
    missing = [i for i in range(plan.samples) if i not in store.done]
    specs = sample_specs(plan, fields, missing)
    if not specs:
        store.create()
        progress.start(plan.samples, plan.samples)
    else:
        if ready is not None:
            ready()
        with dask_client(workers, scheduler) as client:    # connected before DIR is written
            store.create()
            progress.start(plan.samples, plan.samples - len(missing))
            size = batch_size(plan.batch, len(specs), threads(client))
            batches = [specs[k:k + size] for k in range(0, len(specs), size)]
            run_on_dask(client, runner, base, batches,
                        lambda rows: progress.update(store.write_part(rows)), window=window)
    progress.close()
    table = store.table()
    store.write_results(table)
    rows = table.to_pylist()
    summary = summarize(rows, plan, fields, base, store.root, str(out))
    columns = table.to_pydict()
    capture_probability_figure(columns, figure_axes(plan, fields),
                               store.root / FIGURES[0])
    histograms_figure(columns, store.root / FIGURES[1])
    summary["figures"] = list(FIGURES)
    atomic_write(store.root / "summary.json",
                 (json.dumps(summary, indent=2, allow_nan=False) + "\n").encode())
    store.write_marker()
    return summary


def summary_lines(summary: dict) -> list[str]:
    """What the command prints at the end."""
    counts = ", ".join(f"{k} {v}" for k, v in summary["outcomes"].items() if v)
    p, ci = summary["capture_probability"], summary["capture_probability_95"]
    lines = [f"{summary['samples']} samples: {counts}"]
    if p is not None:
        lines.append(f"capture probability {p:.3f} (95 % interval {ci[0]:.3f}-{ci[1]:.3f}) "
                     f"over the samples with a named outcome")
    for kind, n in summary["errors_by_kind"].items():
        lines.append(f"errors: {n} x {kind} (messages in results.parquet, column error)")
    if summary["worst"]:
        w = summary["worst"][0]
        lines.append(f"worst samples in summary.json; e.g. {w['why']}: {w['command']}")
    return lines


def interrupted_text(out) -> str:
    saved = 0
    parts = Path(out) / "parts"
    if parts.is_dir():
        import pyarrow.parquet as pq
        saved = sum(pq.read_metadata(p).num_rows for p in parts.glob("part-*.parquet"))
    return f"{saved} samples saved in {out}; the same command (or --resume) runs the others"
