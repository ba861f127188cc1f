"""Recorded sessions in: an XDF file's force stream gives the live LSL bridge's spikes, and bad files one line each.

The files are written by `save_xdf` / `_write_xdf` (XDF 1.0, written from the specification; the first test
checks their bytes against it) and read by pyxdf, as LabRecorder's are.
"""

import struct
import warnings

import numpy as np
import pytest

from ddmm.population import from_csv, sample_population, simulate
from ddmm.population.io.xdf import XdfStampWarning, _write_xdf, from_xdf, read_xdf, save_xdf
from ddmm.population.runtime.lsl import ForceStream
from ddmm.population.runtime.lsl_bridge import Bridge
from ddmm.population.runtime.stream import Encoder
from ddmm.population.stimuli.scenes import Sites
from ddmm.utils.extras import MissingExtraError

from .lsl_support import FS, Collect

# 500 Hz streams, as in tests/population/test_lsl.py: FA-II's band is missing, and said so once per read
pytestmark = pytest.mark.filterwarnings("ignore::ddmm.population.stimuli.recordings.RecordingBandWarning")


_Collect = Collect


@pytest.fixture(scope="module")
def session():
    """A noisy 500 Hz press in mN as a sender sent it: jittered stamps, a 0.2 s gap, a late sample, a NaN."""
    rng = np.random.default_rng(3)
    n = 900
    t = np.arange(n) / FS
    f = np.column_stack([np.interp(t, [0, 0.6, 1.0], [0, 0, 0.8]), np.interp(t, [0, 0.6, 1.2], [0, 0, -0.5]),
                         np.interp(t, [0, 0.1, 0.5, 2], [0, 0, 2.5, 2.5])]) + rng.normal(0, 0.01, (n, 3))
    stamps = 1000.0 + t + rng.uniform(-0.2, 0.2, n) / FS  # raw: dejittering would move these
    stamps[600:] += 0.2  # 100 samples lost in transmission
    order = np.r_[np.arange(450), 200, np.arange(450, n)]  # sample 200 again, late
    raw, stamps = f[order] * 1e3, stamps[order]
    raw[300, 2] = np.nan  # a sample the encoder refuses
    pop = sample_population("fingertip", rng=0).select(np.arange(0, 991, 5))
    return pop, raw, stamps


def _live(pop, raw, stamps, sites=None, unit="mN", chunk=37):
    """The live bridge on the same samples and stamps, in chunks (`Bridge.consume`, as `Bridge.poll` gives them)."""
    n_sites = 1 if sites is None else len(sites)
    force = ForceStream("glove", "glove-id", "host", FS, n_sites, unit, 1, 0.0, inlet=None)
    sink, messages = _Collect(), []
    bridge = Bridge(Encoder(pop, FS, seed=4, sites=sites), force, sink, report=messages.append)
    for a in range(0, len(stamps), chunk):
        bridge.consume(raw[a:a + chunk], stamps[a:a + chunk])
    return sink.arrays(), bridge.summary, messages


def _spikes(pop, scene):
    ds = simulate(pop, scene, engine="direct", seed=4, quiet=True)
    return ds.afferent.values[ds.spike_afferent.values], ds.spike_time.values


def _chunks(data: bytes):
    """(tag, content) of each chunk after the magic, by the specification's lengths."""
    assert data[:4] == b"XDF:"
    out, i = [], 4
    while i < len(data):
        size = data[i]
        length = int.from_bytes(data[i + 1:i + 1 + size], "little")
        body = data[i + 1 + size:i + 1 + size + length]
        out.append((struct.unpack("<H", body[:2])[0], body[2:]))
        i += 1 + size + length
    assert i == len(data)
    return out


def test_the_file_is_xdfs_documented_layout(tmp_path):
    path = save_xdf(tmp_path / "s.xdf", [[0.0, 0.5, 1.0], [0.25, 0.0, 2.0]], [10.0, 10.002], name="glove",
                    fs=500.0, units="mN", clock_offsets=[(10.0, -0.5)])
    chunks = _chunks(path.read_bytes())
    assert [tag for tag, _ in chunks] == [1, 2, 3, 4, 6]  # FileHeader, StreamHeader, Samples, ClockOffset, Footer
    assert b"<version>1.0</version>" in chunks[0][1]
    header = chunks[1][1]
    assert header[:4] == struct.pack("<I", 1) and b"<channel_format>double64</channel_format>" in header
    assert b"<label>Fx</label><unit>mN</unit><type>Force</type>" in header
    # Samples: stream id, the count as a varlen int (1 byte of length, then 2), then per sample the stamp flag (8),
    # the stamp (double) and the values (3 little-endian doubles)
    assert chunks[2][1] == (struct.pack("<I", 1) + bytes([1, 2]) + b"\x08" + struct.pack("<d", 10.0)
                            + struct.pack("<3d", 0.0, 0.5, 1.0) + b"\x08" + struct.pack("<d", 10.002)
                            + struct.pack("<3d", 0.25, 0.0, 2.0))
    assert chunks[3][1] == struct.pack("<Idd", 1, 10.0, -0.5)
    assert b"<sample_count>2</sample_count>" in chunks[4][1]


def test_a_recorded_session_gives_the_live_bridges_spikes_and_stamps(tmp_path, session):
    """The same samples and stamps: the bridge's chunks (live) and the XDF file read back give the same spikes."""
    pop, raw, stamps = session
    (positions, live_stamps), summary, messages = _live(pop, raw, stamps)
    path = save_xdf(tmp_path / "session.xdf", raw, stamps, name="glove", fs=FS, units="mN",
                    clock_offsets=[(stamps[0], 3.5), (stamps[-1], 3.5)])  # the recorder's clock 3.5 s on
    with pytest.warns(XdfStampWarning, match=r"1 gap\(s\), 1 sample\(s\) out of order, 1 skipped"):
        recording = read_xdf(path, "glove")
    ids, times = _spikes(pop, recording.scene)
    assert ids.size > 200 and summary.gaps and summary.out_of_order == 1 and summary.skipped == 1
    np.testing.assert_array_equal(ids, pop.afferent_id[positions])
    # the spikes on the recording's clock: the live stamps (clock offset 0 here), so raw stamps, not synchronised
    np.testing.assert_allclose(recording.input_clock(times), live_stamps, rtol=0, atol=1e-9)
    assert (recording.summary.samples, recording.summary.gaps, recording.summary.out_of_order,
            recording.summary.skipped) == (summary.samples, summary.gaps, summary.out_of_order, summary.skipped)
    # the stamp rule's own reports, word for word (a skipped sample's reason is worded by who refuses it)
    assert [m for m in recording.reports if "skipped" not in m] == [m for m in messages if "skipped" not in m]
    np.testing.assert_array_equal(recording.clock_offsets, [[stamps[0], 3.5], [stamps[-1], 3.5]])
    assert recording.stream.unit == "mN" and recording.first_stamp == stamps[0]


def test_without_gaps_a_session_equals_the_csv_of_its_samples(tmp_path, session):
    """A clean session is the recording `from_csv` reads: the same scene."""
    _, raw, _ = session
    clean = np.nan_to_num(raw[:400])
    stamps = 5.0 + np.arange(400) / FS
    save_xdf(tmp_path / "s.xdf", clean, stamps, name="glove", fs=FS, units="mN")
    (tmp_path / "s.csv").write_text("time,fx,fy,fz\n" + "".join(
        f"{t!r},{a!r},{b!r},{c!r}\n" for t, (a, b, c) in zip((np.arange(400) / FS).tolist(), clean.tolist())))
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")  # 500 Hz: FA-II's band
        scene, csv = from_xdf(tmp_path / "s.xdf", "glove"), from_csv(tmp_path / "s.csv", units="mN")
    # to rounding: the CSV's rate is measured from its time column (1 / 0.002 s to an ulp), the stream's stated
    np.testing.assert_allclose(np.column_stack([scene.fx, scene.fy, scene.fz]),
                               np.column_stack([csv.fx, csv.fy, csv.fz]), rtol=0, atol=1e-12)


def test_a_sensor_arrays_session_gives_the_live_bridges_spikes(tmp_path, session):
    pop, raw, stamps = session
    sites = Sites([-3.0, 3.0], [0.0, 4.0], 2.0, site_id=["D2d", "D2p"])
    two = np.column_stack([raw, raw[::-1] * 0.5])
    two[:, 5] = np.abs(two[:, 5])
    live, _, _ = _live(pop, two, stamps, sites=sites)
    save_xdf(tmp_path / "array.xdf", two, stamps, name="taxels", fs=FS, units="mN", site_ids=["D2d", "D2p"])
    with pytest.warns(XdfStampWarning):
        recording = read_xdf(tmp_path / "array.xdf", "taxels", sites=sites)
    assert recording.scene.n_sites == 2
    ids, times = _spikes(pop, recording.scene)
    np.testing.assert_array_equal(ids, pop.afferent_id[live[0]])
    np.testing.assert_allclose(recording.input_clock(times), live[1], rtol=0, atol=1e-9)


def _stream(name, *, channels=3, fmt="double64", rate=FS, units="N", labels=("Fx", "Fy", "Fz"), values=None,
            stamps=None, kind="Force"):
    n = 50
    if values is None:
        values = np.zeros((n, channels))
        values[:, 2::3] = 1.0
    return {"info": {"name": name, "type": kind, "channel_count": str(channels), "nominal_srate": repr(rate),
                     "channel_format": fmt, "source_id": f"{name}-id",
                     "desc": {"channels": {"channel": [{"label": label, "unit": units} for label in labels]}}},
            "values": values, "stamps": list(np.arange(n) / FS if stamps is None else stamps)}


def test_the_header_is_read_as_the_live_path_reads_it(tmp_path):
    path = _write_xdf(tmp_path / "h.xdf", [_stream("glove", units="gf")])
    assert read_xdf(path, "glove").stream.unit == "gf"
    assert from_xdf(path, "glove", conditioning=None).fz[-1] == 9.80665e-3  # 1 gf
    with pytest.raises(ValueError, match=r"^XDF file '.*h\.xdf', stream 'glove' declares its forces in gf, not "
                                         r"units='N'$"):
        read_xdf(path, "glove", units="N")
    path = _write_xdf(tmp_path / "l.xdf", [_stream("glove", labels=("Fz", "Fy", "Fx"))])
    with pytest.raises(ValueError, match="stream 'glove': channel 0 is labelled 'Fz', but channels must be F_X"):
        read_xdf(path, "glove")
    path = _write_xdf(tmp_path / "i.xdf", [_stream("glove", rate=0.0)])
    with pytest.raises(ValueError, match=r"stream 'glove' has an irregular rate: give its sample rate \(recorded_fs\)"):
        read_xdf(path, "glove")
    assert read_xdf(path, "glove", recorded_fs=FS).stream.fs == FS


def test_a_sample_without_its_stamp_is_stamped_one_period_on(tmp_path):
    stamps = (2.0 + np.arange(50) / FS).tolist()
    stamps[10:20] = [None] * 10  # the writer may leave out a stamp the rate implies
    path = _write_xdf(tmp_path / "d.xdf", [_stream("glove", stamps=stamps)])
    recording = read_xdf(path, "glove")
    assert recording.summary.samples == 50 and not recording.summary.gaps and not recording.reports


def _truncated(tmp_path):
    path = save_xdf(tmp_path / "cut.xdf", np.tile([0.0, 0.0, 1.0], (3000, 1)), np.arange(3000) / FS, name="glove",
                    fs=FS)
    data = path.read_bytes()
    path.write_bytes(data[:len(data) // 2])  # the recording cut off mid-chunk
    return path


REFUSALS = [
    ("nope", lambda d: _write_xdf(d / "f.xdf", [_stream("glove"), _stream("EEG", channels=8, kind="EEG",
                                                                        labels=())]),
     (r"XDF file '.*f\.xdf' has no stream named 'nope' \(stream=\.\.\., --stream\); its streams: 'glove' \(Force, 3 "
      r"channels\), 'EEG' \(EEG, 8 channels\)")),
    (None, lambda d: _write_xdf(d / "f.xdf", [_stream("glove"), _stream("markers", channels=1, fmt="string",
                                                                        labels=(), values=[["go"]] * 50)]),
     r"holds 2 streams: give one by name \(stream=\.\.\., --stream NAME\); its streams: 'glove'"),
    ("wide", lambda d: _write_xdf(d / "f.xdf", [_stream("wide", channels=6, labels=())]),
     r"XDF file '.*f\.xdf', stream 'wide' has 6 channels; 1 site\(s\) need 3 \(F_X, F_Y, F_Z per site\)"),
    ("words", lambda d: _write_xdf(d / "f.xdf", [_stream("words", fmt="string", labels=(),
                                                          values=[["a", "b", "c"]] * 50)]),
     r"stream 'words' carries strings, not forces \(a numeric channel format is needed\)"),
    ("glove", _truncated, r"XDF file '.*cut\.xdf' is truncated: chunk \d+ ends [\d,]+ bytes short"),
    ("glove", lambda d: (d / "f.xdf").write_bytes(b"time,fx,fy,fz\n") and d / "f.xdf",
     r"XDF file '.*f\.xdf' is not an XDF file"),
    ("glove", lambda d: d / "missing.xdf", r"XDF file '.*missing\.xdf' does not exist"),
]


@pytest.mark.parametrize("stream, make, message", REFUSALS, ids=[r[2][:30] for r in REFUSALS])
def test_a_bad_file_or_stream_is_one_line_and_no_output(tmp_path, capsys, stream, make, message):
    from ddmm.experiments.cli import main

    path = make(tmp_path)
    with pytest.raises(ValueError, match=message):
        read_xdf(path, stream)
    out = tmp_path / "run.nc"
    argv = ["simulate", "--scene", str(path), "--out", str(out), "--engine", "direct", "--quiet"]
    assert main(argv + ([] if stream is None else ["--stream", stream])) == 2
    err = capsys.readouterr().err
    assert len(err.strip().splitlines()) == 1 and err.startswith("ddmm: error: XDF file "), err
    assert not out.exists() and not list(tmp_path.glob(".ddmm-probe-*"))


def test_a_damaged_chunk_is_refused_not_skipped(tmp_path):
    path = save_xdf(tmp_path / "bad.xdf", np.tile([0.0, 0.0, 1.0], (20, 1)), np.arange(20) / FS, name="glove",
                    fs=FS)
    data = bytearray(path.read_bytes())
    count = data.index(struct.pack("<I", 1) + bytes([1, 20])) + 4  # the Samples chunk's count of samples
    data[count] = 3  # a varlen int of 3 bytes, which XDF has not: pyxdf logs it and reads on
    path.write_bytes(bytes(data))
    with pytest.raises(ValueError, match=r"XDF file '.*bad\.xdf' (is damaged|cannot be read)"):
        read_xdf(path, "glove")


def test_the_cli_runs_a_session_and_says_what_the_rules_took(tmp_path, session, capsys):
    from ddmm.experiments.cli import main
    from ddmm.population import load_dataset

    _, raw, stamps = session
    save_xdf(tmp_path / "s.xdf", raw, stamps, name="glove", fs=FS, units="mN")
    out = tmp_path / "run.nc"
    assert main(["simulate", "--scene", str(tmp_path / "s.xdf"), "--stream", "glove", "--engine", "direct",
                 "--types", "SAI,RAI,SAII", "--seed", "4", "--out", str(out), "--quiet"]) == 0
    err = capsys.readouterr().err
    assert "ddmm: warning: XDF file" in err and "1 gap(s), 1 sample(s) out of order, 1 skipped" in err
    ds = load_dataset(out)
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        expected = simulate(sample_population("fingertip", rng=4), from_xdf(tmp_path / "s.xdf", "glove"),
                            engine="direct", seed=4, afferent_types=("SAI", "RAI", "SAII"), quiet=True)
    np.testing.assert_array_equal(ds.spike_afferent.values, expected.spike_afferent.values)
    np.testing.assert_array_equal(ds.spike_time.values, expected.spike_time.values)
    assert main(["simulate", "--scene", "birznieks", "--stream", "glove", "--out", str(out)]) == 2
    assert "--stream picks a stream of an .xdf --scene" in capsys.readouterr().err


def test_without_pyxdf_one_line_names_the_extra(tmp_path, monkeypatch, capsys):
    import sys

    from ddmm.experiments.cli import main

    path = save_xdf(tmp_path / "s.xdf", np.tile([0.0, 0.0, 1.0], (5, 1)), np.arange(5) / FS, name="glove", fs=FS)
    monkeypatch.setitem(sys.modules, "pyxdf", None)
    with pytest.raises(MissingExtraError, match=r'^read_xdf needs pyxdf: pip install "ddmm\[xdf\]"$'):
        read_xdf(path, "glove")
    assert main(["simulate", "--scene", str(path), "--stream", "glove", "--out", str(tmp_path / "r.nc")]) == 2
    assert capsys.readouterr().err == 'ddmm: error: read_xdf needs pyxdf: pip install "ddmm[xdf]"\n'
