"""The slow-type protocols (`ddmm.population.analysis.physiology_slow`): registered, referenced, and measuring."""

from dataclasses import replace

import numpy as np
import pytest

from ddmm.population.data.published import PHYSIOLOGY_REFERENCE
from ddmm.population import sample_population
from ddmm.population.analysis import physiology, physiology_slow
from ddmm.population.analysis.physiology import score_physiology


@pytest.fixture(scope="module")
def slow_pop():
    pop = sample_population("fingertip", rng=0)
    keep = np.r_[np.flatnonzero(pop.afferent_type == "SAI")[::3], np.flatnonzero(pop.afferent_type == "SAII")]
    return pop.select(np.sort(keep))  # every SA-II: the synchrony of 36 random phases is small, of 12 not always


def test_rows_are_registered_with_references_half_held_out():
    names = list(physiology_slow.PROPERTIES)
    assert set(names) <= set(physiology.PROPERTIES) and set(physiology_slow.PROTOCOLS) <= set(physiology.PROTOCOLS)
    roles = [PHYSIOLOGY_REFERENCE[n].role for n in names]
    assert roles.count("held out") * 2 >= len(roles)


def _values(pop, names):
    rows, _ = score_physiology(pop, PHYSIOLOGY_REFERENCE, properties=names, seed=0)
    return {r["name"]: (r["value"], r["pass"]) for r in rows}


def test_preset_passes_the_slow_rows(slow_pop):
    values = _values(slow_pop, list(physiology_slow.PROPERTIES))
    assert all(ok for _, ok in values.values()), values


def test_without_the_options_the_slow_rows_fail(slow_pop):
    """The paper-like SA-II (no normal drive, one bias, start at rest) and SA-I without the dynamic stage fail."""
    off = slow_pop.current.with_type("SAII", normal=0.0, bias_cv=0.0, phase=0.0).with_type("SAI", dynamic=0.0, fall=0.0)
    values = _values(replace(slow_pop, current=off), ["normal_coding_SAII", "rest_spread_SAII", "start_synchrony_SAII",
                                                       "adaptation_8N_SAI"])
    assert not any(ok for _, ok in values.values()), values


def test_sa_i_peaks_need_the_transient_and_the_plateau_keeps_to_force(slow_pop):
    names = ["peak_rate_SAI", "peak_rate_2N_SAI", "plateau_rate_SAI"]
    values = _values(slow_pop, names)
    assert all(ok for _, ok in values.values()), values
    values = _values(replace(slow_pop, current=slow_pop.current.with_type("SAI", transient=0.0)), names)
    assert not values["peak_rate_SAI"][1] and not values["peak_rate_2N_SAI"][1], values
    assert values["plateau_rate_SAI"][1], values  # the plateau never depended on the transient
