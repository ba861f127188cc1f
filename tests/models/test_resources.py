"""The memory check before large allocations: the limit, its override, and refusals that name the job."""

import re

import numpy as np
import pytest

from ddmm.utils.resources import MEMORY_ENV, available_bytes, check_memory
from ddmm.population import birznieks, load_spec, rotating_shear, sample_population, simulate
from ddmm.population.spec import TypeSpec


def test_the_limit_is_positive_and_the_override_parses(monkeypatch):
    monkeypatch.delenv(MEMORY_ENV, raising=False)
    assert available_bytes() > 1 << 20
    for text, value in (("2G", 2 << 30), ("512M", 512 << 20), ("1000", 1000), ("1.5k", 1536), ("3GB", 3 << 30)):
        monkeypatch.setenv(MEMORY_ENV, text)
        assert available_bytes() == value
    monkeypatch.setenv(MEMORY_ENV, "lots")
    with pytest.raises(ValueError, match="DDMM_MEMORY_LIMIT must be a number of bytes"):
        available_bytes()


def test_refusals_name_the_job_the_size_and_the_remedy(monkeypatch):
    monkeypatch.setenv(MEMORY_ENV, "1G")
    with pytest.raises(ValueError, match=r"a table would need about 2 GiB, more than the 1 GiB .* fewer rows .*DDMM_MEMORY_LIMIT"):
        check_memory(2 << 30, "a table", "fewer rows")
    with pytest.raises(ValueError, match=r"a scene of 1e\+09 s at 1000 Hz .* shorten it or lower fs"):
        rotating_shear(period_s=1e9)


def test_a_middle_sized_run_is_refused_before_any_work(monkeypatch):
    """What would be OOM-killed on a machine without swap is refused with the numbers instead."""
    monkeypatch.setenv(MEMORY_ENV, "300M")
    pop = sample_population("fingertip", rng=0)
    with pytest.raises(ValueError, match=r"a run of 1 condition\(s\) x 100,000 trial\(s\) x 991 afferents"):
        simulate(pop, birznieks(90.0), engine="direct", trials=100_000, quiet=True)
    monkeypatch.setenv(MEMORY_ENV, "64G")  # the override lets a knowing user through
    assert simulate(pop.select(range(3)), birznieks(90.0), engine="direct", quiet=True).sizes["afferent"] == 3


def test_absurd_counts_and_steps_are_refused():
    with pytest.raises(ValueError, match=r"count: must be a whole number in \[0, 1,000,000\]"):
        TypeSpec(count=10_000_000)
    with pytest.raises(ValueError, match="density_per_cm2: must be <= 10000 per cm"):
        TypeSpec(density_per_cm2=1e9)
    pop = sample_population(load_spec("fingertip"), rng=0).select(range(2))
    with pytest.raises(ValueError, match=r"dt must be >= 1e-06 s"):
        simulate(pop, birznieks(90.0), engine="direct", dt=1e-9, quiet=True)
    assert np.isfinite(available_bytes())


def test_the_limit_is_the_smallest_of_cgroup_available_memory_and_address_space(monkeypatch):
    import ddmm.utils.resources as res

    monkeypatch.delenv(MEMORY_ENV, raising=False)
    sources = {"_cgroup_room": 5 << 30, "_mem_available": 7 << 30, "_address_room": 3 << 30}
    for name, value in sources.items():
        monkeypatch.setattr(res, name, lambda value=value: value)
    assert available_bytes() == 3 << 30  # the address space
    monkeypatch.setattr(res, "_address_room", lambda: None)  # no ulimit -v
    assert available_bytes() == 5 << 30  # the cgroup
    monkeypatch.setattr(res, "_cgroup_room", lambda: None)
    assert available_bytes() == 7 << 30  # MemAvailable


def test_the_address_space_limit_is_read_from_rlimit_as():
    """Under ``ulimit -v`` the room is the limit less what the process maps already (a child process: the
    limit would bind the test run)."""
    import os
    import subprocess
    import sys

    code = ("import resource; from ddmm.utils import resources as r; hard = resource.getrlimit(resource.RLIMIT_AS)[1];"
            "resource.setrlimit(resource.RLIMIT_AS, (r._statm(0) + (256 << 20), hard));"
            "print(r.available_bytes() <= 256 << 20)")
    env = {k: v for k, v in os.environ.items() if k != MEMORY_ENV}
    out = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, check=True, env=env)
    assert out.stdout.strip() == "True"


def _fake_room(monkeypatch, n_bytes: int) -> None:
    """This process may use ``n_bytes``: MemAvailable faked, no cgroup, no ulimit -v, no override."""
    import ddmm.utils.resources as res

    monkeypatch.delenv(MEMORY_ENV, raising=False)
    monkeypatch.setattr(res, "_mem_available", lambda: n_bytes)
    monkeypatch.setattr(res, "_cgroup_room", lambda: None)
    monkeypatch.setattr(res, "_address_room", lambda: None)


def test_a_run_is_refused_for_its_spike_events_before_any_work(monkeypatch):
    """300 trials of the fingertip make about 6 million spike events (0.8 GiB at the peak): refused under a
    300 MiB limit that the counts and the blocks alone fit, with the estimate and the limit."""
    from ddmm.population import simulation

    def no_work(*args, **kwargs):
        raise AssertionError("the run started")

    _fake_room(monkeypatch, 300 << 20)
    monkeypatch.setattr(simulation, "_run_jobs", no_work)
    pop = sample_population("fingertip", rng=0)
    with pytest.raises(ValueError, match=r"a run of 1 condition\(s\) x 300 trial\(s\) x 991 afferents \(about "
                                         r"[\d,]+ spike events, from a pilot of 128 afferents\) would need about "
                                         r"[\d.]+ MiB, more than the 300 MiB this process may use") as err:
        simulate(pop, birznieks(90.0), engine="direct", trials=300, quiet=True)
    events = int(re.search(r"about ([\d,]+) spike events", str(err.value)).group(1).replace(",", ""))
    assert 0.75 < events / 6_125_789 < 1.33  # the run's own count (seed 0)


def test_the_pilot_admits_a_run_that_the_ceiling_would_refuse(monkeypatch):
    """One trial of the fingertip: at the ceiling of 1,000 imp/s about 104 MiB, by the pilot about 46 MiB."""
    _fake_room(monkeypatch, 80 << 20)
    pop = sample_population("fingertip", rng=0)
    assert simulate(pop, birznieks(90.0), engine="direct", seed=0, quiet=True).sizes["spike"] > 10_000


def test_the_pilot_counts_spike_events_within_a_third():
    """The estimate's events against the run's, on the fingertip's trials and on a taxel array where only
    some sites are pressed (the pilot's strata follow each afferent's own drive)."""
    from ddmm.population import Scene, Sites, plan_run
    from ddmm.population.runtime.memory import estimate_memory

    pop = sample_population("fingertip", rng=0)
    ramp = np.minimum(np.arange(500) / 100.0, 1.0) * 2.0
    forces = np.zeros((500, 4, 3))
    forces[:, :2, 2] = ramp[:, None]  # two of four taxels pressed
    taxels = Scene.from_sites(forces, Sites([-2.0, 0.0, 2.0, 4.0], [0.0] * 4, 1.0), fs=1000.0, name="taxels")
    for scenes, trials in (([birznieks(0.0), birznieks(90.0)], 5), ([taxels], 3)):
        plan = plan_run(pop, scenes, trials=trials, engine="direct")
        estimate = estimate_memory(pop, scenes, plan, seed=1)
        actual = simulate(pop, scenes, engine="direct", trials=trials, seed=1, quiet=True).sizes["spike"]
        assert 0.75 < estimate.events / actual < 1.33, (scenes[0].name, estimate.events, actual)


@pytest.mark.parametrize("wrong, name", [({"population": 5}, "population"), ({"plan": 5}, "plan"),
                                         ({"scenes": [birznieks(0.0), birznieks(90.0)]}, "plan"),
                                         ({"dt": -1e-4}, "dt"), ({"method": "leapfrog"}, "method")])
def test_estimate_memory_names_a_wrong_argument(wrong, name):
    from ddmm.population import plan_run
    from ddmm.population.runtime.memory import estimate_memory

    pop = sample_population("fingertip", rng=0).select(range(4))
    args = {"population": pop, "scenes": [birznieks(90.0)], "plan": plan_run(pop, birznieks(90.0)), **wrong}
    with pytest.raises((TypeError, ValueError), match=rf"\b{name}\b"):
        estimate_memory(args.pop("population"), args.pop("scenes"), args.pop("plan"), **args)


@pytest.mark.slow  # 10 s and 1 GiB: run by `pytest -m slow`
def test_the_estimate_is_within_2x_of_the_measured_peak(tmp_path):
    """Fingertip x 300 trials, simulated and saved in a fresh process: 6 million events make most of its peak."""
    import subprocess
    import sys

    code = ("import resource, sys; from ddmm.population import birznieks, plan_run, sample_population, save_dataset, "
            "simulate; from ddmm.population.runtime.memory import estimate_memory;"
            "pop, scene = sample_population('fingertip', rng=0), birznieks(90.0);"
            "est = estimate_memory(pop, [scene], plan_run(pop, scene, trials=300, engine='direct'));"
            "save_dataset(simulate(pop, scene, engine='direct', trials=300, quiet=True), sys.argv[1]);"
            "print(est.peak / (resource.getrusage(resource.RUSAGE_SELF).ru_maxrss * 1024))")
    out = subprocess.run([sys.executable, "-c", code, str(tmp_path / "run.nc")], capture_output=True, text=True,
                         check=True)
    assert 0.5 < float(out.stdout) < 2.0


def test_plan_prints_the_memory_estimate_and_the_refusal(monkeypatch, capsys):
    from ddmm.experiments.cli import main

    _fake_room(monkeypatch, 1 << 30)
    assert main(["plan", "--population", "fingertip", "--trials", "10000", "--engine", "direct", "--quiet"]) == 0
    line = capsys.readouterr().out.splitlines()[-1]
    assert re.fullmatch(r"memory: about 2\d(\.\d)? GiB at peak \(.*, [\d,]+ spike events at 128 B from a pilot of "
                        r"128 afferents\); this process may use 1 GiB more; simulate would refuse this run", line), line


def test_a_sensor_array_file_is_refused_before_resampling_an_absurd_sample_count(tmp_path, capsys):
    """1e-6 Hz conditioned to 1 kHz is 1e9 samples per sample: refused with its estimate, as from_csv does."""
    from ddmm.experiments.cli import main
    from ddmm.population import from_array

    path = tmp_path / "slow.npz"
    np.savez(path, fs=1e-6, forces=np.ones((20, 4, 3)), x_mm=[0.0, 2.0, 0.0, 2.0], y_mm=[0.0, 0.0, 2.0, 2.0])
    with pytest.warns(Warning), pytest.raises(ValueError, match=r"array file .*slow.npz' resampled to 1000 Hz "
                                                                r"\(20,000,000,000 samples x 4 sites\) would need "
                                                                r"about [\d.]+ TiB, more than the .* this process may use"):
        from_array(path)
    assert main(["simulate", "--scene", str(path), "--engine", "direct", "--out", str(tmp_path / "o.nc")]) == 2
    err = capsys.readouterr().err.splitlines()
    assert err[-1].startswith("ddmm: error: array file") and "TiB" in err[-1] and not (tmp_path / "o.nc").exists()


def _sum_on_the_shared_pool():
    from ddmm.utils.executors import shared_executor

    return shared_executor("test-fork", 1).submit(sum, [1, 2]).result(timeout=10)


def test_a_forked_child_gets_a_pool_of_its_own():
    # A forked child inherits the pool object but not its threads: without a new pool, its work would
    # wait forever (here: the 10 s timeout).
    import multiprocessing

    from ddmm.utils.executors import shared_executor

    assert shared_executor("test-fork", 1).submit(sum, [2, 2]).result() == 4  # the parent's pool exists
    with multiprocessing.get_context("fork").Pool(1) as pool:
        assert pool.apply_async(_sum_on_the_shared_pool).get(timeout=30) == 3
