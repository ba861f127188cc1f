"""Currents (eqs 1-3): analytic ramps, causality, chunking, rectification, bad input."""

import numpy as np
import pytest
from hypothesis import given
from hypothesis import strategies as st

from ddmm.models.currents import CurrentParams, lowpass_sos
from ddmm.models.reference_pipeline import afferent_current

FS = 1000.0
UNIT = CurrentParams().with_type("SAI", gain=1.0).with_type("RAI", gain=1.0).with_type("RAII", gain=1.0)


def test_sai_follows_force():
    f = np.array([[0.0], [1.5], [3.0]])
    i, state = afferent_current(f, FS, "SAI", CurrentParams().with_type("SAI", gain=2.0))
    np.testing.assert_array_equal(i[:, 0], [0.0, 3.0, 6.0])
    assert not state.any()  # the unfiltered stage keeps nothing: its state stays at rest


def test_rai_of_a_ramp_settles_to_its_slope():
    f = (np.arange(2000) / FS * 2.5)[:, None]  # 2.5 N/s
    i, _ = afferent_current(f, FS, "RAI", UNIT)
    assert i[-1, 0] == pytest.approx(2.5, rel=1e-6)


def test_raii_of_a_parabola_settles_to_its_acceleration():
    t = np.arange(3000) / FS
    f = (0.5 * 4.0 * t**2)[:, None]  # 4 N/s^2
    i, _ = afferent_current(f, FS, "RAII", UNIT)
    assert i[-1, 0] == pytest.approx(4.0, rel=1e-4)


def test_derivatives_are_rectified():
    t = np.arange(2000) / FS
    up, _ = afferent_current((3.0 * t)[:, None], FS, "RAI", UNIT)
    down, _ = afferent_current((6.0 - 3.0 * t)[:, None], FS, "RAI", UNIT)
    np.testing.assert_allclose(up, down, atol=1e-9)
    assert np.all(up >= 0)


def test_constant_force_gives_zero_dynamic_current():
    f = np.full((500, 2), 3.0)
    for kind in ("RAI", "RAII"):
        i, _ = afferent_current(f, FS, kind, UNIT)
        np.testing.assert_array_equal(i, 0.0)  # exact: the filter runs on the deviation


def test_filter_is_causal():
    f = np.zeros((400, 1))
    f[200:] = 1.0
    i, _ = afferent_current(f, FS, "RAI", UNIT)
    assert np.all(i[:200] == 0.0) and i[201:].max() > 0


@given(cuts=st.lists(st.integers(1, 299), max_size=6, unique=True),
       kind=st.sampled_from(["RAI", "RAII"]))
def test_chunked_currents_equal_whole(cuts, kind):
    rng = np.random.default_rng(1)
    f = np.cumsum(rng.normal(size=(300, 3)), axis=0) ** 2
    whole, _ = afferent_current(f, FS, kind)
    parts, state = [], None
    for a, b in zip([0] + sorted(cuts), sorted(cuts) + [300]):
        part, state = afferent_current(f[a:b], FS, kind, state=state)  # None: at rest on the first sample
        parts.append(part)
    np.testing.assert_array_equal(np.vstack(parts), whole)


def test_transducer_option_is_linear_for_small_drive():
    f = (np.arange(2000) / FS * 0.01)[:, None]
    lin, _ = afferent_current(f, FS, "RAI", CurrentParams().with_type("RAI", gain=1.0))
    comp, _ = afferent_current(f, FS, "RAI", CurrentParams(i_sat=100.0).with_type("RAI", gain=1.0))
    np.testing.assert_allclose(comp, lin, rtol=1e-3)
    big = np.full((3, 1), 1e4)
    sat, _ = afferent_current(big, FS, "SAI", CurrentParams(i_sat=30.0))
    assert sat.max() < 300.0


@pytest.mark.parametrize("kind,kwargs,match", [
    ("SAI", {"gain": 0.0}, "^gain "), ("RAI", {"gain": -1.0}, "^gain "), (None, {"cutoff_hz": np.nan}, "cutoff_hz"),
    (None, {"filter_order": 0}, "filter_order"), (None, {"i_sat": -1.0}, "i_sat"),
])
def test_bad_params(kind, kwargs, match):
    """A shared field through the constructor, a type's through `CurrentParams.with_type`."""
    with pytest.raises(ValueError, match=match):
        CurrentParams(**kwargs) if kind is None else CurrentParams().with_type(kind, **kwargs)


def test_bad_rates_and_types():
    with pytest.raises(ValueError, match="fs"):
        afferent_current(np.zeros((3, 1)), 0.0, "SAI")
    with pytest.raises(ValueError, match="fs"):
        afferent_current(np.zeros((3, 1)), -5.0, "RAI")
    with pytest.raises(ValueError, match="Nyquist"):
        lowpass_sos(20.0, 2, 30.0)
    with pytest.raises(ValueError, match="afferent_type"):
        afferent_current(np.zeros((3, 1)), FS, "SAIII")
    with pytest.raises(ValueError, match="f_a"):
        afferent_current(np.array([[np.nan]]), FS, "SAI")


def test_filter_kernel_matches_scipy_sosfilt():
    from scipy import signal

    from ddmm.models.reference_pipeline import filter_force, initial_filter_state
    rng = np.random.default_rng(0)
    f = rng.normal(size=(400, 5)).cumsum(axis=0)
    for order, cutoff in ((2, 20.0), (4, 35.0)):
        params = CurrentParams(cutoff_hz=cutoff, filter_order=order)
        sos = lowpass_sos(cutoff, order, FS)
        expected, _ = signal.sosfilt(sos, f - f[0], axis=0, zi=np.zeros((sos.shape[0], 2, 5)))
        got, _ = filter_force(f, FS, params, initial_filter_state(f[0], FS, params))
        np.testing.assert_array_equal(got, expected + f[0])  # filter_force returns deviation + offset
