"""`run_on_dask`'s crash-isolation rules, deterministically, on an in-process cluster (threads)
whose runner fails the way a dead worker does: a batch holding the killer sample fails whole,
and an innocent sample fails once more when it is sent alone beside other work. The rules
(docs/campaigns.md, "Crash isolation"): a lost batch is split into single samples; a single
sample lost is run again with nothing else in flight; only a sample that fails alone is an
error row. The rows are checked against an independent tally of what was submitted."""
import threading

import pytest

pytest.importorskip("distributed")

from drake_dock.campaign.execute import run_on_dask  # noqa: E402

KILLER, UNLUCKY = 5, 6          # in the same batch of four


class DeadWorker(RuntimeError):
    """What `future.result()` raises for a task whose worker died (KilledWorker and such)."""


class Runner:
    """Returns one row per sample; a batch holding KILLER always dies; UNLUCKY dies the first
    time it runs as a single sample (a neighbour killed its worker). Records every call. The
    state lives in the module (the cluster's threads share it; tasks are pickled by name)."""

    calls: list = []
    lock = threading.Lock()
    unlucky_left = [1]

    @classmethod
    def reset(cls):
        cls.calls.clear()
        cls.unlucky_left[0] = 1

    @staticmethod
    def run(base, batch):
        samples = [spec[0] for spec in batch]
        with Runner.lock:
            Runner.calls.append(samples)
            if KILLER in samples:
                raise DeadWorker(f"worker died running {samples}")
            if samples == [UNLUCKY] and Runner.unlucky_left[0]:
                Runner.unlucky_left[0] -= 1
                raise DeadWorker("worker died beside the killer")
        return [{"sample": s, "seed": s, "outcome": "captured", "error": None}
                for s in samples]


@pytest.fixture(scope="module")
def client():
    from distributed import Client, LocalCluster
    with LocalCluster(n_workers=2, threads_per_worker=1, processes=False,
                      dashboard_address=":0", scheduler_kwargs={"dashboard": False}) as cluster, \
            Client(cluster) as c:
        yield c


def test_killer_alone_is_the_only_error_row(client):
    specs = [(k, k, {"initial.chaser_speed": 0.05 + 0.001 * k}) for k in range(12)]
    batches = [specs[k:k + 4] for k in range(0, 12, 4)]
    runner, rows = Runner, []
    runner.reset()
    run_on_dask(client, runner.run, None, batches, rows.extend, window=2)
    by_sample = {}
    for r in rows:
        assert r["sample"] not in by_sample, f"sample {r['sample']} has two rows"
        by_sample[r["sample"]] = r
    assert sorted(by_sample) == list(range(12))
    errors = [s for s, r in by_sample.items() if r["error"] is not None]
    assert errors == [KILLER]
    assert by_sample[KILLER]["reason"] == "worker died"
    assert "DeadWorker" in by_sample[KILLER]["error"]
    assert by_sample[KILLER]["initial.chaser_speed"] == pytest.approx(0.055)
    # The killer's batch was split into single samples, and both lost singles ran again last,
    # each alone (nothing else is in flight then, so they are the last two calls).
    assert [[4], [7]] == [c for c in runner.calls if c in ([4], [7])]
    assert runner.calls.count([UNLUCKY]) == 2 and runner.unlucky_left == [0]
    assert sorted(runner.calls[-2:]) == [[KILLER], [UNLUCKY]]


def test_a_batch_that_succeeds_is_sent_once(client):
    specs = [(k, k, {}) for k in range(20, 28)]
    runner, rows = Runner, []
    runner.reset()
    run_on_dask(client, runner.run, None, [specs[:4], specs[4:]], rows.extend)
    assert sorted(r["sample"] for r in rows) == list(range(20, 28))
    assert sorted(map(tuple, runner.calls)) == [tuple(range(20, 24)), tuple(range(24, 28))]
