"""The parameters of the current stage: `CurrentParams` and the per-type `TypeCurrentParams` it resolves to.

`CurrentParams` holds the shared filter and one `TypeParams` per afferent type
(each type's registered default unless overridden), validated when built;
`CurrentParams.for_type` resolves one type's parameters into a
`TypeCurrentParams`, which the stage arithmetic (`ddmm.models.currents`) and the
fused pipeline (`ddmm.models.fused`) consume.  The model these fields
parametrise, and which of them depart from the paper, is described in
`ddmm.models.currents`.
"""

from __future__ import annotations

from collections.abc import Mapping
from dataclasses import dataclass
from functools import cached_property

from ddmm.models.afferent_types import AFFERENT_TYPES, afferent_type_codes, afferent_type_info, normalize_type
from ddmm.models.type_params import FIELDS as TYPE_FIELDS
from ddmm.models.type_params import TypeParams
from ddmm.utils.deprecation import warn_renamed
from ddmm.utils.validation import check_positive, shown

__all__ = ["DERIVATIVE_ORDER", "LEGACY_FIELDS", "CurrentParams", "TypeCurrentParams", "TypeParams"]

#: Derivative order of each type's drive: force, velocity, acceleration, stretch
#: (`ddmm.models.afferent_types.AfferentType.derivative_order`).
DERIVATIVE_ORDER = {code: afferent_type_info(code).derivative_order for code in AFFERENT_TYPES}


#: The fields ``<prefix>_<type><suffix>`` of the old flat `CurrentParams` (one release of deprecation), by the
#: `TypeParams` field each one is now: ``g_sai`` is ``TypeParams.gain`` of SA-I.
_LEGACY_FORM = {"gain": ("g", ""), "i_sat": ("i_sat", ""), "cutoff_hz": ("cutoff", "_hz"), "order": ("order", ""),
                "highpass_hz": ("highpass", "_hz"), "adapt": ("adapt", ""), "tau_adapt_s": ("tau_adapt", "_s"),
                "threshold": ("threshold", ""), "bias": ("bias", ""), "opponent": ("opponent", ""),
                "normal": ("normal", ""), "bias_cv": ("bias_cv", ""), "phase": ("phase", ""),
                "dynamic": ("dynamic", ""), "fall": ("fall", ""), "tau_dynamic_s": ("tau_dynamic", "_s"),
                "transient": ("transient", ""), "tau_transient_s": ("tau_transient", "_s"), "shear": ("shear", ""),
                "opponent_shear": ("opponent_shear", ""), "depth": ("depth", ""), "i_max": ("i_max", ""),
                "tau_s": ("tau", "_s"), "negative_weight": ("negative_weight", ""), "excite_cv": ("excite_cv", "")}
_LEGACY_NAMES = frozenset("""g_sai g_rai g_raii g_saii i_sat_sai i_sat_rai i_sat_raii cutoff_sai_hz cutoff_rai_hz
cutoff_raii_hz cutoff_saii_hz order_raii highpass_raii_hz adapt_sai tau_adapt_sai_s adapt_rai tau_adapt_rai_s
threshold_rai bias_saii opponent_saii normal_saii bias_cv_saii phase_saii dynamic_sai fall_sai tau_dynamic_sai_s
transient_sai tau_transient_sai_s shear_sai shear_rai shear_raii opponent_shear_sai opponent_shear_rai
opponent_shear_raii depth_sai depth_rai depth_raii i_max_sai i_max_rai i_max_raii i_max_saii tau_sai_s tau_rai_s
tau_raii_s tau_saii_s negative_weight_rai negative_weight_raii excite_cv_sai excite_cv_rai excite_cv_raii
excite_cv_saii""".split())  # noqa: SIM905 (the old fields, as they read)
#: Old flat field -> (type code, `TypeParams` field).
LEGACY_FIELDS = {f"{prefix}_{code.lower()}{suffix}": (code, field) for code in AFFERENT_TYPES  # the package's four
                 for field, (prefix, suffix) in _LEGACY_FORM.items()
                 if f"{prefix}_{code.lower()}{suffix}" in _LEGACY_NAMES}


def _check_order(value, name):
    if isinstance(value, bool) or not isinstance(value, int) or not 1 <= value <= 8:
        raise ValueError(f"{name} must be an int in [1, 8], got {shown(value)}")


@dataclass(frozen=True, init=False)
class CurrentParams:
    """The current stage's parameters: the shared filter, and one `TypeParams` per afferent type.

    The defaults are the paper's eqs 1-3: each type's `TypeParams` is its
    registered default (`ddmm.models.afferent_types.AfferentType.current`),
    whose gains are calibrated so that the CMM (AF = 1) press-push-lift
    response lies near paper Table III (SAI about 47.5 imp/s, RAI and RAII
    10-20; ``experiments/calibration/gains.py`` reproduces the fit).

    Parameters
    ----------
    cutoff_hz : float
        Cut-off in Hz of the causal Butterworth low-pass applied to F_A before
        differentiation, for the types that share it (docs/model.md §1.6: 20 Hz
        restores Table III's aligned > misaligned ordering for RAII).
    filter_order : int
        Order of that Butterworth filter, and of every type's low-pass that
        sets none (2 in the trial of docs/model.md §1.6).
    i_sat : float or None
        Scale of the log compression in mV/ms for every type with
        `AfferentType.log_compression` that sets none:
        ``I = i_sat * log1p(g * x / i_sat)``.  None: linear, as eqs 1-3.
    types : dict of str to TypeParams, optional
        Each type's parameters, by code or any accepted spelling; a type not
        given keeps its registered default.
    **legacy
        Deprecated for one release: the old flat fields ``<field>_<type>``
        (``g_sai=5.0`` is ``types={"SAI": TypeParams(gain=5.0, ...)}``),
        applied on top of ``types`` (`LEGACY_FIELDS` lists them).  Reading
        one (``params.g_sai``) works too, with the same warning.

    Examples
    --------
    >>> from ddmm.models.type_params import TypeParams
    >>> p = CurrentParams(types={"SAI": TypeParams(gain=10.0, i_max=60.0)})
    >>> p.type_params("SAI").gain, p.type_params("RAI").gain
    (10.0, 11.036)
    >>> p.with_type("FA-I", gain=6.0).for_type("RAI").gain
    6.0
    """

    cutoff_hz: float = 20.0
    filter_order: int = 2
    i_sat: float | None = None
    types: tuple = ()

    def __init__(self, cutoff_hz: float = 20.0, filter_order: int = 2, i_sat: float | None = None, types=None,
                 **legacy):
        check_positive(cutoff_hz, "cutoff_hz")
        _check_order(filter_order, "filter_order")
        if i_sat is not None:
            check_positive(i_sat, "i_sat", "mV/ms")
        table = _type_table(types)
        for name, value in legacy.items():
            _apply_legacy(table, name, value)
        defaults = {code: afferent_type_info(code).current for code in table}
        object.__setattr__(self, "cutoff_hz", cutoff_hz)
        object.__setattr__(self, "filter_order", filter_order)
        object.__setattr__(self, "i_sat", i_sat)
        # Only departures from the registered defaults are kept: equal parameters compare equal.
        object.__setattr__(self, "types", tuple((code, tp) for code, tp in table.items() if tp != defaults[code]))

    def type_params(self, afferent_type) -> TypeParams:
        """The `TypeParams` of a type (any accepted spelling): this object's, or the type's registered default.

        Examples
        --------
        >>> CurrentParams().type_params("FA-II").gain
        6.162
        """
        code = afferent_type_info(afferent_type).code
        for own, params in self.types:
            if own == code:
                return params
        return afferent_type_info(code).current

    def with_type(self, afferent_type, **changes) -> CurrentParams:
        """A copy whose ``afferent_type`` parameters have ``changes`` (`TypeParams` fields).

        Examples
        --------
        >>> CurrentParams().with_type("SAI", i_max=60.0).type_params("SAI").i_max
        60.0
        """
        code = afferent_type_info(afferent_type).code
        table = dict(self.types)
        table[code] = self.type_params(code).replace(**changes)
        return CurrentParams(self.cutoff_hz, self.filter_order, self.i_sat, table)

    def with_all_types(self, **changes) -> CurrentParams:
        """A copy in which every registered type's parameters have ``changes`` (`TypeParams` fields).

        Examples
        --------
        >>> CurrentParams().with_all_types(excite_cv=0.0) == CurrentParams()
        True
        """
        table = {code: self.type_params(code).replace(**changes) for code in afferent_type_codes()}
        return CurrentParams(self.cutoff_hz, self.filter_order, self.i_sat, table)

    def gain(self, afferent_type: str) -> float:
        """The gain of ``afferent_type`` (any accepted spelling)."""
        return self.type_params(afferent_type).gain

    def excite_cv(self, afferent_type: str) -> float:
        """The trial-to-trial excitability CV of ``afferent_type`` (dimensionless; 0: none)."""
        return float(self.type_params(afferent_type).excite_cv)

    def saturation(self, afferent_type: str) -> float | None:
        """The log-compression scale of ``afferent_type`` in mV/ms (None: linear, as for a type without
        `AfferentType.log_compression`, SA-II)."""
        kind = afferent_type_info(afferent_type)
        if not kind.log_compression:
            return None
        own = self.type_params(kind.code).i_sat
        return self.i_sat if own is None else own

    def for_type(self, afferent_type: str) -> TypeCurrentParams:
        """The current parameters of one type, resolved: filter, derivative order, transducer."""
        kind = afferent_type_info(afferent_type)
        tp = self.type_params(kind.code)
        cutoff = tp.cutoff_hz
        if kind.shared_cutoff:
            cutoff = cutoff or self.cutoff_hz  # the paper's shared low-pass before the derivatives
        order = self.filter_order if tp.order is None else tp.order
        own = {name: getattr(tp, name) for name in TYPE_FIELDS}
        own.update(cutoff_hz=cutoff, order=order, i_sat=self.saturation(kind.code))
        return TypeCurrentParams(afferent_type=kind.code, derivative=kind.derivative_order, **own)

    def flat(self) -> dict:
        """Every parameter as flat ``{name: value}``: the shared fields, then ``<code>_<field>`` of every
        registered type (the Dataset's ``current_*`` attrs).

        Examples
        --------
        >>> CurrentParams().flat()["RAI_gain"]
        11.036
        """
        out = {"cutoff_hz": self.cutoff_hz, "filter_order": self.filter_order, "i_sat": self.i_sat}
        for code in afferent_type_codes():
            params = self.type_params(code)
            out.update((f"{code}_{name}", getattr(params, name)) for name in TYPE_FIELDS)
        return out

    def __getattr__(self, name):
        if name in LEGACY_FIELDS:  # the old flat fields, read through the shim for one release
            code, field = LEGACY_FIELDS[name]
            warn_renamed(f"CurrentParams.{name}", f"CurrentParams.type_params({code!r}).{field}")
            return getattr(self.type_params(code), field)
        raise AttributeError(f"{type(self).__name__!r} object has no attribute {name!r}")

    def stage(self, afferent_type: str) -> TypeCurrentParams:
        """Deprecated name of `for_type` ("stage" names a scene's interval, `ddmm.population.Stage`)."""
        warn_renamed("CurrentParams.stage()", "CurrentParams.for_type()")
        return self.for_type(afferent_type)


def _type_table(types) -> dict:
    """``types`` (a dict or pairs of code and `TypeParams`) as a dict by code, checked."""
    if types is None:
        return {}
    items = types.items() if isinstance(types, Mapping) else types
    table = {}
    try:
        for spelling, params in items:
            code = normalize_type(spelling, "types")
            if not isinstance(params, TypeParams):
                raise TypeError(f"types[{spelling!r}] must be a TypeParams, got {type(params).__name__}")
            table[code] = params
    except (TypeError, ValueError) as exc:
        if isinstance(exc, ValueError) or str(exc).startswith("types["):
            raise
        raise TypeError(f"types must be a dict of afferent type to TypeParams, got {type(types).__name__}") from None
    return table


def _apply_legacy(table: dict, name: str, value) -> None:
    """Set the old flat field ``name`` in ``table`` (code -> `TypeParams`), with the deprecation warning."""
    if name not in LEGACY_FIELDS:
        raise TypeError(f"CurrentParams() got an unexpected keyword argument {name!r}")
    code, field = LEGACY_FIELDS[name]
    warn_renamed(f"CurrentParams({name}=)", f"types={{{code!r}: TypeParams({field}=...)}}", stacklevel=4)
    base = table.get(code, afferent_type_info(code).current)
    try:
        table[code] = base.replace(**{field: value})
    except (TypeError, ValueError) as exc:  # name the field as the caller wrote it
        message = str(exc)
        raise type(exc)(name + message[len(field):] if message.startswith(field) else message) from None


@dataclass(frozen=True, kw_only=True)
class TypeCurrentParams(TypeParams):
    """One type's `TypeParams` resolved against `CurrentParams` and its registry entry (`CurrentParams.for_type`).

    Every field of `TypeParams`, with three resolved: ``cutoff_hz`` (the
    shared ``CurrentParams.cutoff_hz`` for a `AfferentType.shared_cutoff`
    type without its own; None: unfiltered), ``order`` (an int: the shared
    ``CurrentParams.filter_order`` when the type sets none) and ``i_sat``
    (`CurrentParams.saturation`; None: no log compression); and two from
    the type:

    Attributes
    ----------
    afferent_type : str
        The type's code.
    derivative : int
        0 (force or stretch), 1 (velocity) or 2 (acceleration): its
        `AfferentType.derivative_order`.

    Examples
    --------
    >>> st = CurrentParams().for_type("RAI")
    >>> st.derivative, st.cutoff_hz, st.order
    (1, 20.0, 2)
    """

    afferent_type: str
    derivative: int = 0

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
