"""The ddmm CLI: reproduce output, engine-identical JSON, figures, errors with exit 2."""

import json

import pytest

from ddmm.experiments.cli import main


def run(capsys, *argv):
    code = main(list(argv))
    out = capsys.readouterr()
    return code, out.out, out.err


def test_engines_print_identical_json(capsys):
    outputs = []
    for engine in ("direct", "brian2"):
        code, out, _ = run(capsys, "reproduce", "all", "--json", "--engine", engine)
        assert code == 0
        outputs.append(out)
    assert outputs[0] == outputs[1]
    assert set(json.loads(outputs[0])) == {"cells", "fig8"}


@pytest.mark.parametrize("what,keys,tables", [("table2", ["cells"], {"II"}), ("table3", ["cells"], {"III"}),
                                              ("fig8", ["cells", "fig8"], set())])
def test_json_per_table(capsys, what, keys, tables):
    code, out, _ = run(capsys, "reproduce", what, "--json", "--engine", "direct", "--no-shear", "block")
    result = json.loads(out)
    assert code == 0 and list(result) == keys and {c["table"] for c in result["cells"]} == tables


def test_tables_and_figures_written(capsys, tmp_path):
    code, out, _ = run(capsys, "reproduce", "all", "--engine", "direct", "--out", str(tmp_path))
    assert code == 0
    assert "| II | SAI | selective | PRSI | 0.38 |" in out and "| III | RAII | cmm | SF (75°) | 10.0 |" in out
    assert "Fig. 8" in out and "reading block" in out
    names = {p.name for p in tmp_path.iterdir()}
    expected = {"fig8.png", "reproduce.json"} | {f"fig{n}_{t}_{p}.png" for n in (6, 7) for t in ("SAI", "RAI", "RAII")
                                                 for p in ("selective", "broad", "bipolar", "cmm")}
    assert expected <= names
    assert all((tmp_path / n).stat().st_size > 10_000 for n in expected if n.endswith(".png"))
    assert not [n for n in names if n.endswith(".part")]


@pytest.mark.parametrize("argv", [
    ["reproduce", "table9"], ["reproduce", "all", "--engine", "nest"],
    ["reproduce", "all", "--no-shear", "maybe"], ["reproduce", "all", "--calibration", "mine"],
])
def test_bad_arguments_exit_2(capsys, argv):
    with pytest.raises(SystemExit) as exc:
        main(argv)
    assert exc.value.code == 2
    err = capsys.readouterr().err
    assert err.startswith("ddmm: error:") and err.count("\n") == 1


def test_unwritable_out_is_one_line_error(capsys, tmp_path):
    blocker = tmp_path / "file"
    blocker.write_text("x")
    code, out, err = run(capsys, "reproduce", "table2", "--engine", "direct", "--out", str(blocker / "d"))
    assert code == 2
    assert err.startswith("ddmm: error:") and err.count("\n") == 1 and "Traceback" not in err


def test_every_help_page_prints(capsys):
    """``ddmm --help`` and each command's ``--help`` exit 0 (a stray % in a help string once broke the top one)."""
    from ddmm.experiments.cli import build_parser, main

    commands = build_parser()._subparsers._group_actions[0].choices
    for argv in [["--help"]] + [[c, "--help"] for c in commands]:
        with pytest.raises(SystemExit) as exc:
            main(argv)
        assert exc.value.code == 0, argv
    assert "decode" in capsys.readouterr().out


def test_plot_scaling_and_bench_case_names():
    from ddmm.experiments.plots.common import plot_scaling

    fig = plot_scaling([{"n_afferents": 1000, "sim_s": 1.0, "wall_s": 0.04},
                        {"n_afferents": 10000, "sim_s": 1.0, "wall_s": 0.3},
                        {"n_afferents": 1000, "sim_s": 10.0, "wall_s": 0.3}])
    assert len(fig.axes) == 2 and fig.axes[1].get_ylabel() == "us per afferent-second"
    assert main(["bench", "--cases", "nope"]) == 2


def test_help_loads_no_numerical_stack():
    """``ddmm --help`` (and a subcommand's) imports none of numba, xarray, brian2 or scipy: a fresh interpreter."""
    import subprocess
    import sys

    code = ("import sys\nfrom ddmm.experiments.cli import main\n"
            "for argv in (['--help'], ['simulate', '--help'], ['stream', '--help'], ['reproduce', '--help']):\n"
            "    try:\n        main(argv)\n    except SystemExit:\n        pass\n"
            "print(sorted(m for m in ('numba', 'xarray', 'brian2', 'scipy') if m in sys.modules))")
    out = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, check=True).stdout
    assert out.strip().splitlines()[-1] == "[]"


def test_the_reproduce_help_names_every_calibration():
    from ddmm.experiments.cli.reproduce import CALIBRATION_NAMES
    from ddmm.experiments.paper.calibrations import CALIBRATIONS

    assert CALIBRATION_NAMES == tuple(CALIBRATIONS)
