"""`TypeParams`: one afferent type's current-stage parameters, as a type declares them.

Each registered type (`ddmm.models.afferent_types.AfferentType.current`)
carries its defaults as one `TypeParams`; `ddmm.models.current_params.CurrentParams`
holds a population's overrides, one `TypeParams` per type, and resolves them
with the shared filter fields into the `TypeCurrentParams` the stage
arithmetic consumes.  Which mechanisms a field drives is the type's
(`AfferentType.derivative_order`, ``stretch_drive``, ``log_compression``,
``phase_spread``); a field a type's mechanisms never read is inert.  The
model these fields parametrise is described in `ddmm.models.currents`.
"""

from __future__ import annotations

import dataclasses
from dataclasses import dataclass

import numpy as np

from ddmm.utils.validation import check_positive, shown

__all__ = ["TypeParams"]

_POSITIVE = ("gain", "tau_adapt_s", "tau_dynamic_s", "tau_transient_s")
_OPTIONAL_POSITIVE = {"cutoff_hz": "Hz", "highpass_hz": "Hz", "i_sat": "mV/ms", "i_max": "mV/ms", "tau_s": "s"}
_NON_NEGATIVE = ("adapt", "threshold", "bias", "bias_cv", "dynamic", "transient", "shear", "opponent_shear",
                 "excite_cv", "opponent", "normal")
_UNIT_INTERVAL = ("negative_weight", "depth", "phase")


@dataclass(frozen=True)
class TypeParams:
    """The current-stage parameters of one afferent type (units in each field; *ours*: not in the paper).

    The defaults are the paper's form (eqs 1-3) with a unit gain: every
    departure is off (0, 1 or None).

    Attributes
    ----------
    gain : float
        Gain from the drive to the current: (mV/ms) per N, per (N/s) or per
        (N/s^2) for a type whose current follows force, velocity or
        acceleration (eqs 1-3).
    cutoff_hz : float or None
        Cut-off in Hz of the type's causal Butterworth low-pass.  None: the
        shared ``CurrentParams.cutoff_hz`` for a type with
        `AfferentType.shared_cutoff` (the paper's filter before the
        derivatives), else unfiltered.
    order : int or None
        Order of that low-pass, in [1, 8] (None: ``CurrentParams.filter_order``).
    highpass_hz : float or None
        Ours: cut-off in Hz of a 2nd-order high-pass in the filter cascade
        (RA-II's: the Pacinian capsule filters slow indentation); None: none.
    adapt : float
        Ours: adaptation depth (dimensionless, >= 0; 0: none).  For a
        force-following type, ``adapt (y - slow)`` is added, ``slow`` a
        first-order low-pass of the filtered force (SA-I's slow adaptation);
        for a derivative type, ``adapt`` times a low-pass of the rectified
        derivative is subtracted, floored at 0 (RA-I's adaptation to a
        sustained velocity).
    tau_adapt_s : float
        Ours: time constant of that low-pass in s.
    threshold : float
        Ours: dead zone subtracted from the rectified drive, in the drive's
        units (RA-I's velocity threshold, N/s); each unit's is this over its
        sensitivity.
    negative_weight : float
        Ours: weight in [0, 1] of the derivative's negative half-wave when
        it is rectified (1.0: the absolute value of eqs 2-3).
    i_sat : float or None
        Log-compression scale in mV/ms, ``I = i_sat log1p(d / i_sat)``, for a
        type with `AfferentType.log_compression` (None: the shared
        ``CurrentParams.i_sat``).
    i_max : float or None
        Ours: bound of the saturating transducer in mV/ms,
        ``I = i_max tanh(d / i_max)``; None: no bound.
    excite_cv : float
        Ours: trial-to-trial excitability, the CV (dimensionless, >= 0) of a
        per-trial lognormal factor on the current (`ddmm.models.variability.excitability`).
    tau_s : float or None
        Ours: time constant in s of the first-order low-pass on the current;
        None: none.
    dynamic, fall : float
        Ours: depth of the dynamic response on the current (>= 0) and its
        lasting fall (in [0, 1)), ``I <- max(I + dynamic (I - J) - fall J, 0)``
        with ``J`` a low-pass of the current (SA-I's).
    tau_dynamic_s : float
        Ours: time constant of ``J`` in s.
    transient : float
        Ours: depth of the fast transient on the current (>= 0): a rectified
        band-pass ``transient max(R - K, 0)`` of the current (SA-I's).
    tau_transient_s : float
        Ours: the longer time constant of that band-pass in s.
    shear : float
        Ours: gain (dimensionless) of the shear-magnitude term added to F_A,
        ``shear F_S (AF - opponent_shear (1 - AF))``; 0: the paper's F_A.
    opponent_shear : float
        Ours: how much shear against the preferred direction lowers that
        term (dimensionless, >= 0).
    depth : float
        Ours: depth in [0, 1] of the NAP's attenuation of the normal force,
        ``F_A = (1 + depth (AF - 1)) F_Z`` (1: the paper's ``AF F_Z``, eq. 18).
    bias : float
        Ours: tonic current in mV/ms (a resting discharge).
    bias_cv : float
        Ours: spread (CV, dimensionless) of the tonic current across units,
        a lognormal multiplier keyed by the afferent's id
        (`ddmm.models.variability.bias_multiplier`).
    opponent : float
        Ours, a stretch-drive type's (SA-II's): how much stretch against the
        preferred direction lowers the drive, ``F_S (AF - opponent (1 - AF))``.
    normal : float
        Ours, a stretch-drive type's: weight (dimensionless) of the normal
        force in the drive, ``x + normal F_Z``.
    phase : float
        Ours, a `AfferentType.phase_spread` type's: spread in [0, 1] of its
        neurons' start phases over their tonic cycle
        (`ddmm.models.variability.initial_phase`; 0: every neuron at rest).

    Examples
    --------
    >>> TypeParams(gain=5.0, i_max=60.0).replace(gain=2.0).gain
    2.0
    >>> TypeParams(gain=-1.0)
    Traceback (most recent call last):
    ...
    ValueError: gain must be a finite number > 0, got -1.0
    """

    gain: float = 1.0
    cutoff_hz: float | None = None
    order: int | None = None
    highpass_hz: float | None = None
    adapt: float = 0.0
    tau_adapt_s: float = 1.0
    threshold: float = 0.0
    negative_weight: float = 1.0
    i_sat: float | None = None
    i_max: float | None = None
    excite_cv: float = 0.0
    tau_s: float | None = None
    dynamic: float = 0.0
    fall: float = 0.0
    tau_dynamic_s: float = 1.0
    transient: float = 0.0
    tau_transient_s: float = 0.05
    shear: float = 0.0
    opponent_shear: float = 0.0
    depth: float = 1.0
    bias: float = 0.0
    bias_cv: float = 0.0
    opponent: float = 0.0
    normal: float = 0.0
    phase: float = 0.0

    def __post_init__(self):
        for name in _POSITIVE:
            check_positive(getattr(self, name), name)
        for name, unit in _OPTIONAL_POSITIVE.items():
            if getattr(self, name) is not None:
                check_positive(getattr(self, name), name, unit)
        if self.order is not None and (isinstance(self.order, bool) or not isinstance(self.order, int)
                                       or not 1 <= self.order <= 8):
            raise ValueError(f"order must be an int in [1, 8] or None, got {shown(self.order)}")
        for name in _NON_NEGATIVE:
            if not _is_number(getattr(self, name)) or getattr(self, name) < 0:
                raise ValueError(f"{name} must be a finite number >= 0, got {shown(getattr(self, name))}")
        for name in _UNIT_INTERVAL:
            if not _is_number(getattr(self, name)) or not 0.0 <= getattr(self, name) <= 1.0:
                paper = " (1: the paper's form)" if name != "phase" else ""
                raise ValueError(f"{name} must be a number in [0, 1]{paper}, got {shown(getattr(self, name))}")
        if not self.fall < 1.0:
            raise ValueError(f"fall must be a number in [0, 1), got {shown(self.fall)}")

    def replace(self, **changes) -> TypeParams:
        """A copy with ``changes`` (field names of `TypeParams`), validated.

        Examples
        --------
        >>> TypeParams().replace(adapt=0.5).adapt
        0.5
        """
        unknown = sorted(set(changes) - set(FIELDS))
        if unknown:
            raise TypeError(f"{unknown[0]!r} is not a field of TypeParams; allowed: {', '.join(FIELDS)}")
        return dataclasses.replace(self, **changes)


def _is_number(value) -> bool:
    return isinstance(value, (int, float)) and not isinstance(value, bool) and bool(np.isfinite(value))


#: The fields of `TypeParams`, in declaration order.
FIELDS = tuple(f.name for f in dataclasses.fields(TypeParams))
