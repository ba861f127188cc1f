"""Numba kernels and numpy transducers of the current stage (`ddmm.models.currents`).

Kept apart so that `ddmm.models.currents` stays the readable definition of the
stages; these are the hot loops every stage runs through, offline and
streaming alike.
"""

from __future__ import annotations

import math
from typing import NamedTuple

import numba as nb
import numpy as np

from ddmm.models.rng import normal_row

__all__ = ["TailState", "StageConstants", "UnitScales", "ReceptorNoise", "filter_sections", "stage_tail",
           "receptor_noise", "receptor_noise_keyed", "stage_kernel", "smooth_kernel", "dynamic_step", "dynamic_kernel",
           "transduce_inplace", "transduce_columns", "TransducerRuns", "TransducerPass", "transducer_table",
           "transduce_pre", "transduce_mid", "transduce_post"]


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


def transduce_inplace(drive, stage, excite=None):
    """Log compression and saturation of ``|drive|``, in place.

    ``stage.i_sat`` and ``stage.i_max`` in mV/ms; the sign of SA-II's signed
    drive is restored afterwards.  ``excite`` (per column, dimensionless: the
    trial excitability of `ddmm.models.variability.excitability`) multiplies
    the current after the log compression and before the bound, so
    ``i_max`` still bounds it.
    """
    negative = np.signbit(drive) if stage.signed else None
    if stage.signed:
        np.abs(drive, out=drive)
    if stage.i_sat is not None:
        drive /= stage.i_sat
        np.log1p(drive, out=drive)
        drive *= stage.i_sat
    if excite is not None:
        drive *= excite
    if stage.i_max is not None:
        drive /= stage.i_max
        np.tanh(drive, out=drive)
        drive *= stage.i_max
    if negative is not None:
        np.negative(drive, out=drive, where=negative)
    return drive


#: Zero rows between two live runs that `transduce_columns` still passes to numpy in one call (a zero row maps
#: to itself through every step, so this changes no bit; it saves numpy's per-call cost on scattered rows).
_ROW_GAP = 16


@nb.njit(cache=True, nogil=True)
def _scale_rows(drive, c0, c1, mult, excite, div, live):
    """``x = ((x * mult) * excite[j]) / div`` on columns ``c0..c1``, in place, in the order `transduce_inplace`
    applies them (a factor of 1.0 is exact); ``live[i]``: whether row ``i`` holds a non-zero value after."""
    for i in range(drive.shape[0]):
        row, any_live = drive[i, c0:c1], False
        for j in range(c1 - c0):
            row[j] = ((row[j] * mult) * excite[j]) / div
            any_live |= row[j] != 0.0
        live[i] = any_live


def _live_runs(live):
    """(start, stop) row ranges covering every live row, runs closer than `_ROW_GAP` merged."""
    rows = np.flatnonzero(live)
    if rows.size == 0:
        return []
    cut = np.flatnonzero(np.diff(rows) > _ROW_GAP)
    return list(zip(rows[np.r_[0, cut + 1]], rows[np.r_[cut, rows.size - 1]] + 1))


def transduce_columns(drive, cols, stage, excite=None):
    """`transduce_inplace` on ``drive[:, cols]`` (an unsigned stage), bit for bit, at a fraction of its passes.

    The products and quotients around numpy's log1p and tanh run in one
    numba pass each, and log1p and tanh skip the rows whose values are all
    zero (both map 0 to 0): fast-adapting afferents are silent most of a
    hold.  ``cols`` is a slice; ``excite`` as `transduce_inplace`'s, for the
    columns ``cols``.
    """
    if stage.signed:
        raise ValueError("transduce_columns takes unsigned stages; a signed stage goes through transduce_inplace")
    c0, c1 = cols.start, cols.stop
    ones = np.ones(c1 - c0)
    factor = ones if excite is None else np.ascontiguousarray(excite, dtype=float)
    live = np.empty(drive.shape[0], np.bool_)
    bound = 1.0 if stage.i_max is None else float(stage.i_max)
    if stage.i_sat is not None:
        _scale_rows(drive, c0, c1, 1.0, ones, float(stage.i_sat), live)
        for r0, r1 in _live_runs(live):
            np.log1p(drive[r0:r1, cols], out=drive[r0:r1, cols])
        _scale_rows(drive, c0, c1, float(stage.i_sat), factor, bound, live)
    else:
        _scale_rows(drive, c0, c1, 1.0, factor, bound, live)
    if stage.i_max is not None:
        for r0, r1 in _live_runs(live):
            block = drive[r0:r1, cols]
            np.tanh(block, out=block)
            block *= bound
    return drive


# The transducers of a streaming push in three numba passes around numpy's log1p and tanh (`TransducerRuns`):
# `transduce_pre` (sign, |d|, / i_sat) and `transduce_post` (* i_max, sign back) run inside an engine's parallel
# parts, `transduce_mid` between the two numpy calls.  Each applies `transduce_inplace`'s operations in its order,
# one IEEE operation each (a factor of 1.0 is exact), so the bits are `transduce_inplace`'s.
_RUN_START, _RUN_STOP, _RUN_SIGNED, _RUN_SAT, _RUN_MAX = range(5)


class TransducerRuns(NamedTuple):
    """The transducer of each run of columns, as the split passes read it (`transducer_table` builds it).

    Attributes
    ----------
    runs_i : ndarray of int64, shape (n_runs, 5)
        Start, stop, signed, has ``i_sat``, has ``i_max`` of each run (runs without a transducer have flags 0:
        they take the excitability factor alone).
    runs_f : ndarray, shape (n_runs, 2)
        ``i_sat`` and ``i_max`` of each run (mV/ms; 1.0 where absent).
    sat : tuple of slice
        The columns numpy's log1p runs on (adjacent runs merged).
    bounded : tuple of slice
        The columns numpy's tanh runs on (adjacent runs merged).
    signed : bool
        Whether any run is signed (a sign mask is then kept between the passes).
    """

    runs_i: np.ndarray
    runs_f: np.ndarray
    sat: tuple
    bounded: tuple
    signed: bool


class TransducerPass(NamedTuple):
    """What a streaming push's split transducer passes read and write on each range (`transduce_pre` and
    `transduce_post` in an engine's parallel parts): the runs of `TransducerRuns` and the sign mask between them.

    Attributes
    ----------
    runs_i : ndarray of int64, shape (n_runs, 5)
        `TransducerRuns.runs_i`.
    runs_f : ndarray, shape (n_runs, 2)
        `TransducerRuns.runs_f`.
    negative : ndarray of bool, shape (n_samples, n_afferents)
        Each signed drive's sign, written by the first pass and restored by the last ((0, 0) with no signed run).
    """

    runs_i: np.ndarray
    runs_f: np.ndarray
    negative: np.ndarray


def transducer_table(transducers, plain) -> TransducerRuns:
    """The `TransducerRuns` of a pipeline's ``transducers`` ((columns, stage) runs) and ``plain`` column slices."""
    runs = [(c.start, c.stop, int(st.signed), int(st.i_sat is not None), int(st.i_max is not None),
             1.0 if st.i_sat is None else float(st.i_sat), 1.0 if st.i_max is None else float(st.i_max))
            for c, st in transducers] + [(c.start, c.stop, 0, 0, 0, 1.0, 1.0) for c in plain]
    runs.sort()

    def spans(flag):
        out = []
        for r in runs:
            if r[flag]:
                if out and out[-1][1] == r[0]:
                    out[-1] = (out[-1][0], r[1])
                else:
                    out.append((r[0], r[1]))
        return tuple(slice(int(a), int(b)) for a, b in out)

    runs_i = np.array([r[:5] for r in runs], dtype=np.int64).reshape(-1, 5)
    runs_f = np.array([r[5:] for r in runs], dtype=float).reshape(-1, 2)
    return TransducerRuns(runs_i, runs_f, spans(_RUN_SAT), spans(_RUN_MAX), bool(runs_i[:, _RUN_SIGNED].any()))


@nb.njit(cache=True, nogil=True)
def transduce_pre(drive, runs_i, runs_f, negative, a0, a1):
    """First pass on columns ``a0..a1``: a signed run's sign into ``negative`` and ``|d|``, then ``d / i_sat``."""
    for r in range(runs_i.shape[0]):
        lo, hi = max(a0, runs_i[r, _RUN_START]), min(a1, runs_i[r, _RUN_STOP])
        if lo >= hi:
            continue
        signed, sat, i_sat = runs_i[r, _RUN_SIGNED] != 0, runs_i[r, _RUN_SAT] != 0, runs_f[r, 0]
        for i in range(drive.shape[0]):
            x = drive[i, lo:hi]
            if signed:
                neg = negative[i, lo:hi]
                for j in range(hi - lo):
                    neg[j] = math.copysign(1.0, x[j]) < 0.0  # `np.signbit`
                    x[j] = abs(x[j])
            if sat:
                for j in range(hi - lo):
                    x[j] = x[j] / i_sat


@nb.njit(cache=True, nogil=True)
def transduce_mid(drive, runs_i, runs_f, excite):
    """Between log1p and tanh, every column: ``d i_sat`` (after log1p), ``d excite``, ``d / i_max``."""
    for r in range(runs_i.shape[0]):
        lo, hi = runs_i[r, _RUN_START], runs_i[r, _RUN_STOP]
        sat, bounded, i_sat, i_max = runs_i[r, _RUN_SAT] != 0, runs_i[r, _RUN_MAX] != 0, runs_f[r, 0], runs_f[r, 1]
        e = excite[lo:hi]
        for i in range(drive.shape[0]):  # one loop per case: each operation still rounds on its own
            x = drive[i, lo:hi]
            if sat and bounded:
                for j in range(hi - lo):
                    x[j] = ((x[j] * i_sat) * e[j]) / i_max
            elif sat:
                for j in range(hi - lo):
                    x[j] = (x[j] * i_sat) * e[j]
            elif bounded:
                for j in range(hi - lo):
                    x[j] = (x[j] * e[j]) / i_max
            else:
                for j in range(hi - lo):
                    x[j] = x[j] * e[j]


@nb.njit(cache=True, nogil=True)
def transduce_post(drive, runs_i, runs_f, negative, a0, a1):
    """Last pass on columns ``a0..a1`` (after tanh): ``d i_max``, and a signed run's sign back."""
    for r in range(runs_i.shape[0]):
        lo, hi = max(a0, runs_i[r, _RUN_START]), min(a1, runs_i[r, _RUN_STOP])
        if lo >= hi:
            continue
        signed, bounded, i_max = runs_i[r, _RUN_SIGNED] != 0, runs_i[r, _RUN_MAX] != 0, runs_f[r, 1]
        for i in range(drive.shape[0]):
            x = drive[i, lo:hi]
            if bounded:
                for j in range(hi - lo):
                    x[j] = x[j] * i_max
            if signed:
                neg = negative[i, lo:hi]
                for j in range(hi - lo):
                    if neg[j]:
                        x[j] = -x[j]  # `np.negative(..., where=negative)`
