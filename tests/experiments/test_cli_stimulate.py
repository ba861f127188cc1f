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
    ("centre,0,0,4,,20,80,200,300,20\n", ["--tau", "1e15"], "--tau must be a finite number in (0, 1000] ms, got 1e+15"),
    ("centre,0,0,4,,20,80,200,300,20\n", ["--rate-sat", "1e9"], "--rate-sat must be a finite number in (0, 1000] Hz"),
    ("centre,0,0,4,,20,80,200,300,20\n", ["--rule", "linear-amplitude", "--rate-hz", "1e-3"],
     "--rate-hz must be a finite number in [1, 2000] Hz, got 0.001"),
    ("centre,0,0,4,,20,80,200,300,20\n", ["--rule", "linear-frequency", "--force-sat", "1e15"],
     "--force-sat must be a finite number in (0.05, 500] N, got 1e+15"),
    ('"centre\n  forged: 999 pulses",0,0,4,,20,80,200,300,20\n', [], "holds the unprintable character U+000A"),
    ("far,1000,1000,5,,20,80,200,300,20\nnowhere,,,,D9,20,80,200,300,20\n", [],
     ("no electrode of the table reaches an afferent of population 'custom' or a force site: 'far' (disc (1000, 1000) "
      "mm r 5), 'nowhere' (region 'D9');")),
])
def test_bad_tables_and_options_are_one_line_with_exit_2(run, tmp_path, capsys, body, argv, message):
    table = tmp_path / "e.csv"
    table.write_text(HEADER + body)
    out = tmp_path / "p.nc"
    try:
        code = main(["stimulate", str(run), "--electrodes", str(table), "--out", str(out), *argv])
    except SystemExit as exc:  # argparse's own usage errors
        code = exc.code
    captured = capsys.readouterr()
    assert code == 2 and message in captured.err and len(captured.err.strip().splitlines()) == 1
    assert not out.exists() and "pulses" not in captured.out


@pytest.mark.parametrize("header, message", [
    (HEADER.strip() + ",amplitude_max_ua", "line 1: field 'amplitude_max_ua' is given twice (column 7"),
    (HEADER.strip() + ",ID", "line 1: field 'id' is given twice (column 1 'id' and column 11 'ID'; names ignore case)"),
])
def test_a_header_naming_a_field_twice_is_one_line_with_exit_2(run, tmp_path, capsys, header, message):
    table = tmp_path / "e.csv"
    table.write_text(header + "\ncentre,0,0,4,,20,80,200,300,20,90\n")
    code = main(["stimulate", str(run), "--electrodes", str(table), "--out", str(tmp_path / "p.nc")])
    err = capsys.readouterr().err
    assert code == 2 and f"ddmm: error: electrode table '{table}', {message}" in err and err.count("\n") == 1


def test_a_megabyte_id_is_one_line_naming_the_file(run, tmp_path, capsys):
    table = tmp_path / "e.csv"
    table.write_text(HEADER + "E" * 1_000_000 + ",0,0,4,,20,80,200,300,20\n")
    code = main(["stimulate", str(run), "--electrodes", str(table), "--out", str(tmp_path / "p.nc")])
    err = capsys.readouterr().err
    assert code == 2 and err == (f"ddmm: error: electrode table '{table}', line 2: 1,000,024 characters, more than "
                                 "the 4,096 a table's line may hold\n")


def test_a_field_without_afferents_on_the_contact_still_pulses(run, tmp_path, capsys):
    """The run's two afferents have no region; a D2 field takes the contact's force (its centre lies in D2d)."""
    table = tmp_path / "e.csv"
    table.write_text(HEADER + "index,,,,D2,20,80,200,300,20\n")
    argv = ["stimulate", str(run), "--electrodes", str(table), "--out", str(tmp_path / "p.nc"), "--no-figures"]
    assert main(argv + ["--rule", "linear-amplitude"]) == 0
    assert load_pulses(tmp_path / "p.nc").sizes["pulse"] > 0 and "ddmm: warning" not in capsys.readouterr().err
