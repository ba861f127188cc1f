"""Hard cases through the whole pipeline, on both engines: geometry, forces, scenes, invariances."""

import dataclasses
import tracemalloc
import warnings

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from ddmm.models.attenuation import F_TH
from ddmm.models.engines import SpikeCapWarning
from ddmm.population import Scene, birznieks, from_csv, make_population, sample_population, simulate
from tests.conftest import ENGINES


@pytest.fixture(scope="module")
def pop():
    return sample_population("fingertip", rng=7).select(np.arange(0, 991, 19))  # 53 afferents, noisy


def finite(ds):
    return all(np.all(np.isfinite(ds[v].values)) for v in ds.data_vars if ds[v].dtype.kind == "f")


@pytest.mark.parametrize("engine", ENGINES)
@pytest.mark.parametrize("fy", [1.0, -1.0])
def test_pure_y_push_with_fx_exactly_zero(engine, fy, pop):
    n = 300
    fz = np.linspace(0, 4, n)
    ds = simulate(pop, Scene(np.zeros(n), fy * fz / 4, fz, name="y"), engine=engine, seed=1, quiet=True)
    assert finite(ds) and ds.sizes["spike"] > 0


@pytest.mark.parametrize("engine", ENGINES)
def test_shear_at_just_above_and_just_below_threshold(engine):
    n = 300
    sel = make_population(["SAI"] * 2, [180.0, 0.0], "selective")  # opposed and aligned to +X
    out = {}
    for reading in ("pass", "smooth"):
        for name, fx in (("at", F_TH), ("above", F_TH * (1 + 1e-9)), ("below", F_TH * (1 - 1e-9))):
            ds = simulate(sel, Scene(np.full(n, fx), np.zeros(n), np.full(n, 3.0), name=name), engine=engine,
                          quiet=True, no_shear=reading)
            out[reading, name] = ds.spike_count.values[0, 0]
    np.testing.assert_array_equal(out["pass", "at"], out["pass", "below"])  # eq. 17: AF = 1 up to F_TH
    assert out["pass", "above"][0] < out["pass", "at"][0] and out["pass", "above"][1] == out["pass", "at"][1]
    # the smooth reading has no step at F_TH: 1e-9 N either side changes nothing
    np.testing.assert_array_equal(out["smooth", "above"], out["smooth", "below"])
    assert out["smooth", "above"][0] < out["pass", "at"][0]


@pytest.mark.parametrize("engine", ENGINES)
def test_single_sample_and_all_zero_scenes(engine, pop):
    one = simulate(pop, Scene([0.2], [0.0], [3.0], name="one"), engine=engine, seed=2, quiet=True)
    assert one.sizes["time"] == 1 and finite(one)
    zero = simulate(pop.select(np.arange(10)), Scene(np.zeros(1000), np.zeros(1000), np.zeros(1000), name="z"),
                    engine=engine, quiet=True)
    assert finite(zero)


@pytest.mark.parametrize("engine", ENGINES)
def test_noiseless_all_zero_scene_is_silent(engine):
    quiet = make_population(["SAI", "RAI", "RAII"])
    ds = simulate(quiet, Scene(np.zeros(2000), np.zeros(2000), np.zeros(2000), name="z"), engine=engine, quiet=True)
    assert ds.sizes["spike"] == 0


@pytest.mark.parametrize("engine", ENGINES)
def test_100hz_force_plate_with_sensor_noise(engine, tmp_path):
    rng = np.random.default_rng(0)
    t = np.arange(0, 3.0, 0.01)
    fz = np.interp(t, [0, 0.5, 2.5, 3.0], [0, 3, 3, 0]) + rng.normal(0, 0.02, t.size)
    fy = np.interp(t, [0, 0.5, 2.5, 3.0], [0, 1, 1, 0]) + rng.normal(0, 0.02, t.size)
    fx = rng.normal(0, 0.02, t.size)
    rows = "\n".join(f"{a:.2f},{b:.5f},{c:.5f},{d:.5f}" for a, b, c, d in zip(t, fx, fy, fz))
    path = tmp_path / "plate.csv"
    path.write_text("time,fx,fy,fz\n" + rows)
    scene = from_csv(path, negative_fz="clip")
    ds = simulate(sample_population("fingertip", rng=1).select(np.arange(0, 991, 9)), scene, engine=engine,
                  seed=1, quiet=True)
    rates = ds.spike_count.values[0, 0] / scene.duration
    assert finite(ds) and rates.max() < 500.0  # the derivative filter keeps sensor noise from exploding RAII


@pytest.mark.parametrize("engine", ENGINES)
def test_ten_minute_scene_memory_is_bounded(engine):
    small = make_population(["SAI", "RAI", "RAII"] * 4, np.arange(12) * 30.0, "selective")

    def peak(seconds):
        n = int(seconds * 1000)
        t = np.arange(n) / 1000.0
        fz = 2.0 + np.sin(2 * np.pi * 0.5 * t)
        scene = Scene(0.3 * np.cos(t), 0.3 * np.sin(t), fz, name="long")
        tracemalloc.start()
        with warnings.catch_warnings():
            warnings.simplefilter("ignore", SpikeCapWarning)  # NAP corners give RAII impulses; not the point here
            ds = simulate(small, scene, engine=engine, quiet=True, record=("spikes",))
        _, top = tracemalloc.get_traced_memory()
        tracemalloc.stop()
        return top, ds.nbytes + 3 * 8 * n  # output plus the scene's own arrays

    short_peak, short_out = peak(60.0)
    long_peak, long_out = peak(600.0)
    assert long_peak - long_out < short_peak - short_out + 20e6  # working memory does not grow with duration


@settings(max_examples=8, deadline=None)
@given(alpha=st.floats(0.0, 360.0), engine=st.sampled_from(ENGINES))
def test_rotating_shear_and_tuning_together_leaves_spikes_unchanged(alpha, engine):
    base = sample_population("fingertip", rng=0).select(np.arange(0, 991, 23))
    turned = dataclasses.replace(base, theta_t=(base.theta_t + alpha) % 360.0)  # same ids, same noise
    scene = birznieks(37.0)
    r = np.deg2rad(alpha)
    rotated = Scene(np.cos(r) * scene.fx - np.sin(r) * scene.fy, np.sin(r) * scene.fx + np.cos(r) * scene.fy,
                    scene.fz, name="rotated")
    a = simulate(base, scene, engine=engine, seed=5, quiet=True)
    b = simulate(turned, rotated, engine=engine, seed=5, quiet=True)
    np.testing.assert_array_equal(a.spike_time.values, b.spike_time.values)
    np.testing.assert_array_equal(a.spike_afferent.values, b.spike_afferent.values)


@pytest.mark.parametrize("engine", ENGINES)
def test_identical_seeds_identical_datasets(engine, pop):
    a, b = (simulate(pop, birznieks(10.0), engine=engine, seed=8, trials=2, quiet=True) for _ in range(2))
    assert a.identical(b)


@pytest.mark.parametrize("engine", ENGINES)
def test_a_multistage_method_refuses_a_negative_drive_from_the_pipeline(engine):
    # SA-II stretched against its preferred direction (opponent 1): -30 mV/ms, a 60 mV step at dt = 2 ms.
    # The fused pipeline's smallest current feeds the check; Euler is floored and runs.
    from ddmm.models.currents import CurrentParams
    from ddmm.models.engines import NumericalInstabilityError

    pop = make_population(["SAII"], theta_t=0.0, nap="selective",
                          current=CurrentParams().with_type("SAII", opponent=1.0, gain=10.0))
    scene = Scene(np.full(50, -5.0), np.zeros(50), np.full(50, 1.0), fs=500.0)
    with pytest.raises(NumericalInstabilityError, match="unstable for currents down to -30 mV/ms"):
        simulate(pop, scene, engine=engine, dt=2e-3, method="rk4", seed=0, quiet=True)
    assert finite(simulate(pop, scene, engine=engine, dt=2e-3, method="euler", seed=0, quiet=True))
