"""Type-specific current stages: filters, adaptation, transducers, receptor noise, smoothing, SA-II."""

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from ddmm.models.currents import CurrentParams, check_fs
from ddmm.models.reference_pipeline import afferent_current, current_core
from ddmm.population import load_spec

FS = 1000.0
#: The physiological stages of the presets (population/presets/fingertip.toml).
PHYSIO = load_spec("fingertip").current
TYPES = ("SAI", "RAI", "RAII", "SAII")


def ramp_hold(rate_n_s=10.0, peak=4.0, hold_s=2.0):
    ramp = np.arange(0.0, peak, rate_n_s / FS)
    return np.r_[np.zeros(100), ramp, np.full(int(hold_s * FS), peak), ramp[::-1], np.zeros(300)][:, None]


def test_paper_stage_is_the_default():
    # The defaults are eqs 1-3 verbatim: SAI = g |F|, with no filter and its state at rest.
    f = np.linspace(0.0, 2.0, 50)[:, None]
    i, state = afferent_current(f, FS, "SAI")
    np.testing.assert_array_equal(i, CurrentParams().type_params("SAI").gain * f)
    assert not state.any()


@pytest.mark.parametrize("kind", TYPES)
def test_zero_force_gives_bias_only(kind):
    i, _ = afferent_current(np.zeros((500, 3)), FS, kind, PHYSIO)
    np.testing.assert_array_equal(i, PHYSIO.type_params("SAII").bias if kind == "SAII" else 0.0)


@settings(max_examples=30, deadline=None)
@given(seed=st.integers(0, 2**32 - 1), scale=st.floats(0.01, 1e4), cv=st.floats(0.0, 3.0),
       kind=st.sampled_from(("SAI", "RAI", "RAII")))
def test_transducer_bound_holds_with_receptor_noise(seed, scale, cv, kind):
    rng = np.random.default_rng(seed)
    f = np.abs(rng.normal(size=(400, 4)).cumsum(axis=0)) * scale
    normals = rng.standard_normal((4, 400))
    i, _ = current_core(f, FS, kind, PHYSIO, None, None, normals, np.full(4, cv))
    params = PHYSIO.type_params(kind)
    bound = params.i_max
    if kind == "SAI":  # SA-I's dynamic response acts on the bounded current: I + dynamic (I - J) + transient (R - K),
        bound *= 1.0 + params.dynamic + params.transient  # J, K >= 0 and R <= the bound
    assert np.all(i >= 0.0) and np.all(i <= bound)


def test_receptor_noise_leaves_an_undriven_afferent_at_zero():
    normals = np.random.default_rng(0).standard_normal((2, 300))
    i, _ = current_core(np.zeros((300, 2)), FS, "RAI", PHYSIO, None, None, normals, np.full(2, 2.0))
    np.testing.assert_array_equal(i, 0.0)


@pytest.mark.parametrize("kind", TYPES)
def test_chunks_give_the_currents_of_the_whole_signal(kind):
    rng = np.random.default_rng(1)
    f = np.abs(rng.normal(size=(900, 3)).cumsum(axis=0)) * 0.05
    normals = rng.standard_normal((3, 900))
    cv = np.full(3, 0.5)
    whole, _ = current_core(f, FS, kind, PHYSIO, None, None, normals, cv)
    parts, state = [], None
    for a, b in ((0, 1), (1, 250), (250, 251), (251, 900)):
        part, state = current_core(f[a:b], FS, kind, PHYSIO, state, None, normals[:, a:b], cv)
        parts.append(part)
    np.testing.assert_array_equal(np.concatenate(parts), whole)


def test_sa1_adapts_through_a_hold_and_is_silent_on_release():
    f = ramp_hold()
    i, _ = afferent_current(f, FS, "SAI", PHYSIO)
    hold = slice(100 + 400, 100 + 400 + 2000)
    early, late = i[hold][:500].mean(), i[hold][-500:].mean()
    assert late < 0.9 * early  # decays through the hold (tau 0.5 s); without adaptation late == early
    up, down = i[100 + 200, 0], i[100 + 400 + 2000 + 200, 0]  # both at 2 N, loading and unloading
    assert down < 0.5 * up  # the adaptation undershoots on release: SA-I fall silent early
    assert i[100 + 400 + 2000 + 450:].max() < 1e-3 * late  # rectified: the undershoot never excites


def test_ra1_adapts_to_a_sustained_velocity_and_ignores_slow_changes():
    slow, _ = afferent_current(ramp_hold(rate_n_s=0.6), FS, "RAI", PHYSIO)
    assert slow.max() == 0.0  # 0.6 N/s is inside the median unit's 0.75 N/s dead zone
    fast, _ = afferent_current(ramp_hold(rate_n_s=10.0), FS, "RAI", PHYSIO)
    ramp = fast[100:500, 0]
    assert ramp[300:].mean() < 0.6 * ramp[50:150].mean()  # adapts during a constant-velocity ramp


def test_ra2_is_a_pacinian_band_pass():
    t = np.arange(5000) / 5000.0

    def response(freq):
        f = (1.0 + 0.001 * np.sin(2 * np.pi * freq * t))[:, None]
        i, _ = afferent_current(f, 5000.0, "RAII", PHYSIO.with_type("RAII", i_max=None))
        return i[2500:].mean()

    gains = {f: response(f) for f in (20.0, 100.0, 250.0, 600.0)}
    assert gains[100.0] > 10 * gains[20.0]  # acceleration: ~f^2 below the cut-off
    assert gains[250.0] > gains[100.0] and gains[250.0] > gains[600.0]


def test_a_scene_too_slow_for_ra2_is_refused():
    with pytest.raises(ValueError, match="too slow for RAII.*>= 750 Hz"):
        check_fs(500.0, PHYSIO)
    check_fs(1000.0, PHYSIO)
    with pytest.raises(ValueError, match="RAII"):
        afferent_current(np.zeros((10, 1)), 500.0, "RAII", PHYSIO)


def test_sa2_stretch_raises_and_lowers_the_tonic_current():
    drive = np.r_[np.zeros(200), np.full(800, 1.0), np.full(800, -0.5)][:, None]
    i, _ = afferent_current(drive, FS, "SAII", PHYSIO)
    bias = PHYSIO.type_params("SAII").bias
    assert i[150, 0] == bias
    assert i[900, 0] > bias + 3.0 and i[1700, 0] < bias - 1.0


@pytest.mark.parametrize("kind,field,value", [("RAI", "i_max", -1.0), ("SAI", "tau_s", 0.0), ("RAI", "adapt", -0.1),
                                              ("RAI", "threshold", np.nan), ("RAII", "order", 9),
                                              ("RAII", "cutoff_hz", 0.0), ("RAI", "negative_weight", 1.5),
                                              ("RAII", "negative_weight", -0.1), ("RAI", "negative_weight", np.nan)])
def test_bad_stage_parameters_are_named(kind, field, value):
    with pytest.raises(ValueError, match=f"^{field} "):
        CurrentParams().with_type(kind, **{field: value})


@pytest.mark.parametrize("kind", ["RAI", "RAII"])
def test_the_negative_half_wave_is_weighted(kind):
    """Half-wave drive: loading as the paper's |x|, unloading scaled by negative_weight (1.0: the paper's)."""
    t = np.arange(2000) / FS
    f = (0.5 + 0.4 * np.sin(2 * np.pi * 10.0 * t))[:, None]
    paper, _ = afferent_current(f, FS, kind, CurrentParams())
    assert np.all(paper >= 0.0)
    for w in (0.0, 0.25):
        half, _ = afferent_current(f, FS, kind, CurrentParams().with_type(kind, negative_weight=w))
        signed = np.sign(_signed_derivative(f, kind))
        assert (signed < 0).sum() > 500 and (signed > 0).sum() > 500
        np.testing.assert_allclose(half[signed > 0, 0], paper[signed > 0, 0], rtol=1e-9, atol=1e-9)
        np.testing.assert_allclose(half[signed < 0, 0], w * paper[signed < 0, 0], rtol=1e-9, atol=1e-9)


def _signed_derivative(f, kind):
    """The filtered derivative of the paper's stage with its sign (x 1: no rectification), per sample."""
    from ddmm.models.reference_pipeline import filter_force
    y, _ = filter_force(f, FS, CurrentParams())
    d = np.diff(np.r_[y[:1], y], axis=0) * FS
    return (d if kind == "RAI" else np.diff(np.r_[d[:1], d], axis=0) * FS)[:, 0]


@settings(max_examples=40, deadline=None)
@given(seed=st.integers(0, 2**32 - 1), kind=st.sampled_from(("SAI", "RAI", "RAII")), excited=st.booleans(),
       live=st.lists(st.booleans(), min_size=1, max_size=60), lo=st.integers(0, 3), width=st.integers(1, 6))
def test_fused_transducer_equals_the_stage_transducer(seed, kind, excited, live, lo, width):
    # `transduce_columns` (the fused pipeline's) against `transduce_inplace` (the stages'), bit for bit, on
    # columns lo..lo+width of a drive whose rows are zero or not in any pattern (it skips all-zero rows).
    from ddmm.models._transducer_kernels import transduce_columns, transduce_inplace
    from ddmm.models.currents import type_filter_constants

    rng = np.random.default_rng(seed)
    stage = type_filter_constants(PHYSIO, kind, FS)[0]
    drive = np.abs(rng.normal(0.0, 50.0, (len(live), 10))) * np.asarray(live)[:, None]  # unsigned drive: >= 0
    drive[rng.random(drive.shape) < 0.1] = -0.0
    excite = rng.uniform(0.5, 1.5, width) if excited else None
    cols = slice(lo, lo + width)
    want = drive.copy()
    transduce_inplace(want[:, cols], stage, excite)
    got = transduce_columns(drive.copy(), cols, stage, excite)
    np.testing.assert_array_equal(got.view(np.int64), want.view(np.int64))


def test_fused_transducer_refuses_a_signed_stage():
    from ddmm.models._transducer_kernels import transduce_columns
    from ddmm.models.currents import type_filter_constants

    with pytest.raises(ValueError, match="unsigned"):
        transduce_columns(np.zeros((3, 2)), slice(0, 2), type_filter_constants(PHYSIO, "SAII", FS)[0])
