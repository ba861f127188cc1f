"""The pattern scans' script and its spatial event plot (`experiments/validation/pattern_scans.py`,
`experiments/plots/texture.py`)."""

from pathlib import Path

import numpy as np
import pytest
import xarray as xr
from matplotlib.figure import Figure

from ddmm.experiments.plots.texture import plot_spatial_events
from ddmm.experiments.validation import pattern_scans
from ddmm.population.stimuli.surfaces import letters


def _events(types):
    n = len(types)
    return xr.Dataset({"surface_x_mm": ("event", np.linspace(-1.0, 1.0, n)), "surface_y_mm": ("event", np.zeros(n)),
                       "afferent_type": ("event", np.array(types, dtype=object))})


def test_the_plot_has_a_panel_per_type_present_and_draws_the_relief_under_the_spikes():
    fig = plot_spatial_events(_events(["SAI", "RAII", "SAI"]), letters("I"), extent_mm=(-3.0, 3.0, -3.5, 3.5))
    assert isinstance(fig, Figure)
    assert [ax.get_title() for ax in fig.axes] == ["SA-I (2 spikes)", "FA-II (1 spikes)"]
    assert all(ax.collections and len(ax.collections) == 2 for ax in fig.axes)  # the relief's outline, the spikes
    assert fig.axes[0].get_xlim() == (-3.0, 3.0)
    assert len(plot_spatial_events(_events([])).axes) == 1  # no spike: one empty panel, no error


def test_the_script_prints_held_out_correlations_beside_touchsims_and_writes_the_plot(tmp_path, capsys):
    fixture = Path(__file__).parents[1] / "population" / "data" / "touchsim_pattern_scans.json"
    assert pattern_scans.main(["--seeds", "2", "--patterns", "dots", "--out", str(tmp_path),
                               "--touchsim", str(fixture)]) == 0
    out = capsys.readouterr().out
    assert "HELD OUT" in out and "dots, seed 2: SAI r" in out and "dots: ordering held on 1 of 1 fingertips" in out
    assert "TouchSim (recorded): SA1 r 0.32" in out
    assert (tmp_path / "dots_sep.png").stat().st_size > 10_000 and not (tmp_path / "letters_sep.png").exists()


def test_the_script_refuses_an_output_path_that_is_a_file_before_running(tmp_path, capsys):
    blocker = tmp_path / "file"
    blocker.write_text("x")
    with pytest.raises(SystemExit) as exit_info:
        pattern_scans.main(["--out", str(blocker)])
    assert exit_info.value.code == 2
    assert "cannot be created: File exists" in capsys.readouterr().err


def test_the_script_refuses_a_touchsim_file_that_is_not_a_recording(tmp_path, capsys):
    bad = tmp_path / "other.json"
    bad.write_text('{"responses": {}}')
    for path in (bad, tmp_path / "missing.json"):
        with pytest.raises(SystemExit) as exit_info:
            pattern_scans.main(["--touchsim", str(path)])
        assert exit_info.value.code == 2
        assert "is not a recording of --record" in capsys.readouterr().err
