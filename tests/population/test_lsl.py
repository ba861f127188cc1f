"""Lab Streaming Layer: the stamp rule, the bridge's bit-for-bit equality with offline runs, loopback streams.

Loopback only (tests/conftest.py writes the LSL config and sets LSLAPICFG);
every stream name is unique to its test, every wait is bounded.
"""

import time

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from ddmm.population.runtime.lsl import ChunkReader, ForceStream, open_force_outlet, open_force_stream
from ddmm.population.runtime.lsl_outlets import SpikeOutlet, read_spike_metadata
from ddmm.population.runtime.lsl_bridge import Bridge, check_stamps
from ddmm.population.runtime.stream import Encoder

from .lsl_support import DT, FS, Collect, plate_recording, start_bridge
from .lsl_support import unique_name as _name


@pytest.fixture(scope="module")
def recording(tmp_path_factory):
    return plate_recording(tmp_path_factory)


def _fake(offset=0.25, n_sites=1):
    return ForceStream("fake", "fake-id", "host", FS, n_sites, "mN", 1, offset, inlet=None)


_Collect = Collect


def test_check_stamps_keeps_increasing_stamps_and_measures_gaps():
    keep, excess = check_stamps([0.001, 0.002, 0.0015, 0.002, 0.0041, 0.0051], 0.0, 1000.0)
    assert keep.tolist() == [True, True, False, False, True, True]
    np.testing.assert_allclose(excess, [0, 0, 0, 0, 0.0011, 0], atol=1e-12)
    keep, excess = check_stamps([5.0, 5.0014], None, 1000.0)  # 1.4 periods: jitter, not a gap
    assert keep.all() and not excess.any()


@settings(max_examples=200, deadline=None)
@given(steps=st.lists(st.floats(-0.002, 0.004, allow_nan=False), min_size=1, max_size=6))
def test_the_usual_chunk_test_agrees_with_the_stamp_rule(recording, steps):
    """A chunk the bridge encodes without the rule is one the rule keeps whole with no gap, and vice versa."""
    bridge = Bridge(Encoder(recording[0].select([0]), FS), _fake(), print)
    stamps = 1.0 + np.cumsum(steps)
    bridge._last = 1.0
    keep, excess = check_stamps(stamps, 1.0, FS)
    assert bridge._in_step(stamps) == bool(keep.all() and not excess.any())
    bridge._last = None  # the first chunk always takes the rule's path (it sets the stamps' anchor)
    assert not bridge._in_step(stamps)


@settings(max_examples=8, deadline=None)
@given(cuts=st.lists(st.integers(1, 899), max_size=20, unique=True), jitter=st.floats(0.0, 0.45))
def test_any_arrival_and_stamp_jitter_gives_the_offline_spikes(recording, cuts, jitter):
    """Chunks of any size (arrival) and stamps jittered by up to 0.45 of a period change no spike and no stamp."""
    pop, raw, ids, steps = recording
    rng = np.random.default_rng(len(cuts))
    stamps = 100.0 + np.arange(raw.shape[0]) / FS + rng.uniform(-0.5, 0.5, raw.shape[0]) * jitter / FS
    stamps[0] = 100.0
    sink = _Collect()
    bridge = Bridge(Encoder(pop, FS, seed=4), _fake(), sink)
    edges = [0] + sorted(cuts) + [raw.shape[0]]
    for a, b in zip(edges[:-1], edges[1:]):
        bridge.consume(raw[a:b], stamps[a:b])
    positions, out = sink.arrays()
    np.testing.assert_array_equal(pop.afferent_id[positions], ids)
    np.testing.assert_array_equal(np.round((out - 100.25) / DT).astype(np.int64), steps)
    assert bridge.summary.samples == raw.shape[0] and not bridge.summary.gaps and ids.size > 200


def test_a_gap_is_reported_and_moves_later_stamps_on(recording):
    pop, raw, ids, steps = recording
    stamps = np.arange(raw.shape[0]) / FS
    stamps[600:] += 0.2  # 100 samples lost in transmission
    sink, messages = _Collect(), []
    bridge = Bridge(Encoder(pop, FS, seed=4), _fake(offset=0.0), sink, report=messages.append)
    bridge.consume(raw, stamps)
    positions, out = sink.arrays()
    np.testing.assert_array_equal(pop.afferent_id[positions], ids)  # samples taken as consecutive
    after = steps * DT >= 600 / FS
    np.testing.assert_array_equal(np.round((out - 0.2 * after) / DT).astype(np.int64), steps)
    assert len(bridge.summary.gaps) == 1 and "a gap of 0.202 s" in messages[0]
    assert bridge.summary.gaps[0][0] == pytest.approx(599 / FS)


def test_out_of_order_and_refused_samples_are_dropped_and_reported(recording):
    pop, raw, _, _ = recording
    stamps = np.arange(raw.shape[0]) / FS
    bad = raw.copy()
    bad[300, 2] = np.nan
    order = np.r_[np.arange(450), 200, np.arange(450, raw.shape[0])]  # sample 200 again, late
    sink, messages = _Collect(), []
    bridge = Bridge(Encoder(pop, FS, seed=4), _fake(offset=0.0), sink, report=messages.append)
    bridge.consume(bad[order], stamps[order])
    assert bridge.summary.out_of_order == 1 and bridge.summary.skipped == 1
    assert any("at or before" in m for m in messages) and any("skipped" in m for m in messages)
    # the same as an encoder that never saw either sample, its clock one sample on after the refused one
    expected = _Collect()
    enc = Encoder(pop, FS, seed=4)
    for a, b, shift in ((0, 300, 0.0), (301, raw.shape[0], 1 / FS)):
        out = enc.push(raw[a:b] * 1e-3)
        expected(out.afferent, out.time + shift)
    np.testing.assert_array_equal(sink.arrays()[0], expected.arrays()[0])
    np.testing.assert_allclose(sink.arrays()[1], expected.arrays()[1], atol=1e-9)


def test_bridge_refuses_an_encoder_of_another_rate_or_site_count(recording):
    pop = recording[0]
    with pytest.raises(ValueError, match="encoder's fs"):
        Bridge(Encoder(pop, 1000.0), _fake(), print)
    with pytest.raises(ValueError, match="site"):
        Bridge(Encoder(pop, FS), _fake(n_sites=2), print)


# ---- loopback streams --------------------------------------------------------------------------------------


def _spike_inlet(name, timeout=5.0):
    import pylsl

    found = pylsl.resolve_byprop("name", name, 1, timeout)
    assert found, f"spike stream {name} not found"
    inlet = pylsl.StreamInlet(found[0], max_buflen=3600)  # irregular rate: hundreds of samples
    info = inlet.info(timeout=timeout)
    inlet.open_stream(timeout=timeout)
    return inlet, info


def _drain(inlet, until, expected=None):
    """Pull spikes until ``until()`` and the inlet is quiet, or 20 s."""
    ids, stamps, deadline, quiet = [], [], time.monotonic() + 20.0, 0
    while time.monotonic() < deadline and quiet < 5:
        samples, ts = inlet.pull_chunk(timeout=0.05, max_samples=4096, min_samples=1, as_numpy=True)
        if len(ts):
            ids.append(samples[:, 0].astype(np.int64))
            stamps.append(np.asarray(ts))
            quiet = 0
        elif until():
            quiet += 1
    return np.concatenate(ids or [np.empty(0, np.int64)]), np.concatenate(stamps or [np.empty(0)])


def test_chunk_reader_returns_what_has_arrived_in_order_up_to_its_size():
    import pylsl

    name = _name("reader")
    outlet = open_force_outlet(name, fs=FS)
    force = open_force_stream(name, timeout=5.0)
    force.open()
    reader = ChunkReader(force.inlet, max_samples=4)
    sent = np.arange(30.0).reshape(10, 3)
    stamps = pylsl.local_clock() + np.arange(10) / FS
    outlet.push_chunk(sent, stamps.tolist())
    got, got_stamps, deadline = [], [], time.monotonic() + 10.0
    while sum(len(g) for g in got) < 10 and time.monotonic() < deadline:
        samples, ts = reader.pull(0.2)
        assert len(samples) == len(ts) <= 4
        got.append(samples.copy())
        got_stamps.append(ts.copy())
    np.testing.assert_array_equal(np.concatenate(got), sent)
    np.testing.assert_array_equal(np.concatenate(got_stamps), stamps)
    assert len(reader.pull(0.0)[1]) == 0  # nothing waiting: no wait, nothing returned
    force.close()


def test_chunk_reader_falls_back_on_pylsl_public_pull():
    class Inlet:  # a pylsl without the raw call
        channel_count, np_dtype = 3, np.float64

        def pull_chunk(self, timeout, max_samples, min_samples, as_numpy):
            return np.zeros((1, 3)), np.array([timeout + max_samples + min_samples])

    assert ChunkReader(Inlet(), 8).pull(0.5)[1].tolist() == [9.5]


def test_spikes_over_lsl_equal_the_offline_run_of_the_recorded_scene(recording):
    """A force outlet in mN -> open_force_stream -> Bridge -> SpikeOutlet -> a consumer: the file's spikes."""
    import pylsl

    pop, raw, ids, steps = recording
    names = _name("force"), _name("spikes")
    outlet = open_force_outlet(names[0], fs=FS, units="mN")
    force = open_force_stream(names[0], timeout=5.0)
    assert (force.unit, force.fs, force.n_sites) == ("mN", FS, 1)
    encoder = Encoder(pop, force.fs, seed=4)
    spikes = SpikeOutlet(names[1], encoder, force=force)
    inlet, info = _spike_inlet(names[1])
    meta = read_spike_metadata(info)
    np.testing.assert_array_equal(meta["afferents"]["id"], pop.afferent_id[encoder.positions])
    assert list(meta["afferents"]["type"]) == list(pop.afferent_type[encoder.positions])
    assert meta["input"]["name"] == names[0] and meta["model"]["seed"] == "4"
    bridge = Bridge(encoder, force, spikes.push)
    worker, _ = start_bridge(bridge, raw.shape[0], outlet)
    t0 = pylsl.local_clock()
    rng = np.random.default_rng(1)
    edges = np.unique(np.r_[0, rng.integers(1, raw.shape[0], 60), raw.shape[0]])
    for a, b in zip(edges[:-1], edges[1:]):  # irregular chunks, irregular arrival
        outlet.push_chunk(raw[a:b], (t0 + np.arange(a, b) / FS).tolist())
        time.sleep(rng.uniform(0, 0.004))
    got_ids, got_stamps = _drain(inlet, lambda: not worker.is_alive())
    worker.join(5.0)
    force.close()
    assert bridge.summary.stopped == "duration" and bridge.summary.samples == raw.shape[0]
    np.testing.assert_array_equal(got_ids, ids)
    np.testing.assert_array_equal(np.round((got_stamps - t0 - force.clock_offset_s) / DT).astype(np.int64), steps)


def test_open_force_stream_errors_name_the_problem():
    import pylsl

    missing = _name("missing")
    start = time.monotonic()
    with pytest.raises(ValueError, match=f"no LSL stream named '{missing}' found within 0.5 s"):
        open_force_stream(missing, timeout=0.5)
    assert time.monotonic() - start < 3.0
    name = _name("six")
    keep = open_force_outlet(name, fs=100.0, n_sites=2, units="gf")
    with pytest.raises(ValueError, match="has 6 channels; 1 site.* need 3"):
        open_force_stream(name, timeout=2.0)
    with pytest.raises(ValueError, match="declares its forces in gf, not units='N'"):
        open_force_stream(name, n_sites=2, units="N", timeout=2.0)
    with pytest.raises(ValueError, match="disagrees"):
        open_force_stream(name, n_sites=2, fs=1000.0, timeout=2.0)
    assert open_force_stream(name, n_sites=2, timeout=2.0).scale[2] == pytest.approx(9.80665e-3)
    info = pylsl.StreamInfo(_name("swapped"), "Force", 3, 100.0, pylsl.cf_float32, "swapped")
    channels = info.desc().append_child("channels")
    for label in ("Fz", "Fy", "Fx"):
        channels.append_child("channel").append_child_value("label", label)
    swapped = pylsl.StreamOutlet(info)
    with pytest.raises(ValueError, match="channel 0 is labelled 'Fz'"):
        open_force_stream(info.name(), timeout=2.0)
    irregular = pylsl.StreamOutlet(pylsl.StreamInfo(_name("irr"), "Force", 3, 0.0, pylsl.cf_double64, "irr"))
    with pytest.raises(ValueError, match="irregular rate: give its sample rate"):
        open_force_stream(irregular.get_info().name(), timeout=2.0)
    del keep, swapped, irregular


def test_a_missing_extra_is_one_line_naming_the_install(monkeypatch):
    import sys

    from ddmm.utils.extras import MissingExtraError

    monkeypatch.setitem(sys.modules, "pylsl", None)
    with pytest.raises(MissingExtraError, match=r'pip install "ddmm\[lsl\]"'):
        open_force_stream("anything")


def test_stimulation_pulses_over_lsl_equal_the_offline_stimulation_encoder(recording):
    """--electrodes in closed loop: pulses on an LSL stream equal `StimulationEncoder` on the same samples."""
    import pylsl

    from ddmm.population.runtime.lsl_outlets import PulseOutlet
    from ddmm.population.neurostim import Electrode, StimulationEncoder

    pop, raw, _, _ = recording
    table = [Electrode("centre", 20.0, 80.0, 200.0, 300.0, 20.0, x_mm=0.0, y_mm=0.0, radius_mm=5.0),
             Electrode("D2d", 10.0, 40.0, 100.0, 150.0, 5.0, region="D2d")]
    names = _name("force"), _name("spikes"), _name("pulses")
    outlet = open_force_outlet(names[0], fs=FS, units="mN")
    force = open_force_stream(names[0], timeout=5.0)
    stimulator = StimulationEncoder(Encoder(pop, force.fs, seed=4), table)
    stimulator.warm_up()
    spikes, pulses = SpikeOutlet(names[1], stimulator.encoder, force=force), PulseOutlet(names[2], stimulator)
    inlet, _ = _spike_inlet(names[2])
    bridge = Bridge(stimulator.encoder, force, spikes.push, stimulator=stimulator, pulse_sink=pulses.push)
    worker, deadline = start_bridge(bridge, raw.shape[0], outlet)
    t0 = pylsl.local_clock()
    for a in range(0, raw.shape[0], 50):
        outlet.push_chunk(raw[a:a + 50], (t0 + np.arange(a, min(a + 50, raw.shape[0])) / FS).tolist())
    rows, stamps = [], []
    while time.monotonic() < deadline and (worker.is_alive() or not rows):
        samples, ts = inlet.pull_chunk(timeout=0.1, max_samples=4096, min_samples=1, as_numpy=True)
        if len(ts):
            rows.append(samples)
            stamps.append(ts)
    samples, ts = inlet.pull_chunk(timeout=0.5, max_samples=4096, as_numpy=True)
    rows, stamps = np.concatenate(rows + [samples]), np.concatenate(stamps + [ts])
    worker.join(5.0)
    expected = StimulationEncoder(Encoder(pop, FS, seed=4), table).push(raw * 1e-3)
    assert bridge.summary.pulses == expected.time.size > 20
    np.testing.assert_array_equal(rows[:, 0].astype(int), expected.electrode)
    np.testing.assert_array_equal(rows[:, 1], expected.amplitude_ua)
    np.testing.assert_allclose(stamps - t0 - force.clock_offset_s, expected.time, atol=1e-9)
