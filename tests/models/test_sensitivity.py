"""Per-unit sensitivity in the current stage: a unit of sensitivity s sees the stimulus scaled by s."""

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from ddmm.models.currents import CurrentParams, unit_thresholds
from ddmm.models.reference_pipeline import afferent_current
from ddmm.population import load_spec

FS = 1000.0
PHYSIO = load_spec("fingertip").current  # FA-I with a dead zone, adaptation and a half-wave drive


def _press(n=600, peak=2.0):
    t = np.arange(n) / FS
    return (peak * np.clip(np.sin(np.pi * t / t[-1]) * 1.5, 0.0, 1.0))[:, None]


@pytest.mark.parametrize("kind", ["SAI", "RAI", "RAII"])
@pytest.mark.parametrize("s", [0.25, 0.5, 2.0, 4.0])
def test_a_unit_of_sensitivity_s_sees_the_stimulus_times_s(kind, s):
    """Powers of two scale every float exactly: the same bits, not only the same values."""
    params = (PHYSIO.with_type("SAI", i_max=None, i_sat=None).with_type("RAI", i_max=None)
              .with_type("RAII", i_max=None))
    f = _press()
    scaled, _ = afferent_current(f, FS, kind, params, sensitivity=np.array([s]))
    direct, _ = afferent_current(s * f, FS, kind, params)
    np.testing.assert_array_equal(scaled, direct)


def test_the_dead_zone_is_the_types_over_the_sensitivity():
    stage = PHYSIO.with_type("RAI", threshold=0.8).for_type("RAI")
    np.testing.assert_array_equal(unit_thresholds(stage, np.array([0.5, 1.0, 4.0]), 3), [1.6, 0.8, 0.2])
    np.testing.assert_array_equal(unit_thresholds(stage, None, 2), [0.8, 0.8])


def test_a_sensitive_unit_fires_at_a_slow_ramp_an_insensitive_one_does_not():
    """A 1 N/s ramp: below the median unit's dead zone (0.75 N/s after adaptation), above a unit of s = 4's."""
    f = np.clip((np.arange(3000) / FS - 0.5) * 1.0, 0.0, None)[:, None] * np.ones((1, 2))
    current, _ = afferent_current(f, FS, "RAI", PHYSIO, sensitivity=np.array([0.5, 4.0]))
    assert current[:, 0].max() == 0.0 and current[:, 1].max() > 1.0


def test_unit_sensitivity_is_the_paper_when_one():
    f = np.tile(_press(), (1, 3))
    one, _ = afferent_current(f, FS, "RAI", PHYSIO, sensitivity=np.ones(3))
    none, _ = afferent_current(f, FS, "RAI", PHYSIO)
    np.testing.assert_array_equal(one, none)


@pytest.mark.parametrize("bad", [[0.0], [-1.0], [np.nan], [1.0, 2.0]])
def test_bad_sensitivity_is_refused_naming_it(bad):
    with pytest.raises(ValueError, match="sensitivity"):
        afferent_current(_press(), FS, "RAI", PHYSIO, sensitivity=np.array(bad))


@settings(max_examples=25, deadline=None)
@given(s=st.floats(0.05, 20.0), rate=st.floats(0.2, 20.0))
def test_more_sensitive_units_never_get_less_current(s, rate):
    """Monotone in s: a larger sensitivity lowers the dead zone and raises the gain."""
    f = np.clip((np.arange(800) / FS - 0.1) * rate, 0.0, 2.0)[:, None] * np.ones((1, 2))
    current, _ = afferent_current(f, FS, "RAI", CurrentParams().with_type("RAI", gain=6.0, threshold=1.0, adapt=0.7),
                                  sensitivity=np.array([s, 1.5 * s]))
    assert np.all(current[:, 1] >= current[:, 0])
