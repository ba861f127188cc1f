"""The reference oracle: the DDMM from forces to currents one stage at a time, in numpy.

The package computes currents on one production path, `ddmm.models.fused.FusedPipeline`
(two numba passes over samples, every constant in typed tables), which
`ddmm.models.pipeline.compute_currents`, `simulate`, the streaming encoder, the paper
reproductions and the calibration all run on.  This module computes the same
currents the readable way, each stage over whole arrays:

1. AF of the shear direction (`ddmm.models.attenuation.attenuation_factor`, eqs 16-17);
2. the drive: F_A (`attenuated_force`, eq. 18, with the presets' ``depth``), the
   presets' shear-magnitude term (`shear_drive`), or SA-II's stretch (`stretch_drive`);
3. each type's current stage (`afferent_current`: filter, derivative,
   adaptation, gain, receptor noise, transducer, low-pass, dynamic response
   and bias; the model is described in `ddmm.models.currents`).

It is the explicit oracle the production path is held to, bit for bit
(``tests/models/test_reference_pipeline.py`` and ``tests/models/test_fused.py``):
nothing in the package runs on it.  Both paths share the scalar and
per-sample kernels (`ddmm.models._stage_kernels`, `attenuation.profile_value`),
so an arithmetic change reaches both, and both keep the operations' order.

Filter state between chunks has the production path's layout
(`ddmm.models._fused_tables.rest_state`): two rows per filter section, then
the offset, the last two filtered deviations, the slow adaptation, the
current's low-pass and the dynamic response's three low-passes, one column
per afferent.  A one-type `FusedPipeline` of untuned afferents holds the same
numbers after the same chunk.
"""

from __future__ import annotations

import numpy as np

from ddmm.models._fused_tables import _DYNC, _FASTC, _OFFSET, _RISEC, _SLOW, _SMOOTH, _Y1, _Y2, rest_state
from ddmm.models._stage_kernels import (
    ReceptorNoise,
    StageConstants,
    TailState,
    UnitScales,
    dynamic_kernel,
    smooth_kernel,
    stage_kernel,
)
from ddmm.models._transducer_kernels import transduce_inplace
from ddmm.models.afferent_types import afferent_type_codes, afferent_type_info, normalize_type
from ddmm.models.attenuation import F_TH, attenuation_factor, profile_factor, shear_magnitude
from ddmm.models.current_filters import _stage_sos, check_fs, type_filter_constants
from ddmm.models.current_params import CurrentParams, TypeCurrentParams
from ddmm.models.currents import unit_thresholds
from ddmm.models.pipeline import check_afferents
from ddmm.models.variability import tonic_current
from ddmm.utils.validation import as_finite_array, as_float_array, check_forces, check_instance, check_positive, shown

__all__ = ["afferent_current", "attenuated_force", "current_core", "filter_force", "initial_filter_state",
           "reference_currents", "shear_drive", "stretch_drive"]

_NO_NORMALS = np.zeros((1, 0))  # no receptor noise: the stage kernel draws nothing


def reference_currents(fx, fy, fz, *, fs: float, afferent_type, profile: str = "selective", theta_t=90.0, k=3.0,
                       no_shear: str = "pass", f_th: float = F_TH,
                       current_params: CurrentParams = CurrentParams()) -> np.ndarray:
    """Currents (mV/ms) of N afferents sharing one NAP profile, stage by stage (eqs 1-3, 16-18).

    Arguments and result are those of `ddmm.models.pipeline.compute_currents`, which
    gives the same bits on the production path.

    Examples
    --------
    >>> fz = np.r_[np.linspace(0, 4, 125), np.full(250, 4.0)]
    >>> i = reference_currents(np.zeros(375), np.zeros(375), fz, fs=1000.0,
    ...                        afferent_type="SAI", profile="none", theta_t=[0.0])
    >>> i.shape
    (375, 1)
    """
    fx, fy, fz = check_forces(fx, fy, fz)
    fs = check_positive(fs, "fs", "Hz")
    check_instance(current_params, "current_params", CurrentParams, "a CurrentParams")
    theta, types, _ = check_afferents(theta_t, afferent_type, profile, k)  # AF validates k as the paper's
    af = attenuation_factor(fx, fy, theta, profile, k, f_th=f_th, no_shear=no_shear)
    drive = attenuated_force(fz, af)
    k_all = np.broadcast_to(k, theta.shape)
    for kind in afferent_type_codes():
        cols = np.flatnonzero(types == kind)
        if cols.size:
            drive[:, cols] = _type_drive(kind, current_params.for_type(kind), (fx, fy, fz), af[:, cols],
                                         drive[:, cols], (theta[cols], profile, k_all[cols]))
    current = np.empty_like(drive)
    for kind in afferent_type_codes():
        cols = np.flatnonzero(types == kind)
        if cols.size:
            current[:, cols], _ = afferent_current(drive[:, cols], fs, kind, current_params)
    return current


def _type_drive(kind, stage, forces, af, f_a, tuning):
    """One type's drive (N): F_A with its ``depth`` and shear-magnitude term, or its stretch drive."""
    fx, fy, fz = forces
    theta, profile, k = tuning
    if afferent_type_info(kind).stretch_drive:  # SA-II's: the attenuated shear (skin stretch), not F_Z
        raw = profile_factor(fx, fy, theta, profile, k)
        return stretch_drive(fx, fy, raw, stage.opponent, fz, stage.normal)
    if stage.depth != 1.0:
        f_a = attenuated_force(fz, af, stage.depth)
    if stage.shear != 0.0:
        raw = profile_factor(fx, fy, theta, profile, k)
        f_a = shear_drive(f_a, fx, fy, raw, stage.shear, stage.opponent_shear)
    return f_a


def attenuated_force(fz, af, depth: float = 1.0) -> np.ndarray:
    """Attenuated force F_A = AF * F_Z in newtons (eq. 18), or ``(1 + depth (AF - 1)) F_Z``.

    Parameters
    ----------
    fz : array_like, shape (n_samples,)
        Normal force in newtons.
    af : array_like, shape (n_samples, n_afferents)
        Attenuation factors from `ddmm.models.attenuation.attenuation_factor`.
    depth : float
        How deep the attenuation goes, in [0, 1] (``<TYPE>.depth``;
        1, the default, is eq. 18; 0 passes F_Z whatever the direction).

    Examples
    --------
    >>> attenuated_force([2.0], [[0.5, 1.0]]).tolist()
    [[1.0, 2.0]]
    >>> attenuated_force([2.0], [[0.5, 1.0]], depth=0.5).tolist()
    [[1.5, 2.0]]
    """
    fz = as_finite_array(fz, "fz", ndim=1)
    if isinstance(depth, bool) or not isinstance(depth, (int, float)) or not 0.0 <= depth <= 1.0:
        raise ValueError(f"depth must be a number in [0, 1] (1: eq. 18), got {shown(depth)}")
    af = as_float_array(af, "af", ndim=2)
    if af.shape[0] != fz.size:
        raise ValueError(f"af must have one row per sample of fz ({fz.size}), got shape {af.shape}")
    if depth != 1.0:  # the `_fused_drive._sheared` arithmetic, in its order
        af = 1.0 + depth * (af - 1.0)
    return af * fz[:, None]


def stretch_drive(fx, fy, af, opponent: float = 0.0, fz=None, normal: float = 0.0) -> np.ndarray:
    """SA-II's signed stretch drive ``F_S (AF - opponent (1 - AF))`` in newtons, plus ``normal * F_Z``.

    ``af`` is the profile's AF (shape (n_samples, n_afferents)) on the shear
    direction; stretch along the preferred direction drives the afferent,
    stretch against it lowers the drive when ``opponent > 0``.  With
    ``normal > 0`` (``SAII.normal``) the normal force ``fz`` (N, shape
    (n_samples,) or (n_samples, n_afferents)) adds to it.

    Examples
    --------
    >>> stretch_drive([0.0], [2.0], [[1.0, 0.0]], opponent=0.5).tolist()
    [[2.0, -1.0]]
    """
    f_s = shear_magnitude(fx, fy)
    af = np.asarray(af, dtype=float)
    drive = f_s[:, None] * (af - opponent * (1.0 - af))
    if normal != 0.0:
        fz = np.asarray(fz, dtype=float)
        drive = drive + normal * (fz[:, None] if fz.ndim == 1 else fz)
    return drive


def shear_drive(f_a, fx, fy, af, gain: float, opponent: float = 0.0) -> np.ndarray:
    """A pressure type's drive with its shear-magnitude term, ``max(F_A + gain * stretch_drive, 0)`` (N).

    ``f_a`` is F_A (shape (n_samples, n_afferents)); ``af`` the profile's own
    AF on the shear direction (`ddmm.models.attenuation.profile_factor`, no
    threshold), ``gain`` the type's ``<TYPE>.shear`` and ``opponent`` its
    ``<TYPE>.opponent_shear``.  With ``gain == 0`` F_A is returned as it is
    (the paper's drive).  The floor keeps the drive a pressure: a negative
    drive would read as force to the rectified FA stages.

    Examples
    --------
    >>> shear_drive([[2.0, 0.4]], [0.0], [1.0], [[1.0, 0.2]], 1.0, opponent=1.0).tolist()
    [[3.0, 0.0]]
    """
    f_a = np.asarray(f_a, dtype=float)
    if gain == 0.0:
        return f_a
    x = f_a + gain * stretch_drive(fx, fy, af, opponent)
    return np.where(x > 0.0, x, 0.0)  # floored: shear against the preferred direction silences, never pulls


def afferent_current(f_a, fs: float, afferent_type: str, params: CurrentParams = CurrentParams(), state=None,
                     scale=None, sensitivity=None):
    """Input current of afferents of one type (eqs 1-3, or the type's own stage).

    Parameters
    ----------
    f_a : array_like, shape (n_samples, n_afferents)
        Attenuated force F_A in newtons at sample rate ``fs`` (for SA-II, the
        signed stretch drive in newtons, `stretch_drive`).
    fs : float
        Sample rate in Hz.
    afferent_type : str
        A registered type code (``"SAI"``, ``"RAI"``, ``"RAII"``, ``"SAII"``, ...).
    params : CurrentParams
        Gains, filters and transducers.
    state : ndarray, optional
        Filter state carried over from a previous chunk (the module
        docstring's layout); default: at rest on the first sample.
    scale : array_like, shape (n_afferents,), optional
        Per-afferent multiplier of the drive (gain variability, receptive
        field weight), applied before the transducer.
    sensitivity : array_like, shape (n_afferents,), optional
        Each afferent's sensitivity (dimensionless, > 0; default 1): it
        multiplies the gain and divides the type's dead zone (``RAI.threshold``).

    Returns
    -------
    current : ndarray, shape (n_samples, n_afferents)
        Current in mV/ms (Izhikevich units); >= 0 except SA-II's, which
        stretch against its preferred direction can lower below its bias.
    state : ndarray
        Filter state after the chunk.

    Examples
    --------
    >>> f = np.linspace(0.0, 1.0, 1001)[:, None]          # 1 N/s ramp at 1 kHz
    >>> i, _ = afferent_current(f, 1000.0, "RAI", CurrentParams().with_type("RAI", gain=1.0))
    >>> round(float(i[-1, 0]), 2)                          # settles at 1 N/s
    1.0
    """
    afferent_type = normalize_type(afferent_type)
    fs = check_positive(fs, "fs", "Hz")
    f_a = as_finite_array(f_a, "f_a", ndim=2)
    check_instance(params, "params", CurrentParams, "a CurrentParams")
    check_fs(fs, params, (afferent_type,))
    if sensitivity is not None:
        sensitivity = as_finite_array(sensitivity, "sensitivity", ndim=1)
        if sensitivity.shape != (f_a.shape[1],) or np.any(sensitivity <= 0):
            raise ValueError(f"sensitivity must hold one number > 0 per afferent ({f_a.shape[1]}), got shape "
                             f"{sensitivity.shape}, smallest {float(np.min(sensitivity, initial=np.inf)):g}")
    return current_core(f_a, fs, afferent_type, params, state, scale, sensitivity=sensitivity)


def current_core(f_a, fs, afferent_type, params, state=None, scale=None, normals=None, noise_cv=None, excite=None,
                 afferent_id=None, sensitivity=None):
    """`afferent_current` without validation, with the noise and per-unit options of a population.

    ``normals`` (shape (n_afferents, n_samples), standard normal draws) and
    ``noise_cv`` (sqrt(ms), per afferent) add the receptor noise; without
    them the current is noise-free.  ``excite`` (per afferent,
    dimensionless; `ddmm.models.variability.excitability`) multiplies the
    trial's current after the log compression and before the bound
    ``i_max``.  ``afferent_id`` (int array) keys the per-unit spread of the
    tonic current; None: no spread.  ``sensitivity`` as `afferent_current`.
    Returns the current (mV/ms) and the filter state after the chunk.
    """
    fs = float(fs)
    st, sos, alpha_adapt, alpha_smooth = type_filter_constants(params, afferent_type, fs)
    m = f_a.shape[1]
    gain = st.gain if scale is None else st.gain * np.asarray(scale, dtype=float)
    if sensitivity is not None:
        gain = gain * np.asarray(sensitivity, dtype=float)
    noisy = normals is not None and noise_cv is not None and bool(np.any(np.asarray(noise_cv) > 0))
    if st.derivative == 0 and st.cutoff_hz is None and st.adapt == 0.0 and st.tau_s is None:
        drive = gain * np.abs(f_a)  # the paper's eq. 1, no filter
        current = transduce_inplace(_receptor_noise(drive, normals, noise_cv, fs) if noisy else drive, st, excite)
        return current, (rest_state(sos.shape[0], m) if state is None else state.copy())
    state = initial_filter_state(f_a[0], fs, params, afferent_type) if state is None else state.copy()
    rows = 2 * sos.shape[0]
    gain = gain if np.ndim(gain) else np.full(m, gain)
    cv_scale = np.asarray(noise_cv, dtype=float) / np.sqrt(1000.0 / fs) if noisy else gain
    stage = StageConstants(fs, st.derivative, float(st.adapt), alpha_adapt, st.threshold > 0.0,
                           float(st.negative_weight), st.signed)
    noise = ReceptorNoise(np.ascontiguousarray(normals) if noisy else _NO_NORMALS, noisy)
    tail = TailState(state[rows + _OFFSET], state[rows + _Y1], state[rows + _Y2], state[rows + _SLOW])
    drive = stage_kernel(sos, np.ascontiguousarray(f_a), state[:rows].reshape(sos.shape[0], 2, m), tail, stage,
                         UnitScales(gain, unit_thresholds(st, sensitivity, m), cv_scale), noise)
    current = transduce_inplace(drive, st, excite)  # numpy's vectorised log1p/tanh: 5-10x numba's scalar calls
    return _after_transducer(current, st, state[rows:], fs, alpha_smooth, afferent_id), state


def initial_filter_state(f0, fs: float, params: CurrentParams = CurrentParams(), afferent_type: str = "RAI"
                         ) -> np.ndarray:
    """Filter state (the module docstring's layout) at rest on a constant input ``f0`` (newtons).

    Starting at steady state means a trace that begins mid-contact produces
    no spurious derivative at its first sample; a trace that starts at rest
    (F_A = 0) is unaffected.  ``afferent_type`` selects the stage's filter.

    Examples
    --------
    >>> s = initial_filter_state([2.0, 3.0], 1000.0, afferent_type="RAI")
    >>> s.shape, s[-8].tolist()          # 2 rows per section, then 8; the offset row first
    ((10, 2), [2.0, 3.0])
    """
    f0 = np.atleast_1d(np.asarray(f0, dtype=float))
    n_sections = _stage_sos(params.for_type(normalize_type(afferent_type)), float(fs)).shape[0]
    state = rest_state(n_sections, f0.size)
    state[2 * n_sections + _OFFSET] = f0
    return state


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
    state : ndarray, optional
        State carried from the previous chunk (the module docstring's
        layout, `initial_filter_state`); default: at rest on the first sample.

    Returns
    -------
    y : ndarray, shape (n_samples, n_afferents)
        Filtered force in newtons.
    state : ndarray
        State after the last sample.

    Examples
    --------
    >>> y, _ = filter_force(np.full((50, 1), 2.0), 1000.0)
    >>> float(y[-1, 0])
    2.0
    """
    f_a = as_finite_array(f_a, "f_a", ndim=2)
    fs = check_positive(fs, "fs", "Hz")
    check_instance(params, "params", CurrentParams, "a CurrentParams")
    shared = TypeCurrentParams(afferent_type="RAI", cutoff_hz=params.cutoff_hz, order=params.filter_order)
    sos = _stage_sos(shared, float(fs))
    state = initial_filter_state(f_a[0], fs, params) if state is None else state.copy()
    rows, m = 2 * sos.shape[0], f_a.shape[1]
    state[rows + _SLOW] = 0.0  # the shared filter has no adaptation
    # The stage kernel with order 0, unit gain and a signed drive returns exactly deviation + offset.
    tail = TailState(state[rows + _OFFSET], state[rows + _Y1], state[rows + _Y2], state[rows + _SLOW])
    y = stage_kernel(sos, np.ascontiguousarray(f_a), state[:rows].reshape(sos.shape[0], 2, m), tail,
                     StageConstants(float(fs), 0, 0.0, 0.0, False, 1.0, True),
                     UnitScales(np.ones(m), np.zeros(m), np.ones(m)), ReceptorNoise(_NO_NORMALS, False))
    return y, state


def _after_transducer(current, st, tail, fs, alpha_smooth, afferent_id):
    """The current's low-pass, SA-I's dynamic response and the tonic bias, in that order (their state
    rows of ``tail``, the state after the filter rows, in place)."""
    if st.tau_s is not None:
        current = smooth_kernel(current, tail[_SMOOTH], alpha_smooth)
    if st.dynamic > 0.0 or st.fall > 0.0 or st.transient > 0.0:
        current = dynamic_kernel(current, tail[_DYNC], tail[_FASTC], tail[_RISEC], _alpha(st.tau_dynamic_s, fs),
                                 _alpha(st.tau_transient_s, fs), _alpha(0.5 * st.tau_transient_s, fs),
                                 float(st.dynamic), float(st.transient), float(st.fall))
    if st.bias != 0.0:
        current += tonic_current(st, afferent_id, current.shape[1])
    return current


def _alpha(tau_s: float, fs: float) -> float:
    return float(-np.expm1(-1.0 / (fs * tau_s)))


def _receptor_noise(drive, normals, noise_cv, fs):
    """``d (1 + cv xi / sqrt(h))`` on the paper's unfiltered SAI drive, rectified."""
    scale = np.asarray(noise_cv, dtype=float) / np.sqrt(1000.0 / fs)
    return np.maximum(drive + drive * (normals.T * scale), 0.0)
