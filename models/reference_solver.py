"""A reference solver: fine-step RK4 with exact threshold crossings.

Between current samples the input is constant, so eqs 4-5 are a smooth
autonomous ODE there.  The solver takes classical RK4 steps of ``dt_ref``
aligned to the sample boundaries; when a step ends at ``v >= 30`` it locates
the crossing inside the step with the cubic Hermite interpolant built from
the values and derivatives at both ends (fourth-order accurate, like the
step), records the spike at that time, resets ``v = c, u = u(t*) + d`` there
and integrates the rest of the step (after an absolute refractory period
``t_ref`` with v held at c and u relaxing exactly, when there is one).  Unlike the grid methods, spike times
are continuous.  ``tests/models/test_reference.py`` checks it against
`scipy.integrate.solve_ivp` with event detection.
"""

from __future__ import annotations

from typing import NamedTuple

import numba as nb
import numpy as np

from ddmm.models.neuron import V_PEAK
from ddmm.utils.validation import shown

__all__ = ["reference_spike_times"]


class ReferenceCell(NamedTuple):
    """One neuron's constants for the reference solver's kernels (eqs 4-6).

    Attributes
    ----------
    a : float
        Recovery rate (1/ms).
    b : float
        Sensitivity of u to v (dimensionless).
    c : float
        Reset potential (mV).
    d : float
        Reset increment of u (mV/ms).
    t_ref : float
        Absolute refractory period (ms): v held at c after a spike.
    v_peak : float
        Spike cut-off (mV).
    """

    a: float
    b: float
    c: float
    d: float
    t_ref: float
    v_peak: float


@nb.njit(cache=True, inline="always")
def _f(v, u, i, a, b):
    return 0.04 * v * v + 5.0 * v + 140.0 - u + i, a * (b * v - u)


@nb.njit(cache=True)
def _rk4(v, u, i, a, b, h):
    k1v, k1u = _f(v, u, i, a, b)
    k2v, k2u = _f(v + 0.5 * h * k1v, u + 0.5 * h * k1u, i, a, b)
    k3v, k3u = _f(v + 0.5 * h * k2v, u + 0.5 * h * k2u, i, a, b)
    k4v, k4u = _f(v + h * k3v, u + h * k3u, i, a, b)
    return v + h / 6.0 * (k1v + 2 * k2v + 2 * k3v + k4v), u + h / 6.0 * (k1u + 2 * k2u + 2 * k3u + k4u)


@nb.njit(cache=True, inline="always")
def _hermite(y0, y1, d0, d1, h, s):
    s2, s3 = s * s, s * s * s
    return (2 * s3 - 3 * s2 + 1) * y0 + (s3 - 2 * s2 + s) * h * d0 + (-2 * s3 + 3 * s2) * y1 + (s3 - s2) * h * d1


@nb.njit(cache=True)
def _crossing(v0, u0, v1, u1, i, a, b, h, v_peak):
    """Fraction s of the step at which the Hermite interpolant of v reaches v_peak, and u there."""
    d0v, d0u = _f(v0, u0, i, a, b)
    d1v, d1u = _f(v1, u1, i, a, b)
    lo, hi = 0.0, 1.0
    for _ in range(200):  # bisection to machine precision; the interpolant rises through v_peak
        mid = 0.5 * (lo + hi)
        if _hermite(v0, v1, d0v, d1v, h, mid) >= v_peak:
            hi = mid
        else:
            lo = mid
        if hi - lo < 1e-16:
            break
    return hi, _hermite(u0, u1, d0u, d1u, h, hi)


@nb.njit(cache=True)
def _hold(u, hold, remaining, a, b, c):
    """Spend up to ``remaining`` ms of an absolute refractory period: v stays at c, u relaxes exactly."""
    spent = min(hold, remaining)
    u = b * c + (u - b * c) * np.exp(-a * spent)  # du/dt = a (b c - u) with v = c
    return u, hold - spent, remaining - spent


@nb.njit(cache=True)
def _advance(v, u, hold, i, cell, h, t, out, n):
    """Integrate [t, t + h]: RK4, then split at every crossing and hold v for ``cell.t_ref`` ms after it.

    ``v``, ``u`` and ``hold`` (refractory time left in ms) are the state
    before, ``i`` the current and ``cell`` the neuron's `ReferenceCell`;
    spike times go to ``out`` from position ``n``.  Returns (v, u,
    refractory time left in ms, n).
    """
    a, b, c, d, t_ref, v_peak = cell
    remaining = h
    while remaining > 0.0:
        if hold > 0.0:
            u, hold, remaining = _hold(u, hold, remaining, a, b, c)
            if remaining <= 1e-15:
                return v, u, hold, n
        v1, u1 = _rk4(v, u, i, a, b, remaining)
        if not (v1 >= v_peak):
            return v1, u1, hold, n
        s, u_star = _crossing(v, u, v1, u1, i, a, b, remaining, v_peak)
        t_spike = t + (h - remaining) + s * remaining
        if n < out.size:
            out[n] = t_spike
        n += 1
        v, u, hold = c, u_star + d, t_ref
        remaining = remaining * (1.0 - s)
        if remaining < 1e-15:
            return v, u, hold, n
    return v, u, hold, n


@nb.njit(cache=True, nogil=True)
def _solve_one(current, sample_ms, steps, cell, v, u, out):
    """Spike times (ms) of one neuron from (``v``, ``u``) into ``out``; returns how many (may exceed its size)."""
    h = sample_ms / steps
    n, hold = 0, 0.0
    for k in range(current.size):
        for s in range(steps):
            t = k * sample_ms + s * h
            v, u, hold, n = _advance(v, u, hold, current[k], cell, h, t, out, n)
    return n


def reference_spike_times(current, fs: float, params: dict, v0, u0, *, dt_ref: float = 5e-6) -> list:
    """Spike times (s) of each neuron, continuous in time.

    Parameters
    ----------
    current : ndarray, shape (n_samples, n_neurons)
        Input current in mV/ms, held over each sample of ``1/fs`` s.
    fs : float
        Sample rate in Hz.
    params : dict of ndarray
        Per-neuron ``a``, ``b``, ``c``, ``d`` and optionally ``t_ref`` in s
        (see `ddmm.models.neuron.neuron_arrays`): after each spike v is
        held at c for ``t_ref`` exactly, while u relaxes.
    v0, u0 : ndarray
        Initial state in mV and mV/ms.
    dt_ref : float
        RK4 step in seconds (default 5 us); must divide ``1/fs``.

    Returns
    -------
    list of ndarray
        Spike times in seconds, one array per neuron.
    """
    current = np.ascontiguousarray(np.asarray(current, dtype=float).T)
    sample_ms = 1000.0 / fs
    steps = int(round((1.0 / fs) / dt_ref))
    if steps < 1 or abs(steps * dt_ref * fs - 1.0) > 1e-9:
        raise ValueError(f"dt_ref={shown(dt_ref)} s must divide the sample interval 1/fs = {shown(1.0 / fs)} s")
    t_ref_ms = 1000.0 * np.asarray(params.get("t_ref", np.zeros(current.shape[0])), dtype=float)
    times = []
    for j in range(current.shape[0]):
        cap = max(64, int(current.shape[1] * sample_ms))  # at most one spike per ms is generous here
        while True:
            out = np.empty(cap)
            cell = ReferenceCell(params["a"][j], params["b"][j], params["c"][j], params["d"][j], float(t_ref_ms[j]),
                                 V_PEAK)
            n = _solve_one(current[j], sample_ms, steps, cell, float(v0[j]), float(u0[j]), out)
            if n <= cap:
                break
            cap = n
        times.append(out[:n] / 1000.0)
    return times
