"""Numba kernels of the current stage (`ddmm.models.currents`): filters, the stage's tail, receptor noise,
the dynamic response and the current's low-pass.

Kept apart so that `ddmm.models.currents` stays the readable definition of the
stages; these are the hot loops every stage runs through, offline and
streaming alike.  The transducers (log compression and saturation) are in
`ddmm.models._transducer_kernels`.
"""

from __future__ import annotations

from typing import NamedTuple

import numba as nb
import numpy as np

from ddmm.models.rng import normal_row

__all__ = ["TailState", "StageConstants", "UnitScales", "ReceptorNoise", "filter_sections", "stage_tail",
           "receptor_noise", "receptor_noise_keyed", "stage_kernel", "smooth_kernel", "dynamic_step", "dynamic_kernel"]


class TailState(NamedTuple):
    """The state `stage_tail` carries per afferent (arrays of shape (n_afferents,), updated in place).

    Attributes
    ----------
    offset : ndarray
        Force the filter runs on the deviation from (N; added back when ``order`` is 0).
    y1 : ndarray
        Previous filtered deviation (N).
    y2 : ndarray
        The one before (N).
    slow : ndarray
        Adaptation's slow average (the drive's units).
    """

    offset: np.ndarray
    y1: np.ndarray
    y2: np.ndarray
    slow: np.ndarray


class StageConstants(NamedTuple):
    """A type's scalar constants of the linear stage after the filter (`stage_tail`).

    Attributes
    ----------
    fs : float
        Sample rate (Hz).
    order : int
        Derivative order: 0 (the force), 1 or 2.
    adapt : float
        Adaptation depth (dimensionless; 0: none).
    alpha_adapt : float
        Adaptation's low-pass coefficient per sample.
    thresholded : bool
        Whether the dead zone is subtracted.
    negative : float
        Weight of a derivative's negative half-wave (1: absolute value, 0: half-wave).
    signed : bool
        Whether the drive keeps its sign (SA-II's stretch), else it is rectified.
    """

    fs: float
    order: int
    adapt: float
    alpha_adapt: float
    thresholded: bool
    negative: float
    signed: bool


class UnitScales(NamedTuple):
    """Per-afferent scales of the drive (arrays of shape (n_afferents,)).

    Attributes
    ----------
    gain : ndarray
        Stage gain times the afferent's scale and sensitivity.
    threshold : ndarray
        Dead zone in the drive's units (`ddmm.models.currents.unit_thresholds`).
    cv_scale : ndarray
        Receptor-noise intensity per sample (noise CV over sqrt(ms per sample)).
    """

    gain: np.ndarray
    threshold: np.ndarray
    cv_scale: np.ndarray


class ReceptorNoise(NamedTuple):
    """Receptor-noise draws given in advance (`stage_kernel`'s path; the fused path draws its own, keyed).

    Attributes
    ----------
    normals : ndarray
        Standard normal draws, shape (n_afferents, n_samples) (empty when not ``noisy``).
    noisy : bool
        Whether to apply them.
    """

    normals: np.ndarray
    noisy: bool


@nb.njit(cache=True, nogil=True, inline="always")
def filter_sections(cur, lo, hi, sos, g, n_sections, z):
    """Filter one sample of afferents ``lo..hi`` through the sections ``sos[g]``, in place on ``cur``.

    Direct form II transposed; section ``s``'s state is in rows ``2s`` and
    ``2s + 1`` of ``z`` (updated).  Sections are the outer loop so that the
    loop over afferents vectorises.
    """
    c = cur[lo:hi]  # views from 0: loops over range(lo, hi) vectorise worse
    for s in range(n_sections):
        b0, b1, b2, a1, a2 = sos[g, s, 0], sos[g, s, 1], sos[g, s, 2], sos[g, s, 4], sos[g, s, 5]
        z0, z1 = z[2 * s, lo:hi], z[2 * s + 1, lo:hi]
        for j in range(hi - lo):
            x = c[j]
            new = b0 * x + z0[j]
            z0[j] = b1 * x - a1 * new + z1[j]
            z1[j] = b2 * x - a2 * new
            c[j] = new


@nb.njit(cache=True, nogil=True, inline="always")
def stage_tail(x, lo, hi, state, stage, unit):
    """The drive d of afferents ``lo..hi`` from their filtered deviations ``x`` (newtons), in place on ``x``.

    ``state`` is the `TailState`, ``stage`` the type's `StageConstants` and
    ``unit`` the `UnitScales`: the derivative of ``order``, adaptation and
    ``gain`` (rectified unless ``signed``); the receptor noise comes after
    (`receptor_noise` with draws given, `receptor_noise_keyed` drawing its
    own).  ``threshold`` holds each afferent's dead zone in the drive's units
    (its type's threshold over its sensitivity), subtracted when
    ``thresholded``.  A derivative (``order`` > 0) is rectified with the
    weight ``negative`` on its negative half-wave (1.0: the absolute value,
    the paper's eqs 2-3; 0.0: half-wave rectification, which keeps the phase
    of a vibration); ``y1``, ``y2`` and ``slow`` are updated in place.  Each
    step is its own loop over afferents with its branches outside, so the
    loops vectorise (one loop with all the branches inside ran 10x slower).
    With `filter_sections`, the one implementation that `stage_kernel` and
    the fused streaming kernel (`ddmm.models.fused`) share, so both give the
    same bits.
    """
    _, order, adapt, alpha_adapt, thresholded, negative, signed = stage
    # Views from 0: loops over range(lo, hi) vectorise worse.
    x, offset, y1, y2, slow = x[lo:hi], state.offset[lo:hi], state.y1[lo:hi], state.y2[lo:hi], state.slow[lo:hi]
    gain, threshold, n, fs = unit.gain[lo:hi], unit.threshold[lo:hi], hi - lo, stage.fs
    fs2 = fs * fs
    if order == 0:
        for j in range(n):
            cur = x[j]
            v = cur
            if adapt > 0.0:
                v = cur + adapt * (cur - slow[j])
                slow[j] = slow[j] + alpha_adapt * (cur - slow[j])
            v = v + offset[j]
            if adapt > 0.0 and v < 0.0:
                v = 0.0  # adaptation undershoots on release: a rate cannot go negative
            y2[j] = y1[j]
            y1[j] = cur
            x[j] = v
    elif order == 1:
        for j in range(n):
            cur = x[j]
            x[j] = (cur - y1[j]) * fs
            y2[j] = y1[j]
            y1[j] = cur
    else:
        for j in range(n):
            cur = x[j]
            x[j] = ((cur - 2.0 * y1[j]) + y2[j]) * fs2
            y2[j] = y1[j]
            y1[j] = cur
    if order > 0 and negative != 1.0:
        for j in range(n):
            x[j] = x[j] if x[j] >= 0.0 else -negative * x[j]  # >= 0 from here: abs below leaves it as it is
    if order > 0 and (adapt > 0.0 or thresholded):
        for j in range(n):
            a = abs(x[j])
            slow[j] = slow[j] + alpha_adapt * (a - slow[j])
            x[j] = max((a - adapt * slow[j]) - threshold[j], 0.0)
    if signed:
        for j in range(n):
            x[j] = gain[j] * x[j]
    else:
        for j in range(n):
            x[j] = gain[j] * abs(x[j])


@nb.njit(cache=True, nogil=True, inline="always")
def receptor_noise(x, normals, col, cv_scale, signed):
    """`stage_tail`'s receptor noise from draws given in advance (``normals[:, col]``), in place on ``x``."""
    for j in range(x.size):
        x[j] = _noisy(x[j], normals[j, col], cv_scale[j], signed)


@nb.njit(cache=True, nogil=True, inline="always")
def _noisy(d, xi, cv_scale, signed):
    """Receptor noise on the drive d: ``d (1 + cv xi)``, rectified unless ``signed``."""
    d = d + d * (xi * cv_scale)
    if not signed and d < 0.0:
        d = 0.0
    return d


@nb.njit(cache=True, nogil=True, inline="always")
def receptor_noise_keyed(x, lo, hi, key, afferent_id, sample, cv_scale, signed, words, xi):
    """`stage_tail`'s receptor noise with the draws made here (`ddmm.models.rng.normal_row`), in place on ``x``.

    A group with no driven afferent (every d = 0) keeps d = 0 whatever its
    draws, so it draws nothing: the same bits as drawing, at no cost.
    ``words`` and ``xi`` are scratch.
    """
    for j in range(lo, hi):
        if x[j] != 0.0:
            break
    else:
        return
    normal_row(key, afferent_id, lo, hi, sample, words, xi)
    x, xi, cv_scale = x[lo:hi], xi[lo:hi], cv_scale[lo:hi]  # views from 0 vectorise better
    for j in range(hi - lo):
        if x[j] != 0.0 and cv_scale[j] != 0.0:
            x[j] = _noisy(x[j], xi[j], cv_scale[j], signed)


@nb.njit(cache=True, nogil=True)
def stage_kernel(sos, f_a, zi, state, stage, unit, noise):
    """The linear part of a type's stage: filter (on the deviation from ``state.offset``), then `stage_tail`.

    ``zi`` has shape (n_sections, 2, n_afferents); ``state``, ``stage`` and
    ``unit`` as `stage_tail` (one dead zone per afferent in
    ``unit.threshold``); ``noise`` the `ReceptorNoise` (draws of sample n in
    column n); every state array is updated in place.
    """
    n_samples, m = f_a.shape
    out, cur = np.empty_like(f_a), np.empty(m)
    offset, (normals, noisy), cv_scale = state.offset, noise, unit.cv_scale
    z = zi.reshape((2 * zi.shape[0], zi.shape[2]))  # a view: section s in rows 2s, 2s + 1
    sections = sos.reshape((1, sos.shape[0], sos.shape[1]))
    for n in range(n_samples):
        for j in range(m):
            cur[j] = f_a[n, j] - offset[j]
        filter_sections(cur, 0, m, sections, 0, sos.shape[0], z)
        stage_tail(cur, 0, m, state, stage, unit)
        if noisy:
            receptor_noise(cur, normals, n, cv_scale, stage.signed)
        out[n] = cur
    return out


@nb.njit(cache=True, nogil=True, inline="always")
def dynamic_step(x, c, k, r, alpha, alpha_k, alpha_r, depth, transient, fall):
    """One sample of the dynamic response on the current: ``c += alpha (x - c)``; with ``transient``,
    ``r += alpha_r (x - r)`` and ``k += alpha_k (r - k)``;
    ``max(x + depth (x - c) + transient max(r - k, 0) - fall c, 0)``.  With ``transient`` 0 the sum is that
    of the form without it, bit for bit."""
    c = c + alpha * (x - c)
    y = (x + depth * (x - c)) - fall * c
    if transient != 0.0:
        r = r + alpha_r * (x - r)
        k = k + alpha_k * (r - k)
        if r > k:  # rising current only: a loading response, nothing subtracted while it falls
            y = y + transient * (r - k)
    return max(y, 0.0), c, k, r


@nb.njit(cache=True, nogil=True)
def dynamic_kernel(x, c, k, r, alpha, alpha_k, alpha_r, depth, transient, fall):
    """`dynamic_step` along axis 0, in place on ``x``, with states ``c``, ``k`` and ``r`` (updated)."""
    for n in range(x.shape[0]):
        for j in range(x.shape[1]):
            x[n, j], c[j], k[j], r[j] = dynamic_step(x[n, j], c[j], k[j], r[j], alpha, alpha_k, alpha_r, depth,
                                                     transient, fall)
    return x


@nb.njit(cache=True, nogil=True)
def smooth_kernel(x, c, alpha):
    """First-order low-pass along axis 0, in place on ``x``, with state ``c`` (updated)."""
    for n in range(x.shape[0]):
        for j in range(x.shape[1]):
            c[j] = c[j] + alpha * (x[n, j] - c[j])
            x[n, j] = c[j]
    return x
