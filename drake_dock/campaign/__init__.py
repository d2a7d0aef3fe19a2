"""Capture-envelope campaigns: many seeded working conditions around a base scenario, run on
Dask (one machine or a cluster), saved as Parquet parts, resumable, summed up in figures.

Modules, one job each: `plan` (the plan file, typed and validated), `points` (unit points
with scipy.stats.qmc and their mapping to scenario values), `sample` (one sample run to a plain
row), `store` (the campaign directory: parts written atomically, resume), `execute` (Dask with a
bounded window of futures, crash isolation), `progress`, `report` (summary.json, worst
samples), `figures`, and `campaign` (the whole run, used by ``drake-dock campaign``).
"""
