"""SA-II's normal drive, tonic spread and start phases; SA-I's dynamic response and lasting fall (CurrentParams)."""

import numpy as np
import pytest

from ddmm.models._stage_kernels import dynamic_kernel
from ddmm.models.currents import CurrentParams, bias_multiplier, initial_phase
from ddmm.models.fused import AfferentColumns, FusedPipeline
from ddmm.models.neuron import resting_state
from ddmm.models.reference_pipeline import current_core, stretch_drive
from ddmm.population import load_spec

PHYSIO = load_spec("fingertip").current


@pytest.mark.parametrize("kind, field, value", [("SAII", "normal", -0.1), ("SAII", "bias_cv", float("nan")),
                                                ("SAII", "phase", 1.5), ("SAII", "phase", True),
                                                ("SAI", "dynamic", -1.0), ("SAI", "fall", 1.0),
                                                ("SAI", "tau_dynamic_s", 0.0)])
def test_bad_values_are_refused_naming_the_option(kind, field, value):
    with pytest.raises(ValueError, match=f"^{field} "):
        CurrentParams().with_type(kind, **{field: value})


def test_defaults_are_the_papers():
    sai, saii = CurrentParams().type_params("SAI"), CurrentParams().type_params("SAII")
    assert (saii.normal, saii.bias_cv, saii.phase, sai.dynamic, sai.fall) == (0.0, 0.0, 0.0, 0.0, 0.0)


def test_saii_drive_rises_with_normal_force():
    fz = np.array([0.0, 1.0, 4.0])
    zero = np.zeros(3)
    assert stretch_drive(zero, zero, np.ones((3, 1)), 0.5).ravel().tolist() == [0.0, 0.0, 0.0]
    assert stretch_drive(zero, zero, np.ones((3, 1)), 0.5, fz, 0.25).ravel().tolist() == [0.0, 0.25, 1.0]
    plan = FusedPipeline(AfferentColumns.filled(["SAII"]), PHYSIO, 1000.0, no_shear="smooth")
    current = plan.currents(np.column_stack([zero, zero, fz]).repeat(200, axis=0), plan.new_state(), False)
    assert current[399, 0] > current[199, 0] + 0.9 and current[-1, 0] > current[399, 0] + 2.5


def test_tonic_current_is_spread_by_unit_and_the_same_in_every_run():
    ids = np.arange(500)
    m = bias_multiplier(0.25, ids)
    assert np.array_equal(m, bias_multiplier(0.25, ids)) and 0.2 < m.std() < 0.3 and abs(m.mean() - 1.0) < 0.05
    assert np.array_equal(bias_multiplier(0.25, ids[::-1]), m[::-1])  # keyed by id, not by position
    plan = FusedPipeline(AfferentColumns.filled(["SAII"] * 4, afferent_id=np.arange(4)), PHYSIO, 1000.0,
                         no_shear="smooth")
    rest = plan.currents(np.zeros((5, 3)), plan.new_state(), False)[-1]
    saii = PHYSIO.type_params("SAII")
    np.testing.assert_array_equal(rest, saii.bias * bias_multiplier(saii.bias_cv, np.arange(4)))
    expected, _ = current_core(np.zeros((5, 4)), 1000.0, "SAII", PHYSIO, afferent_id=np.arange(4))
    np.testing.assert_array_equal(expected[-1], rest)


def test_start_phases_are_keyed_by_trial_and_afferent():
    types = ["SAII"] * 3 + ["SAI"]
    plan = FusedPipeline(AfferentColumns.filled(types, noise_sigma=0.5), PHYSIO, 1000.0, no_shear="smooth")
    v_rest, u_rest = resting_state(0.2)
    v, u = plan.initial_neuron(7, np.full(4, 0.2), np.full(4, 8.0), np.full(4, -65.0))
    assert np.all(v[:3] == -65.0) and v[3] == v_rest and u[3] == u_rest
    np.testing.assert_array_equal(u[:3], u_rest + 8.0 * initial_phase(7, np.arange(3)))
    assert len(set(u[:3].tolist())) == 3
    assert not np.array_equal(plan.initial_neuron(8, np.full(4, 0.2), np.full(4, 8.0), np.full(4, -65.0))[1], u)
    v0, u0 = plan.initial_neuron(None, np.full(4, 0.2), np.full(4, 8.0), np.full(4, -65.0))  # noise-free: at rest
    assert np.all(v0 == v_rest) and np.all(u0 == u_rest)


def _sai_current(params, force, n=3000, rise=100):
    fz = np.r_[np.linspace(0.0, force, rise), np.full(n - rise, force)]
    plan = FusedPipeline(AfferentColumns.filled(["SAI"]), params, 1000.0, no_shear="smooth")
    return plan.currents(np.column_stack([0 * fz, 0 * fz, fz]), plan.new_state(), False)[:, 0]


@pytest.mark.parametrize("force", [0.5, 8.0])
def test_sai_current_falls_by_a_fraction_through_a_hold_at_every_force(force):
    off = _sai_current(PHYSIO.with_type("SAI", dynamic=0.0, fall=0.0, transient=0.0), force)
    on = _sai_current(PHYSIO.with_type("SAI", transient=0.0), force)  # the fast transient has its own test
    fall_off = 1.0 - off[-500:].mean() / off[100:600].mean()
    fall_on = 1.0 - on[-500:].mean() / on[100:600].mean()
    assert fall_on > fall_off + 0.1  # the lasting fall adds a tenth or more at 0.5 N and at 8 N alike
    assert on[100:200].max() > off[100:200].max()  # and the overshoot in loading


def test_the_transient_is_a_band_pass_of_tau_times_the_slope():
    """On a ramp of slope a the two low-passes lag by a tau / 2 and a tau: ``transient (R - K)`` tends to
    ``transient a tau``; on a constant it tends to 0, on a falling ramp it adds nothing (rectified), and with
    ``transient`` 0 the form without it holds bit for bit."""
    fs, tau, a = 1000.0, 0.1, 5.0  # Hz, s, mV/ms per s
    x = a * np.arange(3000) / fs
    states = [np.zeros(1) for _ in range(3)]
    alphas = [float(-np.expm1(-1.0 / (fs * t))) for t in (1.0, tau, tau / 2)]
    out = dynamic_kernel(x[:, None].copy(), *states, *alphas, 0.0, 2.0, 0.0)[:, 0]
    assert out[-1] - x[-1] == pytest.approx(2.0 * a * tau, rel=0.02)
    flat = dynamic_kernel(np.full((3000, 1), 7.0), *[np.zeros(1) for _ in range(3)], *alphas, 0.0, 2.0, 0.0)
    assert flat[-1, 0] == pytest.approx(7.0, rel=1e-9)
    falling = x[::-1].copy()  # unloading: rectified, the transient takes nothing away
    states = [np.full(1, falling[0]) for _ in range(3)]
    np.testing.assert_array_equal(dynamic_kernel(falling[:, None].copy(), *states, *alphas, 0.0, 2.0, 0.0)[:, 0],
                                  falling)
    none = dynamic_kernel(x[:, None].copy(), *[np.zeros(1) for _ in range(3)], *alphas, 0.1, 0.0, 0.2)[:, 0]
    c, plain = 0.0, []
    for value in x:  # the form without the transient, written out
        c = c + alphas[0] * (value - c)
        plain.append(max((value + 0.1 * (value - c)) - 0.2 * c, 0.0))
    np.testing.assert_array_equal(none, plain)


def test_the_transient_raises_fast_loading_and_leaves_the_plateau():
    off = _sai_current(PHYSIO.with_type("SAI", transient=0.0), 4.0, rise=130)
    on = _sai_current(PHYSIO, 4.0, rise=130)
    assert on[:130].max() > 1.3 * off[:130].max()  # a 30 N/s ramp: the transient's peak
    # gone within a few tau of the hold, but for tau times the slope of the hold's own slow fall (< 0.5%)
    np.testing.assert_allclose(on[-500:], off[-500:], rtol=5e-3)


@pytest.mark.parametrize(("name", "value", "message"), [
    ("transient", -1.0, r"^transient must be a finite number >= 0, got -1\.0"),
    ("transient", float("nan"), r"^transient must be a finite number >= 0, got nan"),
    ("tau_transient_s", 0.0, r"^tau_transient_s must be a finite number > 0, got 0\.0"),
])
def test_bad_transient_is_refused(name, value, message):
    with pytest.raises(ValueError, match=message):
        CurrentParams().with_type("SAI", **{name: value})
