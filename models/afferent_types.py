"""The afferent types of the package: their codes, display labels and accepted spellings.

The paper models three types (SA-I, RA-I, RA-II; its eqs 1-3); the package
adds SA-II (Ruffini).  Codes (``"SAI"``, ``"RAI"``, ``"RAII"``, ``"SAII"``)
are the data's names in files, presets and the API; the labels are those of
the human literature (FA = fast adapting, the paper's RA).
"""

from __future__ import annotations

__all__ = ["AFFERENT_TYPES", "PAPER_TYPES", "TYPE_LABELS", "normalize_type", "type_label"]

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
