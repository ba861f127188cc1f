"""Current noise as a pure function of its key: independent of chunking, order, process and need.

The draw of afferent ``a`` at current sample ``n`` of trial ``t`` of
condition ``c`` under root seed ``s`` is ``ddmm.models.rng.normal(stream_key(s, c, t), a, n)``:
Philox-4x32-10 (Salmon et al. 2011, the Random123 paper), a counter-based
generator, keyed by the tuple, then a ziggurat.  So an afferent's noise is the
same whichever chunk, worker, subset or streaming encoder simulates it, and
a draw nobody needs (an undriven afferent's receptor noise) is never made.

Noise is white and Gaussian, one draw per afferent and current sample of
length h = 1000/fs ms.  Two terms use it:

* additive, ``sigma * xi / sqrt(h)`` mV/ms: the voltage noise it causes over
  any interval is that of a Wiener process of intensity sigma
  (mV/sqrt(ms)), whatever the sample rate or integration step; it acts at
  rest too;
* drive-proportional (receptor noise), ``I * cv * xi / sqrt(h)``, applied by
  the current stage before the current's low-pass: an undriven afferent
  stays silent.

A third term is drawn once per trial, not per sample: the trial
excitability (``excite_cv_<type>``, `ddmm.models.variability.excitability`),
the draw of sample ``ddmm.models.variability.EXCITE_SAMPLE`` (2**32 - 1) under
the same key.
"""

from __future__ import annotations

import numpy as np

from ddmm.models.rng import normals, stream_key
from ddmm.utils.validation import check_count

__all__ = ["noise_key", "draw_noise", "noise_current", "root_seed"]


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


def noise_key(seed: int, condition: int, trial: int) -> int:
    """The 64-bit stream key of one (root seed, condition, trial) (`ddmm.models.rng.stream_key`).

    Examples
    --------
    >>> noise_key(1, 0, 0) == noise_key(1, 0, 0) != noise_key(1, 0, 1)
    True
    """
    for name, value in (("seed", seed), ("condition", condition), ("trial", trial)):
        check_count(value, name, minimum=0)
    return stream_key(seed, condition, trial)


def draw_noise(key: int, afferent_ids, start: int, n_samples: int) -> np.ndarray:
    """Standard normals of samples ``start .. start + n_samples - 1``, shape (n_afferents, n_samples).

    A pure function: any split of samples or afferents gives the same values.

    Examples
    --------
    >>> k = noise_key(1, 0, 0)
    >>> bool(np.array_equal(draw_noise(k, [5, 6], 0, 4)[1, 2:], draw_noise(k, [6], 2, 2)[0]))
    True
    """
    ids = np.asarray(afferent_ids, dtype=np.int64)
    if ids.size and (ids.min() < 0):
        raise ValueError(f"afferent ids must be >= 0, got {int(ids.min())}")
    return normals(key, ids, start, n_samples)


def noise_current(normals_, sigma, fs: float) -> np.ndarray:
    """Additive noise current (mV/ms), shape (n_samples, n), from draws of shape (n, n_samples).

    ``sigma * normal / sqrt(h)`` with h = 1000/fs ms.  The drive-proportional
    term (``noise_cv``) is applied inside the current stage; both use the
    afferent's one draw per sample.

    Examples
    --------
    >>> noise_current(np.ones((1, 2)), [2.0], 1000.0).ravel().tolist()
    [2.0, 2.0]
    """
    out = normals_ * (np.asarray(sigma, dtype=float) / np.sqrt(1000.0 / fs))[:, None]
    return out.T
