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
def hold_band(x, ref, widths, moves, held, track):
    """The force hold, in place on ``x`` (n, sites, 3); ``held`` (sites, 3) and ``track`` (sites, 3, 4) updated.

    A play operator per axis: the output stays put while the input moves
    within ``widths[a]`` of it and is dragged along, that far behind, when
    the input leaves the band (an axis of width 0 passes as it is).
    ``widths[4 + a]`` is the band's floor: a drag that lasts is a ramp, not
    noise, and the band narrows toward the floor by ``moves[2]`` of the way
    per dragged sample, and widens again by ``1 / moves[1]`` per sample
    otherwise (as slowly as the settling), so a ramp that noise interrupts
    does not stall.

    When a drag ends the output *settles* for ``moves[1]`` samples: it moves
    toward the mean of ``ref`` (the unfiltered input, which does not share
    the tracker's overshoot of a ramp's end) since the drag ended, by
    ``moves[0]`` of the distance per sample, fading to nothing over the
    settling, and never faster than the drag's fastest step.  A ramp's lag
    is then caught up at the ramp's pace, and the hold starts on the mean
    of its input, not a width or an overshoot away from it.  Otherwise the
    output does not move: nothing creeps through a hold.  ``track`` holds,
    per axis, that fastest step, the samples settled so far, their mean and
    the narrowing (0 at the full width, 1 at the floor).

    On the normal axis the width is at most half the force above the
    contact threshold ``widths[3]``, so the held force crosses that
    threshold when the input does.
    """
    for i in range(x.shape[0]):
        for s in range(x.shape[1]):
            for a in range(3):
                width = widths[a]
                if width <= 0.0:
                    continue
                v = x[i, s, a]
                # the normal hold narrows to nothing at contact (widths[3]): contact is not delayed
                most = 0.5 * max(v - widths[3], 0.0) if a == 2 else np.inf
                h = _drag(v, ref[i, s, a], held[s, a], width, widths[4 + a], most, moves, track, s, a)
                held[s, a] = h
                x[i, s, a] = h


@nb.njit(cache=True, nogil=True, inline="always")
def _drag(v, r, h, width, floor, most, moves, track, s, a):
    """One sample of the play operator with settling (`hold_band`): the new output."""
    narrow = track[s, a, 3]  # 0: the full width, 1: the floor
    width = min(width - (width - floor) * narrow, most)
    e = v - h
    step = e - width if e > width else (e + width if e < -width else 0.0)
    last = track[s, a, 0]
    # a drag that lasts is a ramp: the band narrows to its floor, and widens again as slowly as it settles
    track[s, a, 3] = narrow + moves[2] * (1.0 - narrow) if step != 0.0 else narrow * (1.0 - 1.0 / moves[1])
    if step != 0.0:  # dragged: remember the fastest step of this drag, restart the settling
        if step * last <= 0.0 or abs(step) > abs(last) or np.isinf(last):  # (0 once settled, inf at the start)
            track[s, a, 0] = step
        track[s, a, 1] = 0.0
        track[s, a, 2] = 0.0
        return h + step
    if last == 0.0:
        return h
    count = track[s, a, 1] + 1.0  # settling: toward the mean of the input since the drag ended
    mean = track[s, a, 2] + (r - track[s, a, 2]) / count
    track[s, a, 1], track[s, a, 2] = count, mean
    if count >= moves[1]:
        track[s, a, 0] = 0.0
        track[s, a, 1] = 0.0
    d = mean - h  # the approach fades over the settling, so the mean's late jitter barely moves the output
    return h + np.sign(d) * min(abs(last), moves[0] * (1.0 - count / moves[1]) * abs(d))


@nb.njit(cache=True, nogil=True, inline="always")
def _gated(y, slow, kept, i, s, a, gate):
    """The kept band plus the fast band soft-thresholded at ``gate`` (no gate when ``gate`` < 0)."""
    if gate < 0.0:
        return kept[i, s, a]
    fast = y[i, s, a] - slow[i, s, a]
    return kept[i, s, a] + np.sign(fast) * max(abs(fast) - gate, 0.0)


@nb.njit(cache=True, nogil=True)
def gate_hold_contact(y, slow, smooth, gate, widths, moves, held, track, on, off, deadband, state):
    """The gate, the shear hold, contact and the shear deadband of one chunk (see the module docstring).

    ``y`` is the resampled recording (n, sites, 3); ``slow`` and ``smooth``
    are its tracker's slow band and that band smoothed (ignored when
    ``gate`` is negative: no gate, the hold acts on ``y``; ``widths`` (per
    axis), ``moves``, ``held`` and ``track`` are `hold_band`'s).  ``held``,
    ``track`` and ``state`` (sites, bool contact) carry over between chunks.
    Returns the conditioned forces (n, sites, 3) and the contact (n, sites).
    """
    n, sites = y.shape[0], y.shape[1]
    kept = smooth.copy() if gate >= 0.0 else y.copy()
    if widths[:3].max() > 0.0:
        hold_band(kept, y, widths, moves, held, track)
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
