"""Brian2 export: a downstream Brian2 network receives exactly the Dataset's spikes, at the Dataset's dt or another."""

import numpy as np
import pytest

from ddmm.models.engines.brian2 import import_brian2 as _import_brian2
from ddmm.population import birznieks, make_population, simulate
from ddmm.population.io import to_brian2

b2 = _import_brian2()
DT = 1e-4  # the simulation's step (s)


@pytest.fixture(autouse=True)
def numpy_target():
    """Brian2's runtime numpy target (nothing to compile), the user's setting restored afterwards."""
    saved = b2.prefs["codegen.target"]
    b2.prefs["codegen.target"] = "numpy"
    yield
    b2.prefs["codegen.target"] = saved


@pytest.fixture(scope="module")
def ds():
    """SA-I, RA-I, SA-I, RA-I with receptor noise (trials differ), two conditions of 0.5 s, two trials; afferent
    ids 100.. so that an id differs from its position."""
    pop = make_population(["SAI", "RAI", "SAI", "RAI"], x_mm=[0.0, 1.0, 2.0, 3.0], noise_cv=0.05)
    run = simulate(pop, [birznieks(90.0), birznieks(None)], engine="direct", dt=DT, trials=2, seed=1, quiet=True)
    return run.assign_coords(afferent=run["afferent"].values + 100)


def _spikes(ds, c, t):
    """Afferent positions and times (s) of (condition c, trial t), in the Dataset's order (time, afferent)."""
    keep = (ds.spike_condition.values == c) & (ds.spike_trial.values == t)
    return ds.spike_afferent.values[keep].astype(np.int64), ds.spike_time.values[keep]


def _steps(times, dt):
    return np.round(np.asarray(times) / dt).astype(np.int64)


def test_a_downstream_layer_receives_exactly_the_spikes(ds):
    group = to_brian2(ds, "normal", 1)  # condition 1 by name
    relay = b2.NeuronGroup(group.N, "v : 1", threshold="v >= 1", reset="v = 0")
    syn = b2.Synapses(group, relay, on_pre="v_post += 1")
    syn.connect(j="i")
    sent, received = b2.SpikeMonitor(group), b2.SpikeMonitor(relay)
    b2.Network(group, relay, syn, sent, received).run(0.5 * b2.second)
    index, time = _spikes(ds, 1, 1)
    assert index.size > 100 and group.N == 4
    np.testing.assert_array_equal(sent.i[:], index)
    np.testing.assert_array_equal(sent.t_[:], time)  # bit for bit at the simulation's dt
    np.testing.assert_array_equal(received.i[:], index)  # the relay fires in the next step
    np.testing.assert_array_equal(_steps(received.t_[:], DT), _steps(time, DT) + 1)
    np.testing.assert_array_equal(received.count[:], ds.spike_count.values[1, 1])


def test_connect_by_afferent_type_and_position(ds):
    group = to_brian2(ds, 0, 1)
    post = b2.NeuronGroup(2, "v : 1")
    by_type = b2.Synapses(group, post, on_pre="v_post += 1")
    by_type.connect(i=np.flatnonzero(group.afferent_type == "SAI"), j=0)
    by_place = b2.Synapses(group, post, on_pre="v_post += 1")
    by_place.connect(condition="x_mm_pre > 1.5 and j == 1")  # positions 2 (SA-I) and 3 (RA-I)
    b2.Network(group, post, by_type, by_place).run(0.5 * b2.second)
    counts = ds.spike_count.values[0, 1]
    assert post.v[0] == counts[[0, 2]].sum() > 0 and post.v[1] == counts[[2, 3]].sum()
    assert list(group.afferent_type) == ["SAI", "RAI", "SAI", "RAI"] and list(group.region) == [""] * 4
    np.testing.assert_array_equal(group.afferent_id[:], [100, 101, 102, 103])
    np.testing.assert_array_equal(group.x_mm[:], ds.x_mm.values)
    with pytest.raises(TypeError, match="read-only"):
        group.x_mm = 0.0
    with pytest.raises(ValueError, match="read-only"):
        group.afferent_type[0] = "RAI"


def _first_collision(ds, c, t, factor):
    """(afferent position, coarse step) of the first afferent spiking twice in one step of ``factor`` x DT."""
    index, time = _spikes(ds, c, t)
    step = _steps(time, DT) // factor
    order = np.lexsort((index, step))
    index, step = index[order], step[order]
    k = np.flatnonzero((np.diff(step) == 0) & (np.diff(index) == 0))[0]
    return int(index[k]), int(step[k])


def test_a_coarser_dt_refuses_two_spikes_in_one_step_unless_merged(ds):
    a, s = _first_collision(ds, 0, 0, 10)
    with pytest.raises(ValueError, match=rf"afferent {100 + a} \(position {a}\) spikes more than once in step "
                                         rf"{s} .*dt=0\.001 s.*merge=True"):
        to_brian2(ds, dt=1e-3)
    group = to_brian2(ds, dt=1e-3 * b2.second, merge=True)
    sent = b2.SpikeMonitor(group)
    b2.Network(group, sent).run(0.5 * b2.second)
    index, time = _spikes(ds, 0, 0)
    for i in range(4):  # one spike per afferent and occupied step, at the step's start
        steps = np.unique(_steps(time[index == i], DT) // 10)
        np.testing.assert_array_equal(_steps(sent.t_[sent.i[:] == i], 1e-3), steps)
    assert sent.num_spikes < index.size


@pytest.mark.parametrize("dt", [5e-5, 3e-5])
def test_a_finer_dt_keeps_every_spike_in_the_step_that_contains_it(ds, dt):
    group = to_brian2(ds, 1, 0, dt=dt)
    index, time = _spikes(ds, 1, 0)
    order = np.lexsort((index, time))  # the group's order: by time, then afferent
    np.testing.assert_array_equal(group.neuron_index[:], index[order])
    shift = time[order] - group.spike_time_[:]
    assert shift.min() >= -1e-12 and shift.max() < dt and group.clock.dt_ == dt
    if dt == 5e-5:  # DT is a whole multiple: exact
        assert np.abs(shift).max() < 1e-12


@pytest.mark.parametrize("dt, gap_s", [(DT, 0.0), (DT, 0.01), (3e-4, 0.0)])
def test_joined_trials_follow_one_another(ds, dt, gap_s):
    group = to_brian2(ds, dt=dt, join_trials=True, gap_s=gap_s, merge=True)
    assert group.pairs.tolist() == [[0, 0], [0, 1], [1, 0], [1, 1]]
    length = np.ceil((0.5 + gap_s) / dt - 1e-6)  # each trial's duration plus gap, up to a whole step
    np.testing.assert_allclose(group.offsets, np.arange(4) * length * dt, rtol=0, atol=1e-12)
    steps, index = _steps(group.spike_time_[:], dt), group.neuron_index[:]
    for k, (c, t) in enumerate(group.pairs):
        mine = (steps >= round(group.offsets[k] / dt)) & (steps < round(group.offsets[k] / dt) + length)
        a, time = _spikes(ds, c, t)
        expected = {(int(i), int(s)) for i, s in zip(a, np.floor(time / dt + 1e-6).astype(np.int64))}
        assert {(int(i), int(s) - round(group.offsets[k] / dt)) for i, s in zip(index[mine], steps[mine])} \
            == expected
    assert steps.size == len({(int(i), int(s)) for i, s in zip(*_spikes_all(ds, dt, length))})


def _spikes_all(ds, dt, length):
    k = ds.spike_condition.values * 2 + ds.spike_trial.values
    return ds.spike_afferent.values, k * int(length) + np.floor(ds.spike_time.values / dt + 1e-6).astype(np.int64)


@pytest.mark.parametrize("kwargs, error, match", [
    ({"condition": 2}, ValueError, r"condition must be in 0\.\.1, got 2"),
    ({"condition": -1}, ValueError, r"condition must be in 0\.\.1, got -1"),
    ({"condition": "slip"}, ValueError, r"condition='slip' is not in the Dataset; allowed: birznieks_90, normal"),
    ({"condition": 1.0}, TypeError, "condition must be an int or a str, got float"),
    ({"trial": 2}, ValueError, r"trial must be in 0\.\.1, got 2"),
    ({"trial": True}, TypeError, "trial must be an int, got bool"),
    ({"trial": "0"}, TypeError, "trial must be an int, got str"),
    ({"dt": 0.0}, ValueError, "dt must be a finite number > 0 s, got 0.0"),
    ({"dt": -1e-4}, ValueError, "dt must be a finite number > 0 s, got -0.0001"),
    ({"dt": float("inf")}, ValueError, "dt must be a finite number > 0 s, got inf"),
    ({"dt": "0.1 ms"}, TypeError, "dt must be a real number"),
    ({"dt": 3 * b2.mV}, TypeError, "dt must be a time"),
    ({"join_trials": True, "condition": 1}, ValueError, "leave condition and trial at 0"),
    ({"join_trials": 1}, TypeError, "join_trials must be a bool"),
    ({"merge": "yes"}, TypeError, "merge must be a bool"),
    ({"gap_s": -0.1}, ValueError, "gap_s must be a finite number >= 0 s, got -0.1"),
    ({"name": 3}, TypeError, "name must be a str"),
])
def test_bad_arguments(ds, kwargs, error, match):
    with pytest.raises(error, match=match):
        to_brian2(ds, **kwargs)


def test_bad_datasets(ds):
    with pytest.raises(TypeError, match="dataset must be an xarray.Dataset"):
        to_brian2(ds.spike_time)
    with pytest.raises(ValueError, match="no spike events"):
        to_brian2(ds.drop_vars(["spike_time", "spike_afferent", "spike_trial", "spike_condition"]))
    no_dt = ds.copy()
    del no_dt.attrs["dt"]
    with pytest.raises(ValueError, match="attrs lack 'dt'"):
        to_brian2(no_dt)
