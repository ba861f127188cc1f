"""Keyed variability of the current stage: each unit's tonic spread, each trial's excitability, start phases.

Every draw comes from the counter-based streams of `ddmm.models.rng`, keyed
by what it belongs to (the unit alone, or seed, condition, trial and
afferent), so every engine, chunking and process draws the same numbers.
The receptor noise itself is drawn by the population runtime and applied in
the stage (`ddmm.models.fused`; the oracle's `ddmm.models.reference_pipeline.current_core`).
"""

from __future__ import annotations

import numpy as np

from ddmm.models.current_params import TypeCurrentParams

__all__ = ["BIAS_KEY", "EXCITE_SAMPLE", "PHASE_TAG", "bias_multiplier", "excitability", "initial_phase",
           "tonic_current"]

#: Key of the per-unit draws of the tonic current's spread (`bias_multiplier`): a fixed key, so the
#: spread is a property of the unit, not of a run's seed.
BIAS_KEY = 0x5A11_B1A5_0000_0001
#: Tag mixed into a stream key for the initial phase (`initial_phase`): a stream of its own.
PHASE_TAG = 0x9E37_79B9_7F4A_7C15


def bias_multiplier(bias_cv: float, afferent_id) -> np.ndarray:
    """Per-unit lognormal multiplier of the tonic current, mean 1 and CV ``bias_cv``, keyed by afferent id.

    Examples
    --------
    >>> m = bias_multiplier(0.4, np.arange(2000))
    >>> bool(0.35 < m.std() < 0.45), bool(np.all(bias_multiplier(0.0, [3, 4]) == 1.0))
    (True, True)
    """
    ids = np.ascontiguousarray(np.atleast_1d(afferent_id), dtype=np.int64)
    if bias_cv == 0.0:
        return np.ones(ids.size)
    from ddmm.models.rng import normals

    s2 = float(np.log1p(bias_cv * bias_cv))
    return np.exp(np.sqrt(s2) * normals(BIAS_KEY, ids, 0, 1)[:, 0] - s2 / 2.0)


def tonic_current(stage: TypeCurrentParams, afferent_id, m: int):
    """Each afferent's tonic current (mV/ms): ``stage.bias``, times `bias_multiplier` when spread."""
    if stage.bias_cv == 0.0 or afferent_id is None:
        return np.full(m, stage.bias)
    return stage.bias * bias_multiplier(stage.bias_cv, afferent_id)


def initial_phase(key: int, afferent_id) -> np.ndarray:
    """Uniform draws in [0, 1) keyed by (stream ``key``, afferent id): the start phase of each tonic neuron."""
    from math import erf, sqrt

    from ddmm.models.rng import normals

    ids = np.ascontiguousarray(np.atleast_1d(afferent_id), dtype=np.int64)
    z = normals(np.uint64(key) ^ np.uint64(PHASE_TAG), ids, 0, 1)[:, 0]
    return np.array([min(0.5 * (1.0 + erf(v / sqrt(2.0))), np.nextafter(1.0, 0.0)) for v in z])


#: The counter (sample index) of the per-trial excitability draw: no scene reaches 2**32 - 1 samples.
EXCITE_SAMPLE = 0xFFFFFFFF


def excitability(key, afferent_id, cv) -> np.ndarray:
    """Per-trial excitability factors: lognormal, mean 1, coefficient of variation ``cv`` (per afferent).

    ``exp(s z - s^2 / 2)`` with ``s^2 = log(1 + cv^2)`` and ``z`` the
    standard normal of (trial key ``key``, afferent id, sample
    `EXCITE_SAMPLE`) (`ddmm.models.rng.normal`): a pure function of
    (seed, condition, trial, afferent), so every chunking, engine and
    process draws the same factor.

    Examples
    --------
    >>> from ddmm.models.rng import stream_key
    >>> e = excitability(stream_key(0, 0, 0), [3, 4], [0.0, 0.2])
    >>> float(e[0]), bool(e[1] != 1.0)
    (1.0, True)
    """
    from ddmm.models.rng import normals

    cv = np.asarray(cv, dtype=float)
    s = np.sqrt(np.log1p(cv * cv))
    z = normals(int(key), np.asarray(afferent_id, dtype=np.int64), EXCITE_SAMPLE, 1)[:, 0]
    return np.exp(s * z - 0.5 * s * s)
