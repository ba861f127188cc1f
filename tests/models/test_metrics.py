"""SF and PRSI/DSI (eqs 7, 19)."""

import numpy as np
import pytest

from ddmm.models.metrics import direction_index, spiking_frequency


def test_direction_index_analytic():
    assert direction_index(1, 1, 1, 1) == 0.0
    assert direction_index(0, 1, 0, 0) == 1.0
    assert direction_index(2, 0, 0, 0) == 1.0
    assert direction_index(3, 4, 0, 0) == pytest.approx(5 / 7)
    assert direction_index(0, 0, 0, 0) == 0.0  # silent afferent: 0, not NaN
    np.testing.assert_allclose(direction_index([1, 0], [3, 0], [1, 0], [1, 0]), [1 / 3, 0.0])


def test_sf_counts_only_the_active_period():
    fz = np.r_[np.zeros(100), np.ones(200), np.zeros(100)]  # 0.2 s of contact at 1 kHz
    steps = np.array([50, 1500, 2500, 3500]) * 1  # substeps = 10: samples 5, 150, 250, 350
    sf = spiking_frequency(steps, 1, fz=fz, fs=1000.0, substeps=10)
    assert sf[0] == pytest.approx(2 / 0.2)


def test_sf_without_contact_is_zero():
    assert spiking_frequency([1, 2], 1, fz=np.zeros(10), fs=1000.0, substeps=1)[0] == 0.0
