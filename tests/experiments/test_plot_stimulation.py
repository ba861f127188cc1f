"""The stimulation figure: one labelled row per electrode, every pulse of the chosen trial drawn, bad indices named."""

import numpy as np
import pytest
from matplotlib.figure import Figure

from ddmm.experiments.plots.neurostim import plot_stimulation
from ddmm.population import birznieks, sample_population, simulate
from ddmm.population.neurostim import Electrode, stimulation_pulses

TABLE = [Electrode("E1", 20.0, 80.0, 200.0, 300.0, 20.0, x_mm=0.0, y_mm=0.0, radius_mm=4.0),
         Electrode("E2", 10.0, 60.0, 100.0, 200.0, 10.0, x_mm=5.0, y_mm=-5.0, radius_mm=3.0),
         Electrode("D2", 10.0, 60.0, 100.0, 200.0, 10.0, region="D2")]


@pytest.fixture(scope="module")
def pulses():
    """Two conditions x two noisy trials, so the figure must pick the right (condition, trial)."""
    pop = sample_population("fingertip", rng=0).select(range(0, 991, 20))
    ds = simulate(pop, [birznieks(90.0), birznieks(180.0)], engine="direct", trials=2, seed=2, quiet=True)
    return stimulation_pulses(ds, TABLE)


def _pulse_lines(fig):
    return [line for ax in fig.axes for line in ax.lines if line.get_gid() == "pulses"]


def test_one_labelled_row_per_electrode(pulses):
    fig = plot_stimulation(pulses)
    assert isinstance(fig, Figure) and len(fig.axes) == 3 * len(TABLE)
    labels = [ax.get_title(loc="left") for ax in fig.axes if ax.get_title(loc="left")]
    assert [label.split(":")[0] for label in labels] == ["E1", "E2", "D2"]
    assert "disc x 5 mm, y -5 mm, radius 3 mm" in labels[1] and "region D2" in labels[2]
    assert "10-60 µA" in labels[1]
    units = [ax.get_ylabel() for ax in fig.axes]
    assert units == ["force (N)", "rate (Hz)", "amplitude (µA)"] * len(TABLE)
    assert all(ax.get_xlabel() == "time (s)" for ax in fig.axes[-3:])
    title = fig.get_suptitle()
    assert "condition 0 (birznieks" in title and "trial 0" in title and "rule biomimetic" in title
    legend = [t.get_text() for t in fig.legends[0].get_texts()]
    assert "afferent rate (spikes/s per field afferent)" in legend and "commanded pulse rate (Hz)" in legend


@pytest.mark.parametrize("condition,trial", [(0, 0), (1, 1)])
def test_every_pulse_of_the_trial_is_plotted_at_its_time_and_amplitude(pulses, condition, trial):
    fig = plot_stimulation(pulses, condition=condition, trial=trial)
    lines = _pulse_lines(fig)
    mine = (pulses.pulse_condition.values == condition) & (pulses.pulse_trial.values == trial)
    assert len(lines) == len(TABLE) and mine.sum() > 20
    assert sum(len(line.get_xdata()) for line in lines) == int(mine.sum())
    for e, line in enumerate(lines):
        sel = mine & (pulses.pulse_electrode.values == e)
        np.testing.assert_array_equal(line.get_xdata(), pulses.pulse_time.values[sel])
        np.testing.assert_array_equal(line.get_ydata(), pulses.pulse_amplitude.values[sel])
        limits = sorted(ln.get_ydata()[0] for ln in fig.axes[3 * e + 2].lines if ln.get_linestyle() == "--")
        assert limits == [TABLE[e].amplitude_min_ua, TABLE[e].amplitude_max_ua]
    assert f"{int(mine.sum())} pulses" in fig.get_suptitle()


def test_bad_index_names_the_argument(pulses):
    with pytest.raises(ValueError, match=r"condition must be in 0\.\.1.*got 2"):
        plot_stimulation(pulses, condition=2)
    with pytest.raises(ValueError, match=r"trial must be in 0\.\.1.*got -1"):
        plot_stimulation(pulses, trial=-1)
    with pytest.raises(TypeError, match="trial must be an integer"):
        plot_stimulation(pulses, trial=0.5)
