"""The transducers of the current stage (`ddmm.models.currents`): log compression and saturation of the
linear drive, with numpy's log1p and tanh, offline (`transduce_inplace`, `transduce_columns`) and in a
streaming push's split passes around them (`transduce_pre`, `transduce_mid`, `transduce_post`).
"""

from __future__ import annotations

import math
from typing import NamedTuple

import numba as nb
import numpy as np

from ddmm.models._kernel_options import VECTOR_KERNEL

__all__ = ["transduce_inplace", "transduce_columns", "TransducerRuns", "TransducerPass", "transducer_table",
           "transduce_pre", "transduce_mid", "transduce_post"]


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


@nb.njit(**VECTOR_KERNEL)
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


@nb.njit(**VECTOR_KERNEL)
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


@nb.njit(**VECTOR_KERNEL)
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
