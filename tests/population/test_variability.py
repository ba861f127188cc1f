"""Trial-to-trial excitability (``TypeParams.excite_cv``) and the variability protocol of the scorecard."""

import dataclasses

import numpy as np
import pytest

from ddmm.models.currents import CurrentParams, excitability
from ddmm.models.rng import stream_key
from ddmm.population import make_population, sample_population, simulate
from ddmm.population.analysis.physiology_variability import press_scene, variability_stats
from ddmm.population.runtime.plan import make_plan


def test_bad_excite_cv_is_named():
    with pytest.raises(ValueError, match=r"^excite_cv must be a finite number >= 0, got -0.1"):
        CurrentParams().with_type("RAI", excite_cv=-0.1)


def test_excitability_is_keyed_lognormal_of_mean_one():
    key, ids = stream_key(3, 1, 2), np.arange(20_000)
    e = excitability(key, ids, np.full(ids.size, 0.3))
    assert abs(e.mean() - 1.0) < 0.01 and abs(e.std() / e.mean() - 0.3) < 0.01 and e.min() > 0
    np.testing.assert_array_equal(excitability(key, ids[7:9], [0.3, 0.3]), e[7:9])  # a pure function of the key
    assert not np.array_equal(excitability(stream_key(3, 1, 3), ids[:5], np.full(5, 0.3)), e[:5])
    np.testing.assert_array_equal(excitability(key, ids[:5], np.zeros(5)), 1.0)


def _pop(excite_cv, n=30):
    pop = make_population(["SAI"] * n, noise_cv=0.0, current=sample_population("fingertip", rng=0).current.with_type(
        "SAI", excite_cv=excite_cv))
    return pop


def test_excitable_afferents_are_simulated_per_trial_and_vary():
    scene = press_scene()
    off, on = _pop(0.0), _pop(0.3)
    assert make_plan(off, [scene], trials=4).conditions[0].noisy.size == 0  # noise-free: one integration
    assert make_plan(on, [scene], trials=4).conditions[0].noisy.size == len(on)
    ds = simulate(on, [scene], trials=4, seed=0, quiet=True)
    counts = ds.spike_count.values[0]  # (trial, afferent)
    assert np.ptp(counts, axis=0).max() > 0  # counts differ between trials
    silent = simulate(on, [press_scene(0.0)], trials=2, seed=0, quiet=True)
    assert silent.spike_count.values.sum() == 0  # a factor on the current: silent without drive


def test_variability_protocol_on_the_preset():
    pop = sample_population("fingertip", rng=0)
    sub = pop.select(np.flatnonzero(np.isin(pop.afferent_type, ("SAI", "RAI", "RAII")))[::4])
    scene = press_scene()
    stats = variability_stats(simulate(sub, [scene], trials=20, seed=0, quiet=True), 0.2, 0.45)
    assert 0.1 <= stats["fano_SAI"] <= 1.0 and 0.5 <= stats["first_jitter_SAI"] <= 10.0
    off = dataclasses.replace(sub, current=sub.current.with_type("SAI", excite_cv=0.0).with_type("RAI", excite_cv=0.0)
                              .with_type("RAII", excite_cv=0.0))
    base = variability_stats(simulate(off, [scene], trials=20, seed=0, quiet=True), 0.2, 0.45)
    assert base["fano_SAI"] < 0.05  # without it nearly deterministic (the reviewer's finding)


def test_the_protocol_module_registers_in_either_import_order():
    import subprocess
    import sys

    check = "assert 'fano_SAI' in p.PROPERTIES and p.PROTOCOLS.count('variability') == 1"
    for first in ("ddmm.population.analysis.physiology_variability", "ddmm.population.analysis.physiology"):
        code = f"import {first}; from ddmm.population.analysis import physiology as p; {check}"
        subprocess.run([sys.executable, "-c", code], check=True)
