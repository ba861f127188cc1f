"""Population simulation: schema, exact planning, engines, chunking, seeds, round trip."""

import dataclasses

import numpy as np
import pytest
import xarray as xr

from ddmm.models.current_params import CurrentParams
from ddmm.population import (
    Contact,
    birznieks,
    load_dataset,
    make_population,
    plan_run,
    press_push_lift,
    sample_population,
    save_dataset,
    simulate,
)

SCHEMA_COORDS = {"afferent", "afferent_type", "theta_t", "nap", "k", "gain", "x_mm", "y_mm", "noise_sigma",
                 "region", "frame_deg", "condition", "duration", "theta_r", "has_theta_r", "trial", "time"}
SCHEMA_VARS = {"spike_count", "spike_time", "spike_afferent", "spike_trial", "spike_condition", "fx", "fy", "fz",
               "stage_start", "stage_end"}
ATTRS = {"engine", "dt", "method", "seed", "no_shear", "ddmm_version", "f_th", "current_SAI_gain",
         "neuron_SAI_b", "rf_sigma_RAII_mm"}


@pytest.fixture(scope="module")
def fingertip():
    return sample_population("fingertip", rng=0)


@pytest.fixture(scope="module")
def small(fingertip):
    return fingertip.select(np.arange(0, 991, 7))  # 142 afferents of all four types, noisy


def scenes():
    return [birznieks(90.0), birznieks(None), birznieks(200.0, contact=Contact(1.0, -2.0, 2.0))]


def test_schema(small):
    ds = simulate(small, scenes(), engine="direct", trials=2, seed=5, quiet=True)
    assert set(ds.dims) == {"condition", "trial", "afferent", "spike", "time", "stage"}
    assert SCHEMA_COORDS <= set(ds.coords) and SCHEMA_VARS <= set(ds.data_vars)
    assert ds.spike_count.dims == ("condition", "trial", "afferent")
    assert ATTRS <= set(ds.attrs)
    for name in list(ds.coords) + list(ds.data_vars):  # CF: numbers carry units, labels a long_name
        assert ("long_name" in ds[name].attrs and "units" not in ds[name].attrs if ds[name].dtype.kind == "O"
                else "units" in ds[name].attrs), name
    counts = np.zeros(ds.spike_count.shape, int)
    np.add.at(counts, (ds.spike_condition.values, ds.spike_trial.values, ds.spike_afferent.values), 1)
    np.testing.assert_array_equal(counts, ds.spike_count.values)
    assert not any(np.isnan(ds[v].values).any() for v in ("spike_time", "fx", "fy", "fz"))


def test_netcdf_round_trip_is_lossless(small, tmp_path):
    ds = simulate(small, scenes(), engine="direct", trials=2, seed=5, quiet=True)
    path = save_dataset(ds, tmp_path / "run.nc")
    assert load_dataset(path).identical(ds)
    assert [p.name for p in tmp_path.iterdir()] == ["run.nc"]


def test_region_and_frame_round_trip(tmp_path):
    hand = sample_population("hand", rng=0)
    pick = np.r_[np.flatnonzero(hand.region == "D1d")[:3], np.flatnonzero(hand.region == "thenar")[:3]]
    mixed = make_population(["SAI", "RAI"], region=["", "D5m"], frame_deg=[0.0, 14.0])
    for pop in (hand.select(pick), mixed):
        ds = simulate(pop, birznieks(90.0), engine="direct", seed=1, quiet=True)
        np.testing.assert_array_equal(ds.region.values, pop.region)
        np.testing.assert_array_equal(ds.frame_deg.values, pop.frame_deg)
        again = load_dataset(save_dataset(ds, tmp_path / "run.nc"))
        assert again.identical(ds) and again.region.values.tolist() == pop.region.tolist()
    assert set(hand.select(pick).frame_deg) == {-45.0, 0.0}


def test_failed_write_leaves_no_file(small, tmp_path, monkeypatch):
    ds = simulate(small, birznieks(90.0), engine="direct", seed=1, quiet=True)

    def boom(*args, **kwargs):
        raise OSError("disk full")
    for method in ("to_netcdf", "dump_to_store"):  # either writes the file (`ddmm.utils.files.write_netcdf`)
        monkeypatch.setattr(xr.Dataset, method, boom)
    with pytest.raises(OSError):
        save_dataset(ds, tmp_path / "run.nc")
    assert list(tmp_path.iterdir()) == []
    with pytest.raises(ValueError, match="writable"):
        save_dataset(ds, tmp_path / "missing" / "run.nc")


@pytest.mark.parametrize("kwargs", [
    dict(trials=2, seed=3),                                       # noisy population
    dict(trials=3, seed=3, noiseless=True),                       # collapse afferents and trials
    dict(trials=1, seed=3, noiseless=True, no_shear="block"),     # AF = 0 without shear: quiet
    dict(trials=2, seed=3, afferent_types=("RAI", "RAII")),              # types not requested
])
def test_planned_equals_unplanned(small, kwargs):
    kwargs = dict(kwargs)
    pop = small
    if kwargs.pop("noiseless", False):
        pop = pop.select(np.arange(len(pop)))
        pop = make_population(pop.afferent_type, pop.theta_t, pop.nap, np.where(pop.k > 0, pop.k, 3.0),
                              gain=np.round(pop.gain, 1), x_mm=pop.x_mm, y_mm=pop.y_mm, current=pop.current)
    a = simulate(pop, scenes(), engine="direct", quiet=True, **kwargs)
    b = simulate(pop, scenes(), engine="direct", quiet=True, plan=False, **kwargs)
    assert a.identical(b)


def test_plan_keeps_stretch_afferents_a_normal_force_drives():
    """An SA-II without a tonic current but with a normal-force weight fires under a press without shear: the
    planner must not take it for quiet (and must while the weight is 0)."""
    current = CurrentParams().with_type("SAII", gain=4.0, normal=0.25)
    pop = make_population(["SAII"] * 3, [0.0, 90.0, 180.0], "broad", current=current)
    press = birznieks(None)
    planned = simulate(pop, press, engine="direct", seed=0, quiet=True)
    assert planned.sizes["spike"] > 0
    assert planned.identical(simulate(pop, press, engine="direct", seed=0, quiet=True, plan=False))
    unpressed = dataclasses.replace(pop, current=current.with_type("SAII", normal=0.0))
    assert plan_run(unpressed, [press]).conditions[0].n_quiet == 3


def test_plan_skips_what_a_scene_does_not_need(fingertip):
    quiet_pop = make_population(["SAI", "SAI", "RAI", "RAII"], [0.0, 0.0, 90.0, 90.0], "selective",
                                x_mm=[0.0, 0.0, 50.0, 0.0])
    plan = plan_run(quiet_pop, [birznieks(None), birznieks(90.0, contact=Contact(0, 0, 1))], trials=4)
    normal, touch = plan.conditions
    assert not normal.computes_af and normal.weights is None
    assert normal.units.size == 3 and normal.noisy.size == 0  # two identical SAI collapse
    assert touch.computes_af and touch.n_quiet == 1               # the far RAI has zero weight
    text = plan.describe(quiet_pop, [birznieks(None), birznieks(90.0, contact=Contact(0, 0, 1))])
    assert "skipped (no shear" in text and "noise: off" in text and "once for all 4 trials" in text


def test_engines_identical_with_noise(fingertip):
    a = simulate(fingertip, birznieks(90.0), engine="direct", trials=2, seed=11, quiet=True)
    b = simulate(fingertip, birznieks(90.0), engine="brian2", trials=2, seed=11, quiet=True)
    assert a.drop_attrs().identical(b.drop_attrs())
    assert a.sizes["spike"] > 1000


def test_chunking_does_not_change_results(small):
    ref = simulate(small, press_push_lift(90.0), engine="direct", seed=2, quiet=True)
    for chunk_size, time_chunk in ((10, 2000), (137, 777), (64, 30000)):
        ds = simulate(small, press_push_lift(90.0), engine="direct", seed=2, quiet=True,
                      chunk_size=chunk_size, time_chunk=time_chunk)
        assert ds.identical(ref)


def test_large_direct_blocks_run_in_parts_with_the_same_results(fingertip):
    """A block above DIRECT_CHUNK_SIZE (a Dask task's 4096) runs in parts: receptive-field weights,
    trials and time chunks must follow each part."""
    scene = birznieks(90.0, contact=Contact(0.0, 0.0, 4.0))
    ref = simulate(fingertip, scene, engine="direct", seed=3, trials=2, quiet=True)
    big = simulate(fingertip, scene, engine="direct", seed=3, trials=2, quiet=True, chunk_size=4096, time_chunk=333)
    assert ref.sizes["spike"] > 1000
    assert big.identical(ref)


def test_seeds(small):
    a, b, c = (simulate(small, birznieks(90.0), engine="direct", seed=s, quiet=True) for s in (1, 1, 2))
    assert a.identical(b)
    assert not a.spike_time.equals(c.spike_time)


def test_subset_does_not_change_an_afferents_spikes(fingertip):
    full = simulate(fingertip, birznieks(45.0), engine="direct", seed=9, quiet=True)
    ids = np.array([3, 300, 900])
    part = simulate(fingertip.select(ids), birznieks(45.0), engine="direct", seed=9, quiet=True)
    np.testing.assert_array_equal(part.spike_count.values, full.spike_count.sel(afferent=ids).values)


def test_spatial_weighting_silences_far_afferents():
    pop = make_population(["SAI"] * 3, x_mm=[0.0, 2.5, 20.0])
    ds = simulate(pop, birznieks(90.0, contact=Contact(0.0, 0.0, 1.0)), engine="direct", quiet=True)
    near, mid, far = ds.spike_count.values[0, 0]
    assert near > mid > far == 0


@pytest.mark.parametrize("kwargs,exc,match", [
    (dict(dt=0.0), ValueError, "dt"), (dict(dt=3e-4), ValueError, "dt"), (dict(engine="nest"), ValueError, "engine"),
    (dict(trials=0), ValueError, "trials"), (dict(no_shear="x"), ValueError, "no_shear"),
    (dict(afferent_types=("SAIII",)), ValueError, "afferent_types"), (dict(record=("voltage",)), ValueError, "record"),
    (dict(seed=-1), TypeError, "seed"), (dict(chunk_size=0), ValueError, "chunk_size"),
])
def test_bad_arguments(small, kwargs, exc, match):
    with pytest.raises(exc, match=match):
        simulate(small, birznieks(90.0), quiet=True, **{"engine": "direct", **kwargs})
    with pytest.raises(TypeError, match="population"):
        simulate("fingertip", birznieks(90.0))
    with pytest.raises(ValueError, match="unique"):
        simulate(small, [birznieks(90.0), birznieks(90.0)], engine="direct")


def test_same_seed_same_spikes_across_processes():
    import os
    import subprocess
    import sys
    code = ("from ddmm.population import sample_population, simulate, birznieks; import hashlib;"
            "ds = simulate(sample_population('fingertip', rng=0).select(range(0, 991, 5)), birznieks(30.0),"
            " engine='direct', seed=3, quiet=True);"
            "print(hashlib.sha256(ds.spike_time.values.tobytes() + ds.spike_afferent.values.tobytes()).hexdigest())")
    outs = {subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, check=True,
                           env={**os.environ, "PYTHONHASHSEED": str(h)}).stdout for h in (11, 12)}
    assert len(outs) == 1


def test_saved_files_get_normal_permissions(small, tmp_path):
    import os
    import stat
    ds = simulate(small, birznieks(90.0), engine="direct", seed=1, quiet=True)
    path = save_dataset(ds, tmp_path / "run.nc")
    mask = os.umask(0)
    os.umask(mask)
    assert stat.S_IMODE(path.stat().st_mode) == 0o666 & ~mask
