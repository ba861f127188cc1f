"""The hand-map figure: outlines, afferents by type, spike-count map; bad input named."""

import numpy as np
import pytest
from matplotlib.figure import Figure

from ddmm.experiments.plots.hand import hand_counts, plot_hand
from ddmm.models.currents import type_label
from ddmm.population import birznieks, make_population, sample_population, simulate
from ddmm.population.anatomy import hand_map


@pytest.fixture(scope="module")
def hand():
    return sample_population("hand", rng=0)


def test_outlines_and_one_scatter_per_type(hand):
    fig = plot_hand(hand)
    ax = fig.axes[0]
    assert isinstance(fig, Figure) and len(ax.lines) == len(hand_map.REGIONS)
    labels = [t.get_text() for t in ax.get_legend().get_texts()]
    assert labels == [f"{type_label(k)} ({n})" for k, n in hand.counts().items()]
    assert sum(len(c.get_offsets()) for c in ax.collections) == len(hand)
    x0, x1 = ax.get_xlim()
    assert x0 < hand.x_mm.min() and x1 > hand.x_mm.max()


def test_counts_set_marker_sizes_and_silent_afferents_are_grey(hand):
    pop = hand.select(np.flatnonzero(np.isin(hand.region, ["D2d", "D2m"])))
    counts = np.zeros(len(pop))
    counts[:10] = np.arange(1, 11)
    ax = plot_hand(pop, counts=counts).axes[0]
    silent, *active = ax.collections
    assert len(silent.get_offsets()) == len(pop) - 10
    sizes = np.concatenate([c.get_sizes() for c in active])
    assert sizes.size == 10 and sizes.max() == pytest.approx(41.0)
    assert ax.get_ylim()[1] < 20.0  # zoomed on the regions present
    # the legend counts every afferent of a type and names the silent ones; the title names the regions shown
    labels = [t.get_text() for t in ax.get_legend().get_texts()]
    assert labels[0] == f"silent ({len(pop) - 10})"
    types = pop.afferent_type
    for kind, label in zip([k for k in ("SAI", "RAI", "RAII", "SAII") if np.any(types == k)], labels[1:]):
        n = int(np.sum(types == kind))
        quiet = n - int(np.sum(types[:10] == kind))
        assert label == f"{type_label(kind)} ({n}" + (f", {quiet} silent)" if quiet else ")")
    assert ax.get_title() == "regions D2m, D2d of a right hand, palmar view: spike count (marker area)" \
        or ax.get_title() == "regions D2d, D2m of a right hand, palmar view: spike count (marker area)"
    assert plot_hand(hand).axes[0].get_title() == "right hand, palmar view: afferents by type"


def test_draws_into_a_given_axes_and_takes_a_dataset():
    pop = make_population(["SAI", "RAI"], region=["D2d", "D2d"], y_mm=[0.0, 2.0])
    ds = simulate(pop, birznieks(90.0), engine="direct", seed=1, quiet=True)
    ax = Figure().subplots()
    assert plot_hand(ds, counts=hand_counts(ds), ax=ax) is ax.figure
    assert hand_counts(ds).shape == (2,)


def test_bad_input_is_named(hand):
    with pytest.raises(ValueError, match="counts"):
        plot_hand(hand, counts=np.ones(3))
    with pytest.raises(ValueError, match="counts"):
        plot_hand(hand, counts=-np.ones(len(hand)))
    with pytest.raises(TypeError, match="population"):
        plot_hand([1, 2, 3])
