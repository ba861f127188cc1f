"""The causal filters of the current stage: Butterworth designs, their state between chunks, the rate check.

Derivatives of a raw force signal are useless, so each type's drive is
low-passed by a *causal* Butterworth filter (with RA-II's optional
high-pass) before its backward differences.  SciPy designs the sections,
kept on disk by their exact arguments (`lowpass_sos`); `type_filter_constants`
caches a type's sections and coefficients per (params, type, rate);
`FilterState` carries a stage's state from one chunk to the next, so chunked
and whole signals give the same bits; `check_fs` refuses a scene sampled too
slowly for a type's band.
"""

from __future__ import annotations

import os
from dataclasses import dataclass
from functools import lru_cache

import numpy as np

from ddmm.models._stage_kernels import ReceptorNoise, StageConstants, TailState, UnitScales, stage_kernel
from ddmm.models.afferent_types import afferent_type_codes, afferent_type_info
from ddmm.models.current_params import CurrentParams, TypeCurrentParams
from ddmm.utils.cache import cache_root
from ddmm.utils.deprecation import renamed_keyword, warn_renamed
from ddmm.utils.validation import as_finite_array, check_instance, check_positive

__all__ = ["RAII_FS_FACTOR", "FilterState", "check_fs", "filter_force", "initial_filter_state", "lowpass_sos",
           "type_filter_constants"]

#: A scene must be sampled at least this many times faster than RA-II's cut-off
#: (its `ddmm.models.afferent_types.AfferentType.fs_per_cutoff`).
RAII_FS_FACTOR = afferent_type_info("RAII").fs_per_cutoff


@renamed_keyword("types", "afferent_types")
def check_fs(fs: float, params: CurrentParams, afferent_types=None) -> None:
    """Refuse a sample rate too slow for a type's filter band.

    A type with `AfferentType.fs_per_cutoff` needs ``fs >= fs_per_cutoff * cutoff``
    (RA-II's 2.5: its band must sit well below the Nyquist frequency); every
    filter needs its cut-off below ``fs / 2``.

    Raises
    ------
    ValueError
        Naming the type, its band and the rate needed.
    """
    for kind in afferent_type_codes() if afferent_types is None else afferent_types:
        stage = params.for_type(kind)
        if stage.cutoff_hz is None:
            continue
        factor = afferent_type_info(kind).fs_per_cutoff
        if factor is not None:
            too_slow, need = fs < factor * stage.cutoff_hz, f"at >= {factor * stage.cutoff_hz:g} Hz"
        else:  # a cut-off at or above Nyquist is no filter
            too_slow, need = stage.cutoff_hz >= fs / 2.0, f"faster than {2.0 * stage.cutoff_hz:g} Hz"
        if too_slow or stage.cutoff_hz >= fs / 2.0:
            raise ValueError(
                f"fs={fs:g} Hz is too slow for {kind}: its band reaches {stage.cutoff_hz:g} Hz, which needs force "
                f"sampled {need}; resample the scene faster (from_csv(fs=...)) or leave {kind} out (afferent_types=...)"
            )


@dataclass(frozen=True)
class FilterState:
    """State of a type's causal filter, backward differences and adaptation between chunks.

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
    slow : ndarray, shape (n_afferents,) or None
        Slow-adaptation low-pass of the filtered deviation (SA-I), in newtons.
    smooth : ndarray, shape (n_afferents,) or None
        The current's low-pass state in mV/ms (before the bias).
    dyn : ndarray, shape (n_afferents,) or None
        The dynamic response's low-pass of the current in mV/ms (SA-I).
    fast, rise : ndarray, shape (n_afferents,) or None
        The fast transient's two low-passes of the current in mV/ms (SA-I):
        of ``tau_transient_sai_s`` and of half that.
    """

    zi: np.ndarray
    offset: np.ndarray
    y1: np.ndarray
    y2: np.ndarray
    slow: np.ndarray | None = None
    smooth: np.ndarray | None = None
    dyn: np.ndarray | None = None
    fast: np.ndarray | None = None
    rise: np.ndarray | None = None


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
    return _designed("low", order, cutoff_hz, fs)


def _designed(btype: str, order: int, cutoff_hz: float, fs: float) -> np.ndarray:
    """`scipy.signal.butter` sections, kept on disk (``$DDMM_CACHE_DIR/filters``) by their exact arguments.

    Importing scipy.signal costs about 0.4 s, most of a warm start; the
    cached file holds scipy's own float64 coefficients, so results are the
    same bits either way.
    """
    path = _filter_cache() / f"butter_{btype}_{order}_{float(cutoff_hz).hex()}_{float(fs).hex()}.npy"
    try:
        return np.load(path)
    except (OSError, ValueError):
        pass
    from scipy import signal

    sos = signal.butter(order, cutoff_hz, btype=btype, fs=fs, output="sos")
    try:
        path.parent.mkdir(parents=True, exist_ok=True)
        tmp = path.with_suffix(f".{os.getpid()}.tmp.npy")
        np.save(tmp, sos)
        os.replace(tmp, path)  # atomic: a reader sees the whole file or none
    except OSError:
        pass  # a read-only cache only costs the import next time
    return sos


def _filter_cache():
    return cache_root() / "filters"


_PASS_THROUGH = np.array([[1.0, 0.0, 0.0, 1.0, 0.0, 0.0]])  # an identity section: no filter


def _stage_sos(stage: TypeCurrentParams, fs: float) -> np.ndarray:
    if stage.cutoff_hz is None:
        return _PASS_THROUGH
    if not stage.cutoff_hz < fs / 2.0:
        lowpass_sos(stage.cutoff_hz, stage.order, fs)  # raises with the Nyquist message
    sos = _butter_sos(float(stage.cutoff_hz), int(stage.order), float(fs))
    if stage.highpass_hz is not None:
        sos = np.vstack([_highpass_sos(float(stage.highpass_hz), float(fs)), sos])
    return sos


@lru_cache(maxsize=16)
def _highpass_sos(cutoff_hz: float, fs: float) -> np.ndarray:
    return _designed("high", 2, cutoff_hz, fs)


def initial_filter_state(f0, fs: float, params: CurrentParams = CurrentParams(), afferent_type: str = "RAI"
                         ) -> FilterState:
    """Filter state at rest on a constant input ``f0`` (newtons).

    Starting at steady state means a trace that begins mid-contact produces
    no spurious derivative at its first sample; a trace that starts at rest
    (F_A = 0) is unaffected.  ``afferent_type`` selects the stage's filter.
    """
    f0 = np.atleast_1d(np.asarray(f0, dtype=float)).copy()
    sos = _stage_sos(params.for_type(afferent_type), fs)
    zeros = np.zeros_like(f0)
    return FilterState(zi=np.zeros((sos.shape[0], 2, f0.size)), offset=f0, y1=zeros, y2=zeros.copy(),
                       slow=zeros.copy(), smooth=zeros.copy(), dyn=zeros.copy(),
                       fast=zeros.copy(), rise=zeros.copy())


_NO_NORMALS = np.zeros((1, 0))  # no receptor noise: the stage kernel draws nothing


def filter_force(f_a, fs: float, params: CurrentParams = CurrentParams(), state=None):
    """Causally low-pass F_A along time (axis 0) with the shared filter (``cutoff_hz``).

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
    fs = check_positive(fs, "fs", "Hz")
    check_instance(params, "params", CurrentParams, "a CurrentParams")
    shared = TypeCurrentParams("RAI", 0, params.cutoff_hz, params.filter_order, 0.0, 1.0, 1.0, None, None, 0.0)
    if state is None:
        state = initial_filter_state(f_a[0], fs, params)
    m = f_a.shape[1]
    zi, y1, y2 = state.zi.copy(), state.y1.copy(), state.y2.copy()
    slow = np.zeros(m)
    # The stage kernel with order 0, unit gain and a signed drive returns exactly deviation + offset.
    tail = TailState(state.offset, y1, y2, slow)
    y = stage_kernel(_stage_sos(shared, float(fs)), np.ascontiguousarray(f_a), zi, tail,
                     StageConstants(float(fs), 0, 0.0, 0.0, False, 1.0, True),
                     UnitScales(np.ones(m), np.zeros(m), np.ones(m)), ReceptorNoise(_NO_NORMALS, False))
    return y, FilterState(zi=zi, offset=state.offset, y1=y1, y2=y2, slow=slow, smooth=state.smooth)


@lru_cache(maxsize=256)
def type_filter_constants(params: CurrentParams, afferent_type: str, fs: float):
    """(stage, filter sections, adaptation and smoothing coefficients), cached: per call they would
    cost a short chunk more than its arithmetic."""
    stage = params.for_type(afferent_type)
    alpha_adapt = float(-np.expm1(-1.0 / (fs * stage.tau_adapt_s)))
    alpha_smooth = 0.0 if stage.tau_s is None else float(-np.expm1(-1.0 / (fs * stage.tau_s)))
    return stage, _stage_sos(stage, fs), alpha_adapt, alpha_smooth


def stage_constants(params: CurrentParams, afferent_type: str, fs: float):
    """Deprecated name of `type_filter_constants` ("stage" names a scene's interval)."""
    warn_renamed("stage_constants()", "type_filter_constants()")
    return type_filter_constants(params, afferent_type, fs)
