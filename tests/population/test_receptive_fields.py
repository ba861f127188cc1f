"""Receptive-field shapes: the Gaussian with a hard support, and the tailed shape whose fields grow with force."""

import dataclasses

import numpy as np
import pytest
from hypothesis import given
from hypothesis import strategies as st

from ddmm.population import Contact, load_spec, make_population, sample_population
from ddmm.population.analysis.physiology_fields import FIELD_FORCES_N, field_radii
from ddmm.population.anatomy.receptive_fields import (
    RF_SIGMA_MM,
    RF_SUPPORT,
    RF_TAIL_FLOOR,
    receptive_field_weight,
)

SIGMA = RF_SIGMA_MM["RAI"]


def _weights(excess_mm, shape):
    excess = np.atleast_1d(np.asarray(excess_mm, dtype=float))
    return receptive_field_weight(1.0 + excess, np.zeros_like(excess), ["RAI"] * excess.size, Contact(0.0, 0.0, 1.0),
                                  shape)


def test_tail_joins_the_gaussian_core_with_the_same_value_and_slope():
    inside = np.linspace(0.0, SIGMA, 50)
    np.testing.assert_allclose(_weights(inside, "tailed"), _weights(inside, "gaussian"), rtol=1e-12)
    h = 1e-6 * SIGMA
    for shape in ("gaussian", "tailed"):
        below, at, above = _weights([SIGMA - h, SIGMA, SIGMA + h], shape)
        assert at == pytest.approx(np.exp(-0.5), rel=1e-12)
        assert (above - at) / h == pytest.approx((at - below) / h, rel=1e-4)  # slope continuous at one width


def test_half_weight_radius_keeps_the_median_field_area():
    grid = np.linspace(0.0, 3.0 * SIGMA, 300_001)
    half = {shape: grid[np.argmax(_weights(grid, shape) < 0.5)] for shape in ("gaussian", "tailed")}
    assert half["tailed"] == pytest.approx(half["gaussian"], rel=0.015)  # 1.193 against 1.177 widths


@given(st.floats(0.0, 20.0), st.floats(0.0, 20.0))
def test_tailed_weight_falls_with_distance_and_ends_at_its_floor(a, b):
    near, far = sorted((a, b))
    w_near, w_far = _weights([near * SIGMA, far * SIGMA], "tailed")
    assert 0.0 <= w_far <= w_near <= 1.0
    assert w_far == 0.0 or w_far >= RF_TAIL_FLOOR


def test_gaussian_support_is_a_cliff_and_the_tail_reaches_beyond_it():
    beyond = (RF_SUPPORT + 0.5) * SIGMA
    assert _weights(beyond, "gaussian")[0] == 0.0
    assert _weights(beyond, "tailed")[0] > 0.0


def test_fields_grow_with_every_doubling_of_force_only_with_the_tail():
    """The reviewer's cliff: with the Gaussian support FA-I fields stop growing between 0.8 and 1.6 N."""
    context = {"engine": "direct", "seed": 0, "no_shear": "smooth"}
    spec = load_spec("fingertip")
    tailed = sample_population(spec, rng=0)
    gaussian = sample_population(dataclasses.replace(spec, receptive_field="gaussian"), rng=0)
    radii = field_radii(tailed, "RAI", context)
    assert len(radii) == len(FIELD_FORCES_N) and np.all(np.diff(radii) > 0)
    cliff = field_radii(gaussian, "RAI", context)
    assert cliff[-1] == cliff[-2]


def test_shape_travels_with_the_population_and_into_the_dataset():
    from ddmm.population import birznieks, simulate

    pop = make_population(["SAI", "RAI"], receptive_field="tailed")
    assert pop.select([1]).receptive_field == "tailed"
    ds = simulate(pop, birznieks(90.0), engine="direct", seed=0, quiet=True)
    assert ds.attrs["receptive_field"] == "tailed"


@pytest.mark.parametrize("make", [
    lambda: make_population(["SAI"], receptive_field="box"),
    lambda: dataclasses.replace(load_spec("fingertip"), receptive_field="box"),
    lambda: receptive_field_weight([0.0], [0.0], ["SAI"], Contact(0.0, 0.0, 1.0), "box"),
])
def test_unknown_shape_is_refused_by_name(make):
    with pytest.raises(ValueError, match="receptive_field.*'box'.*gaussian, tailed"):
        make()
