"""A fifth afferent type, defined in this file alone, runs wherever the package's own types run.

The type is declared in three places: its `AfferentType` (`TOY`), its registration (the ``toy`` fixture) and a
population spec that counts it (`SPEC`).  Nothing else in the package knows it: it simulates on both engines with
identical spikes, streams as it simulates, and appears in the Dataset and the figures.
"""

import dataclasses

import numpy as np
import pytest
from matplotlib.colors import to_rgba

from ddmm.models import afferent_types as registry
from ddmm.models.afferent_types import AfferentType, register_afferent_type
from ddmm.models.neuron import NeuronParams
from ddmm.models.type_params import TypeParams
from ddmm.population import birznieks, describe_dataset, make_population, psth, sample_population, simulate
from ddmm.population.runtime.stream import Encoder
from ddmm.population.spec import spec_from_dict

# 1. The type: an SA-I-like force follower (existing stage kinds) with its own filter, transducer, neuron and field.
TOY = AfferentType("TOY", "TOY-I", colour="tab:red", current=TypeParams(gain=9.0, cutoff_hz=30.0, i_max=50.0,
                                                                        tau_s=0.01, adapt=0.3, tau_adapt_s=0.4),
                   neuron=NeuronParams(b=0.22, d=6.0, t_ref=0.001), rf_area_mm2=20.0)
# 3. A population that counts it (beside some SA-I), tuned as the spec language allows any type to be.
SPEC = {"name": "toy", "region": {"center_mm": [0.0, 0.0], "semi_axes_mm": [6.0, 8.0]},
        "types": {"SAI": {"count": 12, "noise_cv": 0.2},
                  "TOY": {"count": 18, "noise_cv": 0.2, "theta_t": {"distribution": "uniform"},
                          "nap": {"selective": 0.7, "none": 0.3}}}}


@pytest.fixture
def toy(monkeypatch):
    """2. Its registration, in a copy of the registry that goes away after the test."""
    monkeypatch.setattr(registry, "_REGISTRY", dict(registry._REGISTRY))
    monkeypatch.setattr(registry, "_CODE_OF", dict(registry._CODE_OF))
    register_afferent_type(TOY)
    return sample_population(spec_from_dict(SPEC), rng=0)


@pytest.fixture
def runs(toy):
    scenes = [birznieks(45.0), birznieks(225.0)]
    return toy, {engine: simulate(toy, scenes, engine=engine, seed=4, trials=2, quiet=True)
                 for engine in ("direct", "brian2")}


def test_both_engines_give_the_same_spikes(runs):
    _, ds = runs
    toy = ds["direct"].afferent_type.values == "TOY"
    assert toy.sum() == 18 and int(ds["direct"].spike_count[:, :, toy].sum()) > 50  # the toy type fires
    for name in ("spike_time", "spike_afferent", "spike_trial", "spike_condition", "spike_count"):
        np.testing.assert_array_equal(ds["direct"][name].values, ds["brian2"][name].values)


def test_its_declarations_shape_its_spikes(toy):
    """Its neuron, gain and receptive field are the ones declared here (a changed declaration changes them)."""
    ds = simulate(toy, birznieks(45.0), engine="direct", seed=4, quiet=True)
    assert ds.attrs["neuron_TOY_d"] == 6.0 and ds.attrs["current_TOY_gain"] == 9.0
    assert ds.attrs["rf_sigma_TOY_mm"] == pytest.approx(TOY.rf_sigma_mm)
    weaker = dataclasses.replace(toy, current=toy.current.with_type("TOY", gain=3.0))
    fewer = simulate(weaker, birznieks(45.0), engine="direct", seed=4, quiet=True)
    toy_cols = ds.afferent_type.values == "TOY"
    assert int(fewer.spike_count[..., toy_cols].sum()) < int(ds.spike_count[..., toy_cols].sum())
    np.testing.assert_array_equal(fewer.spike_count[..., ~toy_cols], ds.spike_count[..., ~toy_cols])
    same = dataclasses.replace(toy, neuron={"TOY": TOY.neuron})  # its declared neuron is the one integrated
    np.testing.assert_array_equal(simulate(same, birznieks(45.0), engine="direct", seed=4, quiet=True).spike_time,
                                  ds.spike_time)
    paper = dataclasses.replace(toy, neuron={"TOY": NeuronParams(b=0.22, t_ref=0.001)})  # d = 8, not 6
    assert simulate(paper, birznieks(45.0), engine="direct", seed=4, quiet=True).sizes["spike"] != ds.sizes["spike"]


def test_it_streams_as_it_simulates(toy):
    scene = birznieks(45.0)
    offline = simulate(toy, scene, engine="direct", seed=3, quiet=True)
    encoder = Encoder(toy, scene.fs, engine="direct", seed=3, conditioning=None)
    forces = np.column_stack([scene.fx, scene.fy, scene.fz])
    outs = [encoder.push(forces[a:a + 97]) for a in range(0, forces.shape[0], 97)]
    np.testing.assert_array_equal(np.concatenate([o.afferent for o in outs]), offline.spike_afferent.values)
    np.testing.assert_array_equal(np.concatenate([o.time for o in outs]), offline.spike_time.values)


def test_it_appears_in_the_dataset_and_the_figures(runs):
    from ddmm.experiments.plots.common import plot_polar_counts, plot_psth, plot_raster

    _, ds = runs
    ds = ds["direct"]
    assert "TOY-I" in describe_dataset(ds)
    rates = psth(ds, bin_s=0.05)
    assert "TOY" in rates[rates.dims[1]].values.tolist()
    red = to_rgba("tab:red")
    raster = plot_raster(ds)
    assert any(red in [tuple(c) for c in coll.get_edgecolors()] for coll in raster.axes[0].collections)
    assert "TOY-I" in [t.get_text() for t in raster.axes[0].texts]
    for fig in (plot_polar_counts(ds), plot_psth(rates)):
        labels = [t.get_text() for ax in fig.axes for t in (ax.get_legend().get_texts() if ax.get_legend() else [])]
        titles = [text for ax in fig.axes for text in (ax.get_title(), ax.get_ylabel())]
        assert any("TOY-I" in text for text in labels + titles), (labels, titles)


def test_its_receptive_field_is_the_declared_one(toy):
    """A point probe drives it over the field its declared area gives (wider than SA-I's)."""
    from ddmm.population.analysis.physiology_fields import probe_scene
    from ddmm.population.anatomy.receptive_fields import population_weight

    scene = probe_scene(2.0)
    line = make_population(["TOY", "SAI"] * 4, x_mm=np.repeat([0.0, 2.0, 3.0, 4.0], 2), theta_t=0.0)
    weight = population_weight(line, scene.contact)
    edge = np.array([0.0, 2.0, 3.0, 4.0]) - scene.contact.radius_mm
    np.testing.assert_allclose(weight[::2], np.exp(-0.5 * (np.maximum(edge, 0.0) / TOY.rf_sigma_mm) ** 2))
    assert np.all(weight[2::2] > weight[3::2])  # 20 mm^2 against SA-I's 11: a wider field
    ds = simulate(line, scene, engine="direct", seed=0, quiet=True)
    assert int(ds.spike_count[..., 0].sum()) > int(ds.spike_count[..., 6].sum())  # the centre fires more


def test_two_stretch_drive_types_keep_their_own_weights(monkeypatch):
    """A second stretch-drive type beside SA-II, with other opponent and normal weights: in one population each
    type's spikes are those it fires alone (the front pass reads the weights per group)."""
    monkeypatch.setattr(registry, "_REGISTRY", dict(registry._REGISTRY))
    monkeypatch.setattr(registry, "_CODE_OF", dict(registry._CODE_OF))
    register_afferent_type(AfferentType("STR", "STR-II", stretch_drive=True, log_compression=False,
                                        current=TypeParams(gain=6.0, cutoff_hz=20.0, opponent=0.9, normal=0.6,
                                                           bias=5.5, i_max=40.0)))
    spec = {"name": "two", "region": {"center_mm": [0.0, 0.0], "semi_axes_mm": [6.0, 8.0]},
            "current": {"SAII": {"gain": 4.0, "opponent": 0.2, "bias": 5.5}},
            "types": {"SAII": {"count": 10, "nap": {"broad": 1.0}}, "STR": {"count": 10, "nap": {"broad": 1.0}}}}
    pop = sample_population(spec_from_dict(spec), rng=1)
    scenes = [birznieks(0.0), birznieks(180.0)]
    both = simulate(pop, scenes, engine="direct", seed=2, quiet=True)
    for code in ("SAII", "STR"):
        alone = simulate(pop.select(pop.afferent_type == code), scenes, engine="direct", seed=2, quiet=True)
        np.testing.assert_array_equal(both.spike_count.sel(afferent=alone.afferent.values), alone.spike_count)
    other = dataclasses.replace(pop, current=pop.current.with_type("STR", opponent=0.2, normal=0.0))  # SA-II's
    moved = simulate(other, scenes, engine="direct", seed=2, quiet=True)
    saii = pop.afferent_type == "SAII"
    np.testing.assert_array_equal(moved.spike_count[..., saii], both.spike_count[..., saii])
    assert int(np.abs(moved.spike_count[..., ~saii] - both.spike_count[..., ~saii]).sum()) > 0
