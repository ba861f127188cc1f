"""The offline, two-way conditioning (``Conditioning(mode="zero_phase")``): no lag, not causal."""

from __future__ import annotations

import math

import numpy as np

from ddmm.population.stimuli._conditioning_kernels import hold_band
from ddmm.population.stimuli.conditioning import (
    _GATE,
    _NORMAL_ONLY,
    _ORDER,
    _SHEAR_ONLY,
    _SMOOTH,
    Conditioner,
    Conditioning,
    _lowpass,
    _start_track,
    _tracker,
)

__all__ = ["zero_phase"]


def zero_phase(forces, fs_in, fs_out, conditioning, n_sites):
    """`condition_forces` with ``mode="zero_phase"``: monotone cubic resampling, the filters and holds run
    forwards and backwards, one noise scale for the whole recording."""
    from scipy.interpolate import PchipInterpolator
    from scipy.signal import sosfiltfilt

    causal = Conditioner(Conditioning(**{**conditioning.__dict__, "mode": "causal"}), fs_in, fs_out, n_sites)
    x = causal._shape(forces)
    t_in = np.arange(x.shape[0]) / fs_in
    t_out = np.arange(int(math.floor((x.shape[0] - 1) * fs_out / fs_in + 1e-9)) + 1) / fs_out
    y = PchipInterpolator(t_in, x, axis=0)(t_out) if x.shape[0] > 2 else np.stack(
        [np.interp(t_out, t_in, col) for col in x.T], axis=1)
    padlen = min(y.shape[0] - 1, 3 * (2 * _ORDER + 1))
    if conditioning.bandwidth_hz is not None and conditioning.bandwidth_hz < 0.45 * fs_out:
        y = sosfiltfilt(_lowpass(conditioning.bandwidth_hz, fs_out), y, axis=0, padlen=padlen)
    slow, kept, gate = y, y, -1.0
    widths, moves = causal.widths, causal._moves  # the causal widths: the two-way filters' noise is no larger
    # one noise scale over the whole recording: the largest channel's median of the causal tracker's
    level = max(float(np.median(causal._noise_scale(x, causal._counts(x.shape[0])), axis=0).max()), 1e-12)
    scale = np.full((y.shape[0], y.shape[1] // 3, 3), level)
    if conditioning.noise_n > 0:
        cap, bandwidth = 0.45 * fs_out, conditioning.slow_hz / level
        slow = sosfiltfilt(_tracker(min(bandwidth, cap), fs_out), y, axis=0, padlen=padlen)
        held = _hold_both_ways(np.ascontiguousarray(slow), y, widths * _NORMAL_ONLY, moves, scale)
        smooth = _lowpass(min(_SMOOTH * bandwidth, cap), fs_out)
        kept, gate = sosfiltfilt(smooth, held, axis=0, padlen=padlen), _GATE * conditioning.noise_n
        widths = widths * _SHEAR_ONLY
    kept = _hold_both_ways(np.ascontiguousarray(kept), y, widths, moves, scale)
    return causal._out(*causal._finish(np.ascontiguousarray(y), np.ascontiguousarray(slow), kept, gate,
                                       np.zeros(7), scale))



def _hold_both_ways(kept, y, widths, moves, scale):
    """The force hold run forwards and backwards, averaged: no lag, constant on a hold, as the other filters here."""
    if widths[:3].max() <= 0.0 or kept.shape[0] == 0:
        return kept
    shape = (kept.shape[0], kept.shape[1] // 3, 3)
    forward, backward = kept.reshape(shape).copy(), kept[::-1].reshape(shape).copy()
    ref = np.ascontiguousarray(y).reshape(shape)
    scale = np.ascontiguousarray(scale)
    hold_band(forward, ref, widths, moves, np.array(forward[0]), _start_track(shape[1]), scale)  # copies: in place
    hold_band(backward, np.ascontiguousarray(ref[::-1]), widths, moves, np.array(backward[0]), _start_track(shape[1]),
              np.ascontiguousarray(scale[::-1]))
    held = widths[:3] > 0.0
    forward[..., held] = 0.5 * (forward[..., held] + backward[::-1][..., held])
    return forward.reshape(kept.shape)
