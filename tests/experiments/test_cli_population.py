"""ddmm simulate / plan / info / plot / demo / bench from the command line."""

import json

import pytest

from ddmm.experiments.bench.cases import CASES, run_case
from ddmm.experiments.cli import main
from ddmm.population import load_dataset


def run(capsys, *argv):
    code = main([str(a) for a in argv])
    out = capsys.readouterr()
    return code, out.out, out.err


def test_simulate_info_plot(capsys, tmp_path):
    out = tmp_path / "run.nc"
    code, text, _ = run(capsys, "simulate", "--population", "fingertip", "--scene", "birznieks", "--theta-r",
                        "0,90,none", "--engine", "direct", "--trials", "2", "--seed", "4", "--dt", "0.05",
                        "--out", out)
    assert code == 0 and "wrote" in text
    ds = load_dataset(out)
    assert ds.sizes["condition"] == 3 and ds.sizes["trial"] == 2 and ds.attrs["dt"] == pytest.approx(5e-5)
    code, text, _ = run(capsys, "info", out)
    assert code == 0 and "991 afferents" in text and "birznieks_90" in text
    code, text, _ = run(capsys, "plot", out, "--out", tmp_path / "figs")
    assert code == 0
    assert {p.name for p in (tmp_path / "figs").iterdir()} == {"raster.png", "psth.png", "polar.png", "forces.png",
                                                             "hand.png"}  # the fingertip is D2d of the hand map
    code, text, _ = run(capsys, "plot", out)  # no --out: beside the file, run.nc -> run-figures
    assert code == 0 and {p.name for p in (tmp_path / "run-figures").iterdir()} >= {"raster.png", "psth.png"}


def test_plan_prints_skips(capsys):
    code, text, _ = run(capsys, "plan", "--population", "fingertip", "--theta-r", "none", "--types", "SAI")
    assert code == 0 and "skipped (no shear" in text and "282 SAI" in text


@pytest.mark.slow  # minutes: run by `pytest -m slow`
def test_demo_writes_data_and_figures(capsys, tmp_path):
    code, text, _ = run(capsys, "demo", "--engine", "direct", "--quiet", "--out", tmp_path)
    assert code == 0 and "press_push_lift_90" in text
    assert {"demo.nc", "raster.png", "psth.png", "polar.png", "forces.png"} <= {p.name for p in tmp_path.iterdir()}


def write(tmp_path, name, text):
    path = tmp_path / name
    path.write_text(text)
    return path


BAD_SPECS = [
    ("[types.SAI]\ncount = 3\nflavour = 1\n", "flavour"),
    ("[types.SAI]\ncount = -3\n", "count"),
    ("[types.SAI]\ncount = 3\nnap = { selective = 0.7, none = 0.7 }\n", "sum to 1"),
    ('[types.SAI]\ncount = 3\ntheta_t = { distribution = "zipf" }\n', "zipf"),
]
BAD_SCENES = [
    ("time,fx,fy,fz\n0,0,0,1\n0,0,0,1\n", "increase strictly"),
    ("time,fx,fy,fz\n0,0,0,1\n0.01,0,nan,1\n", "'nan' is not finite"),
    ("time,fx,fy,fz\n0,0,0,1\n0.01,0,0,-1\n", "normal force down to -1 N (line 3)"),
    ("time,fx,fy,fz\n0,0,0,1\n0.01,0,0\n", "line 3 has 3 values but the header has 4"),
    ("", "empty"),
    ("time,fx,fz\n0,0,1\n", "'fy'"),
]


@pytest.mark.parametrize("text,match", BAD_SPECS)
def test_bad_spec_exit_2_nothing_written(capsys, tmp_path, text, match):
    spec = write(tmp_path, "bad.toml", text)
    code, _, err = run(capsys, "simulate", "--population", spec, "--engine", "direct", "--out", tmp_path / "o.nc")
    assert code == 2 and match in err and err.count("\n") == 1
    assert not (tmp_path / "o.nc").exists()


@pytest.mark.parametrize("text,match", BAD_SCENES)
def test_bad_scene_exit_2_nothing_written(capsys, tmp_path, text, match):
    scene = write(tmp_path, "bad.csv", text)
    code, _, err = run(capsys, "simulate", "--scene", scene, "--engine", "direct", "--out", tmp_path / "o.nc")
    assert code == 2 and match in err and err.count("\n") == 1
    assert not (tmp_path / "o.nc").exists()


@pytest.mark.parametrize("out,match", [("missing/o.nc", "does not exist"), ("o.txt", ".nc")])
def test_bad_output_exit_2(capsys, tmp_path, out, match):
    code, _, err = run(capsys, "simulate", "--engine", "direct", "--out", tmp_path / out)
    assert code == 2 and match in err


@pytest.mark.skipif(not __import__("os").path.isdir("/proc/self"), reason="needs Linux /proc")
def test_unwritable_output_dir(capsys):
    code, _, err = run(capsys, "simulate", "--engine", "direct", "--out", "/proc/ddmm-test.nc")
    assert code == 2 and "not writable" in err and err.count("\n") == 1


def test_bench_case_shape():
    result = run_case("fingertip_1s_direct")
    assert {"name", "engine", "n_afferents", "sim_s", "dt_ms", "wall_s", "afferent_s_per_wall_s",
            "peak_rss_mb"} <= set(result)
    assert result["n_afferents"] == 991 and set(CASES) >= {"hand_1s_direct", "hand_10s_direct"}
    json.dumps(result)
