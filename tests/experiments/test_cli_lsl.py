"""``ddmm stream --lsl-in/--lsl-out`` and ``ddmm play`` as separate processes, over loopback LSL.

Each test's streams have unique names; every wait is bounded (process timeouts, resolve timeouts).
"""

import os
import re
import signal
import subprocess
import sys
import time
import uuid
from pathlib import Path

import numpy as np
import pytest

from ddmm.population import birznieks, sample_population
from ddmm.population.runtime.lsl import open_force_outlet
from ddmm.population.runtime.lsl_outlets import decode_spikes, read_spike_metadata
from ddmm.population.runtime.stream import Encoder

DOCS = Path(__file__).resolve().parents[2] / "docs" / "live-sensors.md"


def _name(what):
    return f"ddmm-cli-{what}-{uuid.uuid4().hex[:8]}"


def _ddmm(*argv):
    return subprocess.Popen([sys.executable, "-m", "ddmm.experiments.cli", *argv], stdout=subprocess.PIPE,
                            stderr=subprocess.PIPE, text=True, env={**os.environ, "DDMM_PROGRESS": "0"})


def _inlet(name, timeout):
    import pylsl

    found = pylsl.resolve_byprop("name", name, 1, timeout)
    assert found, f"stream {name} did not appear within {timeout} s"
    inlet = pylsl.StreamInlet(found[0], max_buflen=3600)  # irregular rate: hundreds of samples
    info = inlet.info(timeout=5.0)
    inlet.open_stream(timeout=5.0)
    return inlet, info


@pytest.mark.parametrize("spike_format", ["events", "batched"])
def test_stream_over_lsl_equals_the_in_process_encoder(spike_format):
    """A force outlet here, ``ddmm stream --lsl-in --lsl-out`` in another process, the spikes read back here
    and decoded (`decode_spikes`) as the stream's meta-data say."""
    import pylsl

    force, spikes = _name("force"), _name("spikes")
    scene = birznieks(45.0)
    raw = np.column_stack([scene.fx, scene.fy, scene.fz])[::2] * 1e3  # 500 Hz, in mN
    outlet = open_force_outlet(force, fs=500.0, units="mN")
    proc = _ddmm("stream", "--lsl-in", force, "--lsl-out", spikes, "--seed", "3", "--types", "SAI,RAI,SAII",
                 "--duration", f"{raw.shape[0] / 500.0}", "--resolve-timeout", "60", "--lsl-spike-format",
                 spike_format)
    try:
        inlet, info = _inlet(spikes, 90.0)  # the first run in a fresh environment compiles numba kernels
        meta = read_spike_metadata(info)
        deadline = time.monotonic() + 60.0
        while not outlet.have_consumers() and time.monotonic() < deadline:  # the bridge opens its inlet after
            time.sleep(0.01)  # its spike stream appears: LSL drops what is pushed before it subscribes
        t0 = pylsl.local_clock()
        for a in range(0, raw.shape[0], 7):
            outlet.push_chunk(raw[a:a + 7], (t0 + np.arange(a, min(a + 7, raw.shape[0])) / 500.0).tolist())
            time.sleep(0.002)
        ids, stamps, chunk_len = [], [], 1
        deadline = time.monotonic() + 60.0
        while time.monotonic() < deadline and (proc.poll() is None or len(ids) == 0 or chunk_len):
            samples, ts = inlet.pull_chunk(timeout=0.2, max_samples=max(64, 4096 // info.channel_count()),
                                           min_samples=1, as_numpy=True)
            chunk_len = len(ts)
            if chunk_len:
                got_ids, got_stamps = decode_spikes(samples, ts, meta["format"])
                ids.append(got_ids)
                stamps.append(got_stamps)
        out, err = proc.communicate(timeout=30)
    finally:
        proc.kill()
    assert proc.returncode == 0, err
    assert f"{raw.shape[0]:,} samples in" in err and "(duration)" in err
    assert meta["format"] == spike_format and f"{spike_format} format" in err
    offset = float(meta["input"]["clock_offset_s"])
    pop = sample_population("fingertip", rng=3)
    expected = Encoder(pop, 500.0, seed=3, afferent_types=("SAI", "RAI", "SAII")).push(raw * 1e-3)
    got = np.concatenate(ids)
    np.testing.assert_array_equal(got, pop.afferent_id[expected.afferent])
    steps = np.round((np.concatenate(stamps) - t0 - offset) / 1e-4).astype(np.int64)
    np.testing.assert_array_equal(steps, np.round(expected.time / 1e-4).astype(np.int64))
    assert set(meta["afferents"]["type"]) == {"SAI", "RAI", "SAII"} and got.size > 100


def test_a_signal_stops_the_stream_cleanly():
    force = _name("quiet")
    outlet = open_force_outlet(force, fs=1000.0)
    proc = _ddmm("stream", "--lsl-in", force, "--resolve-timeout", "60")
    try:
        deadline = time.monotonic() + 90.0
        while not outlet.have_consumers() and time.monotonic() < deadline:
            time.sleep(0.05)
        time.sleep(2.0)  # past the encoder's set-up
        outlet.push_chunk(np.tile([0.0, 0.0, 1.0], (50, 1)))
        time.sleep(0.5)
        proc.send_signal(signal.SIGTERM)
        out, err = proc.communicate(timeout=30)
    finally:
        proc.kill()
    assert proc.returncode == 0, err
    assert re.search(r"stream ended: 50 samples in, [\d,]+ spikes out.*\(stopped\)", err), err
    assert "Traceback" not in err


def test_the_docs_two_process_example_runs():
    """The bash block of docs/live-sensors.md marked 'two processes', run as written (with unique names)."""
    block = re.search(r"<!-- two processes -->\n```bash\n(.*?)```", DOCS.read_text(), re.S).group(1)
    names = {"glove": _name("glove")}
    script = re.sub(r"\bglove\b", names["glove"], block)
    done = subprocess.run(["bash", "-c", script], capture_output=True, text=True, timeout=240,
                          env={**os.environ, "DDMM_PROGRESS": "0", "PATH": f"{Path(sys.executable).parent}:"
                                                                           f"{os.environ['PATH']}"})
    assert done.returncode == 0, done.stderr
    assert re.search(r"stream ended: 50 samples in, [\d,]+ spikes out, 0 gap\(s\).*\(end of input\)", done.stderr)
    rows = [line.split(",") for line in done.stdout.strip().splitlines()]
    assert len(rows) > 100 and {r[2] for r in rows} <= {"SAI", "RAI", "SAII"}


@pytest.mark.parametrize("argv, message", [
    (["--lsl-in", "ddmm-cli-nothere", "--resolve-timeout", "1"], "no LSL stream named 'ddmm-cli-nothere' found "
                                                                  "within 1 s"),
    (["--lsl-in", "X", "--sites", "fingertips", "--resolve-timeout", "1"], "no LSL stream named 'X'"),
    (["--lsl-source-id", "abc", "--fs", "100"], "--lsl-source-id goes with --lsl-in"),
    ([], "--fs is required when the input is standard input"),
    (["--threads", "0", "--fs", "100"], "--threads must be >= 1, got 0"),
])
def test_stream_errors_are_one_line(argv, message, capsys):
    from ddmm.experiments.cli import main

    start = time.monotonic()
    assert main(["stream", *argv]) == 2
    err = capsys.readouterr().err
    assert message in err and len(err.strip().splitlines()) == 1
    assert time.monotonic() - start < 10.0


def test_a_stream_of_the_wrong_width_and_a_missing_extra(capsys, monkeypatch):
    from ddmm.experiments.cli import main

    name = _name("wide")
    keep = open_force_outlet(name, fs=100.0, n_sites=2)
    assert main(["stream", "--lsl-in", name, "--resolve-timeout", "5"]) == 2
    assert "has 6 channels; 1 site(s) need 3" in capsys.readouterr().err
    del keep
    monkeypatch.setitem(sys.modules, "pylsl", None)
    assert main(["stream", "--lsl-in", name, "--resolve-timeout", "1"]) == 2
    assert 'open_force_stream needs pylsl: pip install "ddmm[lsl]"' in capsys.readouterr().err


def test_a_live_stream_on_two_cores_pushes_on_one_thread(monkeypatch):
    """--threads' default: one with --lsl-in on a host of at most two cores (unless DDMM_NUM_THREADS is set),
    else the encoder's own default (None); a given count is kept."""
    from ddmm.experiments.cli.stream import encoder_threads

    monkeypatch.delenv("DDMM_NUM_THREADS", raising=False)
    monkeypatch.setattr(os, "cpu_count", lambda: 2)
    assert encoder_threads(None, live=True) == 1 and encoder_threads(None, live=False) is None
    assert encoder_threads(3, live=True) == 3
    monkeypatch.setenv("DDMM_NUM_THREADS", "2")
    assert encoder_threads(None, live=True) is None
    monkeypatch.delenv("DDMM_NUM_THREADS")
    monkeypatch.setattr(os, "cpu_count", lambda: 8)
    assert encoder_threads(None, live=True) is None


def test_the_bench_latency_is_per_sample_until_its_last_spike():
    from ddmm.experiments.bench.lsl import _latencies

    pushed = 10.0 + np.arange(5) / 1000.0 + 0.0002  # pushed 0.2 ms after each due time
    anchor = 10.0  # due time of sample 0 on this host's clock
    arrivals = [(10.0009, np.array([10.00005, 10.00095])), (10.0035, np.array([10.0001, 10.0031]))]
    np.testing.assert_allclose(_latencies(pushed, anchor, arrivals), [0.0035 - 0.0002, 0.0035 - 0.0032])


def test_stream_publishes_stimulation_pulses_equal_to_the_in_process_encoder(tmp_path):
    """``ddmm stream --lsl-in F --electrodes E.csv --lsl-pulses P`` in another process: the pulses read here."""
    import pylsl

    from ddmm.population.neurostim import StimulationEncoder, read_electrodes

    table = tmp_path / "e.csv"
    table.write_text("id,x_mm,y_mm,radius_mm,region,amplitude_min_ua,amplitude_max_ua,phase_width_us,max_rate_hz,"
                     "charge_limit_nc\ncentre,0,0,5,,20,80,200,300,20\nedge,4,4,3,,10,60,100,200,10\n")
    force, pulses = _name("force"), _name("pulses")
    scene = birznieks(90.0)
    raw = np.column_stack([scene.fx, scene.fy, scene.fz])
    outlet = open_force_outlet(force, fs=1000.0)
    proc = _ddmm("stream", "--lsl-in", force, "--electrodes", str(table), "--lsl-pulses", pulses, "--seed", "5",
                 "--lsl-out", _name("spikes"),  # spikes off stdout: an unread pipe would fill and block
                 "--types", "SAI,RAI", "--duration", f"{raw.shape[0] / 1000.0}", "--resolve-timeout", "60")
    try:
        inlet, _ = _inlet(pulses, 90.0)
        deadline = time.monotonic() + 60.0
        while not outlet.have_consumers() and time.monotonic() < deadline:  # the bridge opens its inlet
            time.sleep(0.01)
        t0 = pylsl.local_clock()
        outlet.push_chunk(raw, (t0 + np.arange(raw.shape[0]) / 1000.0).tolist())
        rows, stamps, deadline = [], [], time.monotonic() + 60.0
        while time.monotonic() < deadline and (proc.poll() is None or not rows):
            samples, ts = inlet.pull_chunk(timeout=0.2, max_samples=4096, min_samples=1, as_numpy=True)
            if len(ts):
                rows.append(samples)
                stamps.append(np.asarray(ts))
        out, err = proc.communicate(timeout=30)
    finally:
        proc.kill()
    assert proc.returncode == 0, err
    pop = sample_population("fingertip", rng=5)
    expected = StimulationEncoder(Encoder(pop, 1000.0, seed=5, afferent_types=("SAI", "RAI")),
                                  read_electrodes(table)).push(raw)
    got = np.concatenate(rows)
    assert f"{expected.time.size:,} pulses out" in err and expected.time.size > 20
    np.testing.assert_array_equal(got[:, 0].astype(int), expected.electrode)
    np.testing.assert_array_equal(got[:, 1], expected.amplitude_ua)


def test_liblsl_is_quiet_unless_debugging(monkeypatch):
    """Without --debug (and without a config of the user's) liblsl gets a config that logs fatal errors only."""
    from ddmm.experiments.io import quiet_liblsl

    monkeypatch.delenv("LSLAPICFG", raising=False)
    quiet_liblsl(True)
    assert "LSLAPICFG" not in os.environ
    quiet_liblsl(False)
    assert Path(os.environ["LSLAPICFG"]).read_text() == "[log]\nlevel = -3\n"
    monkeypatch.setenv("LSLAPICFG", "mine.cfg")
    quiet_liblsl(False)
    assert os.environ["LSLAPICFG"] == "mine.cfg"
