"""ddmm export: a simulated dataset to NWB from the command line; errors are one line with exit status 2."""

import sys

import pytest

from ddmm.experiments.cli import main

pynwb = pytest.importorskip("pynwb")

SPEC = '''name = "tiny"
[types.SAI]
count = 4
noise_sigma = 2.0
'''


def run(capsys, *argv):
    code = main([str(a) for a in argv])
    out = capsys.readouterr()
    return code, out.out, out.err


@pytest.fixture(scope="module")
def nc(tmp_path_factory):
    tmp = tmp_path_factory.mktemp("export")
    (tmp / "tiny.toml").write_text(SPEC)
    assert main(["simulate", "--population", str(tmp / "tiny.toml"), "--theta-r", "0,none", "--engine", "direct",
                 "--trials", "2", "--quiet", "--out", str(tmp / "x.nc")]) == 0
    return tmp / "x.nc"


def test_export_writes_and_says_what(capsys, nc, tmp_path):
    out = tmp_path / "x.nwb"
    code, text, err = run(capsys, "export", nc, "--nwb", out)
    assert (code, err) == (0, "")
    assert text == f"wrote {out} (4 units, 4 trials = 2 condition(s) x 2 trial(s), " \
                   f"{text.split(', ')[2].split()[0]} spikes, stimulus fingertip_force (N))\n"
    with pynwb.NWBHDF5IO(out, "r") as io:
        f = io.read()
        assert len(f.units) == 4 and f.trials.has_theta_r[:].tolist() == [True, True, False, False]


@pytest.mark.parametrize("argv,match", [
    (["--nwb", "{tmp}/x.txt"], "--nwb '{tmp}/x.txt' must end in .nwb"),
    (["--nwb", "{tmp}/no/x.nwb"], "--nwb '{tmp}/no/x.nwb': directory '{tmp}/no' does not exist"),
])
def test_bad_output_is_one_line_exit_2(capsys, nc, tmp_path, argv, match):
    code, _, err = run(capsys, "export", nc, *(a.format(tmp=tmp_path) for a in argv))
    assert code == 2 and err == f"ddmm: error: {match.format(tmp=tmp_path)}\n"
    assert list(tmp_path.iterdir()) == []


def test_missing_input_is_one_line_exit_2(capsys, tmp_path):
    code, _, err = run(capsys, "export", tmp_path / "none.nc", "--nwb", tmp_path / "x.nwb")
    assert code == 2 and "does not exist" in err and err.count("\n") == 1
    assert list(tmp_path.iterdir()) == []


def test_missing_extra_is_one_line_exit_2(capsys, nc, tmp_path, monkeypatch):
    monkeypatch.setitem(sys.modules, "pynwb", None)
    code, _, err = run(capsys, "export", nc, "--nwb", tmp_path / "x.nwb")
    assert code == 2 and err == 'ddmm: error: to_nwb needs pynwb: pip install "ddmm[nwb]"\n'
    assert list(tmp_path.iterdir()) == []


def test_nwb_is_required(capsys, nc):
    with pytest.raises(SystemExit) as info:
        main(["export", str(nc)])
    assert info.value.code == 2 and "--nwb" in capsys.readouterr().err


def test_archive_metadata_from_the_command_line(capsys, nc, tmp_path):
    out = tmp_path / "meta.nwb"
    code, _, err = run(capsys, "export", nc, "--nwb", out, "--experimenter", "Doe, Jane", "--experimenter",
                       "Roe, Rick", "--institution", "Lab X", "--related-publication", "doi:10.1000/xyz",
                       "--identifier", "run-42", "--session-start-time", "2026-11-25T09:30:00+00:00")
    assert (code, err) == (0, "")
    with pynwb.NWBHDF5IO(out, "r") as io:
        f = io.read()
        assert f.experimenter == ("Doe, Jane", "Roe, Rick") and f.institution == "Lab X"
        assert f.related_publications == ("doi:10.1000/xyz",) and f.identifier == "run-42"
        assert f.session_start_time.isoformat() == "2026-11-25T09:30:00+00:00"
    for bad, message in (("2026-11-25 09:30", "needs a time zone"), ("yesterday", "is not an ISO 8601 date-time")):
        code, _, err = run(capsys, "export", nc, "--nwb", tmp_path / "bad.nwb", "--session-start-time", bad)
        assert code == 2 and message in err and len(err.strip().splitlines()) == 1
    assert not (tmp_path / "bad.nwb").exists()
