"""A sweep's cells on Dask: a LocalCluster of processes, or a running cluster (docs/planning.md).

Needs the optional extra ``plansim[dask]`` (``dask.distributed``). How it runs:

- **Compiled once before fanning out.** The first cell runs alone on one worker: it compiles the
  numba kernels and writes numba's on-disk cache, which the other workers then read. Workers that
  compile side by side write the same cache files at once, and that crashes them.
- **One thread per worker**, ``NUMBA_NUM_THREADS=1`` in each: the processes are the parallelism, and
  the kernels' own threads would only compete with them.
- **Batches of about a second or more**: cells are grouped so that each task takes at least
  :data:`BATCH_SECONDS` (judged by the first cell's time), since a task's scheduling costs some
  milliseconds.
- **A failed cell** raises a ValueError naming it (the remote error's type and text) and the
  remaining tasks are cancelled; the sweep returns nothing.

Results do not depend on the workers: each cell's numbers come from its scenario and its seed.
"""

from __future__ import annotations

import math
import os
import time

#: the least time a task should take, s
BATCH_SECONDS = 1.0
#: the environment of each LocalCluster worker
WORKER_ENVIRONMENT = {"NUMBA_NUM_THREADS": "1", "OMP_NUM_THREADS": "1", "OPENBLAS_NUM_THREADS": "1",
                      "MKL_NUM_THREADS": "1"}


class _Failed:
    """A cell that raised on a worker: its index and the error, returned in place of its result so that the
    submitting side can name the cell whatever the batch it ran in."""

    def __init__(self, index: tuple, error: Exception):
        self.index, self.error = index, error


def _batch(function, tasks):
    out = []
    for task in tasks:
        try:
            out.append(function(*task))
        except Exception as error:  # named on the submitting side; an interruption ends the worker's task
            out.append(_Failed(task[1], error))
            break
    return out


def _client(workers, scheduler):
    try:
        from dask.distributed import Client, LocalCluster
    except ImportError:
        raise ValueError("executor 'dask' needs dask.distributed: pip install 'plansim[dask]' "
                         "(or choose --executor serial or threads)") from None
    if scheduler is not None:
        try:
            return Client(scheduler, timeout="30s"), None
        except (OSError, TimeoutError) as error:
            raise ValueError(f"scheduler {scheduler!r}: cannot connect ({error})") from None
    cluster = LocalCluster(n_workers=workers or os.cpu_count() or 1, threads_per_worker=1, processes=True,
                           dashboard_address=None, env=dict(WORKER_ENVIRONMENT), silence_logs=40)
    return Client(cluster), cluster


def run_on_dask(tasks, function, workers, scheduler, tick, name_error) -> list:
    """``function(*task)`` for every task on Dask, in the tasks' order; ``tick()`` after each cell;
    ``name_error(index, error)`` makes a failed cell's ValueError (``task[1]`` is the cell's index)."""
    client, cluster = _client(workers, scheduler)
    futures = []
    try:
        start = time.perf_counter()
        first = client.submit(_batch, function, tasks[:1], pure=False)
        futures.append(first)
        results = _gather(first, name_error)
        tick()
        per_cell = max(time.perf_counter() - start, 1e-3)
        size = max(1, math.ceil(BATCH_SECONDS / per_cell))
        rest = tasks[1:]
        batches = [rest[k:k + size] for k in range(0, len(rest), size)]
        futures = [client.submit(_batch, function, batch, pure=False) for batch in batches]
        for batch, future in zip(batches, futures):
            results.extend(_gather(future, name_error))
            for _ in batch:
                tick()
        return results
    finally:
        for future in futures:
            future.cancel()
        client.close()
        if cluster is not None:
            cluster.close()


def _gather(future, name_error) -> list:
    """A batch's results; a failed cell raises ``name_error(index, error)``."""
    results = future.result()
    for result in results:
        if isinstance(result, _Failed):
            raise name_error(result.index, result.error) from result.error
    return results
