"""Afferent currents from the attenuated force (paper eqs 1-3), and type-specific stages.

The paper's stage (the default of `CurrentParams`):

* SAI follows force:            ``I = SAI.gain * |F_A|``           (eq. 1)
* RAI its rate of change:       ``I = RAI.gain * |dF_A/dt|``       (eq. 2)
* RAII its acceleration:        ``I = RAII.gain * |d^2F_A/dt^2|``  (eq. 3)

with one causal 20 Hz low-pass before the derivatives (docs/model.md §1.6).

Every departure from it is a named field of each type's `TypeParams` (written
``<TYPE>.<field>``; `CurrentParams.with_type` sets one), off by default, which
the physiological presets switch on (docs/model.md, "What changed in the model"):

* **Per-type filters.**  ``SAI.cutoff_hz`` low-passes SA-I's force;
  ``RAI.cutoff_hz`` sets RA-I's low-pass before d/dt (a velocity band-pass,
  best near 10-60 Hz); ``RAII.cutoff_hz`` with ``RAII.order`` sets RA-II's
  low-pass before d^2/dt^2 (acceleration: sensitivity grows as f^2 up to the
  cut-off and falls beyond it, a Pacinian band-pass near 150-400 Hz).  A
  scene sampled too slowly to carry RA-II's band is refused (`check_fs`).
* **Phase-preserving rectification.**  ``RAI.negative_weight`` and
  ``RAII.negative_weight`` weight the negative half-wave of the derivative
  (1.0: the paper's absolute value), so that a vibration excites on one
  half-cycle and spikes lock to its phase.
* **Adaptation.**  ``RAI.adapt`` makes RA-I adapt to a sustained velocity
  (the rectified velocity minus a low-pass of itself).
* **Slow adaptation of SA-I.**  ``SAI.adapt`` adds ``adapt * (y - slow)``,
  where ``slow`` is a first-order low-pass of the filtered force with time
  constant ``SAI.tau_adapt_s``: a dynamic loading response that decays
  through a hold, and silence during unloading (the drive is rectified).
* **SA-II (Ruffini), a fourth type.**  Driven by skin stretch, from forces
  the attenuated *shear*: ``x = F_S * (AF - SAII.opponent * (1 - AF))`` (so
  stretch against the preferred direction lowers the rate), low-passed at
  ``SAII.cutoff_hz``, on top of a tonic ``SAII.bias`` current.  Options:
  ``SAII.normal`` adds the normal force to the drive, ``SAII.bias_cv``
  spreads the tonic current across units (keyed by afferent id) and
  ``SAII.phase`` starts each neuron at its own keyed phase.
* **SA-I dynamics on the current.**  ``SAI.dynamic`` and ``SAI.fall`` act
  after the transducer: ``I + dynamic (I - J) - fall J`` with ``J`` a
  low-pass of the current (``SAI.tau_dynamic_s``): an overshoot in fast
  loading and a fractional fall through a hold at every force.
  ``SAI.transient`` adds ``transient max(R - K, 0)``, a rectified band-pass of the current
  (first-order low-passes of ``SAI.tau_transient_s / 2`` and
  ``SAI.tau_transient_s``): SA-I's peak rates while the load rises.
* **Shear magnitude in the pressure types' drive.**  ``SAI.shear``,
  ``RAI.shear`` and ``RAII.shear`` add a stretch-like term to F_A before the
  type's filter, ``x = max(0, F_A + <TYPE>.shear * F_S * (AF - <TYPE>.opponent_shear * (1 - AF)))``
  (AF the profile's own, `attenuation.shear_drive`): tangential force along
  the preferred direction raises the drive, against it lowers it, growing
  with F_S (FA-I and FA-II see its derivatives during a tangential ramp).
  The paper's F_A alone only attenuates: shear can never raise a rate.
* **Saturating transducers.**  ``<TYPE>.i_max`` bounds the current:
  ``I = i_max * tanh(d / i_max)`` for the linear drive ``d = g * x``, so
  rates stay physiological on fast ramps.  The older log compression
  ``i_sat`` (``I = i_sat * log1p(d / i_sat)``, unbounded) is kept.
* **Receptor noise and current smoothing.**  Drive-proportional noise
  (``noise_cv``, a population property) multiplies the linear drive before
  the transducer, ``d (1 + cv * xi / sqrt(h))`` (rectified), so an undriven
  afferent stays silent and the bound ``i_max`` holds with noise; then
  ``<TYPE>.tau_s`` low-passes the current (first order).  The Izhikevich
  neuron with the paper's D = 8 fires its first interval far faster than its
  steady rate when its current *steps* (I = 100 mV/ms: 1/ISI 1,400 Hz, then
  230 Hz); a current that rises over ~10 ms keeps the first interval near
  the steady rate (417 Hz), as real afferents' refractoriness does.

Derivatives of a raw force signal are useless, so F_A is low-passed first by
a *causal* Butterworth filter and differentiated by backward differences.
Every stage keeps explicit state (`FilterState`), so a signal cut into chunks
gives exactly the currents of the whole signal: streaming and offline runs
agree bit for bit.  SciPy designs the filters; one small numba kernel runs
them (direct form II transposed, SciPy's ``sosfilt`` arithmetic), because the
streaming encoder calls it once per millisecond.

Currents are in the Izhikevich model's own units (mV/ms, the units of
``dv/dt`` in eq. 4); the gains convert newtons to them.
"""

from __future__ import annotations

import numpy as np

from ddmm.models._stage_kernels import (
    ReceptorNoise,
    StageConstants,
    TailState,
    UnitScales,
    dynamic_kernel,
    smooth_kernel,
    stage_kernel,
    transduce_inplace,
)
from ddmm.models.afferent_types import AFFERENT_TYPES, PAPER_TYPES, TYPE_LABELS, normalize_type, type_label
from ddmm.models.current_filters import (
    _NO_NORMALS,
    RAII_FS_FACTOR,  # noqa: F401 (re-exported)
    FilterState,
    check_fs,
    filter_force,
    initial_filter_state,
    lowpass_sos,
    type_filter_constants,
)
from ddmm.models.current_params import DERIVATIVE_ORDER, CurrentParams, TypeCurrentParams  # noqa: F401 (re-exported)
from ddmm.models.variability import (
    BIAS_KEY,  # noqa: F401 (re-exported)
    EXCITE_SAMPLE,  # noqa: F401 (re-exported)
    PHASE_TAG,  # noqa: F401 (re-exported)
    bias_multiplier,
    excitability,
    initial_phase,
    tonic_current,
)
from ddmm.utils.validation import as_finite_array, check_instance, check_positive

__all__ = [
    "PAPER_TYPES",
    "AFFERENT_TYPES",
    "CurrentParams",
    "TypeCurrentParams",
    "FilterState",
    "lowpass_sos",
    "initial_filter_state",
    "filter_force",
    "afferent_current",
    "current_core",
    "excitability",
    "check_fs",
    "TYPE_LABELS",
    "type_label",
    "normalize_type",
    "type_filter_constants",
    "bias_multiplier",
    "tonic_current",
    "initial_phase",
    "unit_thresholds",
]
# The type vocabulary (`afferent_types`), the parameters (`current_params`), the filters
# (`current_filters`) and the keyed draws (`variability`) live in modules of their own; every name
# this module held before they moved out stays importable from it, so no caller breaks.


def afferent_current(
    f_a,
    fs: float,
    afferent_type: str,
    params: CurrentParams = CurrentParams(),
    state: FilterState | None = None,
    scale=None,
    sensitivity=None,
):
    """Input current of afferents of one type (eqs 1-3, or the type's own stage).

    Parameters
    ----------
    f_a : array_like, shape (n_samples, n_afferents)
        Attenuated force F_A in newtons at sample rate ``fs`` (for SA-II, the
        signed stretch drive in newtons, see `ddmm.models.attenuation.stretch_drive`).
    fs : float
        Sample rate in Hz.
    afferent_type : {"SAI", "RAI", "RAII", "SAII"}
        Which stage to apply.
    params : CurrentParams
        Gains, filters and transducers.
    state : FilterState, optional
        Filter state carried over from a previous chunk.
    scale : array_like, shape (n_afferents,), optional
        Per-afferent multiplier of the drive (gain variability, receptive
        field weight), applied before the transducer.
    sensitivity : array_like, shape (n_afferents,), optional
        Each afferent's sensitivity (dimensionless, > 0; default 1): it
        multiplies the gain and divides the type's dead zone (``RAI.threshold``),
        so the unit's stimulus thresholds are its type's over its
        sensitivity (docs/model.md, "Units that differ").

    Returns
    -------
    current : ndarray, shape (n_samples, n_afferents)
        Current in mV/ms (Izhikevich units); >= 0 except SA-II's, which
        stretch against its preferred direction can lower below its bias.
    state : FilterState or None
        Filter state after the chunk (None for the paper's unfiltered SAI).

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
    """`afferent_current` without validation (the hot path of `simulate`).

    ``normals`` (shape (n_afferents, n_samples), standard normal draws) and
    ``noise_cv`` (sqrt(ms), per afferent) add the receptor noise of the
    module docstring; without them the current is noise-free.  Every stage
    after the paper's unfiltered SAI runs in one numba pass
    (`ddmm.models._stage_kernels.stage_kernel`) and numpy's vectorised
    transducers; `ddmm.models.fused` runs the same arithmetic for the streaming
    encoder.  ``excite`` (per afferent, dimensionless; `excitability`)
    multiplies the trial's current after the log compression and before
    the bound ``i_max`` (`transduce_inplace`).  ``afferent_id`` (int array)
    keys the per-unit spread of the tonic current (`bias_multiplier`); None:
    no spread.  ``sensitivity`` (per afferent, dimensionless) multiplies the
    gain and divides the dead zone (`unit_thresholds`); None: 1.
    """
    fs = float(fs)
    st, sos, alpha_adapt, alpha_smooth = type_filter_constants(params, afferent_type, fs)
    gain = st.gain if scale is None else st.gain * np.asarray(scale, dtype=float)
    if sensitivity is not None:
        gain = gain * np.asarray(sensitivity, dtype=float)
    noisy = normals is not None and noise_cv is not None and bool(np.any(np.asarray(noise_cv) > 0))
    if st.derivative == 0 and st.cutoff_hz is None and st.adapt == 0.0 and st.tau_s is None:
        drive = gain * np.abs(f_a)  # the paper's eq. 1, no filter
        return transduce_inplace(_receptor_noise(drive, normals, noise_cv, fs) if noisy else drive, st, excite), None
    if state is None:
        state = initial_filter_state(f_a[0], fs, params, afferent_type)
    m = f_a.shape[1]
    zi, y1, y2 = state.zi.copy(), state.y1.copy(), state.y2.copy()
    slow = np.zeros(m) if state.slow is None else state.slow.copy()
    gain = gain if np.ndim(gain) else np.full(m, gain)
    cv_scale = np.asarray(noise_cv, dtype=float) / np.sqrt(1000.0 / fs) if noisy else gain
    stage = StageConstants(fs, st.derivative, float(st.adapt), alpha_adapt, st.threshold > 0.0,
                           float(st.negative_weight), st.signed)
    noise = ReceptorNoise(np.ascontiguousarray(normals) if noisy else _NO_NORMALS, noisy)
    drive = stage_kernel(sos, np.ascontiguousarray(f_a), zi, TailState(state.offset, y1, y2, slow), stage,
                         UnitScales(gain, unit_thresholds(st, sensitivity, m), cv_scale), noise)
    current = transduce_inplace(drive, st, excite)  # numpy's vectorised log1p/tanh: 5-10x numba's scalar calls
    current, smooth, dyn, fast, rise = _after_transducer(current, st, state, m, fs, alpha_smooth, afferent_id)
    return current, FilterState(zi, state.offset, y1, y2, slow, smooth, dyn, fast, rise)


def unit_thresholds(stage: TypeCurrentParams, sensitivity, n: int) -> np.ndarray:
    """Each afferent's dead zone in its drive's units: the type's ``threshold`` over its sensitivity.

    ``sensitivity`` is per afferent (dimensionless, > 0) or None (1 for
    every afferent: the type's threshold, bit for bit).

    Examples
    --------
    >>> st = CurrentParams().with_type("RAI", threshold=1.0).for_type("RAI")
    >>> unit_thresholds(st, np.array([0.5, 2.0]), 2).tolist()
    [2.0, 0.5]
    """
    if sensitivity is None:
        return np.full(n, float(stage.threshold))
    return float(stage.threshold) / np.asarray(sensitivity, dtype=float)


def _after_transducer(current, st, state, m, fs, alpha_smooth, afferent_id):
    """The current's low-pass, SA-I's dynamic response and the tonic bias, in that order; with the new states."""
    smooth = np.zeros(m) if state.smooth is None else state.smooth.copy()
    if st.tau_s is not None:
        current = smooth_kernel(current, smooth, alpha_smooth)
    dyn = np.zeros(m) if state.dyn is None else state.dyn.copy()
    fast = np.zeros(m) if state.fast is None else state.fast.copy()
    rise = np.zeros(m) if state.rise is None else state.rise.copy()
    if st.dynamic > 0.0 or st.fall > 0.0 or st.transient > 0.0:
        current = dynamic_kernel(current, dyn, fast, rise, _alpha(st.tau_dynamic_s, fs), _alpha(st.tau_transient_s, fs),
                                 _alpha(0.5 * st.tau_transient_s, fs), float(st.dynamic), float(st.transient),
                                 float(st.fall))
    if st.bias != 0.0:
        current += tonic_current(st, afferent_id, m)
    return current, smooth, dyn, fast, rise


def _alpha(tau_s: float, fs: float) -> float:
    return float(-np.expm1(-1.0 / (fs * tau_s)))


def _receptor_noise(drive, normals, noise_cv, fs):
    """``d (1 + cv xi / sqrt(h))`` on the paper's unfiltered SAI drive, rectified."""
    scale = np.asarray(noise_cv, dtype=float) / np.sqrt(1000.0 / fs)
    return np.maximum(drive + drive * (normals.T * scale), 0.0)


def __getattr__(name):
    if name == "CurrentStage":  # the old name, for one release (it warns)
        from ddmm.models import current_params

        return current_params.CurrentStage
    raise AttributeError(f"module {__name__!r} has no attribute {name!r}")
