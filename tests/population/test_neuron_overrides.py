"""Per-type neuron parameters (`[neuron.<TYPE>]` in a spec, `Population.neuron`): read, checked, used by both
engines and by the stream, recorded in the dataset."""

import numpy as np
import pytest

from ddmm.models.neuron import NEURON_PARAMS, NeuronParams
from ddmm.population import birznieks, load_spec, make_population, sample_population, simulate
from ddmm.population.spec import spec_from_dict

FAST = {"RAII": NeuronParams(a=0.5, b=0.25, c=-65.0, d=100.0)}


def _small(neuron=None):
    pop = make_population(["RAII"] * 4 + ["RAI"] * 2, theta_t=[0, 90, 180, 270, 90, 270], nap="broad",
                          current=load_spec("fingertip").current)
    return pop if neuron is None else pop.__class__(**{**pop.__dict__, "neuron": neuron})


def test_spec_table_starts_from_the_types_paper_values():
    spec = spec_from_dict({"types": {"RAII": {"count": 3}}, "neuron": {"FA-II": {"a": 0.5, "d": 100.0}}})
    assert spec.neuron == {"RAII": NeuronParams(a=0.5, b=NEURON_PARAMS["RAII"].b, c=-65.0, d=100.0)}
    assert sample_population(spec, rng=0).neuron == spec.neuron
    # the presets keep the paper's neurons but FA-II's (a refractory period and a smaller D, docs/model.md)
    assert load_spec("fingertip").neuron == {"RAII": NeuronParams(b=0.25, d=0.5, t_ref=0.002)}


@pytest.mark.parametrize(("table", "match"), [
    ({"RAII": {"e": 1.0}}, "neuron.RAII.e: unknown key"),
    ({"RAII": {"a": 0.0}}, "a must be a finite number > 0"),
    ({"RAII": {"d": -1.0}}, "d must be a finite number >= 0"),
    ({"RAII": {"b": 0.3}}, r"b must be a finite number in \(0, 0.267\]"),
    ({"RAII": {"t_ref": -0.001}}, r"t_ref must be a finite number in \[0, 0.1\] \(s\), got -0.001"),
    ({"RAII": {"t_ref": 2.0}}, r"t_ref must be a finite number in \[0, 0.1\] \(s\), got 2"),
    ({"XX": {"a": 0.1}}, "neuron.XX: unknown afferent type"),
])
def test_bad_tables_are_named(table, match):
    with pytest.raises(ValueError, match=match):
        spec_from_dict({"types": {"RAII": {"count": 3}}, "neuron": table})


def test_population_refuses_what_is_not_a_table():
    with pytest.raises(TypeError, match="neuron must be a dict"):
        _small(neuron=[("RAII", FAST["RAII"])])


def test_overrides_change_the_spikes_and_both_engines_agree():
    scene = birznieks(90.0)
    paper = simulate(_small(), scene, engine="direct", seed=3, quiet=True)
    direct = simulate(_small(FAST), scene, engine="direct", seed=3, quiet=True)
    brian2 = simulate(_small(FAST), scene, engine="brian2", seed=3, quiet=True)
    assert not np.array_equal(paper.spike_count.values, direct.spike_count.values)
    for name in ("spike_time", "spike_afferent"):
        assert np.array_equal(direct[name].values, brian2[name].values)
    assert direct.attrs["neuron_RAII_d"] == 100.0 and paper.attrs["neuron_RAII_d"] == NEURON_PARAMS["RAII"].d
