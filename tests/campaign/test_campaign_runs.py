"""Campaigns on Dask: the parallel rows equal a serial run of the same samples on fresh
Diagrams, an interrupted campaign resumes with every sample exactly once, and a sample that
kills its worker process is an error row while every other sample completes.

The samples are short (0.05 s of the paper's example at 0.8 or 1.0 m/s: first contact, impacts).
Two closing speeds only, so that a worker's batch of three runs at least two samples on the same
Diagram (`drake_dock.campaign.sample.diagram_for`), which the serial run builds afresh each time."""
import io
import math
import os
import sys

import cloudpickle
import pyarrow.parquet as pq
import pytest

SAMPLES = 8
DOOMED = 2          # the sample whose worker process dies (the test hook below)


def write_plan(tmp_path, samples, batch, sampler="sobol"):
    (tmp_path / "short.yaml").write_text(     # the paper's example: its 12 pairs
        "contact:\n  pairs: paper\nsimulation:\n  duration: 0.05\n  jam_time: 1.0\n")
    plan = tmp_path / "plan.yaml"
    plan.write_text(f"""scenario: short.yaml
samples: {samples}
seed: 7
sampler: {sampler}
batch: {batch}
vary:
  initial.approach_travel: {{uniform: [0.004, 0.01]}}
  initial.chaser_speed: {{choice: [0.8, 1.0]}}
  initial.target_yaw_deg: {{choice: [4.0, 5.0]}}
""")
    return plan


def quiet():
    from drake_dock.campaign.progress import CampaignProgress
    return CampaignProgress(io.StringIO())


def rows_of(out):
    return pq.read_table(out / "results.parquet").to_pylist()


def same(a, b):
    return a == b or (isinstance(a, float) and isinstance(b, float) and math.isnan(a)
                      and math.isnan(b))


@pytest.fixture(scope="module")
def scheduler():
    """A 2-worker LocalCluster with the crash-isolation settings, shared by the tests that
    reach it by address (the path of ``--scheduler``)."""
    import dask
    from distributed import LocalCluster
    import logging
    from drake_dock.campaign.execute import CRASH_ISOLATION
    with dask.config.set(CRASH_ISOLATION):
        with LocalCluster(n_workers=2, threads_per_worker=1, processes=True,
                          dashboard_address=":0", scheduler_kwargs={"dashboard": False},
                          silence_logs=logging.CRITICAL) as cluster:
            yield cluster.scheduler_address


def test_two_workers_equal_the_serial_run_row_for_row(tmp_path):
    from drake_dock.campaign.campaign import run_campaign
    from drake_dock.campaign.plan import load_plan
    from drake_dock.campaign.sample import run_sample, sample_scenario
    from drake_dock.campaign.points import sample_specs
    from drake_dock.docking.scenario.loading import load_scenario
    plan_file = write_plan(tmp_path, SAMPLES, batch=3)
    out = tmp_path / "out"
    summary = run_campaign(plan_file, out, workers=2, progress=quiet())
    rows = rows_of(out)
    plan, base, fields = load_plan(plan_file)
    serial = [run_sample(base, spec, reuse=False)          # a fresh Diagram for every sample
              for spec in sample_specs(plan, fields, list(range(SAMPLES)))]
    assert [r["sample"] for r in rows] == list(range(SAMPLES))
    for r, s in zip(rows, serial):
        assert r["outcome"] != "error", r["error"]
        assert r["impacts"] > 0                              # contact happened in every sample
        diff = {k: (r[k], s[k]) for k in s if k != "wall_time" and not same(r[k], s[k])}
        assert not diff, (r["sample"], diff)
    assert set(rows[0]) == set(serial[0])
    # Each worst sample's file is its sample's scenario (what `drake-dock run` re-runs).
    specs = dict((i, v) for i, _, v in sample_specs(plan, fields, list(range(SAMPLES))))
    assert summary["worst"]
    for w in summary["worst"]:
        assert load_scenario(out / w["scenario"]) == sample_scenario(base, specs[w["sample"]])


class StopAfter:
    """A progress sink that interrupts the campaign (as Ctrl-C would) once ``n`` samples are
    saved, and counts what it saw."""

    def __init__(self, n=None):
        self.n, self.saved, self.run = n, 0, 0

    def start(self, total, saved):
        self.saved = saved

    def update(self, rows):
        self.run += len(rows)
        if self.n is not None and self.run >= self.n:
            raise KeyboardInterrupt

    def close(self):
        pass


def test_an_interrupted_campaign_resumes_with_every_sample_once(tmp_path, scheduler):
    from drake_dock.campaign.campaign import run_campaign
    plan_file = write_plan(tmp_path, 6, batch=2)
    out = tmp_path / "out"
    with pytest.raises(KeyboardInterrupt):
        run_campaign(plan_file, out, scheduler=scheduler, progress=StopAfter(2), window=1)
    first = {p.name: p.read_bytes() for p in (out / "parts").glob("part-*.parquet")}
    done = sorted(s for p in (out / "parts").glob("part-*.parquet")
                  for s in pq.read_table(p)["sample"].to_pylist())
    assert 2 <= len(done) < 6 and not (out / "results.parquet").exists()
    again, ready = StopAfter(), []
    run_campaign(plan_file, out, scheduler=scheduler, resume=True, progress=again,
                 ready=lambda: ready.append(again.run))
    assert ready == [0]                   # once, before any sample ran
    assert (again.saved, again.run) == (len(done), 6 - len(done))
    parts = sorted((out / "parts").glob("part-*.parquet"))
    in_parts = sorted(s for p in parts for s in pq.read_table(p)["sample"].to_pylist())
    assert in_parts == list(range(6))
    assert [r["sample"] for r in rows_of(out)] == list(range(6))
    assert all(p.read_bytes() == first[p.name] for p in parts if p.name in first)
    # A third run finds nothing missing and runs nothing.
    third = StopAfter()
    run_campaign(plan_file, out, scheduler=scheduler, progress=third,
                 ready=lambda: ready.append("again"))
    assert (third.saved, third.run) == (6, 0) and ready == [0]     # nothing to run, not called


def dying_runner(base, specs):
    """The test hook: runs the batch's samples in order and kills its own worker process when
    it reaches sample DOOMED."""
    from drake_dock.campaign.sample import run_sample
    rows = []
    for spec in specs:
        if spec[0] == DOOMED:
            os._exit(13)
        rows.append(run_sample(base, spec))
    return rows


cloudpickle.register_pickle_by_value(sys.modules[__name__])   # the workers cannot import tests


def test_a_sample_that_kills_its_worker_is_an_error_and_the_rest_complete(tmp_path, scheduler):
    from drake_dock.campaign.campaign import run_campaign
    plan_file = write_plan(tmp_path, 5, batch=2)
    out = tmp_path / "out"
    summary = run_campaign(plan_file, out, scheduler=scheduler, progress=quiet(),
                           runner=dying_runner)
    rows = rows_of(out)
    assert [r["sample"] for r in rows] == list(range(5))
    bad = rows[DOOMED]
    assert bad["outcome"] == "error" and "worker process" in bad["error"], bad
    assert all(r["outcome"] != "error" and r["impacts"] > 0
               for r in rows if r["sample"] != DOOMED)
    assert summary["outcomes"]["error"] == 1
