"""Neuron parameters (eqs 4-6) and resting states."""

import numpy as np
import pytest

from ddmm.models.neuron import NEURON_PARAMS, neuron_arrays, resting_state


def test_types_follow_the_paper():
    for kind in ("SAI", "RAI", "RAII"):
        p = NEURON_PARAMS[kind]
        assert (p.a, p.c, p.d) == (0.02, -65.0, 8.0)
    assert NEURON_PARAMS["SAI"].b == 0.2
    assert NEURON_PARAMS["RAI"].b == NEURON_PARAMS["RAII"].b == 0.25


@pytest.mark.parametrize("b,v_expected", [(0.2, -70.0), (0.25, -64.41391)])
def test_resting_state_is_a_fixed_point(b, v_expected):
    v, u = resting_state(b)
    assert v == pytest.approx(v_expected, abs=1e-4)
    assert 0.04 * v**2 + 5 * v + 140 - u == pytest.approx(0.0, abs=1e-9)
    assert u == pytest.approx(b * v)


def test_neuron_arrays_and_bad_type():
    arr = neuron_arrays(["RAII", "SAI"])
    np.testing.assert_array_equal(arr["b"], [0.25, 0.2])
    with pytest.raises(ValueError, match="afferent_type"):
        neuron_arrays(["SAIII"])
