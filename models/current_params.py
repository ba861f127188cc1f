"""The parameters of the current stage: `CurrentParams` and the per-type `TypeCurrentParams` it resolves to.

`CurrentParams` holds every gain, filter and transducer of the four types,
validated when built; `CurrentParams.for_type` resolves one type's fields into a
`TypeCurrentParams`, which the stage arithmetic (`ddmm.models.currents`) and the
fused pipeline (`ddmm.models.fused`) consume.  The model these fields
parametrise, and which of them depart from the paper, is described in
`ddmm.models.currents`.
"""

from __future__ import annotations

from dataclasses import dataclass
from functools import cached_property

import numpy as np

from ddmm.models.afferent_types import AFFERENT_TYPES, afferent_type_info, normalize_type
from ddmm.utils.deprecation import warn_renamed
from ddmm.utils.validation import check_positive, shown

__all__ = ["DERIVATIVE_ORDER", "CurrentParams", "TypeCurrentParams"]

#: Derivative order of each type's drive: force, velocity, acceleration, stretch
#: (`ddmm.models.afferent_types.AfferentType.derivative_order`).
DERIVATIVE_ORDER = {code: afferent_type_info(code).derivative_order for code in AFFERENT_TYPES}


def _optional_positive(obj, names, unit):
    for name in names:
        if getattr(obj, name) is not None:
            check_positive(getattr(obj, name), name, unit)


@dataclass(frozen=True)
class CurrentParams:
    """Gains, filters and transducers of the current stage.

    The defaults are the paper's eqs 1-3, with gains calibrated so that the
    CMM (AF = 1) press-push-lift response lies near paper Table III (SAI
    about 47.5 pulses/s, RAI and RAII 10-20); ``experiments/calibration/gains.py``
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
    transient_sai : float
        Ours: depth of SA-I's fast transient on the current (dimensionless,
        0: none): ``transient_sai max(R - K, 0)`` is added as well, with ``R`` and
        ``K`` first-order low-passes of the current of time constants
        ``tau_transient_sai_s / 2`` and ``tau_transient_sai_s`` (``K``
        filters ``R``): a band-pass, so the receptor noise's fast part is not
        amplified with it, rectified, so that it answers loading and takes
        nothing away in unloading.  While the current rises, ``R - K`` is about
        ``tau dI/dt``: a rate-of-loading response that peaks in fast loading
        and has gone within a few ``tau`` of the hold, so it neither moves
        the plateau nor the slower fall of ``fall_sai`` (docs/model.md, "What
        changed").
    tau_transient_sai_s : float
        Ours: the longer time constant of that band-pass in s.
    shear_sai, shear_rai, shear_raii : float
        Ours: gain of the shear-magnitude term added to the type's F_A
        (dimensionless, N of drive per N of shear; 0: the paper's F_A, which
        shear only attenuates), ``shear * F_S * (AF - opponent_shear (1 - AF))``
        with AF the profile's own factor (docs/model.md, "What changed").
    opponent_shear_sai, opponent_shear_rai, opponent_shear_raii : float
        Ours: how much shear against the preferred direction lowers the
        type's shear term (dimensionless, as ``opponent_saii``; 0: the term
        is AF F_S, never negative).
    depth_sai, depth_rai, depth_raii : float
        Ours: how deep the NAP's attenuation of the normal force goes, in
        [0, 1] (dimensionless; 1: the paper's ``F_A = AF F_Z``, eq. 18):
        ``F_A = (1 + depth (AF - 1)) F_Z``, so at 0.5 the normal force keeps
        at least half its drive in every direction and the direction is
        carried more by the shear term (docs/model.md, "What changed").
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
    transient_sai: float = 0.0
    tau_transient_sai_s: float = 0.05
    shear_sai: float = 0.0
    shear_rai: float = 0.0
    shear_raii: float = 0.0
    opponent_shear_sai: float = 0.0
    opponent_shear_rai: float = 0.0
    opponent_shear_raii: float = 0.0
    depth_sai: float = 1.0
    depth_rai: float = 1.0
    depth_raii: float = 1.0
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
                     "tau_adapt_rai_s", "tau_dynamic_sai_s", "tau_transient_sai_s"):
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
                raise ValueError(f"{name} must be an int in [1, 8], got {shown(value)}")
        if not self.fall_sai < 1.0:
            raise ValueError(f"fall_sai must be a number in [0, 1), got {shown(self.fall_sai)}")
        if isinstance(self.phase_saii, bool) or not isinstance(self.phase_saii, (int, float)) \
                or not 0.0 <= self.phase_saii <= 1.0:
            raise ValueError(f"phase_saii must be a number in [0, 1], got {shown(self.phase_saii)}")
        for name in ("adapt_sai", "adapt_rai", "threshold_rai", "bias_saii", "opponent_saii", "normal_saii",
                     "bias_cv_saii", "dynamic_sai", "transient_sai", "fall_sai", "excite_cv_sai", "excite_cv_rai",
                     "excite_cv_raii", "excite_cv_saii", "shear_sai", "shear_rai", "shear_raii", "opponent_shear_sai",
                     "opponent_shear_rai", "opponent_shear_raii"):
            value = getattr(self, name)
            if isinstance(value, bool) or not isinstance(value, (int, float)) or not np.isfinite(value) or value < 0:
                raise ValueError(f"{name} must be a finite number >= 0, got {shown(value)}")
        for name in ("negative_weight_rai", "negative_weight_raii", "depth_sai", "depth_rai", "depth_raii"):
            value = getattr(self, name)
            if isinstance(value, bool) or not isinstance(value, (int, float)) or not 0.0 <= value <= 1.0:
                raise ValueError(f"{name} must be a number in [0, 1] (1: the paper's form), got {shown(value)}")

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
        """The log-compression scale of ``afferent_type`` in mV/ms (None: linear, as for a type without
        `AfferentType.log_compression`, SA-II)."""
        kind = afferent_type_info(afferent_type)
        if not kind.log_compression:
            return None
        own = self._own("i_sat", kind.code)
        return self.i_sat if own is None else own

    def for_type(self, afferent_type: str) -> TypeCurrentParams:
        """The current parameters of one type, resolved: filter, derivative order, transducer."""
        kind = afferent_type_info(afferent_type)
        afferent_type = kind.code
        cutoff = self._own("cutoff", afferent_type, "_hz")
        if kind.shared_cutoff:
            cutoff = cutoff or self.cutoff_hz  # the paper's shared low-pass before the derivatives
        order = self._own("order", afferent_type)  # the type's own order (``order_raii``), if it has one
        order = self.filter_order if order is None else order
        tau_adapt = self._own("tau_adapt", afferent_type, "_s", self.tau_adapt_sai_s)
        return TypeCurrentParams(afferent_type, kind.derivative_order, cutoff, order,
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
                            self._own("opponent_shear", afferent_type, default=0.0),
                            float(self._own("depth", afferent_type, default=1.0)),
                            float(self._own("transient", afferent_type, default=0.0)),
                            float(self._own("tau_transient", afferent_type, "_s", 0.05)))


    def stage(self, afferent_type: str) -> TypeCurrentParams:
        """Deprecated name of `for_type` ("stage" names a scene's interval, `ddmm.population.Stage`)."""
        warn_renamed("CurrentParams.stage()", "CurrentParams.for_type()")
        return self.for_type(afferent_type)


@dataclass(frozen=True)
class TypeCurrentParams:
    """One type's current parameters, resolved from `CurrentParams` (see `CurrentParams.for_type`).

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
    depth : float
        Depth of the NAP's attenuation of the normal force, in [0, 1] (1: the paper's F_A).
    transient, tau_transient_s : float
        Depth (dimensionless) and time constant (s) of the fast transient on
        the current (SA-I's ``transient_sai``).
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
    depth: float = 1.0
    transient: float = 0.0
    tau_transient_s: float = 0.05

    @cached_property  # read on every streamed push: looked up once per stage
    def signed(self) -> bool:
        """Whether the drive keeps its sign instead of being rectified: a stretch drive's
        (`ddmm.models.afferent_types.AfferentType.stretch_drive`, SA-II's)."""
        return afferent_type_info(self.afferent_type).stretch_drive


def __getattr__(name):
    if name == "CurrentStage":  # the old name, for one release
        warn_renamed("CurrentStage", "TypeCurrentParams")
        return TypeCurrentParams
    raise AttributeError(f"module {__name__!r} has no attribute {name!r}")
