"""The memory check before large allocations: the limit, its override, and refusals that name the job."""

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
