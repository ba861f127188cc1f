"""Electrode tables: where each electrode's projected field lies and the limits of its pulses.

An electrode of a nerve interface evokes sensations projected onto a patch of
skin, its **projected field**: here a disc (centre and radius in mm, in the
population's frame) or a hand-map region (``"D2d"``; a prefix such as
``"D2"`` takes every region whose name starts with it).  Its pulses are
charge-balanced biphasic (cathodic phase, ``interphase_us``, anodic phase of
equal width and amplitude), and every limit is explicit:

========================  ===========================================================
field                     meaning
========================  ===========================================================
``amplitude_min_ua``      amplitude of the weakest pulse, µA (> 0)
``amplitude_max_ua``      amplitude of the strongest pulse, µA
``phase_width_us``        width of each phase, µs
``max_rate_hz``           pulse rate limit, Hz: pulses are >= 1 / max_rate_hz apart
``charge_limit_nc``       charge per phase limit, nC: amplitude x width <= it
``interphase_us``         gap between the two phases, µs (default 0)
========================  ===========================================================

A table is refused, not clipped, when its own limits contradict each other:
``amplitude_max_ua x phase_width_us`` over the charge limit, or a pulse
(``2 phase_width_us + interphase_us``) longer than the interval the rate
limit allows.  Sanity bounds catch unit slips (`MAX_AMPLITUDE_UA`, ...); they
are not safety limits, which are the table's own.

Files: CSV with a header (any column order; ``id`` and the six limits
required; ``x_mm, y_mm, radius_mm`` or ``region``; optional
``interphase_us``) or TOML (``[[electrode]]`` entries with the same keys).
Errors name the file, the row (line) and the field.
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from pathlib import Path

import numpy as np

__all__ = ["Electrode", "ElectrodeTable", "read_electrodes", "MAX_AMPLITUDE_UA", "MAX_PHASE_WIDTH_US",
           "MAX_RATE_HZ", "MAX_CHARGE_NC"]

#: Sanity bounds (unit slips, not safety limits): 20 mA, 10 ms, 2 kHz, 10 µC.
MAX_AMPLITUDE_UA, MAX_PHASE_WIDTH_US, MAX_RATE_HZ, MAX_CHARGE_NC = 20_000.0, 10_000.0, 2_000.0, 10_000.0
_LIMITS = ("amplitude_min_ua", "amplitude_max_ua", "phase_width_us", "max_rate_hz", "charge_limit_nc")
_BOUNDS = {"amplitude_min_ua": MAX_AMPLITUDE_UA, "amplitude_max_ua": MAX_AMPLITUDE_UA,
           "phase_width_us": MAX_PHASE_WIDTH_US, "max_rate_hz": MAX_RATE_HZ, "charge_limit_nc": MAX_CHARGE_NC,
           "interphase_us": MAX_PHASE_WIDTH_US, "radius_mm": 200.0}


@dataclass(frozen=True)
class Electrode:
    """One electrode: its projected field and the limits of its pulses (module docstring).

    Attributes
    ----------
    id : str
        Unique name.
    amplitude_min_ua, amplitude_max_ua : float
        Pulse amplitude range, µA (0 < min <= max).
    phase_width_us : float
        Width of each phase of the biphasic pulse, µs.
    max_rate_hz : float
        Pulse rate limit, Hz.
    charge_limit_nc : float
        Charge-per-phase limit, nC.
    x_mm, y_mm, radius_mm : float or None
        A disc field (all three), in the population's frame, mm.
    region : str or None
        A hand-map region field (exact name or prefix), instead of a disc.
    interphase_us : float
        Gap between the phases, µs.

    Examples
    --------
    >>> e = Electrode("E1", 20.0, 80.0, 200.0, 300.0, 20.0, x_mm=0.0, y_mm=0.0, radius_mm=4.0)
    >>> e.min_interval_s, e.max_charge_nc
    (0.0033333333333333335, 16.0)
    """

    id: str
    amplitude_min_ua: float
    amplitude_max_ua: float
    phase_width_us: float
    max_rate_hz: float
    charge_limit_nc: float
    x_mm: float | None = None
    y_mm: float | None = None
    radius_mm: float | None = None
    region: str | None = None
    interphase_us: float = 0.0

    def __post_init__(self):
        where = f"electrode {self.id!r}"
        if not isinstance(self.id, str) or not self.id.strip():
            raise ValueError(f"electrode id must be a non-empty string, got {self.id!r}")
        for name in (*_LIMITS, "interphase_us"):
            _number(where, name, getattr(self, name), allow_zero=name == "interphase_us")
        _field_kind(where, self)
        if self.amplitude_min_ua > self.amplitude_max_ua:
            raise ValueError(f"{where}: amplitude_min_ua = {self.amplitude_min_ua:g} exceeds amplitude_max_ua = "
                             f"{self.amplitude_max_ua:g}")
        if self.max_charge_nc > self.charge_limit_nc * (1 + 1e-12):
            raise ValueError(f"{where}: amplitude_max_ua x phase_width_us = {self.max_charge_nc:g} nC exceeds "
                             f"charge_limit_nc = {self.charge_limit_nc:g}: lower amplitude_max_ua to <= "
                             f"{self.charge_limit_nc * 1e3 / self.phase_width_us:g} or phase_width_us")
        if self.pulse_s >= self.min_interval_s:
            raise ValueError(f"{where}: a pulse lasts {self.pulse_s * 1e6:g} us (2 x phase_width_us + interphase_us), "
                             f"not shorter than 1 / max_rate_hz = {self.min_interval_s * 1e6:g} us")

    @property
    def min_interval_s(self) -> float:
        """The shortest allowed time from one pulse's start to the next, s."""
        return 1.0 / self.max_rate_hz

    @property
    def pulse_s(self) -> float:
        """Duration of one biphasic pulse, s."""
        return (2.0 * self.phase_width_us + self.interphase_us) * 1e-6

    @property
    def max_charge_nc(self) -> float:
        """Charge per phase of the strongest pulse, nC (µA x µs / 1000)."""
        return self.amplitude_max_ua * self.phase_width_us * 1e-3


def _number(where: str, name: str, value, allow_zero: bool = False) -> None:
    ok = isinstance(value, (int, float, np.floating, np.integer)) and not isinstance(value, bool)
    if not ok or not math.isfinite(float(value)) or value < 0 or (value == 0 and not allow_zero):
        shown = f"{float(value):g}" if ok else repr(value)
        raise ValueError(f"{where}: {name} must be a finite number {'>= 0' if allow_zero else '> 0'}, got {shown}")
    if name in _BOUNDS and value > _BOUNDS[name]:
        raise ValueError(f"{where}: {name} = {float(value):g} is beyond {_BOUNDS[name]:g} (a unit slip?)")


def _field_kind(where: str, e: Electrode) -> str:
    disc = [e.x_mm, e.y_mm, e.radius_mm]
    if e.region is not None and any(v is not None for v in disc):
        raise ValueError(f"{where}: give a disc field (x_mm, y_mm, radius_mm) or a region, not both")
    if e.region is not None:
        if not isinstance(e.region, str) or not e.region.strip():
            raise ValueError(f"{where}: region must be a non-empty region name, got {e.region!r}")
        return "region"
    if any(v is None for v in disc):
        raise ValueError(f"{where}: a field needs x_mm, y_mm and radius_mm (or a region)")
    for name in ("x_mm", "y_mm"):
        value = getattr(e, name)
        if not isinstance(value, (int, float)) or isinstance(value, bool) or not math.isfinite(value):
            raise ValueError(f"{where}: {name} must be a finite number, got {value!r}")
    _number(where, "radius_mm", e.radius_mm)
    return "disc"


class ElectrodeTable:
    """The electrodes of one interface, in order (their position is the ``electrode`` index of pulses).

    Parameters
    ----------
    electrodes : sequence of Electrode
        At least one; ids unique.

    Examples
    --------
    >>> table = ElectrodeTable([Electrode("E1", 20.0, 80.0, 200.0, 300.0, 20.0, region="D2d")])
    >>> table.ids, len(table)
    (['E1'], 1)
    """

    def __init__(self, electrodes):
        electrodes = list(electrodes)
        if not electrodes or not all(isinstance(e, Electrode) for e in electrodes):
            raise TypeError("electrodes must be a non-empty sequence of Electrode")
        ids = [e.id for e in electrodes]
        dup = sorted({i for i in ids if ids.count(i) > 1})
        if dup:
            raise ValueError(f"electrode ids must be unique; {dup[0]!r} appears {ids.count(dup[0])} times")
        self.electrodes = tuple(electrodes)

    def __len__(self) -> int:
        return len(self.electrodes)

    def __iter__(self):
        return iter(self.electrodes)

    @property
    def ids(self) -> list:
        """Electrode ids in order."""
        return [e.id for e in self.electrodes]

    def column(self, name: str) -> np.ndarray:
        """One limit of every electrode, as a float array (e.g. ``"max_rate_hz"``)."""
        return np.array([float(getattr(e, name)) for e in self.electrodes])

    def members(self, x_mm, y_mm, region) -> list:
        """For each electrode, the positions of the afferents (or sites) inside its field."""
        x, y = np.asarray(x_mm, float), np.asarray(y_mm, float)
        region = np.asarray(region, dtype=object).astype(str)
        out = []
        for e in self.electrodes:
            if e.region is not None:
                out.append(np.flatnonzero(np.char.startswith(region.astype(str), e.region)))
            else:
                out.append(np.flatnonzero(np.hypot(x - e.x_mm, y - e.y_mm) <= e.radius_mm))
        return out


_TYPES = {**{k: float for k in (*_LIMITS, "interphase_us", "x_mm", "y_mm", "radius_mm")}, "id": str, "region": str}


def _from_row(where: str, row: dict) -> Electrode:
    missing = [k for k in ("id", *_LIMITS) if row.get(k) in (None, "")]
    if missing:
        raise ValueError(f"{where}: field {missing[0]!r} is missing")
    unknown = sorted(set(row) - set(_TYPES))
    if unknown:
        raise ValueError(f"{where}: unknown field {unknown[0]!r}; allowed: {', '.join(_TYPES)}")
    values = {}
    for key, text in row.items():
        if text in (None, ""):
            continue
        if _TYPES[key] is str:
            values[key] = str(text).strip()
            continue
        try:
            values[key] = _float(text)
        except ValueError:
            raise ValueError(f"{where}: field {key!r}: {text!r} is not a number") from None
    try:
        return Electrode(**values)
    except ValueError as exc:
        raise ValueError(f"{where}: {exc}") from None


def _float(text) -> float:
    if isinstance(text, bool):
        raise ValueError
    if isinstance(text, (int, float)):
        return float(text)
    from ddmm.utils.validation import parse_number

    return parse_number(str(text).strip())


def read_electrodes(path) -> ElectrodeTable:
    """Read an electrode table from CSV or TOML (module docstring for the fields).

    Examples
    --------
    >>> import tempfile, pathlib
    >>> with tempfile.TemporaryDirectory() as tmp:
    ...     p = pathlib.Path(tmp) / "e.csv"
    ...     _ = p.write_text("id,region,amplitude_min_ua,amplitude_max_ua,phase_width_us,max_rate_hz,charge_limit_nc\\n"
    ...                      "E1,D2d,20,80,200,300,20\\n")
    ...     read_electrodes(p).ids
    ['E1']
    """
    path = Path(path)
    where = f"electrode table {str(path)!r}"
    if path.suffix.lower() not in (".csv", ".toml"):
        raise ValueError(f"{where}: expected a .csv or .toml file")
    try:
        text = path.read_bytes().decode("utf-8-sig")
    except UnicodeDecodeError as exc:
        raise ValueError(f"{where}: not UTF-8 text (byte {exc.start})") from None
    rows = _csv_rows(where, text) if path.suffix.lower() == ".csv" else _toml_rows(where, text)
    if not rows:
        raise ValueError(f"{where}: no electrodes")
    electrodes = [_from_row(f"{where}, {label}", row) for label, row in rows]
    try:
        return ElectrodeTable(electrodes)
    except ValueError as exc:
        raise ValueError(f"{where}: {exc}") from None


def _csv_rows(where: str, text: str) -> list:
    import csv

    lines = list(csv.reader(text.splitlines()))
    if not lines:
        return []
    header = [h.strip().lower() for h in lines[0]]
    rows = []
    for number, cells in enumerate(lines[1:], start=2):
        if not any(c.strip() for c in cells):
            continue
        if len(cells) != len(header):
            raise ValueError(f"{where}, line {number}: {len(cells)} fields, the header has {len(header)}")
        rows.append((f"line {number}", dict(zip(header, (c.strip() for c in cells)))))
    return rows


def _toml_rows(where: str, text: str) -> list:
    import tomllib

    try:
        data = tomllib.loads(text)
    except (tomllib.TOMLDecodeError, RecursionError) as exc:
        raise ValueError(f"{where}: not valid TOML ({str(exc).splitlines()[0] if str(exc) else 'too deep'})") from None
    extra = sorted(set(data) - {"electrode"})
    if extra:
        raise ValueError(f"{where}: unknown table {extra[0]!r}; electrodes go in [[electrode]] entries")
    entries = data.get("electrode", [])
    if not isinstance(entries, list) or not all(isinstance(e, dict) for e in entries):
        raise ValueError(f"{where}: electrodes go in [[electrode]] entries")
    return [(f"electrode {i + 1}", {str(k).lower(): v for k, v in e.items()}) for i, e in enumerate(entries)]

