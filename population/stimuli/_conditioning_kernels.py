"""Numba kernels of the causal conditioning (`ddmm.population.stimuli.conditioning`).

A live sensor pushes one sample at a time, so a push must not pay numpy's and
scipy's per-call overhead several times over: measured, the scipy/numpy
conditioner took ~0.17-0.23 ms per one-sample push, more than the model's
integration of a fingertip.  These loops do the same arithmetic in one call
each; offline and streaming run the same kernels, so they agree bit for bit.
Once a stream's states have started, `push_steady` runs a whole push in one
call (the Python glue between those calls cost 20-80 us a one-sample push).
"""

from __future__ import annotations

from typing import NamedTuple

import numba as nb
import numpy as np

__all__ = ["sos_filter", "gate_hold_contact", "GateSettings", "GateState", "hold_band", "hold_counts", "track_noise",
           "noise_scale", "track_band", "smooth_band", "push_steady", "StreamSettings", "StreamState"]


class GateSettings(NamedTuple):
    """The constants of one `gate_hold_contact` call.

    Attributes
    ----------
    gate : float
        The fast band's soft threshold, N, at noise scale 1 (negative: no gate, the hold acts on the input).
    widths : ndarray, shape (7,)
        `hold_band`'s widths, N: the hold's per axis (x, y, z; 0: no hold), the contact threshold at which
        the normal hold narrows to nothing, and the floors per axis (`conditioning.hold_widths`).
    moves : ndarray, shape (3,)
        `hold_band`'s rates: the settling's approach per sample, the settling's length in samples and the
        band's narrowing per dragged sample (`conditioning._hold_moves`).
    on, off : float
        Contact hysteresis thresholds on the gated F_Z, N (``on`` also comes off F_Z).
    deadband : float
        Tangential magnitude taken off in contact, N.
    """

    gate: float
    widths: np.ndarray
    moves: np.ndarray
    on: float
    off: float
    deadband: float


class GateState(NamedTuple):
    """The state `gate_hold_contact` carries between chunks (arrays, updated in place).

    Attributes
    ----------
    held : ndarray, shape (sites, 3)
        `hold_band`'s held output.
    track : ndarray, shape (sites, 3, 4)
        `hold_band`'s drag and settling state.
    contact : ndarray of bool, shape (sites,)
        The contact state per site.
    taken : ndarray, shape (sites,)
        The part of ``on`` taken off F_Z since the contact's onset, per site, N.
    """

    held: np.ndarray
    track: np.ndarray
    contact: np.ndarray
    taken: np.ndarray


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
def hold_band(x, ref, widths, moves, held, track, scale):
    """The force hold, in place on ``x`` (n, sites, 3); ``held`` (sites, 3) and ``track`` (sites, 3, 4) updated.

    ``scale`` (n, sites, 3) multiplies the widths and their floors per sample:
    the sensor's measured noise over the declared (`track_noise`), 1 for the
    declared noise.

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
                if widths[a] <= 0.0:
                    continue
                v, k = x[i, s, a], scale[i, s, a]
                # the normal hold narrows to nothing at contact (widths[3]): contact is not delayed
                most = 0.5 * max(v - widths[3], 0.0) if a == 2 else np.inf
                h = _drag(v, ref[i, s, a], held[s, a], widths[a] * k, widths[4 + a] * k, most, moves, track, s, a)
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
def gate_hold_contact(y, slow, smooth, scale, settings, carry):
    """The gate, the shear hold, contact and the shear deadband of one chunk (see the module docstring).

    ``y`` is the resampled recording (n, sites, 3); ``slow`` and ``smooth``
    are its tracker's slow band and that band smoothed (ignored when
    ``settings.gate`` is negative: no gate, the hold acts on ``y``; the
    settings' ``widths`` (per axis) and ``moves``, the carry's ``held`` and
    ``track`` are `hold_band`'s).  ``scale`` (n, sites, 3) is the noise scale
    per sample (`noise_scale`): it multiplies the gate, the hold's widths,
    the part of ``on`` taken off F_Z and the hysteresis ``on - off``; in
    contact the part taken off stays what it was at the onset (``taken``,
    per site), so the scale's drift does not move a pressed F_Z.
    ``settings`` is a `GateSettings`; ``carry`` a `GateState`, updated in
    place (it carries over between chunks).  Returns the conditioned forces
    (n, sites, 3) and the contact (n, sites).
    """
    gate, widths, moves, on, off, deadband = settings
    held, track, state, taken = carry
    n, sites = y.shape[0], y.shape[1]
    kept = smooth.copy() if gate >= 0.0 else y.copy()
    if widths[:3].max() > 0.0:
        hold_band(kept, y, widths, moves, held, track, scale)
    out = np.empty_like(y)
    contact = np.empty((n, sites), dtype=np.bool_)
    for i in range(n):
        for s in range(sites):
            gx = _gated(y, slow, kept, i, s, 0, gate * scale[i, s, 0])
            gy = _gated(y, slow, kept, i, s, 1, gate * scale[i, s, 1])
            k = scale[i, s, 2]
            gz = _gated(y, slow, kept, i, s, 2, gate * k)
            if state[s]:
                state[s] = gz >= on - (on - off) * k  # hysteresis, as wide as the noise
            elif gz > on:
                state[s], taken[s] = True, on * k
            contact[i, s] = state[s]
            out[i, s, 2] = max(gz - (taken[s] if state[s] else on * k), 0.0)  # continuous at the onset: no step
            magnitude = np.hypot(gx, gy)
            keep = 1.0 - deadband / magnitude if state[s] and magnitude > deadband else 0.0
            out[i, s, 0], out[i, s, 1] = gx * keep, gy * keep
    return out, contact


# Where `track_noise`'s estimate times this sits among |second differences|: set so that it reads white noise's
# SD (measured over 60 s at 100 Hz-5 kHz: 0.97-1.03 of it).
_PERCENTILE = 3.3


@nb.njit(cache=True, nogil=True)
def track_noise(x, noise, rates, state):
    """The sensor's noise over the declared, per input sample: ``scale`` (n, channels) in (0, 1].

    ``x`` (n, channels) are input samples; ``noise`` is the declared SD (N).
    The noise SD is read from second differences, ``d = x[k] - 2 x[k-1] +
    x[k-2]`` (SD ``sqrt(6)`` of white noise's; a ramp gives 0, its corner one
    sample): over the first ``rates[0]`` of them, their RMS (a quarter
    high); then a percentile tracker moves the estimate down by ``rates[1]
    / 3`` (log) when ``|d|`` is within `_PERCENTILE` times it, and up by
    ``rates[1]``, or, on the second such sample in a row, by up to ``8
    rates[1]`` the further out it is: a ramp's lone corner moves it by one
    step, however large, and noise that starts is read within tens of
    samples.  The scale, ``min(1, rates[2] sd / noise)`` with ``rates[2]`` the
    margin, is 1 until the first estimate, starts there and then follows
    the tracker smoothly: up by ``rates[3]`` of the way per sample, down by
    ``rates[4]`` (slower: a hold's band that narrows drags its output).
    ``state`` (6, channels): the last two samples, the differences seen, the
    estimate (the RMS sum while warming up), the scale and whether the last
    difference was out carry over.
    """
    n, c = x.shape
    scale = np.full((n, c), np.nan)  # NaN until the first estimate (`noise_scale` reads it as 1)
    floor = 1e-4 * noise
    for j in range(c):
        for i in range(n):
            v = x[i, j]
            seen = state[2, j]
            if seen >= 0.0:  # (-2, -1: the first two samples, no difference yet)
                d = v - 2.0 * state[1, j] + state[0, j]
                if seen < rates[0]:
                    state[3, j] += d * d
                    if seen + 1.0 >= rates[0]:  # a quarter high: a short RMS may fall short, and low is unsafe
                        state[3, j] = max(1.25 * np.sqrt(state[3, j] / (6.0 * rates[0])), floor)
                        state[4, j] = min(1.0, rates[2] * state[3, j] / noise)
                else:
                    sd = state[3, j]
                    if abs(d) > _PERCENTILE * sd:  # up; on a second sample in a row by more the further out:
                        # noise that starts is read fast, a ramp's lone corner is one sample
                        far = min(1.0 + np.log2(abs(d) / (_PERCENTILE * sd)), 8.0) if state[5, j] > 0.0 else 1.0
                        step, state[5, j] = rates[1] * far, 1.0
                    else:
                        step, state[5, j] = -rates[1] / 3.0, 0.0
                    state[3, j] = max(sd * np.exp(step), floor)
                    target = min(1.0, rates[2] * state[3, j] / noise)
                    state[4, j] += (target - state[4, j]) * (rates[3] if target > state[4, j] else rates[4])
                if seen + 1.0 >= rates[0]:
                    scale[i, j] = state[4, j]
            state[0, j], state[1, j] = state[1, j], v
            state[2, j] = seen + 1.0
    return scale


@nb.njit(cache=True, nogil=True)
def noise_scale(x, noise, rates, state, counts, gamma):
    """`track_noise` of the input samples ``x`` onto the output grid, smoothed there: (m, channels).

    Input sample ``i`` covers ``counts[i]`` output samples (0 or 1 when
    downsampling); there a one-pole low-pass (``gamma`` of the way per
    output sample, its value in ``state[6]``, NaN before the first) smooths
    the scale from its first estimate on (1 before it), and within 1e-9 of 1
    it is 1: the declared noise exactly.
    """
    scale = track_noise(x, noise, rates, state)
    n, c = x.shape
    out = np.empty((counts.sum(), c))
    for j in range(c):
        m, z = 0, state[6, j]
        for i in range(n):
            for _ in range(counts[i]):
                if np.isnan(scale[i, j]):  # no estimate yet: the declared noise
                    out[m, j] = 1.0
                else:  # smoothed from the first estimate on
                    z = scale[i, j] if np.isnan(z) else z + gamma * (scale[i, j] - z)
                    out[m, j] = 1.0 if z > 1.0 - 1e-9 else z
                m += 1
        state[6, j] = z
    return out


@nb.njit(cache=True, nogil=True)
def track_band(y, scale, bandwidth_hz, cap_hz, fs, state):
    """The ramp-following tracker's slow band of ``y`` (n, channels), its bandwidth per sample
    ``min(bandwidth_hz / scale, cap_hz)``: the declared noise's at scale 1, wider as the noise is smaller.

    A critically damped alpha-beta tracker (`conditioning._tracker`: gains ``1 - q^2`` and ``(1 - q)^2``,
    ``q = exp(-2 pi bandwidth / fs)``); ``state`` (2, channels), position and velocity per sample, NaN
    before the first sample (then it starts there, at rest), carries over between chunks.
    """
    n, c = y.shape
    out = np.empty_like(y)
    for j in range(c):
        pos, vel = state[0, j], state[1, j]
        if np.isnan(pos):
            pos, vel = y[0, j], 0.0
        last, g, h = -1.0, 0.0, 0.0
        for i in range(n):
            k = scale[i, j]
            if k != last:  # the gains change only with the scale
                q = np.exp(-2.0 * np.pi * min(bandwidth_hz / max(k, 1e-12), cap_hz) / fs)
                g, h, last = 1.0 - q * q, (1.0 - q) ** 2, k
            residual = y[i, j] - pos - vel
            pos, vel = pos + vel + g * residual, vel + h * residual
            out[i, j] = pos
        state[0, j], state[1, j] = pos, vel
    return out


@nb.njit(cache=True, nogil=True)
def smooth_band(x, scale, cutoff_hz, cap_hz, fs, state):
    """A 2nd-order Butterworth low-pass of ``x`` (n, channels) at ``min(cutoff_hz / scale, cap_hz)`` per sample.

    A state-variable filter discretised by the trapezoidal rule (the bilinear transform, prewarped: at a
    fixed cutoff, `scipy.signal.butter`'s response).  Its states are the two integrators' (a direct
    form's would jump by a change of coefficients times the force: a pressed 3 N read through a scale
    that drifts fired FA-I in holds).  ``state`` (2, channels), NaN before the first sample (then it
    starts at rest on that sample), carries over between chunks.
    """
    n, c = x.shape
    out = np.empty_like(x)
    damping = np.sqrt(2.0)  # 1 / Q, Butterworth
    for j in range(c):
        last, a1, a2, a3 = -1.0, 0.0, 0.0, 0.0
        band, low = state[0, j], state[1, j]
        if np.isnan(low):
            band, low = 0.0, x[0, j]
        for i in range(n):
            k = scale[i, j]
            if k != last:
                g = np.tan(np.pi * min(cutoff_hz / max(k, 1e-12), cap_hz) / fs)
                a1 = 1.0 / (1.0 + g * (g + damping))
                a2, last = g * a1, k
                a3 = g * a2
            v3 = x[i, j] - low
            v1 = a1 * band + a2 * v3
            v2 = low + a2 * band + a3 * v3
            band, low = 2.0 * v1 - band, 2.0 * v2 - low
            out[i, j] = v2
        state[0, j], state[1, j] = band, low
    return out


class StreamSettings(NamedTuple):
    """The constants of a `Conditioner`'s steady pushes (`push_steady`: upsampling or at equal rates).

    Attributes
    ----------
    sos, ratio : ndarray, shape (sections, 6); float
        The resampling low-pass (at the output rate) and ``fs_out / fs_in`` (`hold_counts`).
    noise, adapt : float; bool
        The declared noise SD (N) and whether the noise is measured (`noise_scale`; else its scale is 1).
    rates, gamma : ndarray, shape (5,); float
        `noise_scale`'s rates (`track_noise`'s) and smoothing per output sample.
    bands : tuple of float
        ``(slow_hz, smooth_hz, cap_hz, fs)``: `track_band`'s and `smooth_band`'s arguments.
    masks : ndarray, shape (2, 7)
        The widths' entries the normal hold (before the smoothing) and the shear hold use.
    gate : GateSettings
        `gate_hold_contact`'s (``gate`` < 0: no noise gate, nor masks); its ``widths`` are the call's.
    """

    sos: np.ndarray
    ratio: float
    noise: float
    adapt: bool
    rates: np.ndarray
    gamma: float
    bands: tuple
    masks: np.ndarray
    gate: GateSettings


class StreamState(NamedTuple):
    """The state a `Conditioner` carries between pushes (`push_steady`; arrays, updated in place).

    Attributes
    ----------
    zi : ndarray, shape (sections, 2, channels)
        The resampling low-pass's (`sos_filter`).
    noise : ndarray, shape (7, channels)
        `noise_scale`'s (read only if ``StreamSettings.adapt``).
    slow, smooth : ndarray, shape (2, channels)
        `track_band`'s and `smooth_band`'s (read only with the noise gate).
    gate : GateState
        `gate_hold_contact`'s; its ``held`` and ``track`` are the normal hold's too.
    """

    zi: np.ndarray
    noise: np.ndarray
    slow: np.ndarray
    smooth: np.ndarray
    gate: GateState


@nb.njit(cache=True, nogil=True)
def push_steady(x, k, widths, settings, carry):
    """A `Conditioner`'s push once its states have started: the general path's kernel calls, in its order.

    ``x`` (n, 3) or (n, sites, 3), C-contiguous, n > 0, are the input samples from sample ``k`` on;
    ``widths`` the hold's (`conditioning.hold_widths`); ``settings`` a `StreamSettings`, ``carry`` a
    `StreamState` (updated in place), read by position: plain tuples dispatch ~3x faster than named
    ones.  Returns (finite, forces (m, sites, 3), contact (m, sites)); not finite: nothing changed.
    """
    sos, ratio, noise, adapt, rates, gamma, bands, masks, (gate, _, moves, on, off, deadband) = settings
    n = x.shape[0]
    x = x.reshape((n, x.size // n))
    sites = x.shape[1] // 3
    if not _all_finite(x):
        return False, np.empty((0, sites, 3)), np.empty((0, sites), dtype=np.bool_)
    counts = hold_counts(k, n, ratio)
    if adapt:
        scale = noise_scale(x, noise, rates, carry[1], counts, gamma)
    else:
        scale = np.ones((counts.sum(), x.shape[1]))
    y = sos_filter(sos, _repeat(x, counts), carry[0])
    shape = (y.shape[0], sites, 3)
    if y.shape[0] == 0:
        return True, np.empty(shape), np.empty(shape[:2], dtype=np.bool_)
    if gate >= 0.0:  # the noise gate: the slow band, and the kept band under the normal hold
        slow, kept = _steady_bands(y, scale, widths * masks[0], bands, moves, carry)
        widths = widths * masks[1]
    else:
        slow, kept = y, y
    out, contact = gate_hold_contact(y.reshape(shape), slow.reshape(shape), kept.reshape(shape),
                                     scale.reshape(shape), GateSettings(gate, widths, moves, on, off, deadband),
                                     carry[4])
    return True, out, contact


@nb.njit(cache=True, nogil=True)
def _steady_bands(y, scale, normal, bands, moves, carry):
    """`push_steady`'s slow band (`track_band`) and kept band (the normal hold `hold_band`, `smooth_band`)."""
    slow_hz, smooth_hz, cap, fs = bands
    slow = track_band(y, scale, slow_hz, cap, fs, carry[2])
    held = slow
    if not normal[:3].max() <= 0.0:  # as `Conditioner._hold` skips it
        shape = (y.shape[0], y.shape[1] // 3, 3)
        band = slow.reshape(shape).copy()
        hold_band(band, y.reshape(shape), normal, moves, carry[4][0], carry[4][1], scale.reshape(shape))
        held = band.reshape(y.shape)
    return slow, smooth_band(held, scale, smooth_hz, cap, fs, carry[3])


@nb.njit(cache=True, nogil=True)
def _all_finite(x):
    """Whether every entry of ``x`` (n, channels) is finite."""
    for v in x.flat:
        if not np.isfinite(v):
            return False
    return True


@nb.njit(cache=True, nogil=True)
def _repeat(x, counts):
    """Row ``i`` of ``x`` (n, channels) ``counts[i]`` times (`numpy.repeat` on rows): the zero-order hold."""
    y = np.empty((counts.sum(), x.shape[1]))
    m = 0
    for i in range(x.shape[0]):
        for _ in range(counts[i]):
            y[m] = x[i]
            m += 1
    return y
