"""AF(t) and F_A (eqs 16-18): normalisation, both no-shear readings, hard geometry."""

import numpy as np
import pytest
from hypothesis import given
from hypothesis import strategies as st

from ddmm.models.attenuation import F_TH, attenuation_factor
from ddmm.models.reference_pipeline import attenuated_force

PROFILES = ["selective", "broad", "bipolar"]


@pytest.mark.parametrize("profile", PROFILES)
def test_af_is_one_when_aligned(profile):
    for theta in (0.0, 37.0, 90.0, 180.0, 271.0):
        rad = np.deg2rad(theta)
        af = attenuation_factor([np.cos(rad)], [np.sin(rad)], [theta], profile, 3.0)
        assert af[0, 0] == pytest.approx(1.0, abs=1e-12)


def test_af_values_at_known_angles():
    # theta_R = 90 deg (pure +Y push, F_X = 0 exactly); k = 3.
    af = attenuation_factor([0.0], [1.0], [75.0, 255.0, 0.0, 270.0], "selective", 3.0)
    np.testing.assert_allclose(af[0], [0.574, 0.163, 0.2, 0.2], atol=1e-3)
    af = attenuation_factor([0.0], [1.0], [75.0, 255.0], "broad", 3.0)
    np.testing.assert_allclose(af[0], [0.708 / 0.8667, 0.115 / 0.8667], atol=1e-3)


@pytest.mark.parametrize("fy", [1.0, -1.0])
def test_zero_fx_is_handled(fy):
    af = attenuation_factor([0.0], [fy], [90.0, 270.0], "bipolar", 3.0)
    np.testing.assert_allclose(af[0], [1.0, 1.0])


def test_threshold_readings():
    fx = np.array([0.0, F_TH, F_TH * (1 + 1e-12), F_TH * (1 - 1e-12), 1.0])
    fy = np.zeros_like(fx)
    passed = attenuation_factor(fx, fy, [180.0], "selective", 3.0, no_shear="pass")[:, 0]
    blocked = attenuation_factor(fx, fy, [180.0], "selective", 3.0, no_shear="block")[:, 0]
    # At or below F_TH: AF = 1 (eq. 17) or 0 (block); above it the geometry applies.
    np.testing.assert_array_equal(passed[[0, 1, 3]], 1.0)
    np.testing.assert_array_equal(blocked[[0, 1, 3]], 0.0)
    assert passed[2] == pytest.approx(0.2) and blocked[2] == pytest.approx(0.2)


def test_smooth_reading_is_a_c1_ramp_through_f_th():
    from ddmm.models.attenuation import transition_weight
    f_s = np.array([0.0, 0.05, 0.1, 0.15, 0.2, 0.5])
    af = attenuation_factor(np.zeros(6), f_s, [270.0], "selective", no_shear="smooth")[:, 0]
    w = transition_weight(f_s)
    np.testing.assert_allclose(w, [0.0, 0.15625, 0.5, 0.84375, 1.0, 1.0])
    np.testing.assert_allclose(af, 1.0 - 0.8 * w)  # opposed selective afferent: profile AF 0.2


@given(angle=st.floats(0, 360), theta=st.floats(0, 360), k=st.floats(1.8, 20.0),
       profile=st.sampled_from(PROFILES), mag=st.floats(0.0, 0.3))
def test_smooth_af_is_continuous_in_the_shear_vector(angle, theta, k, profile, mag):
    # A 1e-6 N change of the shear vector moves AF by a bounded amount, also through F_S = 0,
    # where eq. 17's step jumps by up to 0.8.
    rad = np.deg2rad(angle)
    fx, fy = mag * np.cos(rad), mag * np.sin(rad)
    a = attenuation_factor([fx, fx + 1e-6], [fy, fy - 1e-6], [theta], profile, k, no_shear="smooth")
    assert abs(a[1, 0] - a[0, 0]) < 1e-3


def test_stretch_drive_of_sa2_falls_against_its_preferred_direction():
    from ddmm.models.attenuation import profile_factor
    from ddmm.models.reference_pipeline import stretch_drive
    fx, fy = np.zeros(3), np.array([0.0, 1.0, -1.0])
    af = profile_factor(fx, fy, [90.0], "broad", 3.0)
    drive = stretch_drive(fx, fy, af, opponent=0.5)[:, 0]
    assert drive[0] == 0.0 and drive[1] == pytest.approx(1.0) and drive[2] < 0.0


def test_cmm_is_af_one():
    af = attenuation_factor([0.0, 3.0], [0.0, -2.0], [10.0, 200.0], "none")
    np.testing.assert_array_equal(af, 1.0)


@given(phi=st.floats(-np.pi, np.pi), k=st.floats(1.8, 1e6), profile=st.sampled_from(PROFILES))
def test_profile_radius_never_exceeds_its_tip(phi, k, profile):
    # The geometry itself, not the clip in the AF kernel (which binds only for k < 1):
    # for k >= 1 every profile's boundary is nearest the origin off its tip axis.
    from ddmm.models.nap import boundary_radius, tip_radius
    r = float(boundary_radius(np.sin(phi), np.cos(phi), profile, k)) / tip_radius(profile)
    assert 0.0 < r <= 1.0 + 1e-12


@given(angle=st.floats(0, 360), theta=st.floats(0, 360), k=st.floats(1.0, 50.0))
def test_bipolar_af_is_axial(angle, theta, k):
    rad = np.deg2rad(angle)
    a = attenuation_factor([np.cos(rad)], [np.sin(rad)], [theta], "bipolar", k)
    b = attenuation_factor([-np.cos(rad)], [-np.sin(rad)], [theta], "bipolar", k)
    assert a[0, 0] == pytest.approx(b[0, 0], rel=1e-9)


def test_wrapping_across_zero():
    a = attenuation_factor([1.0], [-1e-9], [359.999], "selective", 3.0)
    b = attenuation_factor([1.0], [1e-9], [0.001], "selective", 3.0)
    assert a[0, 0] == pytest.approx(b[0, 0], rel=1e-6)


def test_attenuated_force_is_eq18():
    af = np.array([[0.5, 1.0], [0.25, 0.0]])
    np.testing.assert_array_equal(attenuated_force([2.0, 4.0], af), [[1.0, 2.0], [1.0, 0.0]])


@pytest.mark.parametrize("kwargs,match", [
    (dict(fx=[np.nan], fy=[0.0]), "fx"),
    (dict(fx=[0.0], fy=[np.inf]), "fy"),
    (dict(fx=[0.0, 1.0], fy=[0.0]), "equal length"),
    (dict(fx=[0.0], fy=[0.0], profile="oval"), "profile"),
    (dict(fx=[0.0], fy=[0.0], no_shear="maybe"), "no_shear"),
    (dict(fx=[0.0], fy=[0.0], profile="broad", k=1.0), "k="),
    (dict(fx=[0.0], fy=[0.0], theta_t=[np.nan]), "theta_t"),
])
def test_bad_input(kwargs, match):
    args = dict(theta_t=[0.0], profile="selective", k=3.0)
    args.update(kwargs)
    with pytest.raises(ValueError, match=match):
        attenuation_factor(args.pop("fx"), args.pop("fy"), args.pop("theta_t"), args.pop("profile"),
                           args.pop("k"), **args)
