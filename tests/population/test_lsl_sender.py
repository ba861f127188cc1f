"""A sender that fails: the bridge's timeout and lost-stream rules, without a network (a scripted inlet).

The same over loopback LSL, with a sender process killed mid-stream: tests/experiments/test_cli_lsl_sender.py.
"""

import time

import numpy as np
import pytest

from ddmm.population import make_population
from ddmm.population.runtime.lsl import ForceStream
from ddmm.population.runtime.lsl_bridge import QUIET_END_S, Bridge
from ddmm.population.runtime.stream import Encoder

FS = 1000.0


class _Inlet:
    """Plays a script to the bridge's `ChunkReader` (pylsl's public pull): chunks, silences, a lost stream."""

    channel_count = 3

    def __init__(self, script):
        self.script = list(script)

    def open_stream(self, timeout=None):
        pass

    def close_stream(self):
        pass

    def pull_chunk(self, timeout, max_samples, min_samples, as_numpy):
        import pylsl

        item = self.script[0] if self.script else ("silence", None)
        if isinstance(item, str):  # "lost"
            raise pylsl.util.LostError("the stream was lost")
        if isinstance(item[0], str):  # ("silence", seconds left)
            if item[1] is not None:
                item[1][0] -= timeout
                if item[1][0] <= 0:
                    self.script.pop(0)
            time.sleep(timeout)
            return np.zeros((0, 3)), np.zeros(0)
        self.script.pop(0)
        return item


def _press(n, start=0):
    k = np.arange(start, start + n)
    forces = np.column_stack([np.zeros(n), 0.2 * np.minimum(k / 200, 1.0), np.minimum(k / 100, 2.0)])
    return forces, 50.0 + k / FS


def _bridge(script, messages):
    force = ForceStream("glove", "glove-id", "host", FS, 1, "N", 1, 0.0, _Inlet(script))
    encoder = Encoder(make_population(["SAI", "RAI"], theta_t=[0.0, 90.0]), FS, seed=1)
    encoder.warm_up()  # as `ddmm stream` does: a first push loading the kernels would eat the silences' margins
    spikes = []
    return Bridge(encoder, force, lambda p, t: spikes.append(t), report=messages.append), spikes


def _silence(seconds):
    """Empty pulls for ``seconds`` (None: for ever)."""
    return ("silence", None if seconds is None else [seconds])


def test_no_sample_within_the_timeout_stops_as_a_silent_sender():
    messages = []
    bridge, spikes = _bridge([_press(300), _silence(3.0), "lost"], messages)  # lost: a bound, were the rule broken
    start = time.monotonic()
    summary = bridge.run(timeout=0.3, poll_s=0.02)
    assert summary.stopped == "sender silent" and summary.sender_failed
    assert 0.3 <= summary.quiet_s < 0.6 and time.monotonic() - start < 2.0
    assert summary.samples == 300 and summary.spikes == sum(len(s) for s in spikes) > 0
    assert messages == [(f"LSL stream 'glove' sent no sample for {summary.quiet_s:.3g} s since its last one (the "
                         "timeout is 0.3 s): its sender has stopped")]


def test_a_stream_lost_while_samples_come_is_a_lost_sender():
    messages = []
    bridge, _ = _bridge([_press(200), _press(100, 200), "lost"], messages)
    summary = bridge.run(timeout=5.0, poll_s=0.02)
    assert summary.stopped == "sender lost" and summary.sender_failed and summary.samples == 300
    assert summary.quiet_s < QUIET_END_S
    assert len(messages) == 1 and messages[0].startswith("LSL stream 'glove' was lost ")
    assert "s after its last sample, while samples were coming" in messages[0]


def test_a_stream_withdrawn_after_a_quiet_spell_is_the_end_of_input():
    messages = []
    bridge, _ = _bridge([_press(300), _silence(QUIET_END_S + 0.15), "lost"], messages)
    summary = bridge.run(timeout=5.0, poll_s=0.02)
    assert summary.stopped == "end of input" and not summary.sender_failed and not messages


def test_before_the_first_sample_and_without_a_timeout_the_bridge_waits():
    messages = []
    bridge, _ = _bridge([_silence(0.4), _press(50), _silence(0.3), _press(50, 50)], messages)
    deadline = time.monotonic() + 3.0
    summary = bridge.run(timeout=0.35, poll_s=0.02, should_stop=lambda: time.monotonic() > deadline)
    assert summary.samples == 100 and summary.stopped == "sender silent"  # 0.4 s before the first: waited
    bridge, _ = _bridge([_press(50), _silence(0.5), _press(50, 50)], messages)
    deadline = time.monotonic() + 0.9
    summary = bridge.run(poll_s=0.02, should_stop=lambda: time.monotonic() > deadline)
    assert summary.samples == 100 and summary.stopped == "stopped"
    with pytest.raises(ValueError, match="timeout must be a finite number > 0"):
        bridge.run(timeout=0.0)


def test_the_cli_reports_a_silent_sender_writes_its_spikes_and_exits_3(monkeypatch, capsys):
    """``ddmm stream --lsl-in`` on a scripted stream: the report, every spike produced on stdout, status 3."""
    from ddmm.experiments.cli import main
    from ddmm.experiments.cli.stream import SENDER_FAILED_STATUS
    from ddmm.population.runtime import lsl

    forces, stamps = _press(400)
    script = [(forces[a:a + 40], stamps[a:a + 40]) for a in range(0, 400, 40)] + [_silence(3.0), "lost"]
    monkeypatch.setattr(lsl, "open_force_stream", lambda name, **_: ForceStream(
        name, "id", "host", FS, 1, "N", 1, 0.0, _Inlet(script)))
    status = main(["stream", "--lsl-in", "glove", "--types", "SAI,RAI", "--seed", "2", "--lsl-timeout", "0.25"])
    out, err = capsys.readouterr()
    assert status == SENDER_FAILED_STATUS == 3
    lines = err.strip().splitlines()
    assert lines[1].startswith("ddmm: LSL stream 'glove' sent no sample for ") and "(the timeout is 0.25 s)" in lines[1]
    assert "400 samples in" in lines[2] and lines[2].endswith("(sender silent)")
    from ddmm.population import load_spec, sample_population

    pop = sample_population(load_spec("fingertip"), rng=2)
    expected = Encoder(pop, FS, seed=2, afferent_types=("SAI", "RAI")).push(forces)
    rows = [line.split(",") for line in out.strip().splitlines()]
    assert len(rows) == expected.afferent.size > 10
    np.testing.assert_array_equal([int(r[1]) for r in rows], pop.afferent_id[expected.afferent])
    np.testing.assert_allclose([float(r[0]) for r in rows], 50.0 + expected.time, atol=1e-6)
