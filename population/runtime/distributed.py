"""Running a simulation's afferent blocks as Dask tasks.

`simulate(..., scheduler=...)` accepts ``None`` (in-process, the default),
``"processes"`` (a `distributed.LocalCluster` with one single-threaded
worker process per core), a `distributed.Client`, or a scheduler address
(``"tcp://host:8786"``).  Every afferent block is one task; blocks are
independent and deterministic (noise streams are keyed by afferent id), so
the Dataset is bit-identical whatever the number of workers or the chunk
size.  A worker lost mid-run is Dask's business: its tasks are recomputed
elsewhere, with the same result.

Each worker gets, through a worker plugin, its own Brian2 build directory
(``$DDMM_CACHE_DIR/workers/<name>``, so concurrent compiles never collide), a
thread count for the direct engine (``DDMM_NUM_THREADS``, one per worker
thread by default), and the engine imported in its main thread.
"""

from __future__ import annotations

import os
from contextlib import contextmanager

__all__ = ["DdmmWorkerPlugin", "dask_client", "run_distributed"]


def _plugin_base():
    from distributed.diagnostics.plugin import WorkerPlugin

    return WorkerPlugin


class DdmmWorkerPlugin(_plugin_base()):
    """Per-worker set-up: own Brian2 cache, thread count, engine imported in the main thread."""

    name = "ddmm"

    def __init__(self, engine: str, cache_root: str, threads: int | None = None):
        self.engine, self.cache_root, self.threads = engine, cache_root, threads

    def setup(self, worker):
        safe = "".join(ch if ch.isalnum() else "_" for ch in str(worker.name))
        os.environ["DDMM_CACHE_DIR"] = os.path.join(self.cache_root, "workers", safe)
        os.environ["DDMM_NUM_THREADS"] = str(self.threads or max(1, worker.state.nthreads))
        from ddmm.models.engines import prepare

        prepare(self.engine)


@contextmanager
def dask_client(scheduler):
    """A connected `distributed.Client` for ``scheduler``; closes what it opened."""
    from distributed import Client, LocalCluster

    if isinstance(scheduler, Client):
        yield scheduler
        return
    if scheduler == "processes":
        with LocalCluster(n_workers=os.cpu_count() or 1, threads_per_worker=1, processes=True,
                          dashboard_address=None) as cluster, Client(cluster) as client:
            yield client
        return
    if not isinstance(scheduler, str):
        raise TypeError(f"scheduler must be None, 'processes', a distributed.Client or an address, "
                        f"got {type(scheduler).__name__}")
    try:
        client = Client(scheduler, timeout="5s")
    except (OSError, TimeoutError, ValueError) as exc:
        raise ValueError(f"scheduler={scheduler!r} is unreachable: {exc}") from None
    try:
        yield client
    finally:
        client.close()


def run_distributed(client, jobs, config, run_chunk, progress=None) -> list:
    """Submit one task per job; return the results in job order."""
    from distributed import as_completed

    from ddmm.utils.cache import cache_root

    client.register_plugin(DdmmWorkerPlugin(config.engine, str(cache_root())), name="ddmm")
    futures = [client.submit(run_chunk, job, config, pure=False) for job in jobs]
    work = {f.key: len(j.population) * j.scene.n_samples * len(j.trials) for f, j in zip(futures, jobs)}
    for future in as_completed(futures):
        if progress is not None:
            progress(work[future.key])
    return client.gather(futures)
