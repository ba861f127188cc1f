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
  (AF the profile's own, `reference_pipeline.shear_drive`): tangential force along
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
Every stage keeps explicit state (one array per block of afferents,
`ddmm.models._fused_tables.rest_state`), so a signal cut into chunks
gives exactly the currents of the whole signal: streaming and offline runs
agree bit for bit.  SciPy designs the filters; one small numba kernel runs
them (direct form II transposed, SciPy's ``sosfilt`` arithmetic), because the
streaming encoder calls it once per millisecond.

Currents are in the Izhikevich model's own units (mV/ms, the units of
``dv/dt`` in eq. 4); the gains convert newtons to them.

The package computes this stage on one production path, fused with the
drive (`ddmm.models.fused.FusedPipeline`); `ddmm.models.reference_pipeline`
computes it stage by stage (`afferent_current`), as the reference oracle.
"""

from __future__ import annotations

import numpy as np

from ddmm.models.afferent_types import AFFERENT_TYPES, PAPER_TYPES, TYPE_LABELS, normalize_type, type_label
from ddmm.models.current_filters import (
    RAII_FS_FACTOR,  # noqa: F401 (re-exported)
    check_fs,
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
from ddmm.utils.deprecation import warn_renamed

__all__ = [
    "PAPER_TYPES",
    "AFFERENT_TYPES",
    "CurrentParams",
    "TypeCurrentParams",
    "lowpass_sos",
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


#: The stage-by-stage functions, now the reference oracle's (`ddmm.models.reference_pipeline`), for one release.
_MOVED = ("afferent_current", "current_core", "filter_force", "initial_filter_state")


def __getattr__(name):
    if name == "CurrentStage":  # the old name, for one release (it warns)
        from ddmm.models import current_params

        return current_params.CurrentStage
    if name in _MOVED:
        from ddmm.models import reference_pipeline

        warn_renamed(f"ddmm.models.currents.{name}", f"ddmm.models.reference_pipeline.{name}")
        return getattr(reference_pipeline, name)
    raise AttributeError(f"module {__name__!r} has no attribute {name!r}")
