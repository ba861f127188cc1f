"""What a new user meets in the first hour: typo hints, the compile notice, progress bars, messages, figures."""

import pytest
from matplotlib.backends.backend_agg import FigureCanvasAgg

from ddmm.experiments.cli import main
from ddmm.population import simulation


@pytest.mark.parametrize("argv,hint", [
    (["simulat"], "(did you mean simulate?)"),
    (["simulate", "--engine", "drect", "--out", "x.nc"], "(did you mean direct?)"),
    (["simulate", "--seeed", "3", "--out", "x.nc"], "(did you mean --seed?)"),
    (["reproduce", "tabel2"], "(did you mean table2?)"),
])
def test_a_typo_gets_a_did_you_mean_in_one_line(capsys, argv, hint):
    with pytest.raises(SystemExit) as exc:
        main(argv)
    err = capsys.readouterr().err
    assert exc.value.code == 2 and hint in err and err.count("\n") == 1, err


def test_an_unknown_option_far_from_any_gets_no_guess(capsys):
    with pytest.raises(SystemExit):
        main(["plan", "--xyzzy", "3"])
    err = capsys.readouterr().err
    assert "unrecognized arguments: --xyzzy 3" in err and "did you mean" not in err


@pytest.mark.parametrize("quiet,env,expected", [
    (True, None, True), (False, None, None), (False, "0", True), (False, "1", False), (True, "1", True),
])
def test_progress_follows_tqdm_and_ddmm_progress(monkeypatch, quiet, env, expected):
    if env is None:
        monkeypatch.delenv("DDMM_PROGRESS", raising=False)
    else:
        monkeypatch.setenv("DDMM_PROGRESS", env)
    assert simulation._progress_disabled(quiet) is expected


def test_a_bad_ddmm_progress_is_named(monkeypatch):
    monkeypatch.setenv("DDMM_PROGRESS", "yes")
    with pytest.raises(ValueError, match="DDMM_PROGRESS must be 0 or 1, got 'yes'"):
        simulation._progress_disabled(False)


def test_the_compile_notice_says_so_once_when_the_cache_is_empty(monkeypatch, tmp_path, capsys):
    monkeypatch.setenv("NUMBA_CACHE_DIR", str(tmp_path))
    monkeypatch.setattr(simulation, "_NOTICED", [])
    simulation._compile_notice(quiet=True)
    assert capsys.readouterr().err == ""
    simulation._compile_notice(quiet=False)
    simulation._compile_notice(quiet=False)
    err = capsys.readouterr().err
    assert err.count("compiling the numba kernels (first run only") == 1 and str(tmp_path) in err
    monkeypatch.setattr(simulation, "_NOTICED", [])
    (tmp_path / "_fused_passes._back-1.py311.nbi").write_text("")
    simulation._compile_notice(quiet=False)
    assert capsys.readouterr().err == ""


def test_simulate_reports_wall_time_and_the_engine_help_names_direct(capsys, tmp_path):
    code = main(["simulate", "--population", "fingertip", "--scene", "birznieks", "--types", "SAI",
                 "--engine", "direct", "--out", str(tmp_path / "r.nc")])
    out = capsys.readouterr().out
    assert code == 0 and "spikes; wall time " in out and out.rstrip().endswith(" s)")
    with pytest.raises(SystemExit):
        main(["simulate", "--help"])
    assert "the same spikes bit for bit" in " ".join(capsys.readouterr().out.split())


def test_forces_legend_never_covers_a_trace():
    from ddmm.experiments.plots.common import plot_forces
    from ddmm.population import press_push_lift, sample_population, simulate

    pop = sample_population("fingertip", rng=0).select(range(3))
    ds = simulate(pop, press_push_lift(90.0), engine="direct", seed=0, quiet=True)
    fig = plot_forces(ds)
    canvas = FigureCanvasAgg(fig)
    canvas.draw()
    ax = fig.axes[0]
    legend, frame = ax.get_legend().get_window_extent(), ax.get_window_extent()
    assert legend.x0 >= frame.x1 - 1  # outside the axes, to the right


def test_an_unexpected_error_is_one_line_and_debug_shows_it(capsys, monkeypatch):
    from ddmm.experiments.cli import plan as plan_command

    def broken(args):
        raise KeyError("afferent")

    monkeypatch.setattr(plan_command, "run_plan", broken)
    monkeypatch.delenv("DDMM_DEBUG", raising=False)
    code = main(["plan", "--scene", "birznieks"])
    err = capsys.readouterr().err
    assert code == 2 and err.count("\n") == 1 and "unexpected KeyError: 'afferent'" in err and "--debug" in err
    with pytest.raises(KeyError):
        main(["--debug", "plan", "--scene", "birznieks"])


@pytest.mark.parametrize("argv,match", [
    (["simulate", "--seed", "-1", "--out", "x.nc"], "argument --seed: must be an integer >= 0 (a numpy seed), got -1"),
    (["plan", "--theta-r", "inf"], "--theta-r: 'inf' is not a finite number of degrees or 'none'"),
])
def test_options_are_named_with_plain_numbers(capsys, argv, match):
    try:
        code = main(argv)
    except SystemExit as exc:
        code = exc.code
    err = capsys.readouterr().err
    assert code == 2 and match in err and "np.float64" not in err and err.count("\n") == 1, err
