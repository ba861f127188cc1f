"""Numba kernels and numpy transducers of the current stage (`models.currents`).

Kept apart so that `models.currents` stays the readable definition of the
stages; these are the hot loops every stage runs through, offline and
streaming alike.
"""

from __future__ import annotations

import numba as nb
import numpy as np

__all__ = ["stage_kernel", "smooth_kernel", "transduce_inplace"]


@nb.njit(cache=True, nogil=True)
def stage_kernel(sos, f_a, offset, zi, y1, y2, slow, fs, order, adapt, alpha_adapt, threshold, gain,
                  normals, cv_scale, noisy, signed):
    """The linear part of a type's stage in one pass: the drive d, per sample and afferent.

    Filter (direct form II transposed on the deviation from ``offset``), the
    derivative of ``order``, adaptation, gain and receptor noise (rectified
    unless ``signed``).  The state arrays are updated in place.
    """
    out = np.empty_like(f_a)
    fs2 = fs * fs
    for n in range(f_a.shape[0]):
        for j in range(f_a.shape[1]):
            cur = f_a[n, j] - offset[j]
            for s in range(sos.shape[0]):
                new = sos[s, 0] * cur + zi[s, 0, j]
                zi[s, 0, j] = sos[s, 1] * cur - sos[s, 4] * new + zi[s, 1, j]
                zi[s, 1, j] = sos[s, 2] * cur - sos[s, 5] * new
                cur = new
            if order == 0:
                x = cur
                if adapt > 0.0:
                    x = cur + adapt * (cur - slow[j])
                    slow[j] = slow[j] + alpha_adapt * (cur - slow[j])
                x = x + offset[j]
                if adapt > 0.0 and x < 0.0:
                    x = 0.0  # adaptation undershoots on release: a rate cannot go negative
            elif order == 1:
                x = (cur - y1[j]) * fs
            else:
                x = ((cur - 2.0 * y1[j]) + y2[j]) * fs2
            y2[j] = y1[j]
            y1[j] = cur
            if order > 0 and (adapt > 0.0 or threshold > 0.0):
                a = abs(x)
                slow[j] = slow[j] + alpha_adapt * (a - slow[j])
                x = max((a - adapt * slow[j]) - threshold, 0.0)
            d = gain[j] * (x if signed else abs(x))
            if noisy:
                d = d + d * (normals[j, n] * cv_scale[j])
                if not signed and d < 0.0:
                    d = 0.0
            out[n, j] = d
    return out


@nb.njit(cache=True, nogil=True)
def smooth_kernel(x, c, alpha):
    """First-order low-pass along axis 0, in place on ``x``, with state ``c`` (updated)."""
    for n in range(x.shape[0]):
        for j in range(x.shape[1]):
            c[j] = c[j] + alpha * (x[n, j] - c[j])
            x[n, j] = c[j]
    return x


def transduce_inplace(drive, stage):
    """Log compression and saturation of ``|drive|``, in place.

    ``stage.i_sat`` and ``stage.i_max`` in mV/ms; the sign of SA-II's signed
    drive is restored afterwards.
    """
    negative = np.signbit(drive) if stage.signed else None
    if stage.signed:
        np.abs(drive, out=drive)
    if stage.i_sat is not None:
        drive /= stage.i_sat
        np.log1p(drive, out=drive)
        drive *= stage.i_sat
    if stage.i_max is not None:
        drive /= stage.i_max
        np.tanh(drive, out=drive)
        drive *= stage.i_max
    if negative is not None:
        np.negative(drive, out=drive, where=negative)
    return drive


