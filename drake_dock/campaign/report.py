"""The end of a campaign: ``summary.json`` (outcome counts, capture probability with its 95 %
Wilson interval, statistics of the loads and the capture time, the errors by kind) and the worst
samples, each with its scenario file in ``worst/`` and the command that re-runs it alone with
full outputs."""
from __future__ import annotations

import collections
import math

import numpy as np
from pydrake.common.yaml import yaml_dump_typed

from drake_dock.campaign.progress import ORDER
from drake_dock.campaign.sample import sample_scenario
from drake_dock.campaign.store import atomic_write

Z95 = 1.959963984540054
WORST_PER_KIND = 3       # the largest of each load, the slowest captures
WORST_FAILED = 5         # named outcomes other than captured; errors


def wilson(k: int, n: int) -> list[float] | None:
    """The 95 % Wilson score interval of a proportion k / n."""
    if n == 0:
        return None
    p, z2 = k / n, Z95 ** 2
    centre = (p + z2 / (2 * n)) / (1 + z2 / n)
    half = Z95 * math.sqrt(p * (1 - p) / n + z2 / (4 * n * n)) / (1 + z2 / n)
    return [max(centre - half, 0.0), min(centre + half, 1.0)]


def stats(values) -> dict | None:
    v = np.asarray([x for x in values if x is not None], float)
    if not v.size:
        return None
    return {"median": float(np.median(v)), "p95": float(np.percentile(v, 95)),
            "max": float(v.max()), "samples": int(v.size)}


def row_values(row: dict, fields) -> dict:
    """The sample's {path: value} read back from its row's input columns."""
    out = {}
    for f in fields:
        vals = [row[c] for c in f.columns]
        out[f.path] = vals if f.size else vals[0]
    return out


def worst_samples(rows: list[dict]) -> list[tuple[dict, str]]:
    """(row, why) of the samples to look at: the largest peak contact force, Stewart force and
    stroke, the slowest captures, then the first failures (not captured, errors)."""
    picked, out = set(), []

    def take(candidates, why, key=None, count=WORST_PER_KIND):
        ranked = sorted(candidates, key=key, reverse=True) if key else candidates
        for r in ranked[:count]:
            if r["sample"] not in picked:
                picked.add(r["sample"])
                out.append((r, why))

    ok = [r for r in rows if r["outcome"] != "error"]
    for col, why in (("peak_contact_force", "largest peak contact force"),
                     ("peak_stewart_force", "largest peak Stewart force"),
                     ("peak_stewart_stroke", "largest peak Stewart stroke")):
        take(ok, why, key=lambda r, c=col: (r[c], -r["sample"]))
    take([r for r in ok if r["outcome"] == "captured"], "slowest capture",
         key=lambda r: (r["capture_time"], -r["sample"]))
    take([r for r in ok if r["outcome"] != "captured"], "not captured", count=WORST_FAILED)
    take([r for r in rows if r["outcome"] == "error"], "error", count=WORST_FAILED)
    return out


def summarize(rows: list[dict], plan, fields, base, root, out_text: str) -> dict:
    """summary.json's content; writes the worst samples' scenarios into ``root / worst``."""
    n = len(rows)
    counts = collections.Counter(r["outcome"] for r in rows)
    named = n - counts["error"]
    errors = collections.Counter(r["reason"] for r in rows if r["outcome"] == "error")
    worst = []
    (root / "worst").mkdir(exist_ok=True)
    for row, why in worst_samples(rows):
        name = f"sample_{row['sample']:07d}"
        scenario = sample_scenario(base, row_values(row, fields))
        atomic_write(root / "worst" / f"{name}.yaml",
                     (f"# campaign sample {row['sample']}: {why}\n" + yaml_dump_typed(scenario))
                     .encode())
        worst.append({"sample": row["sample"], "why": why, "outcome": row["outcome"],
                      "peak_contact_force_N": row["peak_contact_force"],
                      "peak_stewart_force_N": row["peak_stewart_force"],
                      "capture_time_s": row["capture_time"], "error": row["error"],
                      "scenario": f"worst/{name}.yaml",
                      "command": f"drake-dock run {out_text}/worst/{name}.yaml "
                                 f"--out {out_text}-{name}"})
    wall = [r["wall_time"] for r in rows if r["wall_time"] is not None]
    return {
        "samples": n, "seed": plan.seed, "sampler": plan.sampler,
        "varied": [f.path for f in fields],
        "outcomes": {k: counts[k] for k in ORDER},
        "capture_probability": counts["captured"] / named if named else None,
        "capture_probability_95": wilson(counts["captured"], named),
        "capture_probability_note": "over the samples with a named outcome (errors excluded)",
        "capture_time_s": stats(r["capture_time"] for r in rows if r["outcome"] == "captured"),
        "peak_contact_force_N": stats(r["peak_contact_force"] for r in rows),
        "peak_stewart_force_N": stats(r["peak_stewart_force"] for r in rows),
        "peak_stewart_stroke_m": stats(r["peak_stewart_stroke"] for r in rows),
        "errors_by_kind": dict(sorted(errors.items())),
        "sample_wall_time_s": stats(wall),
        "worst": worst,
    }
