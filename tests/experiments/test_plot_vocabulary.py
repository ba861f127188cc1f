"""One vocabulary in the figures: SA-I, FA-I, FA-II, SA-II; imp/s for afferent rates; θ_T."""

import re

import numpy as np
import pytest

from ddmm.experiments.plots.common import plot_forces, plot_polar_counts, plot_psth, plot_raster
from ddmm.population import birznieks, psth, sample_population, simulate


@pytest.fixture(scope="module")
def ds():
    pop = sample_population("fingertip", rng=0)
    pick = np.concatenate([np.flatnonzero(pop.afferent_type == k)[:15] for k in ("SAI", "RAI", "RAII", "SAII")])
    return simulate(pop.select(np.sort(pick)), birznieks(90.0), engine="direct", seed=0, quiet=True)


def texts(fig) -> list:
    found = [t.get_text() for t in fig.findobj(match=lambda a: hasattr(a, "get_text"))]
    return [t for t in found if t]


def test_figures_speak_one_vocabulary(ds):
    figures = [plot_raster(ds), plot_psth(psth(ds, 0.05), ds), plot_polar_counts(ds), plot_forces(ds)]
    words = " | ".join(t for fig in figures for t in texts(fig))
    assert not re.search(r"\b(SAI|RAI|RAII|SAII)\b", words), words
    assert "pulses/s" not in words and "theta_T" not in words
    assert all(label in words for label in ("SA-I", "FA-I", "FA-II", "SA-II", "imp/s", "θ_T"))
    assert "50 ms bins" in words and "F_Z (N)" in words and "the forces the model consumed" in words


def test_psth_panels_follow_the_type_order(ds):
    fig = plot_psth(psth(ds, 0.05))
    labels = [ax.get_ylabel().split("\n")[0] for ax in fig.axes]
    assert labels == ["SA-I", "FA-I", "FA-II", "SA-II"]


def test_the_run_summary_speaks_it_too(ds):
    from ddmm.population.dataset import describe_dataset

    text = describe_dataset(ds)
    assert "mean rate per afferent (imp/s): SA-I" in text and "FA-II" in text and "pulses/s" not in text
    assert "no_shear smooth (eq. 17's reading below the shear threshold" in text
