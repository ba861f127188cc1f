"""Depth waveforms of indentation stimuli (mm into the skin, one value a sample): the generators `indent` takes.

`ramp_hold`, `sinusoid`, `band_noise` and `impulse` give TouchSim's standard
stimuli as arrays sampled at ``fs`` Hz (`INDENT_FS`, 5 kHz, by default); any
other array of depths serves as well.  A waveform that would leave the skin
(a negative depth) is refused, naming the sample.  Their home is here; they
are importable from `ddmm.population.stimuli.indentation` too.
"""

from __future__ import annotations

import numpy as np

from ddmm.utils.resources import check_memory
from ddmm.utils.validation import check_nonnegative, check_positive, check_real

__all__ = ["INDENT_FS", "band_noise", "impulse", "ramp_hold", "sinusoid"]

#: Default sample rate of indentation stimuli in Hz (TouchSim's): FA-II's band needs 750 Hz at least.
INDENT_FS = 5000.0


def _timebase(duration_s: float, fs: float) -> np.ndarray:
    check_positive(duration_s, "duration_s", "s")
    check_positive(fs, "fs", "Hz")
    check_memory(64.0 * duration_s * fs, f"an indentation of {float(duration_s):g} s at {float(fs):g} Hz",
                 "shorten it or lower fs")  # as a scene's samples (`scenes`)
    n = int(round(duration_s * fs))
    if n < 2:
        raise ValueError(f"duration_s={float(duration_s):g} s at fs={float(fs):g} Hz gives {n} sample(s); need 2 or more")
    return np.arange(n) / fs


def _envelope(n: int, ramp_s: float, fs: float) -> np.ndarray:
    """Linear on and off ramps of ``ramp_s`` each (0: none) over ``n`` samples."""
    check_nonnegative(ramp_s, "ramp_s", "s")
    k = int(round(ramp_s * fs))
    if 2 * k > n:
        raise ValueError(f"ramp_s={float(ramp_s):g} s is longer than half the stimulus ({n / fs:g} s)")
    env = np.ones(n)
    if k:
        env[:k] = np.linspace(0.0, 1.0, k)
        env[n - k:] = np.linspace(1.0, 0.0, k)
    return env


def _checked_depth(depth: np.ndarray, what: str) -> np.ndarray:
    if np.any(depth < 0.0):
        i = int(np.argmax(depth < 0.0))
        raise ValueError(f"{what} leaves the skin: depth {float(depth[i]):g} mm at sample {i}; raise pre_indent_mm "
                         "so the probe stays in contact")
    return depth


def ramp_hold(depth_mm: float, *, ramp_s: float = 0.05, hold_s: float = 0.5, fs: float = INDENT_FS) -> np.ndarray:
    """Depth (mm) of a ramp-and-hold indentation: a linear ramp to ``depth_mm`` over ``ramp_s``, a hold of
    ``hold_s``, and a ramp back over ``ramp_s``, sampled at ``fs`` Hz.

    Examples
    --------
    >>> d = ramp_hold(0.5, ramp_s=0.1, hold_s=0.2, fs=1000.0)
    >>> d.size, float(d.max())
    (400, 0.5)
    """
    check_nonnegative(depth_mm, "depth_mm", "mm")
    check_nonnegative(ramp_s, "ramp_s", "s")
    check_positive(hold_s, "hold_s", "s")
    t = _timebase(2.0 * ramp_s + hold_s, fs)
    return float(depth_mm) * _envelope(t.size, ramp_s, fs)


def sinusoid(freq_hz: float, amplitude_mm: float, *, pre_indent_mm: float, duration_s: float = 1.0,
             ramp_s: float = 0.05, phase_deg: float = 0.0, fs: float = INDENT_FS) -> np.ndarray:
    """Depth (mm) of a vibration ``amplitude_mm`` at ``freq_hz`` about a pre-indentation, both ramped in and out.

    The probe must stay in the skin (``amplitude_mm <= pre_indent_mm``) and the rate carry the
    frequency (``freq_hz < fs / 2``).

    Examples
    --------
    >>> d = sinusoid(50.0, 0.05, pre_indent_mm=0.3, duration_s=0.2, fs=2000.0)
    >>> round(float(d.max()), 3) <= 0.35
    True
    """
    check_positive(freq_hz, "freq_hz", "Hz")
    check_positive(fs, "fs", "Hz")
    check_nonnegative(amplitude_mm, "amplitude_mm", "mm")
    check_nonnegative(pre_indent_mm, "pre_indent_mm", "mm")
    check_real(phase_deg, "phase_deg", "deg")
    if freq_hz >= fs / 2.0:
        raise ValueError(f"freq_hz={float(freq_hz):g} Hz needs fs above {2.0 * freq_hz:g} Hz, got fs={float(fs):g} Hz")
    if amplitude_mm > pre_indent_mm:
        raise ValueError(f"amplitude_mm={float(amplitude_mm):g} mm exceeds pre_indent_mm={float(pre_indent_mm):g} "
                         "mm: the probe would leave the skin each cycle")
    t = _timebase(duration_s, fs)
    wave = pre_indent_mm + amplitude_mm * np.sin(2.0 * np.pi * freq_hz * t + np.deg2rad(phase_deg))
    return _checked_depth(wave * _envelope(t.size, ramp_s, fs), "the sinusoid")


def band_noise(low_hz: float, high_hz: float, sd_mm: float, *, pre_indent_mm: float, duration_s: float = 1.0,
               ramp_s: float = 0.05, fs: float = INDENT_FS, rng=None) -> np.ndarray:
    """Depth (mm) of band-limited Gaussian noise (standard deviation ``sd_mm``, 3rd-order Butterworth band
    ``low_hz``-``high_hz``) about a pre-indentation, ramped in and out; ``rng`` a Generator, a seed or None.

    Examples
    --------
    >>> d = band_noise(100.0, 300.0, 0.01, pre_indent_mm=0.3, duration_s=0.5, rng=0)
    >>> bool(d.min() >= 0.0)
    True
    """
    from scipy.signal import butter, sosfilt

    from ddmm.utils.validation import check_rng

    for name, value in (("low_hz", low_hz), ("high_hz", high_hz), ("fs", fs)):
        check_positive(value, name, "Hz")
    check_positive(sd_mm, "sd_mm", "mm")
    check_nonnegative(pre_indent_mm, "pre_indent_mm", "mm")
    if not low_hz < high_hz < fs / 2.0:
        raise ValueError(f"need low_hz < high_hz < fs / 2; got {float(low_hz):g}, {float(high_hz):g} Hz at "
                         f"fs={float(fs):g} Hz")
    t = _timebase(duration_s, fs)
    raw = check_rng(rng).standard_normal(t.size)
    band = sosfilt(butter(3, [low_hz, high_hz], btype="bandpass", fs=fs, output="sos"), raw)
    wave = pre_indent_mm + sd_mm * band / np.std(band)
    return _checked_depth(wave * _envelope(t.size, ramp_s, fs), "the noise")


def impulse(amplitude_mm: float, *, width_s: float = 0.01, pad_s: float = 0.045, pre_indent_mm: float = 0.0,
            fs: float = INDENT_FS) -> np.ndarray:
    """Depth (mm) of a brief tap: a Gaussian pulse of peak ``amplitude_mm`` over ``width_s`` (+-3 SD) on a
    pre-indentation, with ``pad_s`` of the pre-indentation before and after.

    Examples
    --------
    >>> d = impulse(0.03, fs=5000.0)
    >>> d.size, float(d.max())
    (501, 0.03)
    """
    check_positive(amplitude_mm, "amplitude_mm", "mm")
    check_nonnegative(pad_s, "pad_s", "s")
    check_nonnegative(pre_indent_mm, "pre_indent_mm", "mm")
    check_positive(width_s, "width_s", "s")
    check_positive(fs, "fs", "Hz")
    check_memory(64.0 * (width_s + 2.0 * pad_s) * fs, f"an impulse of {float(width_s + 2.0 * pad_s):g} s at "
                 f"{float(fs):g} Hz", "shorten pad_s or lower fs")
    n = int(round(width_s * fs))
    if n < 5:
        raise ValueError(f"width_s={float(width_s):g} s is {n} samples at fs={float(fs):g} Hz; a pulse needs 5 "
                         "or more: raise fs or width_s")
    x = np.linspace(-3.0, 3.0, n | 1)  # an odd count: the peak falls on a sample
    pulse = amplitude_mm * np.exp(-0.5 * x * x)
    pad = np.zeros(int(round(pad_s * fs)))
    return pre_indent_mm + np.concatenate([pad, pulse, pad])
