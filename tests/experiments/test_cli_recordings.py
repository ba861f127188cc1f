"""``ddmm simulate`` on recorded force files: options alone read an AMTI-style plate; bad options are one line."""

import numpy as np
import pytest

from ddmm.experiments.cli import main


def plate(path, sign=-1.0, header="Time,Fx,Fy,Fz", noise=0.01):
    rng = np.random.default_rng(1)
    t = np.arange(0, 1.5, 0.001)
    fz = np.interp(t, [0, 0.3, 0.6, 1.5], [0, 0, 2, 2]) + rng.normal(0, noise, t.size)
    fy = np.interp(t, [0, 0.8, 1.1, 1.5], [0, 0, 0.5, 0.5]) + rng.normal(0, noise, t.size)
    rows = "".join(f"{a:.3f},{b:.5f},{c:.5f},{sign * d:.5f}\n" for a, b, c, d in
                   zip(t, rng.normal(0, noise, t.size), fy, fz))
    path.write_text(header + "\n" + rows)
    return path


def test_an_amti_plate_with_negative_pressing_via_options_alone(tmp_path, capsys):
    path = plate(tmp_path / "amti.csv")
    out = tmp_path / "out.nc"
    args = ["simulate", "--scene", str(path), "--engine", "direct", "--quiet", "--types", "SAI,RAI"]
    assert main([*args, "--out", str(out)]) == 2
    err = capsys.readouterr().err.strip()
    assert len(err.splitlines()) == 1 and "--fz-sign -1" in err and "np.float64" not in err
    assert main([*args, "--fz-sign", "-1", "--out", str(out)]) == 0 and out.exists()


def test_columns_and_units_from_the_command_line(tmp_path, capsys):
    path = plate(tmp_path / "mn.csv", sign=1.0, header="t_s,FX,FY,FZ")
    text = path.read_text().splitlines()
    rows = [",".join([r.split(",")[0]] + [f"{1000 * float(v):.2f}" for v in r.split(",")[1:]]) for r in text[1:]]
    path.write_text("\n".join([text[0], *rows]) + "\n")
    out = tmp_path / "out.nc"
    assert main(["simulate", "--scene", str(path), "--engine", "direct", "--quiet", "--types", "SAI",
                 "--columns", "time=t_s", "--units", "mN", "--out", str(out)]) == 0
    import xarray as xr

    with xr.open_dataset(out) as ds:
        assert ds.sizes["spike"] > 100


def test_the_shear_hold_option_reaches_the_conditioning():
    from ddmm.experiments.cli import build_parser
    from ddmm.experiments.cli.recording_options import conditioning_from_args

    parse = build_parser().parse_args
    assert conditioning_from_args(parse(["simulate", "--out", "x.nc", "--shear-hold", "0"])).shear_hold_n == 0.0
    assert conditioning_from_args(parse(["simulate", "--out", "x.nc"])).shear_hold_n == 0.025
    assert conditioning_from_args(parse(["simulate", "--out", "x.nc", "--normal-hold", "0.01"])).normal_hold_n == 0.01
    assert conditioning_from_args(parse(["simulate", "--out", "x.nc"])).adapt_noise is True
    assert conditioning_from_args(parse(["simulate", "--out", "x.nc", "--fixed-noise"])).adapt_noise is False


@pytest.mark.parametrize(("extra", "match"), [
    (["--columns", "tme=Time"], "--columns: 'tme=Time' is not NAME=COLUMN"),
    (["--conditioning", "off", "--sensor-noise", "0.01"], "--sensor-noise, --fixed-noise, --bandwidth, --shear-hold"),
    (["--conditioning", "off", "--shear-hold", "0"], "--sensor-noise, --fixed-noise, --bandwidth, --shear-hold"),
    (["--normal-hold", "-1"], "normal_hold_n must be a finite number >= 0 \\(N\\), got -1"),
    (["--sensor-noise", "-1"], "noise_n must be a finite number >= 0"),
    (["--shear-hold", "-0.5"], "shear_hold_n must be a finite number >= 0 \\(N\\), got -0.5"),
    (["--fs", "100"], "has a time column: give recorded_fs \\(--fs\\) only for a file without one"),
    (["--theta-r", "90"], "--theta-r does not apply to the recorded scene '.*p.csv': the file gives the forces"),
])
def test_bad_recording_options_are_one_line(tmp_path, capsys, extra, match):
    path = plate(tmp_path / "p.csv", sign=1.0)
    code = main(["simulate", "--scene", str(path), "--engine", "direct", "--quiet", "--out",
                 str(tmp_path / "o.nc"), *extra])
    err = capsys.readouterr().err.strip()
    assert code == 2 and len(err.splitlines()) == 1
    import re
    assert re.search(match, err), err


def slow_plate(path):
    """A 100 Hz plate: too slow for FA-II's band."""
    t = np.arange(0, 1.0, 0.01)
    fz = np.interp(t, [0, 0.3, 0.6, 1.0], [0, 0, 2, 2])
    path.write_text("Time (s),Fx (N),Fy (N),Fz (N)\n" + "".join(f"{a:.2f},0,0,{b:.4f}\n" for a, b in zip(t, fz)))
    return path


@pytest.mark.parametrize(("types", "warned"), [(None, True), ("SAI,RAI,SAII", False), ("SA-I,FA-II", True)])
def test_cli_warnings_are_one_line_naming_options_and_stop_when_followed(tmp_path, capsys, types, warned):
    args = ["simulate", "--scene", str(slow_plate(tmp_path / "slow.csv")), "--engine", "direct", "--quiet",
            "--population", "fingertip", "--out", str(tmp_path / "o.nc")] + (["--types", types] if types else [])
    assert main(args) == 0
    err = capsys.readouterr().err
    assert ".py:" not in err and "Warning:" not in err  # never Python's file:line: Category: and a source line
    lines = [line for line in err.splitlines() if line.startswith("ddmm: warning:")]
    assert bool(lines) == warned
    assert all("--types SAI,RAI,SAII" in line and "afferent_types" not in line for line in lines)


def test_the_spike_cap_warning_names_the_dt_option_on_the_command_line():
    from ddmm.models.engines import SpikeCapWarning, integrate
    from ddmm.utils.notices import cli_text

    with pytest.warns(SpikeCapWarning) as caught:
        integrate(np.full((200, 1), 400.0), fs=1000.0, dt=1e-3, afferent_type=np.array(["RAII"]), engine="direct")
    assert "use a smaller dt" in str(caught[0].message) and "use a smaller --dt (ms)" in cli_text(caught[0].message)


@pytest.mark.parametrize(("dt", "match"), [("-1", "argument --dt: must be a positive number of ms, got -1"),
                                           ("abc", "argument --dt: must be a number of ms, got 'abc'"),
                                           ("2", r"\(2 ms\) must divide the sample interval .* \(1 ms\)")])
def test_dt_is_answered_in_ms(tmp_path, capsys, dt, match):
    import re

    with pytest.raises(SystemExit) if dt != "2" else _no_exit():
        code = main(["simulate", "--scene", "birznieks", "--quiet", "--dt", dt, "--out", str(tmp_path / "o.nc")])
        assert code == 2
    err = capsys.readouterr().err.strip()
    assert len(err.splitlines()) == 1 and re.search(match, err), err


def _no_exit():
    import contextlib

    return contextlib.nullcontext()


@pytest.mark.parametrize(("extra", "match"), [
    (["--population", "fingertips"], "'fingertips' is neither a preset .* \\(did you mean fingertip\\?\\)"),
    (["--scene", "press_push_lift_90"], "--scene 'press_push_lift_90' is unknown.*\\(did you mean press-push-lift\\?\\)"),
])
def test_a_misspelt_population_or_scene_gets_a_did_you_mean(tmp_path, capsys, extra, match):
    import re

    assert main(["simulate", "--quiet", "--out", str(tmp_path / "o.nc"), *extra]) == 2
    err = capsys.readouterr().err.strip()
    assert len(err.splitlines()) == 1 and re.search(match, err), err


def test_other_libraries_warnings_stay_quiet_unless_debugging(monkeypatch, capsys):
    """Only the package's own warnings reach the user; a library's (Brian2's pyparsing deprecations) need --debug."""
    import argparse
    import warnings

    def command(args):
        warnings.warn_explicit("'setResultsName' deprecated", DeprecationWarning, "pyparsing/core.py", 1,
                               module="pyparsing.core")
        warnings.warn_explicit("a library's note", UserWarning, "h5py/x.py", 2, module="h5py.x")
        warnings.warn_explicit("the package's own note", UserWarning, "population/x.py", 3, module="ddmm.population.x")
        return 0

    class Parser:
        def parse_args(self, argv):
            return argparse.Namespace(func=command, debug="--debug" in argv, types=None)

    monkeypatch.setattr("ddmm.experiments.cli.app.build_parser", Parser)
    assert main(["x"]) == 0
    err = capsys.readouterr().err
    assert err == "ddmm: warning: the package's own note\n", err
    assert main(["--debug", "x"]) == 0
    err = capsys.readouterr().err
    assert "ddmm: warning: 'setResultsName' deprecated" in err and "a library's note" in err


def test_a_brian2_run_prints_no_warning(tmp_path):
    """The default engine, in a fresh process as a user runs it: nothing on stderr but, on a cold cache, the
    one-line notice that it compiles."""
    import os
    import subprocess
    import sys

    done = subprocess.run([sys.executable, "-m", "ddmm.experiments.cli", "simulate", "--population", "fingertip",
                           "--engine", "brian2", "--quiet", "--out", str(tmp_path / "o.nc")],
                          capture_output=True, text=True, timeout=600, env={**os.environ, "DDMM_PROGRESS": "0"})
    lines = [line for line in done.stderr.splitlines() if not line.startswith("ddmm: compiling the Brian2 engine")]
    assert done.returncode == 0 and lines == [] and done.stderr.count("\n") <= 1, done.stderr
