"""Hard numerical cases at the engine level, on both engines."""

import warnings

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from ddmm.models.engines import NumericalInstabilityError, SpikeCapWarning, integrate
from ddmm.models.neuron import V_FLOOR
from ddmm.models.pipeline import simulate_afferents
from tests.conftest import ENGINES

TYPES = ["SAI", "RAI", "RAII"]


@pytest.mark.parametrize("engine", ENGINES)
def test_strong_input_at_1ms_is_finite_and_warns_when_capped(engine):
    current = np.full((200, 3), 5e3)
    with pytest.warns(SpikeCapWarning, match="consecutive steps"):
        res = integrate(current, fs=1000.0, dt=1e-3, afferent_type=TYPES, engine=engine)
    assert np.all(np.isfinite(res.state.v)) and np.all(np.isfinite(res.state.u))
    assert res.counts(3).max() <= 200


@pytest.mark.parametrize("order", ["by_time", "by_neuron_descending_time"])
def test_cap_check_finds_consecutive_spikes_in_any_order(order):
    """`check_integration` scans in one pass when each neuron's spikes come in time order, and sorts when not."""
    from ddmm.models.engines import check_integration

    neuron, step = np.array([0, 1, 1, 2]), np.array([3, 7, 8, 20])
    if order != "by_time":
        neuron, step = neuron[::-1], step[::-1]
    state = np.zeros(3)
    with pytest.warns(SpikeCapWarning, match="1 neuron"):
        check_integration(neuron, step, state, state, np.zeros((1, 3)), "euler", 1e-4)
    with warnings.catch_warnings():
        warnings.simplefilter("error", SpikeCapWarning)
        check_integration(neuron[:2], step[:2], state, state, np.zeros((1, 3)), "euler", 1e-4)


@pytest.mark.parametrize("engine", ENGINES)
def test_moderate_input_does_not_warn(engine):
    with warnings.catch_warnings():
        warnings.simplefilter("error", SpikeCapWarning)
        integrate(np.full((300, 3), 15.0), fs=1000.0, dt=1e-4, afferent_type=TYPES, engine=engine)


@pytest.mark.parametrize("engine", ENGINES)
@pytest.mark.parametrize("current", [-30.0, -2e3])
def test_strongly_negative_current_cannot_make_euler_spike(engine, current):
    # Without the floor, Euler at 1 ms oscillates into 1/(2 dt) spiking for I << 0.
    res = integrate(np.full((500, 3), current), fs=1000.0, dt=1e-3, afferent_type=TYPES, engine=engine)
    assert res.afferent.size == 0
    assert np.all(res.state.v >= V_FLOOR)


@pytest.mark.parametrize("engine", ENGINES)
@pytest.mark.parametrize("method", ["rk2", "rk4", "izhikevich2003"])
def test_multistage_methods_refuse_unstable_negative_drive(engine, method):
    ok = integrate(np.full((300, 3), -30.0), fs=1000.0, dt=1e-3, afferent_type=TYPES, engine=engine, method=method)
    assert ok.afferent.size == 0 and np.all(ok.state.v >= V_FLOOR)
    with pytest.raises(NumericalInstabilityError, match="unstable for currents down to"):
        integrate(np.full((300, 3), -2e3), fs=1000.0, dt=1e-3, afferent_type=TYPES, engine=engine, method=method)


@pytest.mark.parametrize("engine", ENGINES)
@pytest.mark.parametrize("method", ["rk4", "izhikevich2003"])
def test_divergence_is_an_error_not_nan(engine, method):
    with pytest.raises(NumericalInstabilityError, match=f"method='{method}' diverged"):
        integrate(np.full((50, 1), 1e6), fs=1000.0, dt=1e-3, afferent_type="SAI", engine=engine, method=method)


@pytest.mark.parametrize("engine", ENGINES)
def test_step_discontinuity_impact(engine):
    fz = np.r_[np.zeros(100), np.full(400, 5.0)]
    zeros = np.zeros_like(fz)
    with pytest.warns(SpikeCapWarning):  # an impact drives RA afferents at the step rate: say so
        res = simulate_afferents(zeros, zeros, fz, fs=1000.0, afferent_type=TYPES, profile="none",
                                 theta_t=[0.0, 0.0, 0.0], engine=engine)
    counts = res.counts(3)
    assert np.all(counts > 0) and np.all(np.isfinite(res.state.v))
    assert res.step.min() >= 1000  # nothing before the impact


@pytest.mark.parametrize("engine", ENGINES)
def test_forces_of_1e4_newton(engine):
    n = 300
    fz = np.r_[np.linspace(0, 1e4, 100), np.full(n - 100, 1e4)]
    fy = 0.3 * fz
    with warnings.catch_warnings():
        warnings.simplefilter("ignore", SpikeCapWarning)  # the paper's linear currents saturate the neuron
        res = simulate_afferents(np.zeros(n), fy, fz, fs=1000.0, afferent_type=TYPES, profile="broad",
                                 theta_t=[90.0, 270.0, 0.0], k=1.8, engine=engine)
    assert np.all(np.isfinite(res.state.v)) and res.afferent.size > 0


@settings(max_examples=25, deadline=None)
@given(low=st.floats(0.0, 8.0), delta=st.floats(0.0, 8.0))
def test_sai_rate_non_decreasing_in_normal_force(low, delta):
    fz = np.array([low, low + delta])
    current = np.repeat(5.367 * fz[None, :], 400, axis=0)  # SAI.gain * F_A at fixed AF = 1
    counts = integrate(current, fs=1000.0, dt=1e-4, afferent_type="SAI", engine="direct").counts(2)
    assert counts[1] >= counts[0]


@pytest.mark.parametrize("engine", ENGINES)
@pytest.mark.parametrize("k", [1.8, 1e6])
def test_k_at_bounds(engine, k):
    n = 200
    fz = np.linspace(0, 4, n)
    res = simulate_afferents(np.zeros(n), 0.4 * fz, fz, fs=1000.0, afferent_type=["SAI"] * 2, profile="broad",
                             theta_t=[90.0, 0.0], k=k, engine=engine)
    assert np.all(np.isfinite(res.state.v))


def test_brian2_does_not_take_over_python_warnings():
    import logging
    import subprocess
    import sys
    code = ("import warnings; from ddmm.models.engines import prepare; prepare('brian2');"
            "import logging, brian2;"
            "w = warnings.catch_warnings(record=True); rec = w.__enter__(); warnings.simplefilter('always');"
            "warnings.warn('mine', UserWarning); print(len(rec), logging.getLogger('py.warnings').handlers == [] or 'captured')")
    out = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, check=True).stdout.split()
    assert out[0] == "1"
    assert logging.getLogger("brian2") is not None


def test_brian2_log_warnings_become_python_warnings():
    from ddmm.models.engines.brian2.engine import Brian2Warning, import_brian2
    import_brian2()
    import logging
    with pytest.warns(Brian2Warning, match="test message"):
        logging.getLogger("brian2.devices").warning("test message")
