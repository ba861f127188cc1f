"""The direct engine: a numba integrator of eqs 4-6 that matches Brian2 bit for bit.

Each step follows the schedule of DDMM-NOTES §3 exactly as Brian2 runs it:

1. u and v are both updated from the old (v, u) (forward Euler);
2. threshold ``v >= 30`` on the new v;
3. reset ``v = c; u = u + d`` and the spike is recorded at the step index.

The arithmetic is written in the same association order as the C++ that
Brian2 2.9 generates for `models.brian2_engine`'s equations (sympy's
canonical order), and both are compiled without fast-math or FMA
contraction, so the two engines give identical spikes, not merely close
ones.  ``tests/models/test_engines.py`` holds them to it.

Neurons are processed in blocks with time as the outer loop, so the inner
loop over a block vectorises; blocks are shared between threads (numba
``nogil``), each thread owning a disjoint range of neurons.
"""

from __future__ import annotations

import os
from concurrent.futures import ThreadPoolExecutor

import numba as nb
import numpy as np

__all__ = ["run_direct", "default_threads"]

_BLOCK = 64  # neurons advanced together; 64 doubles of v and u stay in L1
_METHOD_CODES = {"euler": 0}


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


@nb.njit(cache=True, nogil=True)
def _grow(buf, n):
    out = np.empty(max(16, 2 * buf.size), buf.dtype)
    out[:n] = buf[:n]
    return out


@nb.njit(cache=True, nogil=True)
def _euler_block(current, substeps, dt_ms, a, b, c, d, v, u, v_peak, j0, j1, idx, stp, n):
    """Advance neurons j0..j1 over all samples; append spikes to (idx, stp)."""
    n_samples = current.shape[0]
    for k in range(n_samples):
        for s in range(substeps):
            step = k * substeps + s
            for j in range(j0, j1):
                vj = v[j]
                uj = u[j]
                # Same association as Brian2's generated code (see module doc).
                u[j] = (dt_ms * (a[j] * ((b[j] * vj) - uj))) + uj
                v[j] = (dt_ms * ((140.0 + ((current[k, j] + (0.04 * (vj * vj))) + (5.0 * vj))) - uj)) + vj
            for j in range(j0, j1):
                if v[j] >= v_peak:
                    v[j] = c[j]
                    u[j] = u[j] + d[j]
                    if n == idx.size:
                        idx = _grow(idx, n)
                        stp = _grow(stp, n)
                    idx[n] = j
                    stp[n] = step
                    n += 1
    return idx, stp, n


@nb.njit(cache=True, nogil=True)
def _integrate_range(current, substeps, dt_ms, a, b, c, d, v, u, v_peak, block):
    """Integrate every neuron of the given column range; return spike arrays."""
    n_neurons = current.shape[1]
    idx = np.empty(1024, np.int64)
    stp = np.empty(1024, np.int64)
    n = 0
    for j0 in range(0, n_neurons, block):
        j1 = min(n_neurons, j0 + block)
        idx, stp, n = _euler_block(current, substeps, dt_ms, a, b, c, d, v, u, v_peak, j0, j1, idx, stp, n)
    return idx[:n].copy(), stp[:n].copy()


_EXECUTOR: ThreadPoolExecutor | None = None


def _executor(threads: int) -> ThreadPoolExecutor:
    global _EXECUTOR
    if _EXECUTOR is None or _EXECUTOR._max_workers != threads:
        _EXECUTOR = ThreadPoolExecutor(max_workers=threads, thread_name_prefix="ddmm-direct")
    return _EXECUTOR


def run_direct(current, substeps, dt, params, v, u, method="euler", v_peak=30.0, threads=None):
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
        Per-neuron ``a``, ``b``, ``c``, ``d`` (see `models.neuron`).
    v, u : ndarray, shape (n_neurons,)
        Initial state in mV and mV/ms; updated in place to the final state.
    method : str
        Integration scheme (``"euler"``).
    v_peak : float
        Spike cut-off in mV.
    threads : int, optional
        Worker threads; default `default_threads`.

    Returns
    -------
    neuron, step : ndarray of int64
        One entry per spike, sorted by step then neuron.
    """
    if method not in _METHOD_CODES:  # validated at the seam; guard the kernel
        raise ValueError(f"method={method!r} is not implemented by the direct engine")
    dt_ms = 1.0 * dt / 0.001  # Brian2 computes dt/ms the same way
    n_neurons = current.shape[1]
    threads = default_threads() if threads is None else threads
    bounds = np.linspace(0, n_neurons, min(threads, max(1, n_neurons // _BLOCK)) + 1).astype(int)
    # Keep ranges on block boundaries so a neuron's block never depends on threads.
    bounds = np.unique(np.minimum(n_neurons, (bounds + _BLOCK - 1) // _BLOCK * _BLOCK))
    bounds[0] = 0
    args = [params[p] for p in ("a", "b", "c", "d")]

    def work(lo, hi):
        sl = slice(lo, hi)
        idx, stp = _integrate_range(
            current[:, sl], substeps, dt_ms, *(x[sl] for x in args), v[sl], u[sl], v_peak, _BLOCK
        )
        return idx + lo, stp

    ranges = list(zip(bounds[:-1], bounds[1:]))
    if len(ranges) == 1:
        parts = [work(*ranges[0])]
    else:
        parts = list(_executor(threads).map(lambda r: work(*r), ranges))
    neuron = np.concatenate([p[0] for p in parts]) if parts else np.empty(0, np.int64)
    step = np.concatenate([p[1] for p in parts]) if parts else np.empty(0, np.int64)
    order = np.lexsort((neuron, step))
    return neuron[order], step[order]
