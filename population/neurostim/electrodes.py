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
Field names ignore case, and a name given twice (``ID`` beside ``id``, say)
is refused, never merged.  Ids and region names print on one line
(`MAX_NAME_CHARS` printable characters at most, no control characters), as
``ddmm stimulate`` prints a line per electrode.  A table file holds at most
`MAX_TABLE_BYTES` bytes and a CSV line at most `MAX_LINE_CHARS` characters:
far more than any interface needs (about 100 bytes a row).  Errors name the
file, the row (line) and the field.
"""

from __future__ import annotations

import csv
import io
import math
from dataclasses import dataclass
from pathlib import Path

import numpy as np

from ddmm.utils.validation import check_path

__all__ = ["Electrode", "ElectrodeTable", "read_electrodes", "MAX_AMPLITUDE_UA", "MAX_PHASE_WIDTH_US",
           "MAX_RATE_HZ", "MAX_CHARGE_NC", "MAX_NAME_CHARS", "MAX_TABLE_BYTES", "MAX_LINE_CHARS"]

#: Sanity bounds (unit slips, not safety limits): 20 mA, 10 ms, 2 kHz, 10 µC.
MAX_AMPLITUDE_UA, MAX_PHASE_WIDTH_US, MAX_RATE_HZ, MAX_CHARGE_NC = 20_000.0, 10_000.0, 2_000.0, 10_000.0
_LIMITS = ("amplitude_min_ua", "amplitude_max_ua", "phase_width_us", "max_rate_hz", "charge_limit_nc")
_BOUNDS = {"amplitude_min_ua": MAX_AMPLITUDE_UA, "amplitude_max_ua": MAX_AMPLITUDE_UA,
           "phase_width_us": MAX_PHASE_WIDTH_US, "max_rate_hz": MAX_RATE_HZ, "charge_limit_nc": MAX_CHARGE_NC,
           "interphase_us": MAX_PHASE_WIDTH_US, "radius_mm": 200.0}
#: Longest id or region name, characters: each is printed in a line per electrode.
MAX_NAME_CHARS = 64
#: Largest table file, bytes (1 MiB), and longest CSV line, characters: a row needs about 100.
MAX_TABLE_BYTES, MAX_LINE_CHARS = 1 << 20, 4096


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
        _check_name("electrode id", self.id)
        where = f"electrode {self.id!r}"
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


def _short(value) -> str:
    """``repr`` of a value for a message, cut to 40 characters (an id may be megabytes long)."""
    if isinstance(value, str) and len(value) > 40:
        return repr(value[:40]) + "..."
    return repr(value)


def _check_name(what: str, value) -> None:
    """An id or region name must print as one short line: it is printed in a line per electrode."""
    if not isinstance(value, str) or not value.strip():
        raise ValueError(f"{what} must be a non-empty string, got {_short(value)}")
    if len(value) > MAX_NAME_CHARS:
        raise ValueError(f"{what} must be at most {MAX_NAME_CHARS} characters, got {len(value):,} "
                         f"({_short(value)})")
    bad = next((c for c in value if not c.isprintable()), None)
    if bad is not None:  # newlines, control, format and separator characters could forge or hide output
        raise ValueError(f"{what} {_short(value)} holds the unprintable character U+{ord(bad):04X}: it must print "
                         "on one line (letters, digits, punctuation and spaces)")


def _field_kind(where: str, e: Electrode) -> str:
    disc = [e.x_mm, e.y_mm, e.radius_mm]
    if e.region is not None and any(v is not None for v in disc):
        raise ValueError(f"{where}: give a disc field (x_mm, y_mm, radius_mm) or a region, not both")
    if e.region is not None:
        _check_name(f"{where}: region", e.region)
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
        if not hasattr(electrodes, "__iter__"):
            raise TypeError(f"electrodes must be a non-empty sequence of Electrode, got {type(electrodes).__name__}")
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
        raise ValueError(f"{where}: unknown field {_short(unknown[0])}; allowed: {', '.join(_TYPES)}")
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
            raise ValueError(f"{where}: field {key!r}: {_short(text)} is not a number") from None
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

    Raises
    ------
    ValueError
        Naming the file (and the line or entry, and the field) for a table that
        is not one: a field missing, unknown or given twice, a limit out of
        range or contradicting another, an unprintable or overlong id, a file
        over `MAX_TABLE_BYTES` or a CSV line over `MAX_LINE_CHARS`.

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
    path = check_path(path)
    where = f"electrode table {str(path)!r}"
    if path.suffix.lower() not in (".csv", ".toml"):
        raise ValueError(f"{where}: expected a .csv or .toml file")
    text = _read_text(where, path)
    rows = _csv_rows(where, text) if path.suffix.lower() == ".csv" else _toml_rows(where, text)
    if not rows:
        raise ValueError(f"{where}: no electrodes")
    electrodes = [_from_row(f"{where}, {label}", row) for label, row in rows]
    try:
        return ElectrodeTable(electrodes)
    except ValueError as exc:
        raise ValueError(f"{where}: {exc}") from None


def _read_text(where: str, path: Path) -> str:
    """The file's text, refusing before reading it whole a file larger than any table (a sparse 1 GiB file, say)."""
    size, data = path.stat().st_size, b""
    if size <= MAX_TABLE_BYTES:
        with path.open("rb") as f:
            data = f.read(MAX_TABLE_BYTES + 1)  # a pipe or a growing file has no size to trust
        size = max(size, len(data))
    if size > MAX_TABLE_BYTES:
        raise ValueError(f"{where}: larger than the {MAX_TABLE_BYTES:,} bytes an electrode table may hold (a row "
                         "needs about 100)")
    try:
        return data.decode("utf-8-sig")
    except UnicodeDecodeError as exc:
        raise ValueError(f"{where}: not UTF-8 text (byte {exc.start})") from None


def _unique_names(where: str, names, kind: str) -> list:
    """Field names, stripped and lower-cased; a name given twice (in any case) is refused, never merged."""
    seen, out = {}, []
    for position, raw in enumerate(map(str, names), start=1):
        key = raw.strip().lower()
        if key in seen:
            where_first = f"{kind} {seen[key][0]} " if kind == "column" else ""
            where_again = f"{kind} {position} " if kind == "column" else ""
            raise ValueError(f"{where}: field {_short(key)} is given twice ({where_first}{_short(seen[key][1])} and "
                             f"{where_again}{_short(raw)}; names ignore case)")
        seen[key] = (position, raw)
        out.append(key)
    return out


def _csv_rows(where: str, text: str) -> list:
    # Lines keep their ends, as csv wants: a quoted newline stays in its field (and an id refuses it).
    lines = io.StringIO(text, newline="").readlines()
    for number, line in enumerate(lines, start=1):
        length = len(line.rstrip("\r\n"))
        if length > MAX_LINE_CHARS:
            raise ValueError(f"{where}, line {number}: {length:,} characters, more than the {MAX_LINE_CHARS:,} a "
                             "table's line may hold")
    reader, rows, start, header = csv.reader(lines), [], 1, None
    try:
        for cells in reader:
            if header is None:
                header = _unique_names(f"{where}, line 1", cells, "column")
            elif any(c.strip() for c in cells):
                if len(cells) != len(header):
                    raise ValueError(f"{where}, line {start}: {len(cells)} fields, the header has {len(header)}")
                rows.append((f"line {start}", dict(zip(header, (c.strip() for c in cells)))))
            start = reader.line_num + 1  # a quoted field may span lines: the next row starts after this one
    except csv.Error as exc:
        raise ValueError(f"{where}, line {start}: not valid CSV ({exc}: is a quote left open?)") from None
    return rows


def _toml_rows(where: str, text: str) -> list:
    import tomllib

    try:
        data = tomllib.loads(text)
    except (tomllib.TOMLDecodeError, RecursionError) as exc:
        raise ValueError(f"{where}: not valid TOML ({str(exc).splitlines()[0] if str(exc) else 'too deep'})") from None
    extra = sorted(set(data) - {"electrode"})
    if extra:
        raise ValueError(f"{where}: unknown table {_short(extra[0])}; electrodes go in [[electrode]] entries")
    entries = data.get("electrode", [])
    if not isinstance(entries, list) or not all(isinstance(e, dict) for e in entries):
        raise ValueError(f"{where}: electrodes go in [[electrode]] entries")
    return [(f"electrode {i + 1}", dict(zip(_unique_names(f"{where}, electrode {i + 1}", e, "key"), e.values())))
            for i, e in enumerate(entries)]
