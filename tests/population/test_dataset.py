"""Dataset helpers: binned rates and PSTHs against hand counts."""

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from ddmm.population import binned_counts, birznieks, make_population, psth, simulate


@pytest.fixture(scope="module")
def ds():
    pop = make_population(["SAI", "SAI", "RAI"], [90.0, 270.0, 90.0], "selective")
    return simulate(pop, [birznieks(90.0), birznieks(None)], engine="direct", trials=2, quiet=True)


def test_binned_counts_sum_to_spike_counts(ds):
    counts = binned_counts(ds, 0.05)
    np.testing.assert_array_equal(counts.sum("bin").values, ds.spike_count.values)
    assert counts.sizes["bin"] == 10 and counts.bin.values[0] == pytest.approx(0.025)


def test_spike_on_a_bin_edge_opens_the_next_bin(ds):
    # 5.97 // 0.01 == 596.0 in float64: without the snap the spike at 5.97 s fell into [5.96, 5.97).
    one = ds.isel(spike=[0]).assign(spike_time=("spike", [5.97]), spike_afferent=("spike", [0]),
                                    spike_trial=("spike", [0]), spike_condition=("spike", [0]))
    counts = binned_counts(one, 0.01, t_max=6.0).isel(condition=0, trial=0, afferent=0).values
    assert np.flatnonzero(counts).tolist() == [597]


def test_psth_is_mean_rate_per_type(ds):
    rates = psth(ds, 0.1)
    assert set(rates.afferent_type.values) == {"SAI", "RAI"}
    sai = ds.spike_count.where(ds.afferent_type == "SAI", drop=True).mean(("trial", "afferent"))
    np.testing.assert_allclose((rates.sel(afferent_type="SAI") * 0.1).sum("bin").values, sai.values)


def test_rates_need_events(ds):
    with pytest.raises(ValueError, match="bin_s"):
        binned_counts(ds, 0.0)
    with pytest.raises(ValueError, match="spike events"):
        binned_counts(ds.drop_vars("spike_time"), 0.1)


@settings(max_examples=60, deadline=None)
@given(st.lists(st.tuples(st.integers(0, 3), st.integers(0, 2), st.integers(0, 10**6), st.integers(0, 50)),
                max_size=60, unique=True),
       st.sampled_from([5, 10**6 + 1, 10**17]))
def test_events_sort_like_lexsort(events, n_steps_bound):
    """Each path of the event sort (counting sorts for few time slots, the packed key, lexsort when the key
    would overflow) orders like lexsort and counts like bincount."""
    from ddmm.population.dataset import _sorted_events

    cond, trial, step, aff = (np.array([e[i] for e in events], np.int64) for i in range(4))
    step %= n_steps_bound
    if step.size:
        step[0] = n_steps_bound - 1  # sets n_steps: 5 takes the counting sorts, 10**17 the lexsort
    keep = np.sort(np.unique(np.column_stack([cond, trial, step, aff]), axis=0, return_index=True)[1])
    cond, trial, step, aff = cond[keep], trial[keep], step[keep], aff[keep]
    order = np.lexsort((aff, step, trial, cond))
    *got, counts = _sorted_events(cond, trial, step, aff, 4, 3, 51)
    for g, want in zip(got, (cond, trial, step, aff)):
        np.testing.assert_array_equal(g, want[order])
    np.testing.assert_array_equal(counts.ravel(), np.bincount((cond * 3 + trial) * 51 + aff, minlength=4 * 3 * 51))
