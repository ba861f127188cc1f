"""Dask-distributed simulation: bit-identical to in-process, robust to a lost worker."""

import os
import signal
import sys
import threading
import time
import warnings

import numpy as np
import pytest
from distributed import Client, LocalCluster

from ddmm.models.engines import SpikeCapWarning
from ddmm.population import birznieks, press_push_lift, sample_population, simulate


@pytest.fixture(scope="module")
def client():
    with LocalCluster(n_workers=2, threads_per_worker=1, processes=True, dashboard_address=None) as cluster, \
            Client(cluster) as c:
        yield c


@pytest.fixture(scope="module")
def pop():
    return sample_population("fingertip", rng=1).select(np.arange(0, 991, 4))  # 248 afferents, noisy


@pytest.mark.parametrize("engine", ["direct", "brian2"])
def test_bit_identical_to_in_process(client, pop, engine):
    scenes = [birznieks(90.0), birznieks(None)]
    ref = simulate(pop, scenes, engine=engine, seed=4, trials=2, quiet=True)
    for chunk in (40, 239):
        ds = simulate(pop, scenes, engine=engine, seed=4, trials=2, quiet=True, chunk_size=chunk, scheduler=client)
        assert ds.identical(ref)


def test_multi_site_runs_are_identical_on_workers(client, pop):
    from ddmm.population.stimuli.site_scenes import torsion

    scenes = [torsion(5.0, 3.0, direction=d, hold_s=0.1, name=f"t{d}") for d in (1, -1)]
    ref = simulate(pop, scenes, engine="direct", seed=4, trials=2, quiet=True)
    ds = simulate(pop, scenes, engine="direct", seed=4, trials=2, quiet=True, chunk_size=60, scheduler=client)
    assert ds.identical(ref) and ref.spike_count.sum() > 100


def test_workers_keep_their_own_brian2_cache(client, pop):
    simulate(pop.select(range(20)), birznieks(90.0), engine="direct", seed=4, quiet=True, scheduler=client)  # plugin
    dirs = client.run(lambda: os.environ.get("DDMM_CACHE_DIR"))
    assert len(set(dirs.values())) == 2 and all("workers" in d for d in dirs.values())


def test_local_processes_scheduler(pop):
    ref = simulate(pop, birznieks(45.0), engine="direct", seed=2, quiet=True)
    assert simulate(pop, birznieks(45.0), engine="direct", seed=2, quiet=True, chunk_size=80,
                    scheduler="processes").identical(ref)


def test_unreachable_scheduler_fails_fast(pop):
    start = time.perf_counter()
    with pytest.raises(ValueError, match="unreachable"):
        simulate(pop, birznieks(45.0), engine="direct", scheduler="tcp://127.0.0.1:9", quiet=True)
    assert time.perf_counter() - start < 15.0
    with pytest.raises(TypeError, match="scheduler"):
        simulate(pop, birznieks(45.0), engine="direct", scheduler=3, quiet=True)


def test_lost_worker_is_retried(client, pop):
    scene = press_push_lift(90.0)
    with warnings.catch_warnings():
        warnings.simplefilter("ignore", SpikeCapWarning)  # a few RA afferents cap at shear onset; not the point
        ref = simulate(pop, scene, engine="direct", seed=6, quiet=True)
    out = {}
    runner = threading.Thread(target=lambda: out.update(
        ds=simulate(pop, scene, engine="direct", seed=6, quiet=True, chunk_size=16, scheduler=client)))
    runner.start()
    deadline = time.time() + 60
    while time.time() < deadline and not any(client.processing().values()):
        time.sleep(0.05)
    busy = [w for w, tasks in client.processing().items() if tasks]
    assert busy, "no task started"
    pid = client.run(os.getpid, workers=[busy[0]])[busy[0]]
    os.kill(pid, signal.SIGKILL)
    runner.join(timeout=300)
    assert "ds" in out and out["ds"].identical(ref)


def test_missing_dask_extra_is_one_line_error(pop, monkeypatch):
    monkeypatch.setitem(sys.modules, "distributed", None)  # as if the [dask] extra were not installed
    with pytest.raises(ImportError, match=r'pip install "ddmm\[dask\]"'):
        simulate(pop.select(range(4)), birznieks(90.0), engine="direct", quiet=True, scheduler="processes")
