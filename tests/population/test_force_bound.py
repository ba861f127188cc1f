"""Unit slips are refused: a force beyond a stated bound (1 kN a site unless raised), on every way forces come in.

A file in mN read as kgf turns a 3 N press into 29 kN; a CSV of 1e12 N is a broken export.  No hand contact comes
near 1 kN, so the readers, the streaming encoder and the command line refuse it, naming the bound and the option
that raises it.
"""

import io
import warnings

import numpy as np
import pytest

from ddmm.experiments.cli import main
from ddmm.population import Sites, from_array, from_csv, from_long_csv, make_population, save_array
from ddmm.population.runtime.stream import Encoder
from ddmm.population.stimuli.scenes import Scene


def _plate(path, scale=1.0, header="Time,Fx,Fy,Fz"):
    t = np.arange(0, 0.5, 0.001)
    fz = np.interp(t, [0, 0.1, 0.5], [0, 3, 3]) * scale
    path.write_text(header + "\n" + "".join(f"{a:.3f},0,0,{float(b)!r}\n" for a, b in zip(t, fz)))
    return path


def test_a_csv_beyond_the_bound_is_refused_naming_it_and_a_raised_bound_reads_it(tmp_path):
    path = _plate(tmp_path / "huge.csv", scale=1e12)
    with pytest.raises(ValueError, match=r"huge.csv': a force of 3e\+10 N at t = 0.001 s, beyond max_force_n = 1000 N"):
        from_csv(path, conditioning=None)
    assert from_csv(_plate(tmp_path / "rig.csv", scale=500.0), conditioning=None, max_force_n=2000.0).fz.max() > 1000


def test_a_file_in_mn_read_as_kgf_is_refused(tmp_path):
    path = _plate(tmp_path / "mn.csv", scale=1000.0)  # 3000 mN
    assert from_csv(path, units="mN", conditioning=None).fz.max() == pytest.approx(3.0)
    with pytest.raises(ValueError, match="mn.csv': a force of 1176.8 N at t = 0.004 s, .*check the unit"):
        from_csv(path, units="kgf", conditioning=None)


def test_sensor_array_files_and_long_csvs_are_bounded(tmp_path):
    forces = np.zeros((100, 2, 3))
    forces[50:, 1, 2] = 2000.0
    scene = Scene.from_sites(forces, Sites([0.0, 5.0], [0.0, 0.0], 2.0), fs=1000.0, name="pad")
    path = save_array(tmp_path / "pad.npz", scene)
    with pytest.raises(ValueError, match=r"pad.npz.*'forces': a force of 2000 N at t = 0.05 s"):
        from_array(path, conditioning=None)
    assert from_array(path, conditioning=None, max_force_n=5000.0).n_sites == 2
    (tmp_path / "f.csv").write_text("time,site,fx,fy,fz\n0,a,0,0,1\n0,b,0,0,1\n0.01,a,0,0,1\n0.01,b,0,0,1e6\n")
    (tmp_path / "s.csv").write_text("site,x_mm,y_mm\na,0,0\nb,5,0\n")
    with pytest.raises(ValueError, match="beyond max_force_n = 1000 N"):
        from_long_csv(tmp_path / "f.csv", tmp_path / "s.csv", conditioning=None)


def test_the_encoder_refuses_a_chunk_beyond_the_bound_and_keeps_its_state():
    enc = Encoder(make_population(["SAI"]), 1000.0, seed=0, conditioning=None)
    with pytest.raises(ValueError, match="forces: a force of 1500 N at sample 1"):
        enc.push(np.array([[0.0, 0.0, 1.0], [0.0, 900.0, 1200.0]]))
    assert enc.n_samples == 0
    enc.push(np.array([[0.0, 0.0, 1.0]]))
    raised = Encoder(make_population(["SAI"]), 1000.0, conditioning=None, max_force_n=2000.0)
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")  # 1.5 kN drives the unit past the step cap: not what this test reads
        assert raised.push(np.array([[0.0, 900.0, 1200.0]])).forces.shape == (1, 3)


def test_the_encoder_refuses_a_rate_beyond_any_sensor():
    with pytest.raises(ValueError, match=r"fs = 1e\+12 Hz is beyond any force sensor \(at most 1e\+06 Hz\)"):
        Encoder(make_population(["SAI"]), 1e12)


def test_the_command_line_names_max_force(tmp_path, capsys):
    path = _plate(tmp_path / "huge.csv", scale=1e12)
    code = main(["simulate", "--scene", str(path), "--engine", "direct", "--out", str(tmp_path / "o.nc")])
    err = capsys.readouterr().err
    assert code == 2 and err.count("\n") == 1 and "--max-force" in err and not (tmp_path / "o.nc").exists()
    code = main(["simulate", "--scene", str(path), "--engine", "direct", "--max-force", "1e13", "--quiet",
                 "--conditioning", "off", "--types", "SAI", "--out", str(tmp_path / "o.nc")])
    assert code == 0, capsys.readouterr().err


def test_stdin_numbers_parse_as_the_file_readers_parse_them(monkeypatch, capsys):
    lines = "t,fx,fy,fz\n0,0,0,1\n0.001,0,0,1_0\n0.002,0,0,0x10\n0.003,0,0,2000\n"
    monkeypatch.setattr("sys.stdin", io.StringIO(lines))
    assert main(["stream", "--fs", "1000", "--types", "SAI"]) == 0
    err = capsys.readouterr().err
    assert "line 3 skipped: '1_0' is not a number" in err and "line 4 skipped: '0x10' is not a number" in err
    assert "line 5 skipped: forces: a force of 2000 N" in err


@pytest.mark.parametrize(("text", "match"), [("0,0,0," + "1" * 10_000 + "\n", "line 1 is longer than 512 characters"),
                                             ("\x00" * 100, "line 1 holds a NUL character")])
def test_stdin_lines_are_bounded(monkeypatch, capsys, text, match):
    monkeypatch.setattr("sys.stdin", io.StringIO(text))
    assert main(["stream", "--fs", "1000", "--types", "SAI"]) == 2
    err = capsys.readouterr().err
    assert match in err and err.count("\n") == 1
