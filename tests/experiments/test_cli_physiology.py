"""``ddmm physiology``: JSON shape, figures, one-line errors."""

import json

import numpy as np
import pytest

from ddmm.experiments.cli import main


def run(capsys, *argv):
    code = main([str(a) for a in argv])
    out = capsys.readouterr()
    return code, out.out, out.err


def test_json_shape_and_figures(capsys, tmp_path):
    code, out, _ = run(capsys, "physiology", "--properties", "rest_rate_RAI,best_frequency_RAII,continuity",
                       "--json", "--out", tmp_path)
    assert code == 0
    result = json.loads(out)
    assert set(result) == {"properties", "all_pass"}
    assert [p["name"] for p in result["properties"]] == ["rest_rate_RAI", "best_frequency_RAII", "continuity"]
    assert {"name", "type", "value", "low", "high", "source", "role", "pass"} <= set(result["properties"][0])
    assert result["all_pass"] is True
    assert {"scorecard.json", "rest.png", "frequency_tuning.png"} <= {p.name for p in tmp_path.iterdir()}


def test_table_marks_roles(capsys):
    code, out, _ = run(capsys, "physiology", "--properties", "rest_rate_SAII,force_coding_SAI")
    assert code == 0
    assert "| rest_rate_SAII | SA-II | rest |" in out and "constrained" in out and "held out" in out
    assert out.strip().splitlines()[-1].startswith("physiology: 2/2 properties pass")


def test_bad_input_is_one_line_and_exit_2(capsys, tmp_path):
    code, _, err = run(capsys, "physiology", "--properties", "resting")
    assert code == 2 and err.count("\n") == 1 and "unknown property 'resting'" in err
    spec = tmp_path / "sa_only.toml"
    spec.write_text('[types.SAI]\ncount = 5\n')
    code, _, err = run(capsys, "physiology", "--population", spec, "--properties", "best_frequency_RAII")
    assert code == 2 and err.count("\n") == 1 and "needs RAII afferents" in err


def test_phase_locking_rows_and_cycle_histograms(capsys, tmp_path):
    code, out, _ = run(capsys, "physiology", "--properties", "vs_RAI,vs_RAI_2N", "--json", "--out", tmp_path)
    assert code == 0 and json.loads(out)["all_pass"] is True
    assert "cycle_histograms.png" in {p.name for p in tmp_path.iterdir()}


def test_cycle_histograms_plot_one_panel_per_type():
    import numpy as np

    from ddmm.experiments.plots.physiology import plot_cycle_histograms

    phases = np.r_[np.full(30, 0.25), np.full(10, 0.75)]
    fig = plot_cycle_histograms({"RAI": {"frequency_hz": 20.0, "phases": phases},
                                 "RAII": {"frequency_hz": 200.0, "phases": np.zeros(0)}, "SAI": {"rates": [1.0]}})
    axes = fig.get_axes()
    assert len(axes) == 2 and "FA-I, 20 Hz" in axes[0].get_title() and "VS 0.50" in axes[0].get_title()
    heights = [p.get_height() for p in axes[0].patches]
    assert max(heights) == pytest.approx(0.75) and sum(heights) == pytest.approx(1.0)


def test_everyday_figures_are_written_from_a_small_population(tmp_path):
    """The recruitment curve and the threshold distributions, from the protocols' own data."""
    from ddmm.experiments.plots.physiology import physiology_figures, plot_threshold_spread

    data = {"everyday_loading": {"rates": (0.5, 1.0, 2.0), "fractions": [0.1, 0.5, 0.9]},
            "everyday_threshold": {"RAI": {"frequency_hz": 40.0, "thresholds_n": np.array([1e-3, 4e-3, np.inf])}}}
    figures = physiology_figures(data, {})
    assert set(figures) == {"recruitment.png", "threshold_spread.png"}
    line = plot_threshold_spread(data["everyday_threshold"]).axes[0].lines[0]
    np.testing.assert_allclose(line.get_xdata(), [1.0, 4.0])  # mN, the unit without a threshold left out
