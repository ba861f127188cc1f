"""No command writes over one of its own inputs: the input survives, byte for byte, and the error is one line."""

import os

import numpy as np
import pytest

from ddmm.experiments.cli import main
from ddmm.population import Contact, Scene, Sites, make_population, save_array, save_dataset, simulate

HEADER = "id,x_mm,y_mm,radius_mm,region,amplitude_min_ua,amplitude_max_ua,phase_width_us,max_rate_hz,charge_limit_nc\n"


@pytest.fixture(scope="module")
def files(tmp_path_factory):
    folder = tmp_path_factory.mktemp("inputs")
    t = np.arange(300) / 1000.0
    fz = np.interp(t, [0, 0.1, 0.3], [0, 2.0, 2.0])
    scene = Scene(0 * t, 0 * t, fz, 1000.0, "press", contact=Contact(0.0, 0.0, 5.0))
    run = save_dataset(simulate(make_population(["SAI"]), scene, engine="direct", seed=1, quiet=True),
                       folder / "run.nc")
    forces = np.zeros((300, 1, 3))
    forces[:, 0, 2] = fz
    array = save_array(folder / "arr.nc", Scene.from_sites(forces, Sites([0.0], [0.0], 3.0), fs=1000.0, name="a"))
    (folder / "e.csv").write_text(HEADER + "centre,0,0,4,,20,80,200,300,20\n")
    return folder, run, array


def _refused(argv, victim, capsys, match):
    before = victim.read_bytes()
    assert main(argv) == 2
    err = capsys.readouterr().err
    assert err.count("\n") == 1 and match in err and "would destroy the input" in err, err
    assert victim.read_bytes() == before


def test_stimulate_does_not_write_over_its_dataset(files, capsys):
    folder, run, _ = files
    _refused(["stimulate", str(run), "--electrodes", str(folder / "e.csv"), "--out", str(run)], run, capsys,
             "is the input dataset")


def test_simulate_does_not_write_over_its_sensor_array(files, capsys):
    folder, _, array = files
    _refused(["simulate", "--scene", str(array), "--engine", "direct", "--out", str(array)], array, capsys,
             "is the input --scene")


def test_a_link_to_the_input_is_the_input(files, capsys, tmp_path):
    folder, run, _ = files
    os.link(run, tmp_path / "hard.nc")
    os.symlink(run, tmp_path / "soft.nc")
    for name in ("hard.nc", "soft.nc"):
        _refused(["stimulate", str(run), "--electrodes", str(folder / "e.csv"), "--out", str(tmp_path / name)], run,
                 capsys, "is the input dataset")
