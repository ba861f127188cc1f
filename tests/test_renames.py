"""Renamed names keep working for one release, each with a DeprecationWarning, and mean what the new name means."""

import importlib
import sys

import numpy as np
import pytest

from ddmm.models.current_params import CurrentParams, TypeCurrentParams
from ddmm.population import birznieks, make_population, plan_run, simulate


def test_types_keyword_is_afferent_types():
    pop = make_population(["SAI", "RAI", "SAII"], theta_t=[0.0, 90.0, 0.0])
    new = simulate(pop, birznieks(90.0), engine="direct", seed=1, quiet=True, afferent_types=("SAI",))
    with pytest.warns(DeprecationWarning, match="afferent_types="):
        old = simulate(pop, birznieks(90.0), engine="direct", seed=1, quiet=True, types=("SAI",))
    assert list(old.afferent_type.values) == ["SAI"]
    assert np.array_equal(old.spike_time.values, new.spike_time.values)
    with pytest.raises(TypeError, match="afferent_types="):
        plan_run(pop, birznieks(90.0), types=("SAI",), afferent_types=("SAI",))


def test_stimulation_is_neurostim():
    sys.modules.pop("ddmm.population.stimulation", None)
    with pytest.warns(DeprecationWarning, match="neurostim"):
        old = importlib.import_module("ddmm.population.stimulation")
    from ddmm.population import neurostim
    from ddmm.population.neurostim import electrodes

    assert old.read_electrodes is neurostim.read_electrodes
    assert importlib.import_module("ddmm.population.stimulation.electrodes") is electrodes
    assert set(old.__all__) == set(neurostim.__all__)


def test_current_stage_is_type_current_params():
    params = CurrentParams()
    with pytest.warns(DeprecationWarning, match="for_type"):
        assert params.stage("RAI") == params.for_type("RAI")
    with pytest.warns(DeprecationWarning, match="TypeCurrentParams"):
        from ddmm.models.current_params import CurrentStage
    assert CurrentStage is TypeCurrentParams
    from ddmm.models.current_filters import stage_constants, type_filter_constants

    with pytest.warns(DeprecationWarning, match="type_filter_constants"):
        assert stage_constants(params, "SAI", 1000.0) is type_filter_constants(params, "SAI", 1000.0)


def test_af_stage_is_computes_af():
    pop = make_population(["SAI"], theta_t=[0.0], nap=["selective"])
    cond = plan_run(pop, birznieks(90.0), engine="direct").conditions[0]
    with pytest.warns(DeprecationWarning, match="computes_af"):
        assert cond.af_stage is cond.computes_af
