"""The reference solver against scipy's solve_ivp with event detection."""

import numpy as np
import pytest
from scipy.integrate import solve_ivp

from ddmm.models.neuron import neuron_arrays, resting_state
from ddmm.models.reference_solver import reference_spike_times


def ivp_spike_times(current, fs, a, b, c, d, v, u):
    """Piecewise-constant input: integrate each sample, restart after each threshold event."""
    width = 1000.0 / fs
    out = []

    def rhs(t, y, i):
        return [0.04 * y[0] ** 2 + 5 * y[0] + 140 - y[1] + i, a * (b * y[0] - y[1])]

    def threshold(t, y, i):
        return y[0] - 30.0
    threshold.terminal, threshold.direction = True, 1
    for k, i in enumerate(current):
        t0, t1, y = k * width, (k + 1) * width, [v, u]
        while True:
            sol = solve_ivp(rhs, (t0, t1), y, method="DOP853", rtol=1e-12, atol=1e-12, events=threshold, args=(i,))
            if sol.status != 1:
                y = sol.y[:, -1]
                break
            out.append(sol.t_events[0][0])
            y, t0 = [c, sol.y_events[0][0][1] + d], sol.t_events[0][0]
        v, u = y
    return np.array(out) / 1000.0


def test_reference_agrees_with_solve_ivp_to_1e_6_ms():
    rng = np.random.default_rng(1)
    current = np.repeat(rng.uniform(0, 40, (12, 3)), 5, axis=0)  # 60 ms, steps every 5 ms
    types = ["SAI", "RAI", "RAII"]
    p = neuron_arrays(types)
    v0, u0 = resting_state(p["b"])
    ref = reference_spike_times(current, 1000.0, p, v0, u0)
    for j in range(3):
        ivp = ivp_spike_times(current[:, j], 1000.0, p["a"][j], p["b"][j], p["c"][j], p["d"][j], v0[j], u0[j])
        assert ref[j].size == ivp.size > 3
        assert np.max(np.abs(ref[j] - ivp)) * 1e3 < 1e-6  # ms


def test_reference_bad_step():
    p = neuron_arrays(["SAI"])
    with pytest.raises(ValueError, match="dt_ref"):
        reference_spike_times(np.zeros((3, 1)), 1000.0, p, [-70.0], [-14.0], dt_ref=3e-4)


def test_refractory_hold_agrees_with_a_grid_engine_as_dt_shrinks():
    """With t_ref the reference holds v at c for exactly t_ref; the grid engines converge to it."""
    from ddmm.models.engines import integrate
    from ddmm.models.neuron import NeuronParams

    current = np.repeat([[60.0], [150.0], [20.0], [250.0]], 25, axis=0)  # 100 ms at 1 kHz
    neuron = {"RAII": NeuronParams(b=0.25, t_ref=0.002)}
    p = neuron_arrays(["RAII"], neuron)
    v0, u0 = resting_state(p["b"])
    ref = reference_spike_times(current, 1000.0, p, v0, u0, dt_ref=1e-6)[0]
    free = reference_spike_times(current, 1000.0, {**p, "t_ref": np.zeros(1)}, v0, u0, dt_ref=1e-6)[0]
    assert np.diff(ref).min() >= 0.002 and np.diff(free).min() < 0.002 and ref.size < free.size
    errors = []
    for dt in (1e-5, 2.5e-6):
        res = integrate(current, fs=1000.0, dt=dt, afferent_type="RAII", engine="direct", method="rk4",
                        neuron_params=neuron)
        assert res.time.size == ref.size
        errors.append(np.abs(res.time - ref).max())
    # first order: each spike time and each period start round to a step, and the offsets add up spike by spike
    assert errors[1] < errors[0] / 3 and errors[1] < 3e-5
