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
def _euler_block(current, substeps, dt_ms, a, b, c, d, v, u, v_peak, j0, k_start, idx, stp, n):
    """Advance one block (local arrays a..u, columns j0.. of ``current``) from sample k_start.

    Spikes go to the fixed buffers ``idx``/``stp`` from position ``n``.  The
    buffers are never reallocated here (that would stop the update loop from
    vectorising); when one more sample could overflow them, the kernel
    returns early and the caller grows them and resumes.  Returns the sample
    to resume at (``n_samples`` when done) and the new fill level.
    """
    n_samples = current.shape[0]
    m = v.size
    for k in range(k_start, n_samples):
        if n + m * substeps > idx.size:
            return k, n
        row = current[k, j0 : j0 + m]
        for s in range(substeps):
            step = k * substeps + s
            for j in range(m):
                vj = v[j]
                uj = u[j]
                # Same association as Brian2's generated code (see module doc).
                u[j] = (dt_ms * (a[j] * ((b[j] * vj) - uj))) + uj
                v[j] = (dt_ms * ((140.0 + ((row[j] + (0.04 * (vj * vj))) + (5.0 * vj))) - uj)) + vj
            for j in range(m):
                if v[j] >= v_peak:
                    v[j] = c[j]
                    u[j] = u[j] + d[j]
                    idx[n] = j0 + j
                    stp[n] = step
                    n += 1
    return n_samples, n


@nb.njit(cache=True, nogil=True)
def _double(buf, n):
    out = np.empty(2 * buf.size, buf.dtype)
    out[:n] = buf[:n]
    return out


@nb.njit(cache=True, nogil=True)
def _integrate_range(current, substeps, dt_ms, a, b, c, d, v, u, v_peak, block, lo, hi):
    """Integrate neurons lo..hi (columns of the C-contiguous ``current``); return spikes."""
    capacity = max(4096, 4 * block * substeps)
    idx, stp, n = np.empty(capacity, np.int64), np.empty(capacity, np.int64), 0
    for j0 in range(lo, hi, block):
        j1 = min(hi, j0 + block)
        # Fresh local copies: LLVM can prove they do not alias and vectorises.
        ab, bb, cb, db = a[j0:j1].copy(), b[j0:j1].copy(), c[j0:j1].copy(), d[j0:j1].copy()
        vb, ub = v[j0:j1].copy(), u[j0:j1].copy()
        k = 0
        while k < current.shape[0]:
            k, n = _euler_block(current, substeps, dt_ms, ab, bb, cb, db, vb, ub, v_peak, j0, k, idx, stp, n)
            if k < current.shape[0]:  # buffers nearly full: double them and resume
                idx, stp = _double(idx, n), _double(stp, n)
        v[j0:j1] = vb
        u[j0:j1] = ub
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

    # The whole C-contiguous array goes to every thread (a column slice would
    # be strided and defeat vectorisation); each thread owns a column range.
    def work(lo, hi):
        return _integrate_range(current, substeps, dt_ms, *args, v, u, v_peak, _BLOCK, int(lo), int(hi))

    ranges = list(zip(bounds[:-1], bounds[1:]))
    if len(ranges) == 1:
        parts = [work(*ranges[0])]
    else:
        parts = list(_executor(threads).map(lambda r: work(*r), ranges))
    neuron = np.concatenate([p[0] for p in parts]) if parts else np.empty(0, np.int64)
    step = np.concatenate([p[1] for p in parts]) if parts else np.empty(0, np.int64)
    order = np.lexsort((neuron, step))
    return neuron[order], step[order]
