"""The afferent types of the package: one registered `AfferentType` each, with what the model path asks of it.

The paper models three types (SA-I, RA-I, RA-II; its eqs 1-3); the package
adds SA-II (Ruffini).  Codes (``"SAI"``, ``"RAI"``, ``"RAII"``, ``"SAII"``)
are the data's names in files, presets and the API; the labels are those of
the human literature (FA = fast adapting, the paper's RA).

Each type is declared once, here, by `register_afferent_type`: its code,
label, accepted spellings, figure colour, whether microneurography records it,
and the mechanisms of its current stage (the derivative of its drive, the
stretch drive, the log compression, the shared low-pass, the sampling its
band needs, the spread start phases).  Code elsewhere asks the registry
(`afferent_type_info`, `afferent_type_codes`, `type_mask`) instead of
comparing a type's code.  `AFFERENT_TYPES`, `PAPER_TYPES` and `TYPE_LABELS`
are the registry's views once the package's types are registered.
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field, fields
from operator import attrgetter

import numpy as np

from ddmm.models.neuron import NeuronParams
from ddmm.models.type_params import TypeParams

__all__ = ["AFFERENT_TYPES", "PAPER_TYPES", "TYPE_LABELS", "AfferentType", "afferent_type_codes",
           "afferent_type_info", "is_type", "normalize_type", "register_afferent_type", "type_label", "type_mask"]


@dataclass(frozen=True)
class AfferentType:
    """One afferent type: its names, its figure colour and the mechanisms of its current stage.

    Attributes
    ----------
    code : str
        The data's name of the type (files, presets, the API, the
        ``<field>_<code>`` fields of `ddmm.models.current_params.CurrentParams`),
        upper-case letters and digits.
    label : str
        Display label, as the human literature names the type (``"FA-I"``).
    spellings : tuple of str
        Further spellings accepted on input (compared without case, "-", "_"
        or spaces); the code and the label are always accepted.
    colour : str
        Its colour in every figure (a matplotlib colour).
    in_paper : bool
        Whether the paper models it (its eqs 1-3): `PAPER_TYPES`.
    recorded_by_humans : bool
        Whether the human direction-tuning recordings pool it (Birznieks et
        al. 2001 have no FA-II): `ddmm.population.analysis.tuning.RECORDED_TYPES`.
    derivative_order : int
        Derivative of the filtered drive its current follows: 0 (force or
        stretch), 1 (velocity) or 2 (acceleration).
    stretch_drive : bool
        Whether its drive is the signed skin-stretch drive
        (`ddmm.models.reference_pipeline.stretch_drive`: the attenuated shear, with
        ``SAII.opponent`` and ``SAII.normal``) instead of the attenuated
        force F_A, kept signed through the stage (not rectified); it then
        takes no depth or shear-magnitude term, which shape F_A.
    log_compression : bool
        Whether the log-compression transducer (``i_sat``, ``i_sat_<code>``)
        applies to its current.
    shared_cutoff : bool
        Whether its low-pass falls back to the shared ``cutoff_hz`` when
        ``cutoff_<code>_hz`` is None (the paper's filter before the
        derivatives); otherwise None leaves it unfiltered.
    fs_per_cutoff : float or None
        Sample rate its band needs, as a multiple of its cut-off (RA-II's
        2.5); None: above twice the cut-off (Nyquist) only.
    phase_spread : bool
        Whether `TypeParams.phase` spreads its neurons' start phases over
        their tonic cycle (`ddmm.models.currents.initial_phase`).
    current : TypeParams
        Its current-stage parameters by default (the paper's eqs 1-3 for
        the paper's types); a population overrides them in
        `ddmm.models.current_params.CurrentParams`.
    neuron : NeuronParams
        Its Izhikevich neuron by default (eqs 4-6); a population overrides
        it by type (``[neuron.<code>]``).
    rf_area_mm2 : float
        Its median receptive-field area in mm^2: the receptive-field law's
        width (`rf_sigma_mm`; `ddmm.population.anatomy.receptive_fields`).
    density_share : float or None
        Its share of the afferents in every region of the hand map
        (`ddmm.population.anatomy.hand_map`); None: not on the map (a
        population spec then gives its count).
    receptor_depth_mm : float
        Depth below the skin surface in mm at which its ending reads the
        skin's stress under indentation (`ddmm.population.stimuli.contact`;
        docs/model.md, "Skin contact mechanics").

    Examples
    --------
    >>> afferent_type_info("RAII").derivative_order, afferent_type_info("SAII").stretch_drive
    (2, True)
    """

    code: str
    label: str
    spellings: tuple = ()
    colour: str = "tab:gray"
    in_paper: bool = False
    recorded_by_humans: bool = False
    derivative_order: int = 0
    stretch_drive: bool = False
    log_compression: bool = True
    shared_cutoff: bool = False
    fs_per_cutoff: float | None = None
    phase_spread: bool = False
    current: TypeParams = field(default_factory=TypeParams)
    neuron: NeuronParams = field(default_factory=NeuronParams)
    rf_area_mm2: float = 11.0
    density_share: float | None = None
    receptor_depth_mm: float = 1.0

    def __post_init__(self):
        if not isinstance(self.code, str) or not self.code.isalnum() or self.code != self.code.upper():
            raise ValueError(f"code must be upper-case letters and digits, e.g. 'SAI', got {self.code!r}")
        for name in ("label", "colour"):
            if not isinstance(getattr(self, name), str) or not getattr(self, name):
                raise TypeError(f"{name} must be a non-empty str, got {getattr(self, name)!r}")
        if not isinstance(self.spellings, tuple) or not all(isinstance(s, str) and s for s in self.spellings):
            raise TypeError(f"spellings must be a tuple of non-empty str, got {self.spellings!r}")
        if self.derivative_order not in (0, 1, 2) or isinstance(self.derivative_order, bool):
            raise ValueError(f"derivative_order must be 0, 1 or 2, got {self.derivative_order!r}")
        if self.fs_per_cutoff is not None and not (isinstance(self.fs_per_cutoff, (int, float))
                                                   and self.fs_per_cutoff >= 2.0):
            raise ValueError(f"fs_per_cutoff must be a number >= 2 (Nyquist) or None, got {self.fs_per_cutoff!r}")
        for name, cls in (("current", TypeParams), ("neuron", NeuronParams)):
            if not isinstance(getattr(self, name), cls):
                raise TypeError(f"{name} must be a {cls.__name__}, got {type(getattr(self, name)).__name__}")
        if not _positive_number(self.receptor_depth_mm) or self.receptor_depth_mm > 10.0:
            raise ValueError(f"receptor_depth_mm must be a number in (0, 10] mm, got {self.receptor_depth_mm!r}")
        if not _positive_number(self.rf_area_mm2):
            raise ValueError(f"rf_area_mm2 must be a finite number > 0 (mm^2), got {self.rf_area_mm2!r}")
        if self.density_share is not None and not (_positive_number(self.density_share) and self.density_share < 1):
            raise ValueError(f"density_share must be a number in (0, 1) or None, got {self.density_share!r}")

    @property
    def rf_sigma_mm(self) -> float:
        """Gaussian fall-off width of its receptive field in mm: a point probe gets weight >= 1/2 within
        ``sigma sqrt(2 ln 2)``, a disc of area `rf_area_mm2`.

        Examples
        --------
        >>> round(afferent_type_info("SAI").rf_sigma_mm, 3)
        1.589
        """
        return float(np.sqrt(self.rf_area_mm2 / np.pi) / np.sqrt(2.0 * np.log(2.0)))

    def accepted(self) -> tuple:
        """Every spelling of the type, compacted as `normalize_type` compares them (code, label, spellings).

        Examples
        --------
        >>> afferent_type_info("RAI").accepted()
        ('RAI', 'FAI', 'RA1', 'FA1')
        """
        return tuple(dict.fromkeys(_compact(s) for s in (self.code, self.label, *self.spellings)))


def _positive_number(value) -> bool:
    return isinstance(value, (int, float)) and not isinstance(value, bool) and math.isfinite(value) and value > 0


_REGISTRY: dict = {}  # code -> AfferentType, in registration order
_CODE_OF: dict = {}  # compacted spelling -> code


def _compact(spelling: str) -> str:
    return spelling.upper().replace("-", "").replace("_", "").replace(" ", "")


def register_afferent_type(kind: AfferentType) -> AfferentType:
    """Add an afferent type to the registry under ``kind.code``; returns it.

    Raises
    ------
    TypeError
        If ``kind`` is not an `AfferentType`.
    ValueError
        If its code, or one of its spellings, is already another type's.

    Examples
    --------
    >>> register_afferent_type(afferent_type_info("SAI"))
    Traceback (most recent call last):
    ...
    ValueError: kind: afferent type 'SAI' is already registered
    """
    if not isinstance(kind, AfferentType):
        raise TypeError(f"kind must be an AfferentType, got {type(kind).__name__}")
    if kind.code in _REGISTRY:
        raise ValueError(f"kind: afferent type {kind.code!r} is already registered")
    taken = [s for s in kind.accepted() if s in _CODE_OF]
    if taken:
        raise ValueError(f"kind: spelling {taken[0]!r} of {kind.code!r} already names {_CODE_OF[taken[0]]!r}")
    _REGISTRY[kind.code] = kind
    _CODE_OF.update((s, kind.code) for s in kind.accepted())
    return kind


def afferent_type_info(afferent_type) -> AfferentType:
    """The registered `AfferentType` of a code or any accepted spelling.

    Examples
    --------
    >>> afferent_type_info("FA-II").code, afferent_type_info("RAII").fs_per_cutoff
    ('RAII', 2.5)
    """
    kind = _REGISTRY.get(afferent_type) if isinstance(afferent_type, str) else None  # a code: the hot path
    return kind if kind is not None else _REGISTRY[normalize_type(afferent_type)]


def afferent_type_codes(where=None) -> tuple:
    """Codes of the registered types, in registration order; with ``where``, those for which it holds.

    ``where`` is a callable taking an `AfferentType`, or the name of one of
    its boolean fields.

    Examples
    --------
    >>> afferent_type_codes("stretch_drive"), afferent_type_codes(lambda t: t.derivative_order > 0)
    (('SAII',), ('RAI', 'RAII'))
    """
    if where is None:
        return tuple(_REGISTRY)
    if isinstance(where, str):
        if where not in {f.name for f in fields(AfferentType)}:
            raise ValueError(f"where={where!r} is not a field of AfferentType")
        where = attrgetter(where)
    if not callable(where):
        raise TypeError(f"where must be a callable or a field name of AfferentType, got {type(where).__name__}")
    return tuple(code for code, kind in _REGISTRY.items() if where(kind))


def type_mask(afferent_type, where) -> np.ndarray:
    """Whether each afferent's type is one for which ``where`` holds (as `afferent_type_codes`).

    One comparison a type (``np.isin`` would sort the strings).

    Examples
    --------
    >>> type_mask(np.array(["SAI", "SAII", "RAI"]), "stretch_drive").tolist()
    [False, True, False]
    """
    afferent_type = np.asarray(afferent_type)
    out = np.zeros(afferent_type.shape, dtype=bool)
    for code in afferent_type_codes(where):
        out |= afferent_type == code
    return out


def is_type(afferent_type, code) -> np.ndarray:
    """Whether each afferent is of the type ``code`` (any accepted spelling): a protocol's selection of units.

    Examples
    --------
    >>> is_type(np.array(["SAI", "SAII", "RAI"]), "SA-I").tolist()
    [True, False, False]
    """
    return np.asarray(afferent_type) == normalize_type(code, "code")


def type_label(afferent_type: str) -> str:
    """The display label of a type code (``"RAI"`` -> ``"FA-I"``), for figures and text.

    Examples
    --------
    >>> [type_label(t) for t in AFFERENT_TYPES]
    ['SA-I', 'FA-I', 'FA-II', 'SA-II']
    """
    return _REGISTRY[normalize_type(afferent_type)].label


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
        code = _CODE_OF.get(_compact(afferent_type))
        if code is not None:
            return code
    raise ValueError(f"{name}={afferent_type!r} is not an afferent type; allowed: "
                     f"{', '.join(_REGISTRY)} or {', '.join(k.label for k in _REGISTRY.values())} (RA-I/RA-II too)")


# The package's types.  Currents: the paper's eqs 1-3, gains fitted so that the CMM (AF = 1) press-push-lift
# response lies near Table III (``experiments/calibration/gains.py``); SA-II's are ours.  Neurons: regular spiking
# (B = 0.2) for the slowly adapting types, low-threshold spiking (B = 0.25) for the fast ones (eqs 4-6, docs/model.md
# §1.7).  Receptive-field areas: docs/references.md row 17 (SA-I, FA-I read; SA-II about 5x and FA-II about 10x, read
# in a secondary source).  Shares: the fingertip's SA-I 70, FA-I 141, FA-II 21, SA-II 9 of 241 units (row 16, R).
register_afferent_type(AfferentType(
    "SAI", "SA-I", ("SA1",), "tab:blue", in_paper=True, recorded_by_humans=True,
    current=TypeParams(gain=5.367),  # fitted: CMM SAI SF 47.5 imp/s (Table III)
    neuron=NeuronParams(b=0.2), rf_area_mm2=11.0, density_share=70.0 / 241.0,
    receptor_depth_mm=0.5))
register_afferent_type(AfferentType(
    "RAI", "FA-I", ("RA1", "FA1"), "tab:orange", in_paper=True, recorded_by_humans=True, derivative_order=1,
    shared_cutoff=True, current=TypeParams(gain=11.036, tau_adapt_s=0.1),  # fitted: CMM RAI SF 15 imp/s
    neuron=NeuronParams(b=0.25), rf_area_mm2=12.6, density_share=141.0 / 241.0,
    receptor_depth_mm=0.7))
register_afferent_type(AfferentType(
    "RAII", "FA-II", ("RA2", "FA2"), "tab:green", in_paper=True, derivative_order=2, shared_cutoff=True,
    fs_per_cutoff=2.5, current=TypeParams(gain=6.162),  # fitted: CMM RAII SF 10 imp/s (Table III)
    neuron=NeuronParams(b=0.25), rf_area_mm2=10 * 12.6, density_share=21.0 / 241.0,
    receptor_depth_mm=2.0))
register_afferent_type(AfferentType(
    "SAII", "SA-II", ("SA2",), "tab:purple", recorded_by_humans=True, stretch_drive=True, log_compression=False,
    phase_spread=True, current=TypeParams(gain=1.0, cutoff_hz=20.0),  # ours: a stretch low-pass at 20 Hz
    neuron=NeuronParams(b=0.2), rf_area_mm2=5 * 11.0, density_share=9.0 / 241.0,
    receptor_depth_mm=1.0))

#: The paper's three afferent types (eqs 1-3).
PAPER_TYPES = afferent_type_codes("in_paper")
#: Every afferent type of the package, in the order used throughout: the paper's
#: three, then SA-II (Ruffini), which the paper leaves out (its §I).
AFFERENT_TYPES = afferent_type_codes()
#: Display label of each type code, as the human literature names them (FA = fast
#: adapting, the paper's RA).  Codes stay the data's names (files, presets, the API).
TYPE_LABELS = {code: kind.label for code, kind in _REGISTRY.items()}
