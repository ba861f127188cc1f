"""The direct engine: a numba integrator of eqs 4-6 that matches Brian2 bit for bit.

Each step follows the schedule of docs/model.md §3 exactly as Brian2 runs it:

1. the state is updated (forward Euler, Brian2's "rk2" midpoint and "rk4",
   or Izhikevich's 2003 scheme: two half-steps of v, then u from the new v);
2. v is floored at ``V_FLOOR`` (-100 mV; it stops strongly negative
   currents from driving Euler into false spiking at large dt, and it binds,
   changing the trajectory, whenever a negative current reaches it);
3. threshold ``v >= 30`` on the new v;
4. reset ``v = c; u = u + d`` and the spike is recorded at the step index.

The arithmetic is written in the same association order as the C++ that
Brian2 2.9 generates for `ddmm.models.engines.brian2.engine`'s equations (sympy's
canonical order, e.g. its rk updaters expand ``5 (v + k/2)`` into
``2.5 k + 5 v``), and both are compiled without fast-math or FMA
contraction, so the two engines give identical spikes, not merely close
ones.  ``tests/models/test_engines.py`` holds them to it for every method.

Neurons are processed in blocks with time as the outer loop, so the inner
loop over a block vectorises; blocks are shared between threads (numba
``nogil``), each thread owning a disjoint range of neurons.
"""

from __future__ import annotations

import math
import os
from typing import NamedTuple

import numba as nb
import numpy as np

from ddmm.models.neuron import V_FLOOR, V_PEAK, refractory_steps
from ddmm.utils.executors import shared_executor

__all__ = ["run_direct", "default_threads", "BLOCK", "PUSH_BLOCK", "METHOD_CODES", "NeuronTable", "Membrane", "neuron_table",
           "integrate_range", "integrate_span", "integrate_parts", "part_bounds", "spike_checks", "cap_scan"]

BLOCK = 64  # neurons advanced together; 64 doubles of v and u stay in L1
#: Neurons advanced together in a streaming push (`ddmm.models.engines.direct_fused.push_fused`): a push of a
#: sample or a few has no long time loop for a block's state to stay in L1 over, so a larger block only saves
#: per-block set-up (the hand's 1 ms push integrates in 0.09 ms against 0.14 ms with `BLOCK`, measured).
PUSH_BLOCK = 512
METHOD_CODES = {"euler": 0, "rk2": 1, "rk4": 2, "izhikevich2003": 3}


class NeuronTable(NamedTuple):
    """The integrator's constants for N neurons at one step and method (`neuron_table` builds it).

    Attributes
    ----------
    substeps : int
        Integration steps per current sample.
    method : int
        Scheme, a value of `METHOD_CODES`.
    h : float
        Step in ms (Brian2's dt/ms).
    half : float
        Half-step of the 2003 scheme in ms (Brian2's (0.5 dt)/ms).
    a : ndarray
        Recovery rate per neuron (1/ms).
    b : ndarray
        Sensitivity of u to v per neuron.
    c : ndarray
        Reset potential per neuron (mV).
    d : ndarray
        Reset increment of u per neuron (mV/ms).
    nr : ndarray
        Refractory steps per neuron (whole numbers as float64, `ddmm.models.neuron.refractory_steps`).
    v_peak : float
        Spike cut-off (mV).
    v_floor : float
        Lower bound on v after every step (mV).
    block : int
        Neurons advanced together (`BLOCK`).
    """

    substeps: int
    method: int
    h: float
    half: float
    a: np.ndarray
    b: np.ndarray
    c: np.ndarray
    d: np.ndarray
    nr: np.ndarray
    v_peak: float
    v_floor: float
    block: int


class Membrane(NamedTuple):
    """The state of N neurons, arrays of shape (n,) that the integrator updates in place.

    Attributes
    ----------
    v : ndarray
        Membrane potential (mV).
    u : ndarray
        Recovery variable (mV/ms).
    r : ndarray
        Refractory steps left (whole numbers as float64).
    """

    v: np.ndarray
    u: np.ndarray
    r: np.ndarray


def neuron_table(params, substeps, dt, method, v_peak=V_PEAK, v_floor=V_FLOOR) -> NeuronTable:
    """The `NeuronTable` of per-neuron ``params`` (``a``, ``b``, ``c``, ``d`` and optionally ``t_ref`` in s)
    at step ``dt`` (s) with ``method`` (a name of `METHOD_CODES`), ``substeps`` steps per sample.

    Examples
    --------
    >>> table = neuron_table({k: np.array([x]) for k, x in zip("abcd", (0.02, 0.2, -65.0, 8.0))}, 10, 1e-4, "rk4")
    >>> table.method, round(table.h, 12), table.nr.tolist()
    (2, 0.1, [0.0])
    """
    if method not in METHOD_CODES:  # validated at the seam; guard the kernel
        raise ValueError(f"method={method!r} is not implemented by the direct engine")
    h = 1.0 * dt / 0.001  # Brian2 computes dt/ms the same way
    half = (1.0 * (0.5 * dt)) / 0.001  # and the Izhikevich half-step as (0.5 dt)/ms
    nr = refractory_steps(params.get("t_ref", np.zeros(np.size(params["a"]))), dt)
    return NeuronTable(substeps, METHOD_CODES[method], h, half, params["a"], params["b"], params["c"], params["d"], nr,
                       v_peak, v_floor, BLOCK)


def default_threads() -> int:
    """Threads used by the direct engine: ``$DDMM_NUM_THREADS`` or all cores."""
    env = os.environ.get("DDMM_NUM_THREADS")
    if env:
        try:
            value = int(env)
        except ValueError:
            raise ValueError(f"DDMM_NUM_THREADS must be an integer, got {env!r}") from None
        if value < 1:
            raise ValueError(f"DDMM_NUM_THREADS must be >= 1, got {value}")
        return value
    return max(1, os.cpu_count() or 1)


@nb.njit(cache=True, nogil=True, inline="always")
def _dv(v, u, i):
    """dv/dt without dt, in Brian2's association: 140 + ((I + 0.04 v^2) + 5 v) - u."""
    return (140.0 + ((i + (0.04 * (v * v))) + (5.0 * v))) - u


@nb.njit(cache=True, nogil=True, inline="always")
def _dv_shifted(v, u, i, kv, ku, f):
    """dv/dt at (v + f kv, u + f ku) as Brian2's rk code expands it (f = 0.5 or 1)."""
    w = (f * kv) + v if f != 1.0 else kv + v
    shifted_u = (f * ku) + u if f != 1.0 else ku + u
    return (140.0 + (((i + ((5.0 * f) * kv)) + (5.0 * v)) + (0.04 * (w * w)))) - shifted_u


@nb.njit(cache=True, nogil=True, inline="always")
def _du_shifted(v, u, a, b, kv, ku, f):
    """du/dt at (v + f kv, u + f ku) as Brian2's rk code expands it (f = 0.5 or 1)."""
    if f != 1.0:
        return a * (((f * (-ku)) + (b * ((f * kv) + v))) - u)
    return a * (((-ku) + (b * (kv + v))) - u)


@nb.njit(cache=True, nogil=True)
def _update(method, h, half, row, a, b, v, u):
    """One step of the chosen scheme for every neuron of a block (Brian2's arithmetic)."""
    m = v.size
    if method == 0:  # forward Euler
        for j in range(m):
            vj, uj = v[j], u[j]
            u[j] = (h * (a[j] * ((b[j] * vj) - uj))) + uj
            v[j] = (h * _dv(vj, uj, row[j])) + vj
    elif method == 1:  # midpoint (Brian2 "rk2")
        for j in range(m):
            vj, uj, i = v[j], u[j], row[j]
            ku = h * (a[j] * ((b[j] * vj) - uj))
            kv = h * _dv(vj, uj, i)
            u[j] = (h * _du_shifted(vj, uj, a[j], b[j], kv, ku, 0.5)) + uj
            v[j] = (h * _dv_shifted(vj, uj, i, kv, ku, 0.5)) + vj
    elif method == 2:  # classical Runge-Kutta (Brian2 "rk4")
        for j in range(m):
            vj, uj, i, aj, bj = v[j], u[j], row[j], a[j], b[j]
            k1u = h * (aj * ((bj * vj) - uj))
            k1v = h * _dv(vj, uj, i)
            k2u = h * _du_shifted(vj, uj, aj, bj, k1v, k1u, 0.5)
            k2v = h * _dv_shifted(vj, uj, i, k1v, k1u, 0.5)
            k3u = h * _du_shifted(vj, uj, aj, bj, k2v, k2u, 0.5)
            k3v = h * _dv_shifted(vj, uj, i, k2v, k2u, 0.5)
            k4u = h * _du_shifted(vj, uj, aj, bj, k3v, k3u, 1.0)
            k4v = h * _dv_shifted(vj, uj, i, k3v, k3u, 1.0)
            sixth, third = 0.16666666666666666, 0.3333333333333333
            u[j] = ((((sixth * k1u) + (third * k2u)) + (third * k3u)) + (sixth * k4u)) + uj
            v[j] = ((((sixth * k1v) + (third * k2v)) + (third * k3v)) + (sixth * k4v)) + vj
    else:  # Izhikevich (2003): two half-steps of v, then u from the new v
        for j in range(m):
            vj, uj, i = v[j], u[j], row[j]
            vj = vj + half * _dv(vj, uj, i)
            vj = vj + half * _dv(vj, uj, i)
            v[j] = vj
            u[j] = uj + h * (a[j] * ((b[j] * vj) - uj))


@nb.njit(cache=True, nogil=True)
def _block(current, table, mem, j0, k_start, idx, stp, n, refractory):
    """Advance one block (``table``'s a..nr and ``mem`` local to it, columns j0.. of ``current``) from sample k_start.

    Each step: update (``method``), floor v at ``v_floor``, hold v at C while
    the refractory count ``r`` is positive (counting it down; only when
    ``refractory``, so blocks without it keep the plain loop), threshold,
    reset (``r`` to ``nr``).  Spikes go to the fixed buffers ``idx``/``stp``
    from position ``n``.  The buffers are never reallocated here (that would
    stop the update loop from vectorising); when one more sample could
    overflow them, the kernel returns early and the caller grows them and
    resumes.  Returns the sample to resume at (``n_samples`` when done) and
    the new fill level.
    """
    substeps, method, h, half, a, b, c, d, nr, v_peak, v_floor, _ = table
    v, u, r = mem
    n_samples = current.shape[0]
    m = v.size
    for k in range(k_start, n_samples):
        if n + m * substeps > idx.size:
            return k, n
        row = current[k, j0 : j0 + m]
        for s in range(substeps):
            step = k * substeps + s
            _update(method, h, half, row, a, b, v, u)
            if refractory:
                for j in range(m):
                    if v[j] < v_floor:
                        v[j] = v_floor
                    if r[j] > 0.5:  # Brian2: v held at c, r = clip(r - 1, 0, inf)
                        v[j] = c[j]
                        r[j] = r[j] - 1.0
                    if v[j] >= v_peak:
                        v[j] = c[j]
                        u[j] = u[j] + d[j]
                        r[j] = nr[j]
                        idx[n] = j0 + j
                        stp[n] = step
                        n += 1
                continue
            for j in range(m):
                if v[j] < v_floor:
                    v[j] = v_floor
                if v[j] >= v_peak:
                    v[j] = c[j]
                    u[j] = u[j] + d[j]
                    idx[n] = j0 + j
                    stp[n] = step
                    n += 1
    return n_samples, n


@nb.njit(cache=True, nogil=True)
def cap_scan(idx, stp, n_neurons):
    """(capped, ordered) in one pass: whether a neuron spiked on consecutive steps, and whether each
    neuron's spikes came in time order (both engines give them so; when not, ``capped`` means
    nothing and the caller sorts)."""
    last, capped, ordered = np.full(n_neurons, -2, np.int64), False, True
    for k in range(idx.size):
        if stp[k] == last[idx[k]] + 1:
            capped = True
        elif stp[k] <= last[idx[k]]:
            ordered = False
        last[idx[k]] = stp[k]
    return capped, ordered


@nb.njit(cache=True, nogil=True)
def spike_checks(idx, stp, v, u):
    """(finite, capped, ordered): whether ``v`` and ``u`` are finite, then `cap_scan`."""
    finite = True
    for j in range(v.size):
        if not (math.isfinite(v[j]) and math.isfinite(u[j])):
            finite = False
    capped, ordered = cap_scan(idx, stp, v.size)
    return finite, capped, ordered


@nb.njit(cache=True, nogil=True)
def _double(buf, n):
    out = np.empty(2 * buf.size, buf.dtype)
    out[:n] = buf[:n]
    return out


@nb.njit(cache=True, nogil=True)
def integrate_range(current, table, mem, lo, hi):
    """Integrate neurons lo..hi (columns of the C-contiguous ``current``) with the `NeuronTable` ``table``;
    return spikes.

    ``mem`` (`Membrane`) is updated in place: ``v``, ``u`` and ``r``, the
    refractory steps each neuron has left (`ddmm.models.neuron.refractory_steps`).
    Both may come as plain tuples (from Python: numba types them in C, a
    named tuple in Python).
    """
    return integrate_span(current, table, mem, mem, lo, hi)


@nb.njit(cache=True, nogil=True)
def integrate_span(current, table, source, mem, lo, hi):
    """`integrate_range` from the state ``source`` (a `Membrane`, left as it is unless it is ``mem``) into
    ``mem``: each block reads its neurons' state from ``source`` and writes it to ``mem``, so a caller
    that must keep the state before (a streaming push, committed only when it succeeds) copies nothing."""
    substeps, method, h, half, a, b, c, d, nr, v_peak, v_floor, block = table
    v0, u0, r0 = source
    v, u, r = mem
    capacity = max(4096, 4 * block * substeps)
    idx, stp, n = np.empty(capacity, np.int64), np.empty(capacity, np.int64), 0
    for j0 in range(lo, hi, block):
        j1 = min(hi, j0 + block)
        # Fresh local copies: LLVM can prove they do not alias and vectorises.
        ab, bb, cb, db = a[j0:j1].copy(), b[j0:j1].copy(), c[j0:j1].copy(), d[j0:j1].copy()
        vb, ub, nrb, rb = v0[j0:j1].copy(), u0[j0:j1].copy(), nr[j0:j1].copy(), r0[j0:j1].copy()
        refractory = False
        for j in range(j1 - j0):
            if nrb[j] > 0.0 or rb[j] > 0.0:
                refractory = True
        local = NeuronTable(substeps, method, h, half, ab, bb, cb, db, nrb, v_peak, v_floor, block)
        k = 0
        while k < current.shape[0]:
            k, n = _block(current, local, Membrane(vb, ub, rb), j0, k, idx, stp, n, refractory)
            if k < current.shape[0]:  # buffers nearly full: double them and resume
                idx, stp = _double(idx, n), _double(stp, n)
        v[j0:j1] = vb
        u[j0:j1] = ub
        r[j0:j1] = rb
    return idx[:n].copy(), stp[:n].copy()


@nb.njit(cache=True, nogil=True, parallel=True)
def integrate_parts(current, table, mem, bounds):
    """`integrate_range` on the column ranges ``bounds[p]..bounds[p+1]`` in parallel (numba threads).

    For a latency-bound caller (the streaming encoder's 1 ms chunk): one
    parallel region costs microseconds, where a Python thread hand-off
    costs more than it saves.  Ranges on block boundaries give the spikes
    of the serial call, concatenated range by range.
    """
    table, mem = NeuronTable(*table), Membrane(*mem)  # plain tuples from Python, named again
    n_parts = bounds.size - 1
    idx_parts = [np.empty(0, np.int64) for _ in range(n_parts)]
    stp_parts = [np.empty(0, np.int64) for _ in range(n_parts)]
    for p in nb.prange(n_parts):
        idx_parts[p], stp_parts[p] = integrate_range(current, table, mem, bounds[p], bounds[p + 1])
    return _concatenate(idx_parts), _concatenate(stp_parts)


@nb.njit(cache=True, nogil=True)
def _concatenate(parts):
    total = 0
    for part in parts:
        total += part.size
    out, n = np.empty(total, np.int64), 0
    for part in parts:
        out[n : n + part.size] = part
        n += part.size
    return out


def part_bounds(n_neurons: int, parts: int) -> np.ndarray:
    """``parts`` column ranges of about equal size on `BLOCK` boundaries (so no neuron changes block)."""
    bounds = np.linspace(0, n_neurons, min(parts, max(1, n_neurons // BLOCK)) + 1).astype(int)
    bounds = np.unique(np.minimum(n_neurons, (bounds + BLOCK - 1) // BLOCK * BLOCK))
    bounds[0] = 0
    return bounds.astype(np.int64)


def run_direct(current, substeps, dt, params, v, u, r=None, method="euler", v_peak=30.0, v_floor=-100.0,
               threads=None):
    """Integrate eqs 4-6 for N neurons with the direct engine.

    Parameters
    ----------
    current : ndarray, shape (n_samples, n_neurons), float64
        Input current in mV/ms, held for ``substeps`` steps per sample.
    substeps : int
        Integration steps per current sample.
    dt : float
        Step in seconds.
    params : dict of ndarray
        Per-neuron ``a``, ``b``, ``c``, ``d`` and optionally ``t_ref`` in
        seconds (see `ddmm.models.neuron`; no ``t_ref``: none).
    v, u : ndarray, shape (n_neurons,)
        Initial state in mV and mV/ms; updated in place to the final state.
    r : ndarray, shape (n_neurons,), optional
        Refractory steps left (whole numbers as float64; None: zeros);
        updated in place.
    method : {"euler", "rk2", "rk4", "izhikevich2003"}
        Integration scheme.
    v_peak : float
        Spike cut-off in mV.
    v_floor : float
        Lower bound on v in mV, applied after every step.
    threads : int, optional
        Worker threads; default `default_threads`.

    Returns
    -------
    neuron, step : ndarray of int64
        One entry per spike, sorted by step then neuron.
    """
    n_neurons = current.shape[1]
    table = tuple(neuron_table(params, substeps, dt, method, v_peak, v_floor))  # plain tuples: typed in C
    threads = default_threads() if threads is None else threads
    bounds = part_bounds(n_neurons, threads)  # a neuron's block never depends on threads
    mem = (v, u, np.zeros(n_neurons) if r is None else r)

    # The whole C-contiguous array goes to every thread (a column slice would
    # be strided and defeat vectorisation); each thread owns a column range.
    def work(lo, hi):
        return integrate_range(current, table, mem, int(lo), int(hi))

    ranges = list(zip(bounds[:-1], bounds[1:]))
    if len(ranges) == 1:
        parts = [work(*ranges[0])]
    else:
        parts = list(shared_executor("direct", threads).map(lambda r: work(*r), ranges))
    neuron = np.concatenate([p[0] for p in parts]) if parts else np.empty(0, np.int64)
    step = np.concatenate([p[1] for p in parts]) if parts else np.empty(0, np.int64)
    order = np.lexsort((neuron, step))
    return neuron[order], step[order]
