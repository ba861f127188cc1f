"""Per-unit sensitivity in populations: its own keyed draws, the planner, and the Dataset and its exports."""

import dataclasses

import numpy as np
import pytest

from ddmm.population import (PopulationSpec, birznieks, load_dataset, load_spec, make_plan, make_population,
                             sample_population, save_dataset, simulate)
from ddmm.population.spec import TypeSpec

_KEPT = ("afferent_type", "theta_t", "nap", "k", "gain", "x_mm", "y_mm", "region", "frame_deg")


def _without_spread(spec: PopulationSpec) -> PopulationSpec:
    types = {kind: dataclasses.replace(t, sensitivity_sd=0.0) for kind, t in spec.types.items()}
    return dataclasses.replace(spec, types=types)


@pytest.mark.parametrize("seed", [0, 1, 2, 3, 4])
def test_the_spread_leaves_every_other_draw_of_a_seed_as_it_was(seed):
    spread = sample_population("fingertip", rng=seed)
    plain = sample_population(_without_spread(load_spec("fingertip")), rng=seed)
    for name in _KEPT:
        np.testing.assert_array_equal(getattr(spread, name), getattr(plain, name), err_msg=name)
    assert np.all(plain.sensitivity == 1.0) and np.std(np.log(spread.sensitivity)) > 0.2


def test_sensitivity_is_lognormal_with_median_one_and_the_specs_spread():
    pop = sample_population("hand", rng=3)
    for kind in ("SAI", "RAI", "RAII", "SAII"):
        logs = np.log(pop.sensitivity[pop.afferent_type == kind])
        sd = load_spec("hand").types[kind].sensitivity_sd
        assert abs(np.median(logs)) < 0.1 and np.std(logs) == pytest.approx(sd, rel=0.1), kind


def test_the_same_seed_gives_the_same_sensitivities_and_types_draw_apart():
    a, b = sample_population("fingertip", rng=11), sample_population("fingertip", rng=11)
    np.testing.assert_array_equal(a.sensitivity, b.sensitivity)
    ra, ra2 = a.sensitivity[a.afferent_type == "RAI"], a.sensitivity[a.afferent_type == "RAII"]
    assert not np.allclose(np.log(ra[:50]) / 0.9, np.log(ra2[:50]) / 0.75)  # each type its own stream
    assert not np.array_equal(a.sensitivity, sample_population("fingertip", rng=12).sensitivity)


@pytest.mark.parametrize("bad", [-0.1, float("nan"), 3.0, True])
def test_a_bad_spread_is_refused_naming_it(bad):
    with pytest.raises((ValueError, TypeError), match="sensitivity_sd"):
        TypeSpec(count=3, sensitivity_sd=bad)


@pytest.mark.parametrize("bad", [0.0, -1.0, np.inf])
def test_a_population_refuses_a_sensitivity_not_above_zero(bad):
    with pytest.raises(ValueError, match="sensitivity"):
        make_population(["RAI", "RAI"], sensitivity=[1.0, bad])


def test_the_planner_keeps_units_of_other_sensitivity_apart():
    params = load_spec("fingertip").current.with_type("RAI", excite_cv=0.0)  # noise-free: shared
    same = make_population(["RAI"] * 3, nap="none", current=params)
    apart = make_population(["RAI"] * 3, nap="none", current=params, sensitivity=[1.0, 1.0, 2.0])
    scene = birznieks(90.0)
    assert make_plan(same, [scene]).conditions[0].units.size == 1
    assert make_plan(apart, [scene]).conditions[0].units.size == 2
    ds = simulate(apart, scene, seed=0, quiet=True)
    counts = ds.spike_count.values[0, 0]
    assert counts[0] == counts[1] and counts[2] > counts[0]  # the sensitive unit fires more


def test_the_dataset_carries_sensitivity_and_an_older_file_reads_as_one(tmp_path):
    pop = sample_population("fingertip", rng=0).select(np.arange(0, 991, 50))
    ds = simulate(pop, birznieks(90.0), seed=0, quiet=True)
    np.testing.assert_array_equal(ds.sensitivity.values, pop.sensitivity)
    assert ds.sensitivity.attrs["units"] == "1"
    old = ds.drop_vars("sensitivity")  # as written before units had a sensitivity
    save_dataset(old, tmp_path / "old.nc")
    back = load_dataset(tmp_path / "old.nc")
    np.testing.assert_array_equal(back.sensitivity.values, np.ones(ds.sizes["afferent"]))


def test_neo_and_brian2_carry_sensitivity_and_older_datasets_export_as_one():
    pytest.importorskip("neo")
    pytest.importorskip("brian2")
    from ddmm.population import to_brian2, to_neo

    pop = sample_population("fingertip", rng=0).select(np.arange(0, 991, 100))
    ds = simulate(pop, birznieks(90.0), seed=0, quiet=True)
    train = to_neo(ds).segments[0].spiketrains[3]
    assert train.annotations["sensitivity"] == float(ds.sensitivity.values[3])
    group = to_brian2(ds)
    np.testing.assert_array_equal(group.sensitivity[:], ds.sensitivity.values)
    np.testing.assert_array_equal(group.k[:], ds.k.values)
    old = ds.drop_vars("sensitivity")
    assert to_neo(old).segments[0].spiketrains[3].annotations["sensitivity"] == 1.0
    np.testing.assert_array_equal(to_brian2(old).sensitivity[:], np.ones(ds.sizes["afferent"]))
