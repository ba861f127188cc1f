"""``ddmm stimulate``: pulses file, figures, summary lines; bad tables and options end in one line, exit 2."""

import numpy as np
import pytest

from ddmm.experiments.cli import main
from ddmm.population import Contact, Scene, make_population, save_dataset, simulate
from ddmm.population.neurostim import check_pulses, load_pulses

HEADER = "id,x_mm,y_mm,radius_mm,region,amplitude_min_ua,amplitude_max_ua,phase_width_us,max_rate_hz,charge_limit_nc\n"


@pytest.fixture(scope="module")
def run(tmp_path_factory):
    t = np.arange(800) / 1000.0
    fz = np.interp(t, [0, 0.1, 0.6, 0.7], [0, 2.0, 2.0, 0])
    scene = Scene(0 * t, 0 * t, fz, 1000.0, "press", contact=Contact(0.0, 0.0, 5.0))
    ds = simulate(make_population(["SAI", "RAI"]), scene, engine="direct", seed=1, quiet=True)
    folder = tmp_path_factory.mktemp("stim")
    return save_dataset(ds, folder / "run.nc")


def test_stimulate_writes_checked_pulses_and_a_figure(run, tmp_path, capsys):
    table = tmp_path / "e.csv"
    table.write_text(HEADER + "centre,0,0,4,,20,80,200,300,20\nfar,0,-30,2,,20,80,200,300,20\n")
    out = tmp_path / "pulses.nc"
    assert main(["stimulate", str(run), "--electrodes", str(table), "--out", str(out)]) == 0
    text = capsys.readouterr().out
    pulses = load_pulses(out)
    assert check_pulses(pulses) == [] and pulses.attrs["rule"] == "biomimetic"
    assert f"{pulses.sizes['pulse']:,} pulses on 2 electrode(s)" in text and "far: 0 pulses" in text
    assert (tmp_path / "pulses_press.png").stat().st_size > 10_000


def test_linear_rules_take_their_options(run, tmp_path):
    table = tmp_path / "e.csv"
    table.write_text(HEADER + "centre,0,0,4,,20,80,200,300,20\n")
    out = tmp_path / "lin.nc"
    argv = ["stimulate", str(run), "--electrodes", str(table), "--out", str(out), "--no-figures"]
    assert main(argv + ["--rule", "linear-amplitude", "--rate-hz", "50", "--force-sat", "2"]) == 0
    pulses = load_pulses(out)
    hold = (pulses.pulse_time > 0.2) & (pulses.pulse_time < 0.6)
    assert int(hold.sum()) == pytest.approx(0.4 * 50, abs=1)
    under = 2.0 * 4.0 ** 2 / 5.0 ** 2  # the 4 mm field holds 64% of the 5 mm contact's 2 N
    expected = 20.0 + 60.0 * (under - 0.05) / (2.0 - 0.05)
    assert pulses.pulse_amplitude.values[hold.values] == pytest.approx(expected)
    assert not list(tmp_path.glob("*.png"))


@pytest.mark.parametrize("body, argv, message", [
    ("centre,0,0,4,,20,200,200,300,20\n", [], "line 2: electrode 'centre': amplitude_max_ua x phase_width_us = 40 nC"),
    ("centre,0,0,4,,20,80,200,3OO,20\n", [], "field 'max_rate_hz': '3OO' is not a number"),
    ("centre,0,0,4,,20,80,200,300,20\n", ["--rule", "biomimetic", "--rate-hz", "50"],
     "--rate-hz applies to the linear-amplitude rule(s), not --rule biomimetic"),
    ("centre,0,0,4,,20,80,200,300,20\n", ["--rule", "nope"], "invalid choice: 'nope'"),
])
def test_bad_tables_and_options_are_one_line_with_exit_2(run, tmp_path, capsys, body, argv, message):
    table = tmp_path / "e.csv"
    table.write_text(HEADER + body)
    out = tmp_path / "p.nc"
    try:
        code = main(["stimulate", str(run), "--electrodes", str(table), "--out", str(out), *argv])
    except SystemExit as exc:  # argparse's own usage errors
        code = exc.code
    err = capsys.readouterr().err
    assert code == 2 and message in err and len(err.strip().splitlines()) == 1
    assert not out.exists()
