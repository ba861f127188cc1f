"""NAP geometry: closed-form radii against the table of docs/model.md §1.2 and a numerical ray scan."""

import numpy as np
import pytest
from hypothesis import given
from hypothesis import strategies as st

from ddmm.population.data.published import PAPER_RADII_K3
from ddmm.models.nap import PROFILES, boundary_radius, get_profile, k_from_selectivity, selectivity_from_k, tip_radius


def implicit(x, y, prof, k):
    """Left-hand side of eq. 9 with the tip on +Y."""
    return prof.p1 * (np.abs(k * x) + np.abs(prof.p2 * y - prof.p3) - prof.p4) - prof.p5 * y


def scanned_radius(phi, prof, k):
    """First sign change of eq. 9 along the ray, by brute force."""
    r = np.linspace(1e-7, 3.0, 600_001)
    f = implicit(r * np.sin(phi), r * np.cos(phi), prof, k)
    i = np.flatnonzero(np.sign(f[1:]) != np.sign(f[:-1]))[0]
    return r[i]


@pytest.mark.parametrize("name", ["bipolar", "selective", "broad"])
def test_radii_match_notes_table(name):
    phi = np.deg2rad(PAPER_RADII_K3["phi_deg"])
    got = boundary_radius(np.sin(phi), np.cos(phi), name, 3.0)
    np.testing.assert_allclose(got, PAPER_RADII_K3[name], atol=1e-3)


@pytest.mark.parametrize("name", ["bipolar", "selective", "broad"])
@pytest.mark.parametrize("k", [1.8, 3.0, 7.0])
def test_radii_match_numerical_scan(name, k):
    prof = PROFILES[name]
    for phi in np.deg2rad([0, 10, 37, 90, 133, 179, 180, 250]):
        exact = boundary_radius(np.sin(phi), np.cos(phi), prof, k)
        assert exact == pytest.approx(scanned_radius(phi, prof, k), abs=2e-5)


@given(phi=st.floats(-2 * np.pi, 2 * np.pi), k=st.floats(1.8, 1e6),
       name=st.sampled_from(["bipolar", "selective", "broad"]))
def test_radius_lies_on_the_boundary(phi, k, name):
    prof = PROFILES[name]
    r = boundary_radius(np.sin(phi), np.cos(phi), prof, k)
    assert np.isfinite(r) and r > 0
    residual = implicit(r * np.sin(phi), r * np.cos(phi), prof, k)
    assert abs(residual) < 1e-9 * max(1.0, k)


@given(phi=st.floats(0, 2 * np.pi), k=st.floats(1.0, 100.0))
def test_bipolar_radius_is_symmetric(phi, k):
    a = boundary_radius(np.sin(phi), np.cos(phi), "bipolar", k)
    b = boundary_radius(np.sin(phi + np.pi), np.cos(phi + np.pi), "bipolar", k)
    assert a == pytest.approx(b, rel=1e-12)


def test_tip_radii():
    assert tip_radius("bipolar") == 1.0
    assert tip_radius("selective") == 1.0
    assert tip_radius("broad") == pytest.approx(13 / 15)


def test_k_and_selectivity_are_inverse():
    for name in ("bipolar", "selective", "broad"):
        theta = np.array([20.0, 45.0, 90.0]) if name != "broad" else np.array([50.0, 90.0, 117.0])
        k = k_from_selectivity(theta, name)
        np.testing.assert_allclose(selectivity_from_k(k, name), theta)
    assert k_from_selectivity(90.0, "selective") == pytest.approx(1.0)
    assert k_from_selectivity(90.0, "broad") == pytest.approx(3.0)


@pytest.mark.parametrize("theta", [0.0, 180.0, -5.0, 200.0, np.nan])
def test_selectivity_outside_open_interval_is_rejected(theta):
    with pytest.raises(ValueError, match="theta_a"):
        k_from_selectivity(theta, "selective")


@pytest.mark.parametrize("name,k", [("selective", 0.0), ("bipolar", -1.0), ("broad", 1.79),
                                    ("selective", np.inf)])
def test_bad_k_is_rejected(name, k):
    with pytest.raises(ValueError, match="k="):
        boundary_radius(0.0, 1.0, name, k)


def test_unknown_profile_is_rejected():
    with pytest.raises(ValueError, match="profile='round'"):
        get_profile("round")
    with pytest.raises(TypeError, match="profile"):
        get_profile(3)
