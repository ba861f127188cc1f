"""Afferent currents from the attenuated force (paper eqs 1-3), and type-specific stages.

The paper's stage (the default of `CurrentParams`):

* SAI follows force:            ``I = g_sai * |F_A|``           (eq. 1)
* RAI its rate of change:       ``I = g_rai * |dF_A/dt|``       (eq. 2)
* RAII its acceleration:        ``I = g_raii * |d^2F_A/dt^2|``  (eq. 3)

with one causal 20 Hz low-pass before the derivatives (docs/model.md §1.6).

Every departure from it is a named field of `CurrentParams`, off by default,
which the physiological presets switch on (docs/model.md, "What changed in the model"):

* **Per-type filters.**  ``cutoff_sai_hz`` low-passes SA-I's force;
  ``cutoff_rai_hz`` sets RA-I's low-pass before d/dt (a velocity band-pass,
  best near 10-60 Hz); ``cutoff_raii_hz`` with ``order_raii`` sets RA-II's
  low-pass before d^2/dt^2 (acceleration: sensitivity grows as f^2 up to the
  cut-off and falls beyond it, a Pacinian band-pass near 150-400 Hz).  A
  scene sampled too slowly to carry RA-II's band is refused (`check_fs`).
* **Phase-preserving rectification.**  ``negative_weight_rai`` and
  ``negative_weight_raii`` weight the negative half-wave of the derivative
  (1.0: the paper's absolute value), so that a vibration excites on one
  half-cycle and spikes lock to its phase.
* **Adaptation.**  ``adapt_rai`` makes RA-I adapt to a sustained velocity
  (the rectified velocity minus a low-pass of itself).
* **Slow adaptation of SA-I.**  ``adapt_sai`` adds ``adapt * (y - slow)``,
  where ``slow`` is a first-order low-pass of the filtered force with time
  constant ``tau_adapt_sai_s``: a dynamic loading response that decays
  through a hold, and silence during unloading (the drive is rectified).
* **SA-II (Ruffini), a fourth type.**  Driven by skin stretch, from forces
  the attenuated *shear*: ``x = F_S * (AF - opponent_saii * (1 - AF))`` (so
  stretch against the preferred direction lowers the rate), low-passed at
  ``cutoff_saii_hz``, on top of a tonic ``bias_saii`` current.  Options:
  ``normal_saii`` adds the normal force to the drive, ``bias_cv_saii``
  spreads the tonic current across units (keyed by afferent id) and
  ``phase_saii`` starts each neuron at its own keyed phase.
* **SA-I dynamics on the current.**  ``dynamic_sai`` and ``fall_sai`` act
  after the transducer: ``I + dynamic (I - J) - fall J`` with ``J`` a
  low-pass of the current (``tau_dynamic_sai_s``): an overshoot in fast
  loading and a fractional fall through a hold at every force.
* **Shear magnitude in the pressure types' drive.**  ``shear_sai``,
  ``shear_rai`` and ``shear_raii`` add a stretch-like term to F_A before the
  type's filter, ``x = max(0, F_A + shear_<type> * F_S * (AF - opponent_shear_<type> * (1 - AF)))``
  (AF the profile's own, `attenuation.shear_drive`): tangential force along
  the preferred direction raises the drive, against it lowers it, growing
  with F_S (FA-I and FA-II see its derivatives during a tangential ramp).
  The paper's F_A alone only attenuates: shear can never raise a rate.
* **Saturating transducers.**  ``i_max_<type>`` bounds the current:
  ``I = i_max * tanh(d / i_max)`` for the linear drive ``d = g * x``, so
  rates stay physiological on fast ramps.  The older log compression
  ``i_sat`` (``I = i_sat * log1p(d / i_sat)``, unbounded) is kept.
* **Receptor noise and current smoothing.**  Drive-proportional noise
  (``noise_cv``, a population property) multiplies the linear drive before
  the transducer, ``d (1 + cv * xi / sqrt(h))`` (rectified), so an undriven
  afferent stays silent and the bound ``i_max`` holds with noise; then
  ``tau_<type>_s`` low-passes the current (first order).  The Izhikevich
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

import os
from dataclasses import dataclass
from functools import lru_cache

import numpy as np

from ddmm.models._cache import cache_root
from ddmm.models._stage_kernels import dynamic_kernel, smooth_kernel, stage_kernel, transduce_inplace
from ddmm.models._validation import as_finite_array, check_positive

__all__ = [
    "PAPER_TYPES",
    "AFFERENT_TYPES",
    "CurrentParams",
    "CurrentStage",
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
    "stage_constants",
    "bias_multiplier",
    "tonic_current",
    "initial_phase",
]

#: The paper's three afferent types (eqs 1-3).
PAPER_TYPES = ("SAI", "RAI", "RAII")
#: Every afferent type of the package, in the order used throughout: the paper's
#: three, then SA-II (Ruffini), which the paper leaves out (its §I).
AFFERENT_TYPES = PAPER_TYPES + ("SAII",)
#: Display label of each type code, as the human literature names them (FA = fast
#: adapting, the paper's RA).  Codes stay the data's names (files, presets, the API).
TYPE_LABELS = {"SAI": "SA-I", "RAI": "FA-I", "RAII": "FA-II", "SAII": "SA-II"}
#: Spellings accepted on input for each code (compared without case, "-", "_" or spaces).
_SPELLINGS = {"SAI": ("SAI", "SA1"), "RAI": ("RAI", "FAI", "RA1", "FA1"), "RAII": ("RAII", "FAII", "RA2", "FA2"),
              "SAII": ("SAII", "SA2")}
_CODE_OF = {spelling: code for code, names in _SPELLINGS.items() for spelling in names}
#: Derivative order of each type's drive: force, velocity, acceleration, stretch.
DERIVATIVE_ORDER = {"SAI": 0, "RAI": 1, "RAII": 2, "SAII": 0}
#: A scene must be sampled at least this many times faster than RA-II's cut-off.
RAII_FS_FACTOR = 2.5


def type_label(afferent_type: str) -> str:
    """The display label of a type code (``"RAI"`` -> ``"FA-I"``), for figures and text.

    Examples
    --------
    >>> [type_label(t) for t in AFFERENT_TYPES]
    ['SA-I', 'FA-I', 'FA-II', 'SA-II']
    """
    return TYPE_LABELS[normalize_type(afferent_type)]


def normalize_type(afferent_type, name: str = "afferent_type") -> str:
    """The type code of any accepted spelling: ``"FA-I"``, ``"RA-I"``, ``"fa1"`` -> ``"RAI"``.

    Raises
    ------
    ValueError
        Naming ``name``, the value and the allowed spellings.

    Examples
    --------
    >>> normalize_type("FA-II"), normalize_type("SA-I"), normalize_type("RAI")
    ('RAII', 'SAI', 'RAI')
    """
    if isinstance(afferent_type, str):
        key = afferent_type.upper().replace("-", "").replace("_", "").replace(" ", "")
        if key in _CODE_OF:
            return _CODE_OF[key]
    raise ValueError(f"{name}={afferent_type!r} is not an afferent type; allowed: "
                     f"{', '.join(AFFERENT_TYPES)} or {', '.join(TYPE_LABELS.values())} (RA-I/RA-II too)")


def _optional_positive(obj, names, unit):
    for name in names:
        if getattr(obj, name) is not None:
            check_positive(getattr(obj, name), name, unit)


@dataclass(frozen=True)
class CurrentParams:
    """Gains, filters and transducers of the current stage.

    The defaults are the paper's eqs 1-3, with gains calibrated so that the
    CMM (AF = 1) press-push-lift response lies near paper Table III (SAI
    about 47.5 pulses/s, RAI and RAII 10-20); ``experiments/calibrate_core.py``
    reproduces the fit.  Fields marked *ours* are off (None or 0) by default.

    Attributes
    ----------
    g_sai : float
        SAI gain, (mV/ms) per N (eq. 1).
    g_rai : float
        RAI gain, (mV/ms) per (N/s) (eq. 2).
    g_raii : float
        RAII gain, (mV/ms) per (N/s^2) (eq. 3).
    cutoff_hz : float
        Cut-off in Hz of the causal Butterworth low-pass applied to F_A before
        differentiation (docs/model.md §1.6: 20 Hz restores Table III's
        aligned > misaligned ordering for RAII).
    filter_order : int
        Order of that Butterworth filter (2 in the trial of docs/model.md §1.6).
    i_sat : float or None
        Scale of the log compression in mV/ms, for every paper type:
        ``I = i_sat * log1p(g * x / i_sat)``.  None: linear, as eqs 1-3.
    i_sat_sai, i_sat_rai, i_sat_raii : float or None
        Per-type log-compression scales; they override ``i_sat``.
    cutoff_sai_hz : float or None
        Ours: low-pass of SA-I's force in Hz (None: unfiltered, eq. 1).
    cutoff_rai_hz : float or None
        Ours: RA-I's low-pass before d/dt in Hz (None: ``cutoff_hz``).
    cutoff_raii_hz : float or None
        Ours: RA-II's low-pass before d^2/dt^2 in Hz (None: ``cutoff_hz``).
    order_raii : int or None
        Ours: order of RA-II's low-pass (None: ``filter_order``).
    highpass_raii_hz : float or None
        Ours: cut-off in Hz of a 2nd-order high-pass before RA-II's d^2/dt^2,
        the Pacinian capsule's mechanical filtering of slow indentation
        (None: none).
    adapt_sai : float
        Ours: depth of SA-I's slow adaptation (dimensionless, 0: none).
    tau_adapt_sai_s : float
        Ours: time constant of that adaptation in s.
    adapt_rai : float
        Ours: depth of RA-I's adaptation to a sustained velocity
        (dimensionless, 0: none): the rectified velocity minus ``adapt_rai``
        times its first-order low-pass, floored at 0.  RA-I afferents signal
        changes; a slow ramp excites them only at its start.
    tau_adapt_rai_s : float
        Ours: time constant of that adaptation in s.
    threshold_rai : float
        Ours: RA-I's velocity threshold in N/s, subtracted from the adapted
        rectified velocity (a dead zone: slow changes do not excite).
    g_saii : float
        Ours: SA-II gain, (mV/ms) per N of attenuated shear.
    bias_saii : float
        Ours: SA-II's tonic current in mV/ms (its resting discharge).
    cutoff_saii_hz : float
        Ours: low-pass of SA-II's stretch drive in Hz.
    opponent_saii : float
        Ours: how much stretch against SA-II's preferred direction lowers its
        drive (dimensionless, 0: attenuated shear only).
    normal_saii : float
        Ours: weight of the normal force F_Z in SA-II's drive (dimensionless,
        0: stretch only): the drive becomes ``x + normal_saii * F_Z``, so
        SA-II respond to pressing as well as to stretch (docs/references.md
        row 24: every nail-border SA-II responded to a 4 N normal force).
    bias_cv_saii : float
        Ours: spread of SA-II's resting discharge across units
        (dimensionless, 0: every unit gets ``bias_saii``).  Each afferent's
        tonic current is ``bias_saii * m`` with the lognormal multiplier
        ``m = exp(s z - s^2 / 2)``, ``s^2 = log(1 + bias_cv_saii^2)``, and
        ``z`` the standard normal keyed by the afferent's id alone
        (`bias_multiplier`): a property of the unit, the same in every run,
        seed, trial and engine.
    phase_saii : float
        Ours: spread of SA-II neurons' start phases over their tonic cycle
        (dimensionless, in [0, 1]; 0: every neuron at rest, so tonic units
        start in step).  The initial state is ``v = c``,
        ``u = u_rest + phase_saii * U * d`` with ``U`` uniform in [0, 1) from
        a draw keyed by (seed, condition, trial, afferent) (`initial_phase`);
        noise-free runs (no key) start at rest.
    dynamic_sai : float
        Ours: depth of SA-I's dynamic response on the *current*
        (dimensionless, 0: none): ``I <- max(I + dynamic_sai (I - J) - fall_sai J, 0)``
        with ``J`` a first-order low-pass of the current (time constant
        ``tau_dynamic_sai_s``), after the transducer and the current's
        low-pass.  Being after the transducer, the overshoot in fast loading
        and its decay through a hold are fractions of the current at every
        force (the force-level ``adapt_sai`` is squashed by the log
        compression and the bound at high forces).
    fall_sai : float
        Ours: SA-I's lasting adaptation on the current (dimensionless, in
        [0, 1); 0: none): ``fall_sai * J`` is subtracted as well, so a held
        current settles at ``(1 - fall_sai)`` of its value with time
        constant ``tau_dynamic_sai_s``, a fraction at every force.
    tau_dynamic_sai_s : float
        Ours: time constant of that low-pass in s.
    shear_sai, shear_rai, shear_raii : float
        Ours: gain of the shear-magnitude term added to the type's F_A
        (dimensionless, N of drive per N of shear; 0: the paper's F_A, which
        shear only attenuates), ``shear * F_S * (AF - opponent_shear (1 - AF))``
        with AF the profile's own factor (docs/model.md, "What changed").
    opponent_shear_sai, opponent_shear_rai, opponent_shear_raii : float
        Ours: how much shear against the preferred direction lowers the
        type's shear term (dimensionless, as ``opponent_saii``; 0: the term
        is AF F_S, never negative).
    i_max_sai, i_max_rai, i_max_raii, i_max_saii : float or None
        Ours: bound of the saturating transducer in mV/ms,
        ``I = i_max * tanh(d / i_max)``; None: no bound.
    tau_sai_s, tau_rai_s, tau_raii_s, tau_saii_s : float or None
        Ours: time constant in s of the first-order low-pass on the current
        (after the transducer and the receptor noise); None: none.
    negative_weight_rai, negative_weight_raii : float
        Ours: weight (dimensionless, 0 to 1) of the negative half-wave of
        RA-I's velocity and RA-II's acceleration when they are rectified:
        ``d = x`` for ``x >= 0`` and ``-w x`` for ``x < 0``.  1.0 is the
        absolute value of eqs 2-3 (both half-cycles of a vibration excite, so
        spikes lock to twice its frequency); below 1 the drive keeps the
        phase of the cycle (one preferred half-cycle), while ``w > 0`` keeps
        a response to unloading (RA-I's OFF response).
    excite_cv_sai, excite_cv_rai, excite_cv_raii, excite_cv_saii : float
        Ours: trial-to-trial excitability of the spike generator
        (dimensionless coefficient of variation, >= 0; 0: none, the paper).
        On each trial every afferent's current is multiplied by its own
        lognormal factor of mean 1 and this CV, drawn from the trial's noise
        key (`excitability`), after the log compression ``i_sat`` and
        before the bound ``i_max`` (which still holds), the low-pass and
        SA-II's bias: an undriven afferent stays silent.
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
    cutoff_sai_hz: float | None = None
    cutoff_rai_hz: float | None = None
    cutoff_raii_hz: float | None = None
    order_raii: int | None = None
    highpass_raii_hz: float | None = None
    adapt_sai: float = 0.0
    tau_adapt_sai_s: float = 1.0
    adapt_rai: float = 0.0
    tau_adapt_rai_s: float = 0.1
    threshold_rai: float = 0.0
    g_saii: float = 1.0
    bias_saii: float = 0.0
    cutoff_saii_hz: float = 20.0
    opponent_saii: float = 0.0
    normal_saii: float = 0.0
    bias_cv_saii: float = 0.0
    phase_saii: float = 0.0
    dynamic_sai: float = 0.0
    fall_sai: float = 0.0
    tau_dynamic_sai_s: float = 1.0
    shear_sai: float = 0.0
    shear_rai: float = 0.0
    shear_raii: float = 0.0
    opponent_shear_sai: float = 0.0
    opponent_shear_rai: float = 0.0
    opponent_shear_raii: float = 0.0
    i_max_sai: float | None = None
    i_max_rai: float | None = None
    i_max_raii: float | None = None
    i_max_saii: float | None = None
    tau_sai_s: float | None = None
    tau_rai_s: float | None = None
    tau_raii_s: float | None = None
    tau_saii_s: float | None = None
    negative_weight_rai: float = 1.0
    negative_weight_raii: float = 1.0
    excite_cv_sai: float = 0.0
    excite_cv_rai: float = 0.0
    excite_cv_raii: float = 0.0
    excite_cv_saii: float = 0.0

    def __post_init__(self):
        for name in ("g_sai", "g_rai", "g_raii", "g_saii", "cutoff_hz", "cutoff_saii_hz", "tau_adapt_sai_s",
                     "tau_adapt_rai_s", "tau_dynamic_sai_s"):
            check_positive(getattr(self, name), name)
        _optional_positive(self, ("i_sat", "i_sat_sai", "i_sat_rai", "i_sat_raii", "i_max_sai", "i_max_rai",
                                  "i_max_raii", "i_max_saii"), "mV/ms")
        _optional_positive(self, ("cutoff_sai_hz", "cutoff_rai_hz", "cutoff_raii_hz", "highpass_raii_hz"), "Hz")
        _optional_positive(self, ("tau_sai_s", "tau_rai_s", "tau_raii_s", "tau_saii_s"), "s")
        for name in ("filter_order", "order_raii"):
            value = getattr(self, name)
            if value is None and name == "order_raii":
                continue
            if isinstance(value, bool) or not isinstance(value, int) or not 1 <= value <= 8:
                raise ValueError(f"{name} must be an int in [1, 8], got {value!r}")
        if not self.fall_sai < 1.0:
            raise ValueError(f"fall_sai must be a number in [0, 1), got {self.fall_sai!r}")
        if isinstance(self.phase_saii, bool) or not isinstance(self.phase_saii, (int, float)) \
                or not 0.0 <= self.phase_saii <= 1.0:
            raise ValueError(f"phase_saii must be a number in [0, 1], got {self.phase_saii!r}")
        for name in ("adapt_sai", "adapt_rai", "threshold_rai", "bias_saii", "opponent_saii", "normal_saii",
                     "bias_cv_saii", "dynamic_sai", "fall_sai", "excite_cv_sai", "excite_cv_rai", "excite_cv_raii",
                     "excite_cv_saii", "shear_sai", "shear_rai", "shear_raii", "opponent_shear_sai",
                     "opponent_shear_rai", "opponent_shear_raii"):
            value = getattr(self, name)
            if isinstance(value, bool) or not isinstance(value, (int, float)) or not np.isfinite(value) or value < 0:
                raise ValueError(f"{name} must be a finite number >= 0, got {value!r}")
        for name in ("negative_weight_rai", "negative_weight_raii"):
            value = getattr(self, name)
            if isinstance(value, bool) or not isinstance(value, (int, float)) or not 0.0 <= value <= 1.0:
                number = isinstance(value, (int, float)) and not isinstance(value, bool)
                shown = f"{float(value):g}" if number else repr(value)
                raise ValueError(f"{name} must be a number in [0, 1] (1: the paper's absolute value), got {shown}")

    def _own(self, prefix: str, afferent_type: str, suffix: str = "", default=None):
        """The per-type field ``<prefix>_<type><suffix>`` (e.g. ``i_max_raii``), or ``default`` if it has none."""
        return getattr(self, f"{prefix}_{afferent_type.lower()}{suffix}", default)

    def gain(self, afferent_type: str) -> float:
        """The gain of ``afferent_type`` (``"SAI"``, ``"RAI"``, ``"RAII"`` or ``"SAII"``)."""
        afferent_type = normalize_type(afferent_type)
        return self._own("g", afferent_type)

    def excite_cv(self, afferent_type: str) -> float:
        """The trial-to-trial excitability CV of ``afferent_type`` (dimensionless; 0: none)."""
        return float(self._own("excite_cv", normalize_type(afferent_type)))

    def saturation(self, afferent_type: str) -> float | None:
        """The log-compression scale of ``afferent_type`` in mV/ms (None: linear; SA-II has none)."""
        if afferent_type == "SAII":
            return None
        own = self._own("i_sat", afferent_type)
        return self.i_sat if own is None else own

    def stage(self, afferent_type: str) -> "CurrentStage":
        """The resolved stage of one type: filter, derivative order, transducer."""
        afferent_type = normalize_type(afferent_type)
        cutoff = self._own("cutoff", afferent_type, "_hz")
        if afferent_type in ("RAI", "RAII"):
            cutoff = cutoff or self.cutoff_hz  # the paper's shared low-pass before the derivatives
        order = self.order_raii if afferent_type == "RAII" and self.order_raii is not None else self.filter_order
        tau_adapt = self._own("tau_adapt", afferent_type, "_s", self.tau_adapt_sai_s)
        return CurrentStage(afferent_type, DERIVATIVE_ORDER[afferent_type], cutoff, order,
                            self._own("adapt", afferent_type, default=0.0), tau_adapt, self.gain(afferent_type),
                            self.saturation(afferent_type), self._own("i_max", afferent_type),
                            self._own("bias", afferent_type, default=0.0), self._own("tau", afferent_type, "_s"),
                            self._own("threshold", afferent_type, default=0.0),
                            self._own("highpass", afferent_type, "_hz"),
                            float(self._own("negative_weight", afferent_type, default=1.0)),
                            self._own("dynamic", afferent_type, default=0.0),
                            self._own("tau_dynamic", afferent_type, "_s", 1.0),
                            self._own("bias_cv", afferent_type, default=0.0), self._own("fall", afferent_type, default=0.0),
                            self._own("shear", afferent_type, default=0.0),
                            self._own("opponent_shear", afferent_type, default=0.0))


@dataclass(frozen=True)
class CurrentStage:
    """One type's resolved current stage (see `CurrentParams.stage`).

    Attributes
    ----------
    afferent_type : str
    derivative : int
        0 (force or stretch), 1 (velocity) or 2 (acceleration).
    cutoff_hz : float or None
        Low-pass cut-off in Hz (None: no filter).
    order : int
        Low-pass order.
    adapt, tau_adapt_s : float
        Slow-adaptation depth (dimensionless) and time constant (s).
    gain : float
        Gain from the drive to mV/ms.
    i_sat, i_max : float or None
        Log-compression scale and saturation bound, mV/ms.
    bias : float
        Tonic current in mV/ms.
    tau_s : float or None
        Time constant of the current's low-pass in s.
    threshold : float
        Dead zone of the rectified drive (RA-I's velocity threshold, N/s).
    highpass_hz : float or None
        Cut-off of a 2nd-order high-pass in the filter cascade (RA-II), Hz.
    negative_weight : float
        Weight of the derivative's negative half-wave when it is rectified
        (1.0: the absolute value; dimensionless).
    dynamic, tau_dynamic_s : float
        Depth (dimensionless) and time constant (s) of the current-level
        dynamic response (SA-I's ``dynamic_sai``).
    bias_cv : float
        Spread of the tonic current across units (SA-II's ``bias_cv_saii``).
    fall : float
        Lasting adaptation of the current (SA-I's ``fall_sai``).
    shear : float
        Gain of the shear-magnitude term added to F_A (dimensionless; 0: none).
    opponent_shear : float
        How much shear against the preferred direction lowers that term (dimensionless).
    """

    afferent_type: str
    derivative: int
    cutoff_hz: float | None
    order: int
    adapt: float
    tau_adapt_s: float
    gain: float
    i_sat: float | None
    i_max: float | None
    bias: float
    tau_s: float | None = None
    threshold: float = 0.0
    highpass_hz: float | None = None
    negative_weight: float = 1.0
    dynamic: float = 0.0
    tau_dynamic_s: float = 1.0
    bias_cv: float = 0.0
    fall: float = 0.0
    shear: float = 0.0
    opponent_shear: float = 0.0

    @property
    def signed(self) -> bool:
        """Whether the drive keeps its sign (SA-II's stretch) instead of being rectified."""
        return self.afferent_type == "SAII"


def check_fs(fs: float, params: "CurrentParams", types=AFFERENT_TYPES) -> None:
    """Refuse a sample rate too slow for a type's filter band.

    RA-II's stage needs ``fs >= 2.5 * cutoff`` (its band must sit well below
    the Nyquist frequency); every filter needs its cut-off below ``fs / 2``.

    Raises
    ------
    ValueError
        Naming the type, its band and the rate needed.
    """
    for kind in types:
        stage = params.stage(kind)
        if stage.cutoff_hz is None:
            continue
        need = RAII_FS_FACTOR * stage.cutoff_hz if kind == "RAII" else 2.0 * stage.cutoff_hz
        if fs < need or stage.cutoff_hz >= fs / 2.0:
            raise ValueError(
                f"fs={fs:g} Hz is too slow for {kind}: its band reaches {stage.cutoff_hz:g} Hz, which needs force "
                f"sampled at >= {need:g} Hz; resample the scene faster or leave {kind} out (types=...)"
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
    """

    zi: np.ndarray
    offset: np.ndarray
    y1: np.ndarray
    y2: np.ndarray
    slow: np.ndarray | None = None
    smooth: np.ndarray | None = None
    dyn: np.ndarray | None = None


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


def _stage_sos(stage: CurrentStage, fs: float) -> np.ndarray:
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
    sos = _stage_sos(params.stage(afferent_type), fs)
    zeros = np.zeros_like(f0)
    return FilterState(zi=np.zeros((sos.shape[0], 2, f0.size)), offset=f0, y1=zeros, y2=zeros.copy(),
                       slow=zeros.copy(), smooth=zeros.copy(), dyn=zeros.copy())


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
    shared = CurrentStage("RAI", 0, params.cutoff_hz, params.filter_order, 0.0, 1.0, 1.0, None, None, 0.0)
    if state is None:
        state = initial_filter_state(f_a[0], fs, params)
    m = f_a.shape[1]
    zi, y1, y2 = state.zi.copy(), state.y1.copy(), state.y2.copy()
    slow = np.zeros(m)
    # The stage kernel with order 0, unit gain and a signed drive returns exactly deviation + offset.
    y = stage_kernel(_stage_sos(shared, float(fs)), np.ascontiguousarray(f_a), state.offset, zi, y1, y2, slow,
                      float(fs), 0, 0.0, 0.0, 0.0, 1.0, np.ones(m), _NO_NORMALS, np.ones(m), False, True)
    return y, FilterState(zi=zi, offset=state.offset, y1=y1, y2=y2, slow=slow, smooth=state.smooth)


def afferent_current(
    f_a,
    fs: float,
    afferent_type: str,
    params: CurrentParams = CurrentParams(),
    state: FilterState | None = None,
    scale=None,
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
    >>> i, _ = afferent_current(f, 1000.0, "RAI", CurrentParams(g_rai=1.0))
    >>> round(float(i[-1, 0]), 2)                          # settles at 1 N/s
    1.0
    """
    afferent_type = normalize_type(afferent_type)
    fs = check_positive(fs, "fs", "Hz")
    f_a = as_finite_array(f_a, "f_a", ndim=2)
    check_fs(fs, params, (afferent_type,))
    return current_core(f_a, fs, afferent_type, params, state, scale)


def current_core(f_a, fs, afferent_type, params, state=None, scale=None, normals=None, noise_cv=None, excite=None,
                 afferent_id=None):
    """`afferent_current` without validation (the hot path of `simulate`).

    ``normals`` (shape (n_afferents, n_samples), standard normal draws) and
    ``noise_cv`` (sqrt(ms), per afferent) add the receptor noise of the
    module docstring; without them the current is noise-free.  Every stage
    after the paper's unfiltered SAI runs in one numba pass
    (`ddmm.models._stage_kernels.stage_kernel`) and numpy's vectorised
    transducers; `ddmm.models.fused` runs the same arithmetic for the streaming
    encoder.  ``excite`` (per afferent, dimensionless; `excitability`)
    multiplies the trial's current after the log compression and before
    the bound ``i_max`` (`transduce_inplace`).
    encoder.  ``afferent_id`` (int array) keys the per-unit spread of the
    tonic current (`bias_multiplier`); None: no spread.
    """
    fs = float(fs)
    st, sos, alpha_adapt, alpha_smooth = stage_constants(params, afferent_type, fs)
    gain = st.gain if scale is None else st.gain * np.asarray(scale, dtype=float)
    noisy = normals is not None and noise_cv is not None and bool(np.any(np.asarray(noise_cv) > 0))
    if st.derivative == 0 and st.cutoff_hz is None and st.adapt == 0.0 and st.tau_s is None:
        drive = gain * np.abs(f_a)  # the paper's eq. 1, no filter
        return transduce_inplace(_receptor_noise(drive, normals, noise_cv, fs) if noisy else drive, st, excite), None
    if state is None:
        state = initial_filter_state(f_a[0], fs, params, afferent_type)
    m = f_a.shape[1]
    zi, y1, y2 = state.zi.copy(), state.y1.copy(), state.y2.copy()
    slow = np.zeros(m) if state.slow is None else state.slow.copy()
    smooth = np.zeros(m) if state.smooth is None else state.smooth.copy()
    gain = gain if np.ndim(gain) else np.full(m, gain)
    cv_scale = np.asarray(noise_cv, dtype=float) / np.sqrt(1000.0 / fs) if noisy else gain
    drive = stage_kernel(sos, np.ascontiguousarray(f_a), state.offset, zi, y1, y2, slow, fs, st.derivative,
                         float(st.adapt), alpha_adapt, float(st.threshold), float(st.negative_weight), gain,
                         np.ascontiguousarray(normals) if noisy else _NO_NORMALS, cv_scale, noisy, st.signed)
    current = transduce_inplace(drive, st, excite)  # numpy's vectorised log1p/tanh: 5-10x numba's scalar calls
    if st.tau_s is not None:
        current = smooth_kernel(current, smooth, alpha_smooth)
    dyn = np.zeros(m) if state.dyn is None else state.dyn.copy()
    if st.dynamic > 0.0 or st.fall > 0.0:
        current = dynamic_kernel(current, dyn, _alpha(st.tau_dynamic_s, fs), float(st.dynamic), float(st.fall))
    if st.bias != 0.0:
        current += tonic_current(st, afferent_id, m)
    return current, FilterState(zi, state.offset, y1, y2, slow, smooth, dyn)


#: Key of the per-unit draws of the tonic current's spread (`bias_multiplier`): a fixed key, so the
#: spread is a property of the unit, not of a run's seed.
BIAS_KEY = 0x5A11_B1A5_0000_0001
#: Tag mixed into a stream key for the initial phase (`initial_phase`): a stream of its own.
PHASE_TAG = 0x9E37_79B9_7F4A_7C15


def _alpha(tau_s: float, fs: float) -> float:
    return float(-np.expm1(-1.0 / (fs * tau_s)))


def bias_multiplier(bias_cv: float, afferent_id) -> np.ndarray:
    """Per-unit lognormal multiplier of the tonic current, mean 1 and CV ``bias_cv``, keyed by afferent id.

    Examples
    --------
    >>> m = bias_multiplier(0.4, np.arange(2000))
    >>> bool(0.35 < m.std() < 0.45), bool(np.all(bias_multiplier(0.0, [3, 4]) == 1.0))
    (True, True)
    """
    ids = np.ascontiguousarray(np.atleast_1d(afferent_id), dtype=np.int64)
    if bias_cv == 0.0:
        return np.ones(ids.size)
    from ddmm.models.rng import normals

    s2 = float(np.log1p(bias_cv * bias_cv))
    return np.exp(np.sqrt(s2) * normals(BIAS_KEY, ids, 0, 1)[:, 0] - s2 / 2.0)


def tonic_current(stage: CurrentStage, afferent_id, m: int):
    """Each afferent's tonic current (mV/ms): ``stage.bias``, times `bias_multiplier` when spread."""
    if stage.bias_cv == 0.0 or afferent_id is None:
        return np.full(m, stage.bias)
    return stage.bias * bias_multiplier(stage.bias_cv, afferent_id)


def initial_phase(key: int, afferent_id) -> np.ndarray:
    """Uniform draws in [0, 1) keyed by (stream ``key``, afferent id): the start phase of each tonic neuron."""
    from math import erf, sqrt

    from ddmm.models.rng import normals

    ids = np.ascontiguousarray(np.atleast_1d(afferent_id), dtype=np.int64)
    z = normals(np.uint64(key) ^ np.uint64(PHASE_TAG), ids, 0, 1)[:, 0]
    return np.array([min(0.5 * (1.0 + erf(v / sqrt(2.0))), np.nextafter(1.0, 0.0)) for v in z])


_NO_NORMALS = np.zeros((1, 0))


@lru_cache(maxsize=256)
def stage_constants(params: CurrentParams, afferent_type: str, fs: float):
    """(stage, filter sections, adaptation and smoothing coefficients), cached: per call they would
    cost a short chunk more than its arithmetic."""
    stage = params.stage(afferent_type)
    alpha_adapt = float(-np.expm1(-1.0 / (fs * stage.tau_adapt_s)))
    alpha_smooth = 0.0 if stage.tau_s is None else float(-np.expm1(-1.0 / (fs * stage.tau_s)))
    return stage, _stage_sos(stage, fs), alpha_adapt, alpha_smooth


#: The counter (sample index) of the per-trial excitability draw: no scene reaches 2**32 - 1 samples.
EXCITE_SAMPLE = 0xFFFFFFFF


def excitability(key, afferent_id, cv) -> np.ndarray:
    """Per-trial excitability factors: lognormal, mean 1, coefficient of variation ``cv`` (per afferent).

    ``exp(s z - s^2 / 2)`` with ``s^2 = log(1 + cv^2)`` and ``z`` the
    standard normal of (trial key ``key``, afferent id, sample
    `EXCITE_SAMPLE`) (`ddmm.models.rng.normal`): a pure function of
    (seed, condition, trial, afferent), so every chunking, engine and
    process draws the same factor.

    Examples
    --------
    >>> from ddmm.models.rng import stream_key
    >>> e = excitability(stream_key(0, 0, 0), [3, 4], [0.0, 0.2])
    >>> float(e[0]), bool(e[1] != 1.0)
    (1.0, True)
    """
    from ddmm.models.rng import normals

    cv = np.asarray(cv, dtype=float)
    s = np.sqrt(np.log1p(cv * cv))
    z = normals(int(key), np.asarray(afferent_id, dtype=np.int64), EXCITE_SAMPLE, 1)[:, 0]
    return np.exp(s * z - 0.5 * s * s)


def _receptor_noise(drive, normals, noise_cv, fs):
    """``d (1 + cv xi / sqrt(h))`` on the paper's unfiltered SAI drive, rectified."""
    scale = np.asarray(noise_cv, dtype=float) / np.sqrt(1000.0 / fs)
    return np.maximum(drive + drive * (normals.T * scale), 0.0)
