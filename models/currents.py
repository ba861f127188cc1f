"""Afferent currents from the attenuated force (paper eqs 1-3).

* SAI follows force:            ``I = g_sai * |F_A|``           (eq. 1)
* RAI its rate of change:       ``I = g_rai * |dF_A/dt|``       (eq. 2)
* RAII its acceleration:        ``I = g_raii * |d^2F_A/dt^2|``  (eq. 3)

By default the drive is used as is (the paper's linear eqs).  An optional
compressive transducer ``I = i_sat * log1p(x / i_sat)`` bounds the rates on
fast ramps: with the Table III gains, Birznieks' 32 N/s ramp drives RAI to
~1.8 kHz and RAII to one spike per step in 10 ms bins, because the
Izhikevich rate grows ~2.2 Hz per unit current without bound.  The README
("Model") records the measured trade-off.

Derivatives of a raw force signal are useless (DDMM-NOTES §1.6), so F_A is
low-passed first by a *causal* Butterworth filter and differentiated by
backward differences.  Both keep explicit state (`FilterState`), so a signal
cut into chunks gives exactly the currents of the whole signal: streaming and
offline runs agree bit for bit.  SciPy designs the filter; a small numba
kernel runs it (direct form II transposed, SciPy's algorithm), because the
streaming encoder calls it once per millisecond and ``sosfilt``'s ~0.1 ms call
overhead alone would exceed its latency budget.  Offline and streaming use the
same kernel, so their arithmetic is identical by construction.

Currents are in the Izhikevich model's own units (mV/ms, the units of
``dv/dt`` in eq. 4); the gains convert newtons to them.
"""

from __future__ import annotations

from dataclasses import dataclass
from functools import lru_cache

import numba as nb
import numpy as np
from scipy import signal

from ._validation import as_finite_array, check_choice, check_positive

__all__ = [
    "AFFERENT_TYPES",
    "CurrentParams",
    "FilterState",
    "lowpass_sos",
    "initial_filter_state",
    "filter_force",
    "afferent_current",
    "current_core",
]

#: The afferent types of the model, in the order used throughout the package.
AFFERENT_TYPES = ("SAI", "RAI", "RAII")


@dataclass(frozen=True)
class CurrentParams:
    """Gains and derivative filter of the current stage (eqs 1-3).

    The gains are calibrated so that the CMM (AF = 1) press-push-lift response
    lies near paper Table III (SAI about 47.5 pulses/s, RAI and RAII 10-20);
    ``experiments/calibrate_core.py`` reproduces the fit.

    Attributes
    ----------
    g_sai : float
        SAI gain, (mV/ms) per N (eq. 1).
    g_rai : float
        RAI gain, (mV/ms) per (N/s) (eq. 2).
    g_raii : float
        RAII gain, (mV/ms) per (N/s^2) (eq. 3).
    cutoff_hz : float
        Cut-off of the causal Butterworth low-pass applied to F_A before
        differentiation, in Hz (DDMM-NOTES §1.6: 20 Hz restores Table III's
        aligned > misaligned ordering for RAII).
    filter_order : int
        Order of that Butterworth filter (2 in the notes' trial).
    i_sat : float or None
        Scale of the compressive transducer in mV/ms, for every type:
        ``I = i_sat * log1p(g * x / i_sat)``, about ``g * x`` while
        ``g * x << i_sat``.  None: the paper's linear eqs 1-3 verbatim.
    i_sat_sai, i_sat_rai, i_sat_raii : float or None
        Per-type scales; when given they override ``i_sat`` for that type.
    """

    g_sai: float = 5.367  # fitted: CMM SAI SF 47.5 pulses/s (Table III)
    g_rai: float = 11.036  # fitted: CMM RAI SF 15 pulses/s (Table III)
    g_raii: float = 6.162  # fitted: CMM RAII SF 10 pulses/s (Table III)
    cutoff_hz: float = 20.0
    filter_order: int = 2
    i_sat: float | None = None
    i_sat_sai: float | None = None
    i_sat_rai: float | None = None
    i_sat_raii: float | None = None

    def __post_init__(self):
        for name in ("g_sai", "g_rai", "g_raii", "cutoff_hz"):
            check_positive(getattr(self, name), name)
        for name in ("i_sat", "i_sat_sai", "i_sat_rai", "i_sat_raii"):
            if getattr(self, name) is not None:
                check_positive(getattr(self, name), name, "mV/ms")
        if not isinstance(self.filter_order, int) or not 1 <= self.filter_order <= 8:
            raise ValueError(f"filter_order must be an int in [1, 8], got {self.filter_order!r}")

    def gain(self, afferent_type: str) -> float:
        """The gain of ``afferent_type`` (``"SAI"``, ``"RAI"`` or ``"RAII"``)."""
        check_choice(afferent_type, "afferent_type", AFFERENT_TYPES)
        return {"SAI": self.g_sai, "RAI": self.g_rai, "RAII": self.g_raii}[afferent_type]

    def saturation(self, afferent_type: str) -> float | None:
        """The transducer scale of ``afferent_type`` in mV/ms (None: linear)."""
        own = {"SAI": self.i_sat_sai, "RAI": self.i_sat_rai, "RAII": self.i_sat_raii}[afferent_type]
        return self.i_sat if own is None else own


@dataclass(frozen=True)
class FilterState:
    """State of the causal low-pass and backward differences between chunks.

    The filter runs on the deviation from ``offset`` (the first sample), so a
    constant force is filtered exactly and gives exactly zero RAI/RAII current.

    Attributes
    ----------
    zi : ndarray, shape (n_sections, 2, n_afferents)
        Second-order-section state of `scipy.signal.sosfilt`.
    offset : ndarray, shape (n_afferents,)
        Force subtracted before filtering, in newtons.
    y1, y2 : ndarray, shape (n_afferents,)
        The last and second-to-last filtered deviations, in newtons.
    """

    zi: np.ndarray
    offset: np.ndarray
    y1: np.ndarray
    y2: np.ndarray


def lowpass_sos(cutoff_hz: float, order: int, fs: float) -> np.ndarray:
    """Second-order sections of the Butterworth low-pass (cut-off in Hz, fs in Hz).

    Examples
    --------
    >>> lowpass_sos(20.0, 2, 1000.0).shape
    (1, 6)
    """
    fs = check_positive(fs, "fs", "Hz")
    if not cutoff_hz < fs / 2.0:
        raise ValueError(
            f"cutoff_hz={cutoff_hz!r} must be below the Nyquist frequency fs/2 = {fs / 2.0} Hz"
        )
    return _butter_sos(float(cutoff_hz), int(order), fs).copy()


@lru_cache(maxsize=64)
def _butter_sos(cutoff_hz: float, order: int, fs: float) -> np.ndarray:
    return signal.butter(order, cutoff_hz, btype="low", fs=fs, output="sos")


def initial_filter_state(f0, fs: float, params: CurrentParams = CurrentParams()) -> FilterState:
    """Filter state at rest on a constant input ``f0`` (newtons).

    Starting at steady state means a trace that begins mid-contact produces
    no spurious derivative at its first sample; a trace that starts at rest
    (F_A = 0) is unaffected.
    """
    f0 = np.atleast_1d(np.asarray(f0, dtype=float)).copy()
    sos = lowpass_sos(params.cutoff_hz, params.filter_order, fs)
    zeros = np.zeros_like(f0)
    return FilterState(zi=np.zeros((sos.shape[0], 2, f0.size)), offset=f0, y1=zeros, y2=zeros.copy())


@nb.njit(cache=True, nogil=True)
def _derivative_kernel(sos, f_a, offset, zi, y1, y2, fs, order):
    """Filter the deviation from ``offset`` (direct form II transposed, SciPy's
    ``sosfilt`` arithmetic) and return it (order 0) or its backward difference
    ``(y - y1) fs`` (order 1) or ``(y - 2 y1 + y2) fs^2`` (order 2), in one pass.

    ``zi`` (sections, 2, channels), ``y1`` and ``y2`` carry the state and are
    updated in place.
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
                out[n, j] = cur
            elif order == 1:
                out[n, j] = (cur - y1[j]) * fs
            else:
                out[n, j] = ((cur - 2.0 * y1[j]) + y2[j]) * fs2
            y2[j] = y1[j]
            y1[j] = cur
    return out


def _run_kernel(f_a, fs, params, state: FilterState, order: int):
    """`_derivative_kernel` on copies of the state; returns (output, new state)."""
    sos = _butter_sos(float(params.cutoff_hz), int(params.filter_order), fs)
    zi, y1, y2 = state.zi.copy(), state.y1.copy(), state.y2.copy()
    out = _derivative_kernel(sos, np.ascontiguousarray(f_a), state.offset, zi, y1, y2, float(fs), order)
    return out, FilterState(zi=zi, offset=state.offset, y1=y1, y2=y2)


def filter_force(f_a, fs: float, params: CurrentParams = CurrentParams(), state=None):
    """Causally low-pass F_A along time (axis 0).

    Parameters
    ----------
    f_a : array_like, shape (n_samples, n_afferents)
        Attenuated force in newtons.
    fs : float
        Sample rate in Hz.
    params : CurrentParams
        Filter cut-off and order.
    state : FilterState, optional
        State carried from the previous chunk; default: at rest on the first
        sample.

    Returns
    -------
    y : ndarray, shape (n_samples, n_afferents)
        Filtered force in newtons.
    state : FilterState
        State after the last sample.
    """
    f_a = as_finite_array(f_a, "f_a", ndim=2)
    if state is None:
        state = initial_filter_state(f_a[0], fs, params)
    dev, new_state = _run_kernel(f_a, fs, params, state, 0)
    return dev + state.offset, new_state


def afferent_current(
    f_a,
    fs: float,
    afferent_type: str,
    params: CurrentParams = CurrentParams(),
    state: FilterState | None = None,
    scale=None,
):
    """Input current of afferents of one type (eqs 1-3).

    Parameters
    ----------
    f_a : array_like, shape (n_samples, n_afferents)
        Attenuated force F_A in newtons at sample rate ``fs``.
    fs : float
        Sample rate in Hz.
    afferent_type : {"SAI", "RAI", "RAII"}
        Which of eqs 1-3 to apply.
    params : CurrentParams
        Gains and derivative filter.
    state : FilterState, optional
        Filter state carried over from a previous chunk (RAI and RAII only).
    scale : array_like, shape (n_afferents,), optional
        Per-afferent multiplier of the drive (gain variability, receptive
        field weight), applied before the optional compressive transducer.

    Returns
    -------
    current : ndarray, shape (n_samples, n_afferents)
        Rectified current in mV/ms (Izhikevich units), >= 0.
    state : FilterState or None
        Filter state after the chunk (None for SAI, which needs no filter).

    Examples
    --------
    >>> f = np.linspace(0.0, 1.0, 1001)[:, None]          # 1 N/s ramp at 1 kHz
    >>> i, _ = afferent_current(f, 1000.0, "RAI", CurrentParams(g_rai=1.0))
    >>> round(float(i[-1, 0]), 2)                          # settles at 1 N/s
    1.0
    """
    check_choice(afferent_type, "afferent_type", AFFERENT_TYPES)
    fs = check_positive(fs, "fs", "Hz")
    f_a = as_finite_array(f_a, "f_a", ndim=2)
    return current_core(f_a, fs, afferent_type, params, state, scale)


def current_core(f_a, fs, afferent_type, params, state=None, scale=None):
    """`afferent_current` without validation (the streaming encoder's hot path)."""
    gain = params.gain(afferent_type)
    if scale is not None:
        gain = gain * np.asarray(scale, dtype=float)
    i_sat = params.saturation(afferent_type)
    if afferent_type == "SAI":
        return _saturate(gain * np.abs(f_a), i_sat), None
    if state is None:
        state = initial_filter_state(f_a[0], fs, params)
    deriv, new_state = _run_kernel(f_a, fs, params, state, 1 if afferent_type == "RAI" else 2)
    return _saturate(gain * np.abs(deriv), i_sat), new_state


def _saturate(drive, i_sat):
    """Compressive transduction of the linear drive (see the module docstring)."""
    if i_sat is not None:
        drive = i_sat * np.log1p(drive / i_sat)
    return drive
