"""Numba kernels of the causal conditioning (`ddmm.population.stimuli.conditioning`).

A live sensor pushes one sample at a time, so a push must not pay numpy's and
scipy's per-call overhead several times over: measured, the scipy/numpy
conditioner took ~0.17-0.23 ms per one-sample push, more than the model's
integration of a fingertip.  These loops do the same arithmetic in one call
each; offline and streaming run the same kernels, so they agree bit for bit.
"""

from __future__ import annotations

import numba as nb
import numpy as np

__all__ = ["sos_filter", "gate_hold_contact", "hold_band", "hold_counts"]


@nb.njit(cache=True, nogil=True)
def hold_counts(first, n, ratio):
    """Output samples each of the input samples ``first .. first + n - 1`` covers when upsampling by ``ratio``.

    Input sample k covers outputs ``ceil(k ratio) .. ceil((k + 1) ratio) - 1``
    (less 1e-9, so an exact product is not pushed up by rounding).
    """
    counts = np.empty(n, dtype=np.int64)
    edge = np.ceil(float(first) * ratio - 1e-9)
    for i in range(n):
        following = np.ceil(float(first + i + 1) * ratio - 1e-9)
        counts[i] = np.int64(following - edge)
        edge = following
    return counts


@nb.njit(cache=True, nogil=True)
def sos_filter(sos, x, zi):
    """Second-order sections over the rows of ``x`` (n, c); the state ``zi`` (sections, 2, c) is updated.

    Direct form II transposed, the arithmetic of `scipy.signal.sosfilt`
    (sections normalised, ``a0 = 1``).
    """
    n, c = x.shape
    y = np.empty_like(x)
    for j in range(c):
        for i in range(n):
            v = x[i, j]
            for s in range(sos.shape[0]):
                new = sos[s, 0] * v + zi[s, 0, j]
                zi[s, 0, j] = sos[s, 1] * v - sos[s, 4] * new + zi[s, 1, j]
                zi[s, 1, j] = sos[s, 2] * v - sos[s, 5] * new
                v = new
            y[i, j] = v
    return y


@nb.njit(cache=True, nogil=True)
def hold_band(x, widths, alpha, held):
    """The force hold, in place on ``x`` (n, sites, 3); ``held`` (sites, 3) updated.

    A play operator per axis that re-centres: the output relaxes toward the
    input by ``alpha`` per sample (a first-order low-pass, far slower than
    any afferent cares about) and never strays more than ``widths[a]`` from
    it (an axis of width 0 passes as it is).  On the normal axis the width is
    at most half the force above the contact threshold ``widths[3]``, so the
    held force crosses that threshold when the input does.  On a hold the output settles
    on the hold's mean and barely moves; on a ramp it moves with the ramp's
    slope, at most the width behind.
    """
    for i in range(x.shape[0]):
        for s in range(x.shape[1]):
            for a in range(3):
                width = widths[a]
                if width <= 0.0:
                    continue
                v = x[i, s, a]
                if a == 2:  # the normal hold narrows to nothing at contact (widths[3]): contact is not delayed
                    width = min(width, 0.5 * max(v - widths[3], 0.0))
                h = held[s, a] + alpha * (v - held[s, a])
                held[s, a] = min(max(h, v - width), v + width)
                x[i, s, a] = held[s, a]


@nb.njit(cache=True, nogil=True, inline="always")
def _gated(y, slow, kept, i, s, a, gate):
    """The kept band plus the fast band soft-thresholded at ``gate`` (no gate when ``gate`` < 0)."""
    if gate < 0.0:
        return kept[i, s, a]
    fast = y[i, s, a] - slow[i, s, a]
    return kept[i, s, a] + np.sign(fast) * max(abs(fast) - gate, 0.0)


@nb.njit(cache=True, nogil=True)
def gate_hold_contact(y, slow, smooth, gate, widths, alpha, held, on, off, deadband, state):
    """The gate, the shear hold, contact and the shear deadband of one chunk (see the module docstring).

    ``y`` is the resampled recording (n, sites, 3); ``slow`` and ``smooth``
    are its tracker's slow band and that band smoothed (ignored when
    ``gate`` is negative: no gate, the hold acts on ``y``; ``widths`` (per
    axis) and ``alpha`` are `hold_band`'s).  ``held`` (sites, 3) and
    ``state`` (sites, bool contact) carry over between chunks.  Returns
    the conditioned forces (n, sites, 3) and the contact (n, sites).
    """
    n, sites = y.shape[0], y.shape[1]
    kept = smooth.copy() if gate >= 0.0 else y.copy()
    if widths[:3].max() > 0.0:
        hold_band(kept, widths, alpha, held)
    out = np.empty_like(y)
    contact = np.empty((n, sites), dtype=np.bool_)
    for i in range(n):
        for s in range(sites):
            gx, gy = _gated(y, slow, kept, i, s, 0, gate), _gated(y, slow, kept, i, s, 1, gate)
            gz = _gated(y, slow, kept, i, s, 2, gate)
            state[s] = gz >= off if state[s] else gz > on  # hysteresis
            contact[i, s] = state[s]
            out[i, s, 2] = max(gz - on, 0.0)  # continuous at the onset: no force step
            magnitude = np.hypot(gx, gy)
            keep = 1.0 - deadband / magnitude if state[s] and magnitude > deadband else 0.0
            out[i, s, 0], out[i, s, 1] = gx * keep, gy * keep
    return out, contact
