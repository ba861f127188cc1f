"""Per-afferent current-noise streams that do not depend on chunking.

Each (seed, condition, trial, afferent_id) owns one Philox stream whose
128-bit key *is* that tuple: Philox is counter-based, and distinct keys are
its designed way to give independent streams (Salmon et al. 2011, the
Random123 paper; NumPy's `~numpy.random.Philox`).  An afferent's noise is
therefore the same whichever chunk, worker or subset simulates it.

Noise is white and Gaussian, one draw per afferent and current sample of
length h = 1000/fs ms.  Two terms use it:

* additive, ``sigma * xi / sqrt(h)`` mV/ms: the voltage noise it causes over
  any interval is that of a Wiener process of intensity sigma
  (mV/sqrt(ms)), whatever the sample rate or integration step; it acts at
  rest too;
* drive-proportional (receptor noise), ``I * cv * xi / sqrt(h)``, applied by
  the current stage before the current's low-pass: an undriven afferent
  stays silent.
"""

from __future__ import annotations

import os
from concurrent.futures import ThreadPoolExecutor

import numpy as np

__all__ = ["MAX_AFFERENT_ID", "MAX_TRIALS", "MAX_CONDITIONS", "noise_streams", "draw_noise", "noise_current",
           "root_seed"]

MAX_AFFERENT_ID = 1 << 24
MAX_TRIALS = 1 << 20
MAX_CONDITIONS = 1 << 20
_POOL = ThreadPoolExecutor(max_workers=max(1, min(4, os.cpu_count() or 1)), thread_name_prefix="ddmm-noise")


def root_seed(seed) -> int:
    """A 63-bit integer seed from an int, a Generator or None (fresh entropy).

    Examples
    --------
    >>> root_seed(7)
    7
    """
    if seed is None:
        return int(np.random.SeedSequence().generate_state(1, np.uint64)[0] >> np.uint64(1))
    if isinstance(seed, np.random.Generator):
        return int(seed.integers(0, 2**63 - 1))
    if isinstance(seed, bool) or not isinstance(seed, (int, np.integer)) or not 0 <= seed < 2**63:
        raise TypeError(f"seed must be an int in [0, 2**63), a numpy Generator or None, got {seed!r}")
    return int(seed)


def _key(seed: int, condition: int, trial: int, afferent_id: int) -> int:
    if not (0 <= afferent_id < MAX_AFFERENT_ID and 0 <= trial < MAX_TRIALS and 0 <= condition < MAX_CONDITIONS):
        raise ValueError(
            f"noise streams support afferent ids < {MAX_AFFERENT_ID}, trials < {MAX_TRIALS} and "
            f"conditions < {MAX_CONDITIONS}; got {afferent_id}, {trial}, {condition}"
        )
    return (seed << 64) | (condition << 44) | (trial << 24) | afferent_id


def noise_streams(seed: int, condition: int, trial: int, afferent_ids) -> list:
    """One independent Generator per afferent for this condition and trial.

    Examples
    --------
    >>> a = noise_streams(1, 0, 0, [5, 6])
    >>> b = noise_streams(1, 0, 0, [6])
    >>> bool(a[1].standard_normal() == b[0].standard_normal())
    True
    """
    return [np.random.Generator(np.random.Philox(key=_key(seed, condition, trial, int(a)))) for a in afferent_ids]


def _fill(rows, streams):
    for row, gen in zip(rows, streams):
        gen.standard_normal(out=row)  # releases the GIL while filling


def draw_noise(streams, n_samples: int) -> np.ndarray:
    """The next ``n_samples`` standard normal draws per stream, shape (n, n_samples).

    Streams advance, so consecutive calls continue each afferent's sequence.
    Rows are filled on a small thread pool; each stream is used by one thread.
    """
    out = np.empty((len(streams), n_samples))
    parts = np.array_split(np.arange(len(streams)), _POOL._max_workers)
    list(_POOL.map(lambda p: _fill(out[p[0]:p[-1] + 1] if p.size else out[:0], streams[p[0]:p[-1] + 1] if p.size else []), parts))
    return out


def noise_current(normals, sigma, fs: float) -> np.ndarray:
    """Additive noise current (mV/ms), shape (n_samples, n), from draws of shape (n, n_samples).

    ``sigma * normal / sqrt(h)`` with h = 1000/fs ms.  The drive-proportional
    term (``noise_cv``) is applied inside the current stage
    (`models.currents.current_core`), before the current's low-pass; both use
    the afferent's one draw per sample.

    Examples
    --------
    >>> noise_current(np.ones((1, 2)), [2.0], 1000.0).ravel().tolist()
    [2.0, 2.0]
    """
    out = normals * (np.asarray(sigma, dtype=float) / np.sqrt(1000.0 / fs))[:, None]
    return out.T
