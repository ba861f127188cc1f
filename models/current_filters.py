"""The causal filters of the current stage: Butterworth designs, their state between chunks, the rate check.

Derivatives of a raw force signal are useless, so each type's drive is
low-passed by a *causal* Butterworth filter (with RA-II's optional
high-pass) before its backward differences.  SciPy designs the sections,
kept on disk by their exact arguments (`lowpass_sos`); `type_filter_constants`
caches a type's sections and coefficients per (params, type, rate);
`check_fs` refuses a scene sampled too slowly for a type's band.  The
filters' state between chunks is one array per block of afferents
(`ddmm.models._fused_tables.rest_state`), so chunked and whole signals give
the same bits.
"""

from __future__ import annotations

import os
from functools import lru_cache

import numpy as np

from ddmm.models.afferent_types import afferent_type_codes, afferent_type_info
from ddmm.models.current_params import CurrentParams, TypeCurrentParams
from ddmm.utils.cache import cache_root
from ddmm.utils.deprecation import renamed_keyword, warn_renamed
from ddmm.utils.validation import check_positive

__all__ = ["RAII_FS_FACTOR", "check_fs", "lead_lag_sos", "lowpass_sos", "type_filter_constants"]

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


def lead_lag_sos(zero_hz: float, pole_hz: float, fs: float) -> np.ndarray:
    """One section of the first-order lead-lag ``(1 + s / w_z) / (1 + s / w_p)`` (w = 2 pi f; unit gain at 0 Hz).

    A zero below the pole is a lead (the drive follows the signal and its
    rate: gain ``pole_hz / zero_hz`` at high frequencies); a zero above the
    pole is a lag (high frequencies cut by ``pole_hz / zero_hz``).  Designed
    by the bilinear map without pre-warping, so it is stable at any rate;
    corners near or above ``fs / 2`` are compressed towards Nyquist.

    Parameters
    ----------
    zero_hz, pole_hz : float
        Corner frequencies in Hz (> 0).
    fs : float
        Sample rate in Hz.

    Returns
    -------
    ndarray, shape (1, 6)
        ``[b0, b1, 0, 1, a1, 0]``, as `lowpass_sos`'s sections.

    Examples
    --------
    >>> sos = lead_lag_sos(10.0, 100.0, 1000.0)
    >>> bool(abs(sos[0, :3].sum() / sos[0, 3:].sum() - 1.0) < 1e-12)  # unit gain at 0 Hz
    True
    """
    zero_hz, pole_hz = check_positive(zero_hz, "zero_hz", "Hz"), check_positive(pole_hz, "pole_hz", "Hz")
    fs = check_positive(fs, "fs", "Hz")
    tz, tp, k = 1.0 / (2.0 * np.pi * zero_hz), 1.0 / (2.0 * np.pi * pole_hz), 2.0 * fs
    # s -> k (1 - z^-1) / (1 + z^-1): (1 + tz s) / (1 + tp s), normalised to a0 = 1
    a0 = 1.0 + tp * k
    return np.array([[(1.0 + tz * k) / a0, (1.0 - tz * k) / a0, 0.0, 1.0, (1.0 - tp * k) / a0, 0.0]])


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


#: Moved to the reference oracle (`ddmm.models.reference_pipeline`), for one release.
_MOVED = ("filter_force", "initial_filter_state")


def __getattr__(name):
    if name in _MOVED:
        from ddmm.models import reference_pipeline

        warn_renamed(f"ddmm.models.current_filters.{name}", f"ddmm.models.reference_pipeline.{name}")
        return getattr(reference_pipeline, name)
    if name == "FilterState":
        raise AttributeError("FilterState was removed: filter state is one array per block of afferents "
                             "(ddmm.models._fused_tables.rest_state's layout)")
    raise AttributeError(f"module {__name__!r} has no attribute {name!r}")
