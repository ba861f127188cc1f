"""The spike stream's formats: batched frames decode to the events format's ids and stamps, bit for bit.

Loopback only (tests/conftest.py writes the LSL config); every stream name is unique, every wait bounded.
"""

import subprocess
import sys
import time
from itertools import pairwise

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from ddmm.population.runtime.lsl import open_force_outlet, open_force_stream
from ddmm.population.runtime.lsl_bridge import Bridge
from ddmm.population.runtime.lsl_outlets import SpikeOutlet, read_spike_metadata
from ddmm.population.runtime.spike_formats import FRAME_CAPACITY, SPIKE_FORMATS, _frames, _jit, decode_spikes
from ddmm.population.runtime.stream import Encoder

from .lsl_support import DT, FS, plate_recording, start_bridge
from .lsl_support import unique_name as _name


def _bits(x):
    return np.asarray(x, np.float64).view(np.int64)


def _round_trip(ids, stamps):
    frames, frame_stamps = SPIKE_FORMATS["batched"].pack(ids, stamps)
    return frames, frame_stamps, decode_spikes(frames, frame_stamps, "batched")


def test_a_push_over_a_frame_goes_on_in_more_frames():
    """5,000 spikes in one push, one step holding 3,000 (more than a frame): 3 frames, the same spikes back."""
    rng = np.random.default_rng(5)
    stamps = np.repeat(1234.5678 + np.array([0.0, 1e-4, 2e-4, 3e-4]), [1000, 3000, 999, 1])
    ids = rng.integers(0, 12_584, stamps.size)
    frames, frame_stamps, (got_ids, got_stamps) = _round_trip(ids, stamps)
    assert frames.shape == (3, FRAME_CAPACITY) and frames.dtype == np.int32
    np.testing.assert_array_equal(got_ids, ids)
    np.testing.assert_array_equal(_bits(got_stamps), _bits(stamps))
    # frame 0: 1,000 spikes, then 1,042 of the 3,000 (a full frame); frame 1 goes on with their 1,958 under
    # its own header, then 84 of the next step's; frame 2 holds the rest and is padded.  Each frame's stamp
    # is its first group's.
    assert frames[0, 0] == 1000 and frames[0, 1003] == 1042 and frames[1, 0] == 1958 and frames[1, 1961] == 84
    assert frames[2, 0] == 915 and frames[2, 918] == 1 and np.all(frames[2, 922:] == -1)
    np.testing.assert_array_equal(_bits(frame_stamps), _bits(stamps[[0, 1000, 4000]]))


def test_an_empty_push_has_no_frame_and_empty_frames_no_spike():
    frames, frame_stamps, (ids, stamps) = _round_trip(np.empty(0, np.int64), np.empty(0))
    assert frames.shape == (0, FRAME_CAPACITY) and frame_stamps.size == 0 and ids.size == 0 and stamps.size == 0
    for samples in (np.empty((0, FRAME_CAPACITY), np.int32), [], np.full((2, FRAME_CAPACITY), -1, np.int32)):
        ids, stamps = decode_spikes(samples, np.zeros(len(samples)), "batched")
        assert ids.dtype == np.int64 and stamps.dtype == np.float64 and ids.size == 0 and stamps.size == 0
    ids, stamps = decode_spikes(np.empty((0, 1), np.int32), [], "events")
    assert ids.size == 0 and stamps.size == 0


def test_malformed_frames_and_unknown_formats_are_refused():
    events = np.arange(8, dtype=np.int32).reshape(2, 4) + 5  # a count running past the frame's end
    with pytest.raises(ValueError, match="batched spike frame 0 is malformed"):
        decode_spikes(events, np.zeros(2), "batched")
    zero = np.full((1, 8), -1, np.int32)
    zero[0, :3] = 0
    with pytest.raises(ValueError, match="malformed"):
        decode_spikes(zero, np.zeros(1), "batched")
    with pytest.raises(ValueError, match="spike_format must be one of events, batched, got 'frames'"):
        decode_spikes(events, np.zeros(2), "frames")


@settings(max_examples=200, deadline=None)
@given(groups=st.lists(st.tuples(st.integers(1, 12), st.floats(-1e9, 1e9, allow_nan=False)), max_size=12),
       capacity=st.integers(4, 16))
def test_frames_of_any_capacity_decode_to_the_spikes_bit_for_bit(groups, capacity):
    """Groups of equal stamps split at any frame boundary (small frames: every edge is reached)."""
    counts = [c for c, _ in groups]
    stamps = np.repeat(np.array([s for _, s in groups], np.float64), counts)
    ids = np.arange(stamps.size, dtype=np.int32) * 7 + 3
    frames, first = _jit(_frames)(ids, stamps.view(np.int64), stamps, capacity) if ids.size else (
        np.empty((0, capacity), np.int32), np.empty(0))
    got_ids, got_stamps = decode_spikes(frames, first, "batched")
    np.testing.assert_array_equal(got_ids, ids)
    np.testing.assert_array_equal(_bits(got_stamps), _bits(stamps))
    # no frame wasted: every frame but the last has fewer than 4 slots of padding (ids are >= 3, counts >= 1)
    assert not np.any(np.all(frames[:-1, -4:] == -1, axis=1))
    heads = (frames[:, 1].astype(np.int64) << 32) | (frames[:, 2].astype(np.int64) & 0xFFFFFFFF)
    np.testing.assert_array_equal(_bits(first), heads)  # a frame's stamp: its first group's


@pytest.fixture(scope="module")
def recording(tmp_path_factory):
    return plate_recording(tmp_path_factory)


def _spike_inlet(name):
    import pylsl

    found = pylsl.resolve_byprop("name", name, 1, 5.0)
    assert found, f"spike stream {name} not found"
    inlet = pylsl.StreamInlet(found[0], max_buflen=3600)
    info = inlet.info(timeout=5.0)
    inlet.open_stream(timeout=5.0)
    return inlet, info


def _drain(inlet, until):
    """Pull samples until ``until()`` and the inlet is quiet, or 20 s: (samples, stamps) as received."""
    samples, stamps, deadline, quiet = [], [], time.monotonic() + 20.0, 0
    while time.monotonic() < deadline and quiet < 5:
        got, ts = inlet.pull_chunk(timeout=0.05, max_samples=4096, min_samples=1, as_numpy=True)
        if len(ts):
            samples.append(np.asarray(got))
            stamps.append(np.asarray(ts))
            quiet = 0
        elif until():
            quiet += 1
    width = inlet.channel_count
    return (np.concatenate(samples) if samples else np.empty((0, width), np.int32),
            np.concatenate(stamps) if stamps else np.empty(0))


def test_batched_spikes_over_lsl_equal_the_offline_run_and_the_events_stamps(recording):
    """One bridge, both formats: the batched stream decodes to the offline run's spikes and to the events
    stream's stamps, bit for bit."""
    import pylsl

    pop, raw, ids, steps = recording
    names = _name("force"), _name("events"), _name("batched")
    outlet = open_force_outlet(names[0], fs=FS, units="mN")
    force = open_force_stream(names[0], timeout=5.0)
    encoder = Encoder(pop, force.fs, seed=4)
    events = SpikeOutlet(names[1], encoder, force=force)
    batched = SpikeOutlet(names[2], encoder, force=force, spike_format="batched")
    (events_inlet, events_info), (batched_inlet, batched_info) = _spike_inlet(names[1]), _spike_inlet(names[2])
    meta = read_spike_metadata(batched_info)
    assert meta["format"] == "batched" and read_spike_metadata(events_info)["format"] == "events"
    assert batched_info.channel_count() == FRAME_CAPACITY and events_info.channel_count() == 1
    np.testing.assert_array_equal(meta["afferents"]["id"], pop.afferent_id[encoder.positions])
    assert batched_info.desc().child("frame").child_value("capacity") == str(FRAME_CAPACITY)

    def both(positions, stamps):
        events.push(positions, stamps)
        batched.push(positions, stamps)
    bridge = Bridge(encoder, force, both)
    worker, _ = start_bridge(bridge, raw.shape[0], outlet)
    t0 = pylsl.local_clock()
    rng = np.random.default_rng(1)
    edges = np.unique(np.r_[0, rng.integers(1, raw.shape[0], 60), raw.shape[0]])
    for a, b in pairwise(edges):  # irregular chunks, irregular arrival
        outlet.push_chunk(raw[a:b], (t0 + np.arange(a, b) / FS).tolist())
        time.sleep(rng.uniform(0, 0.004))
    frames, frame_stamps = _drain(batched_inlet, lambda: not worker.is_alive())
    got_events = decode_spikes(*_drain(events_inlet, lambda: True), "events")
    worker.join(5.0)
    force.close()
    assert bridge.summary.stopped == "duration" and bridge.summary.samples == raw.shape[0]
    got_ids, got_stamps = decode_spikes(frames, frame_stamps, meta["format"])
    assert 0 < frames.shape[0] < got_ids.size  # frames, not one sample per spike
    np.testing.assert_array_equal(got_ids, ids)
    np.testing.assert_array_equal(np.round((got_stamps - t0 - force.clock_offset_s) / DT).astype(np.int64), steps)
    np.testing.assert_array_equal(got_events[0], got_ids)
    np.testing.assert_array_equal(_bits(got_events[1]), _bits(got_stamps))


def test_an_outlet_push_over_a_frame_arrives_whole(recording):
    """One push of 5,000 spikes through a batched SpikeOutlet: 3 frames over LSL, every spike back."""
    pop = recording[0]
    name = _name("burst")
    encoder = Encoder(pop, FS, seed=4)
    outlet = SpikeOutlet(name, encoder, spike_format="batched")
    inlet, _ = _spike_inlet(name)
    rng = np.random.default_rng(2)
    positions = rng.integers(0, len(pop), 5000)
    stamps = np.repeat(100.0 + np.arange(3) * 1e-4, [1000, 3000, 1000])
    outlet.push(positions, stamps)
    outlet.push([], [])  # nothing to send: no frame
    frames, frame_stamps = _drain(inlet, lambda: True)
    assert frames.shape[0] == 3
    ids, got = decode_spikes(frames, frame_stamps, "batched")
    np.testing.assert_array_equal(ids, pop.afferent_id[positions])
    np.testing.assert_array_equal(_bits(got), _bits(stamps))
    with pytest.raises(ValueError, match="spike_format must be one of events, batched, got 'Batched'"):
        SpikeOutlet(_name("bad"), encoder, spike_format="Batched")


def test_closing_an_outlet_waits_for_its_consumers_and_delivers_the_last_spikes(recording):
    """close() right after a push stays open `linger` seconds while an inlet is connected (liblsl drops what
    it has queued but not sent when an outlet dies); with nobody connected it returns at once."""
    pop = recording[0]
    encoder = Encoder(pop, FS, seed=4)
    outlet = SpikeOutlet(_name("linger"), encoder)
    inlet, _ = _spike_inlet(outlet.name)
    positions = np.random.default_rng(5).integers(0, len(pop), 200000)
    stamps = 100.0 + np.arange(positions.size) * 1e-5
    outlet.push(positions, stamps)
    start = time.monotonic()
    outlet.close(linger=1.0)
    assert time.monotonic() - start >= 1.0
    samples, got = _drain(inlet, lambda: True)
    np.testing.assert_array_equal(decode_spikes(samples, got, "events")[0], pop.afferent_id[positions])
    alone = SpikeOutlet(_name("alone"), encoder)
    start = time.monotonic()
    alone.close(linger=30.0)
    assert time.monotonic() - start < 30.0
    with pytest.raises(ValueError, match="linger must be a finite number >= 0 s, got -1"):
        SpikeOutlet(_name("bad"), encoder).close(linger=-1.0)


@pytest.mark.parametrize("argv, message", [
    (["--lsl-spike-format", "frames"], ("argument --lsl-spike-format: invalid choice: 'frames' (choose from "
                                        "'events', 'batched')")),
    (["--lsl-spike-format", "batched", "--fs", "100"], "--lsl-spike-format goes with --lsl-out"),
])
def test_a_bad_spike_format_is_one_line_and_exit_status_2(argv, message):
    done = subprocess.run([sys.executable, "-m", "ddmm.experiments.cli", "stream", *argv], capture_output=True,
                          text=True, stdin=subprocess.DEVNULL, timeout=120, check=False)
    assert done.returncode == 2 and message in done.stderr, done.stderr
    assert len(done.stderr.strip().splitlines()) == 1
