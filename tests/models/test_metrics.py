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


def test_sf_peak_bin_is_the_busiest_bin_over_its_length():
    fz = np.ones(1000)  # 1 s of contact at 1 kHz; 0.4 s bins: [0, 0.4), [0.4, 0.8), [0.8, 1.0)
    samples = np.array([10, 20, 500, 510, 520, 900])  # 2, 3 and 1 spikes
    sf = spiking_frequency(samples * 10, 1, fz=fz, fs=1000.0, substeps=10, definition="peak_bin", bin_s=0.4)
    assert sf[0] == pytest.approx(3 / 0.4)
    assert spiking_frequency(samples * 10, 1, fz=fz, fs=1000.0, substeps=10)[0] == pytest.approx(6.0)


def test_sf_peak_bin_ignores_spikes_out_of_contact_and_bad_definitions():
    fz = np.r_[np.zeros(400), np.ones(400)]
    sf = spiking_frequency(np.array([1, 2, 3, 500]) * 10, 1, fz=fz, fs=1000.0, substeps=10, definition="peak_bin")
    assert sf[0] == pytest.approx(1 / 0.4)
    with pytest.raises(ValueError, match="definition='mean' is not allowed; allowed: contact_mean, peak_bin"):
        spiking_frequency([1], 1, fz=fz, fs=1000.0, substeps=1, definition="mean")
    with pytest.raises(ValueError, match="bin_s"):
        spiking_frequency([1], 1, fz=fz, fs=1000.0, substeps=1, definition="peak_bin", bin_s=0.0)
