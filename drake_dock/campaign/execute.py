"""Runs batches of samples on Dask distributed: a `LocalCluster` of single-threaded worker
processes (Drake's Python systems hold the GIL: threads do not help) or, given its address, an
existing cluster's scheduler; nothing else differs.

Batches go out through a bounded window of futures in flight (twice the workers' threads), so
that a campaign of any size keeps the scheduler small. Crash isolation
(`CRASH_ISOLATION`): a task whose worker process dies is not retried on another worker
(``allowed-failures: 0``) and no task waits queued behind it on that worker
(``worker-saturation: 1.0``). The samples of a batch lost that way are sent again one per task,
and a single sample lost so is run once more with nothing else in flight: a sample whose
worker dies then is its row's error, with the cause, and the campaign goes on.
For a cluster started by hand the scheduler must be given the same settings (docs/campaigns.md).
"""
from __future__ import annotations

import collections
import contextlib
import logging
import os

from drake_dock.campaign.sample import failed, input_columns
from drake_dock.errors import InputError

CRASH_ISOLATION = {"distributed.scheduler.allowed-failures": 0,
                   "distributed.scheduler.worker-saturation": 1.0}
CONNECT_TIMEOUT = "30s"


def default_workers() -> int:
    """One worker per core this process may use."""
    try:
        return len(os.sched_getaffinity(0))
    except AttributeError:              # not on Linux
        return os.cpu_count() or 1


@contextlib.contextmanager
def dask_client(workers: int | None = None, scheduler: str | None = None):
    """A Dask client on a new LocalCluster of ``workers`` single-threaded processes (default:
    one per core), or on the running scheduler at ``scheduler``; closed on leaving."""
    import dask
    from distributed import Client, LocalCluster
    with dask.config.set(CRASH_ISOLATION), contextlib.ExitStack() as stack:
        if scheduler is None:
            n = default_workers() if workers is None else workers
            cluster = stack.enter_context(LocalCluster(
                n_workers=n, threads_per_worker=1, processes=True,
                # The scheduler's HTTP server (health and metrics routes, no dashboard) on a
                # free port: another cluster on Dask's default 8787 is no collision.
                dashboard_address=":0", scheduler_kwargs={"dashboard": False},
                silence_logs=logging.CRITICAL))
            client = stack.enter_context(Client(cluster))
        else:
            try:
                client = stack.enter_context(Client(scheduler, timeout=CONNECT_TIMEOUT))
            except (OSError, TimeoutError, ValueError) as e:
                raise InputError("--scheduler", scheduler, "the address of a running Dask "
                                 "scheduler (tcp://HOST:8786)", str(e)) from None
        yield client


def threads(client) -> int:
    """The cluster's worker threads (one per worker process here)."""
    return max(sum(client.nthreads().values()), 1)


def worker_death(spec, error) -> dict:
    """The row of a sample whose worker process died running it alone."""
    sample, seed, values = spec
    row = {"sample": int(sample), "seed": int(seed), **input_columns(values)}
    row.update(failed(f"the worker process running this sample died ({type(error).__name__}:"
                      f" {error})"[:2000], "worker died"))
    row["wall_time"] = None
    return row


def run_on_dask(client, runner, base, batches, on_rows, *, window: int | None = None):
    """Submits ``runner(base, batch) -> rows`` for each batch of sample specs, at most
    ``window`` in flight (default: twice the cluster's threads), and calls ``on_rows(rows)`` in
    the driver as each finishes. A batch lost with its worker is split into single samples. A
    single sample lost so may have shared its worker with the one that killed it: it is run
    again alone, with nothing else in flight, and only a sample whose worker dies then is
    recorded as an error row."""
    from distributed import as_completed
    pending = collections.deque(batches)
    suspects = collections.deque()
    window = window or 2 * threads(client)
    inflight, alone = {}, set()
    done = as_completed()

    def send(batch):
        future = client.submit(runner, base, batch, pure=False)
        inflight[future.key] = batch
        done.add(future)
        return future.key

    def submit():
        while pending and len(inflight) < window:
            send(pending.popleft())
        if suspects and not pending and not inflight:
            alone.add(send([suspects.popleft()]))

    submit()
    for future in done:
        batch = inflight.pop(future.key)
        rows = []
        try:
            rows = future.result()
        except Exception as e:  # noqa: BLE001 - a worker that died (KilledWorker) and such
            if len(batch) > 1:
                pending.extendleft([spec] for spec in reversed(batch))
            elif future.key in alone:
                rows = [worker_death(batch[0], e)]
            else:
                suspects.append(batch[0])
        finally:
            future.release()
        if rows:
            on_rows(rows)
        submit()
