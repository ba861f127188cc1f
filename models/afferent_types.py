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

from dataclasses import dataclass, fields
from operator import attrgetter

import numpy as np

__all__ = ["AFFERENT_TYPES", "PAPER_TYPES", "TYPE_LABELS", "AfferentType", "afferent_type_codes",
           "afferent_type_info", "normalize_type", "register_afferent_type", "type_label", "type_mask"]


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
        (`ddmm.models.attenuation.stretch_drive`: the attenuated shear, with
        ``opponent_saii`` and ``normal_saii``) instead of the attenuated
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
        Whether ``phase_saii`` spreads its neurons' start phases over their
        tonic cycle (`ddmm.models.currents.initial_phase`).

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

    def accepted(self) -> tuple:
        """Every spelling of the type, compacted as `normalize_type` compares them (code, label, spellings).

        Examples
        --------
        >>> afferent_type_info("RAI").accepted()
        ('RAI', 'FAI', 'RA1', 'FA1')
        """
        return tuple(dict.fromkeys(_compact(s) for s in (self.code, self.label, *self.spellings)))


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


register_afferent_type(AfferentType("SAI", "SA-I", ("SA1",), "tab:blue", in_paper=True, recorded_by_humans=True))
register_afferent_type(AfferentType("RAI", "FA-I", ("RA1", "FA1"), "tab:orange", in_paper=True,
                                    recorded_by_humans=True, derivative_order=1, shared_cutoff=True))
register_afferent_type(AfferentType("RAII", "FA-II", ("RA2", "FA2"), "tab:green", in_paper=True,
                                    derivative_order=2, shared_cutoff=True, fs_per_cutoff=2.5))
register_afferent_type(AfferentType("SAII", "SA-II", ("SA2",), "tab:purple", recorded_by_humans=True,
                                    stretch_drive=True, log_compression=False, phase_spread=True))

#: The paper's three afferent types (eqs 1-3).
PAPER_TYPES = afferent_type_codes("in_paper")
#: Every afferent type of the package, in the order used throughout: the paper's
#: three, then SA-II (Ruffini), which the paper leaves out (its §I).
AFFERENT_TYPES = afferent_type_codes()
#: Display label of each type code, as the human literature names them (FA = fast
#: adapting, the paper's RA).  Codes stay the data's names (files, presets, the API).
TYPE_LABELS = {code: kind.label for code, kind in _REGISTRY.items()}
