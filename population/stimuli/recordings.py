"""Scenes from real force recordings: CSV files of any sensor, at any sample rate.

`from_csv` reads a file's columns (matched case-insensitively, mapped with
``columns``), converts units and the sign convention, checks the time base
(strictly increasing; gaps refused unless ``gaps="interpolate"``), handles a
negative normal force (an error, clipped, or an offset removed from a quiet
baseline) and hands the recording to the conditioning stage
(`ddmm.population.stimuli.conditioning`), which is on by default here and
brings it to the model's sample rate.  Every message names the file, the
column or line, and shows plain numbers.
"""

from __future__ import annotations

import csv
import math
import warnings
from pathlib import Path

import numpy as np

from ddmm.population.stimuli._csv_header import match_columns, split_unit
from ddmm.population.stimuli.file_options import GAPS, MAX_FORCE_N, NEGATIVE_FZ, TIME_UNITS, UNITS
from ddmm.population.stimuli.conditioning import Conditioning, condition_forces, noise_allowance
from ddmm.population.stimuli.scenes import DEFAULT_FS, MAX_FS, Contact, Scene
from ddmm.utils.notices import with_cli
from ddmm.utils.resources import check_memory
from ddmm.utils.validation import as_finite_array, check_path, check_positive, parse_number, shown

__all__ = ["from_csv", "resample_unconditioned", "warn_band", "check_force_bound", "UNITS", "RECORDED",
           "RecordingBandWarning", "NEGATIVE_FZ", "GAPS", "FA_II_MIN_FS", "MAX_FORCE_N"]

#: The conditioning `from_csv` applies unless told otherwise.
RECORDED = Conditioning()
#: A recording slower than this cannot carry FA-II's band (up to 300 Hz, sampled at 2.5x).
FA_II_MIN_FS = 750.0
_FIELDS = ("time", "fx", "fy", "fz")
_BASELINE_S = 0.1  # quiet baseline for negative_fz="offset"
_GAP = 1.5  # an interval longer than this many times the median is a gap
_JITTER = 0.01  # intervals within 1% of the median count as uniform


class RecordingBandWarning(UserWarning):
    """A recording's sample rate cannot carry a band a simulated type needs."""


def _read(path, wanted: dict) -> tuple:
    """(the mapped columns as float arrays, the file's header): header names matched case-insensitively."""
    try:
        with open(path, newline="", encoding="utf-8-sig") as fh:  # a byte-order mark is not part of the header
            rows = [row for row in csv.reader(fh) if row and any(cell.strip() for cell in row)]
    except OSError as exc:
        raise ValueError(f"scene file {str(path)!r} cannot be read: {exc.strerror}") from None
    except UnicodeDecodeError as exc:
        raise ValueError(f"scene file {str(path)!r} is not UTF-8 text (byte {exc.start})") from None
    if not rows:
        raise ValueError(f"scene file {str(path)!r} is empty")
    header = [h.strip() for h in rows[0]]
    index = match_columns(path, header, wanted)
    if len(rows) < 2:
        raise ValueError(f"scene file {str(path)!r} has a header but no data rows")
    out = {k: np.empty(len(rows) - 1) for k in wanted}
    for r, row in enumerate(rows[1:], start=2):
        if len(row) != len(header):
            raise ValueError(f"scene file {str(path)!r}: line {r} has {len(row)} values but the header has "
                             f"{len(header)}")
        for ours, i in index.items():
            try:
                out[ours][r - 2] = parse_number(row[i])
            except ValueError:
                raise ValueError(f"scene file {str(path)!r}: column {header[i]!r}, line {r}: {row[i]!r} is not a "
                                 "number") from None
            if not math.isfinite(out[ours][r - 2]):
                raise ValueError(f"scene file {str(path)!r}: column {header[i]!r}, line {r}: {row[i]!r} is not "
                                 "finite")
    return out, header, {ours: header[i] for ours, i in index.items()}


def _mapping(columns, recorded_fs) -> dict:
    mapping = {k: k for k in _FIELDS}
    if columns is not None and not isinstance(columns, dict):
        raise TypeError(f"columns must be a dict (our name -> the file's column) or None, got {type(columns).__name__}")
    for key, value in (columns or {}).items():
        if key not in mapping:
            raise ValueError(f"columns: unknown key {key!r}; allowed: {', '.join(_FIELDS)}")
        if not isinstance(value, str) or not value.strip():
            raise ValueError(f"columns: {key} must name a column, got {value!r}")
        mapping[key] = value.strip()
    if recorded_fs is not None:
        if columns and "time" in columns:
            raise ValueError("give recorded_fs or a time column, not both")
        del mapping["time"]
    return mapping


def _uniform(path, t, data: dict, gaps: str) -> tuple:
    """(sample rate in Hz, the columns on a uniform grid): gaps refused or interpolated, jitter resampled."""
    step = np.diff(t)
    if np.any(step <= 0):
        line = int(np.flatnonzero(step <= 0)[0]) + 3
        raise ValueError(f"scene file {str(path)!r}: time must increase strictly (line {line}: "
                         f"{float(t[line - 2]):g} s after {float(t[line - 3]):g} s)")
    median = float(np.median(step))
    gap = step > _GAP * median
    if np.any(gap) and gaps == "error":
        i = int(np.flatnonzero(gap)[0])
        raise ValueError(f"scene file {str(path)!r}: a gap of {float(step[i]):g} s at t = {float(t[i]):g} s "
                         f"(line {i + 2}; samples every {median:g} s); use gaps='interpolate' (--gaps interpolate) to fill it")
    span = float(t[-1] - t[0])
    check_memory(64.0 * (span / median + 1), f"scene file {str(path)!r} ({span:g} s sampled every {median:g} s)",
                 "check its time column and --time-scale")
    if not np.any(gap) and np.all(np.abs(step - median) <= _JITTER * median):
        return 1.0 / median, data
    grid = t[0] + np.arange(int(math.floor((t[-1] - t[0]) / median + 1e-9)) + 1) * median
    return 1.0 / median, {k: np.interp(grid, t, v) for k, v in data.items()}


def _negative(path, fz, forces, negative_fz, conditioning, fs_in):
    """Apply the negative-F_Z rule; raise with plain numbers when a negative force is not noise."""
    if negative_fz == "offset":
        quiet = slice(0, max(1, int(round(_BASELINE_S * fs_in))))
        forces = forces - np.median(forces[quiet], axis=0)
        fz = forces[:, 2]
    tolerance = 0.0 if conditioning is None else noise_allowance(conditioning)
    if negative_fz == "clip" or fz.min() >= -tolerance:
        forces[:, 2] = np.maximum(fz, -tolerance)
        return forces
    line = int(np.argmin(fz)) + 2
    hint = (" and it is never positive: a plate that reports pressing as negative needs fz_sign=-1 (--fz-sign -1)"
            if fz.max() <= tolerance else
            "; for a sensor offset use negative_fz='offset' or 'clip' (--negative-fz offset|clip)")
    raise ValueError(f"scene file {str(path)!r}: normal force down to {float(fz.min()):.4g} N (line {line}){hint}")


def from_csv(path, *, columns: dict | None = None, fs: float = DEFAULT_FS, recorded_fs: float | None = None,
             time_scale: float | None = None, units: str | None = None, force_scale: float = 1.0, fz_sign: int = 1,
             negative_fz: str = "error", gaps: str = "error", conditioning: Conditioning | None = RECORDED,
             name: str | None = None, contact: Contact | None = None, max_force_n: float = MAX_FORCE_N) -> Scene:
    """A scene from a recorded force file (a force plate, a load cell, a fingertip sensor).

    Parameters
    ----------
    path : str or Path
        A CSV file with a header.  By default its columns are ``time, fx, fy,
        fz`` in any case, with or without a unit: ``Time,Fx,Fy,Fz`` and
        ``Time (ms),Fx [mN],...`` read as they are.  A UTF-8 byte-order mark
        is skipped.
    columns : dict, optional
        Our names (``time``, ``fx``, ``fy``, ``fz``) to the file's, e.g.
        ``{"time": "t_ms", "fz": "Fz_N"}``.
    fs : float
        Sample rate of the scene (the model's), Hz.
    recorded_fs : float, optional
        The recording's sample rate, Hz, for a file without a time column.
    time_scale : float, optional
        The time column's unit in seconds (1e-3 for milliseconds); default:
        the unit its header names (s, ms, us), else 1.
    units : {"N", "mN", "gf", "kgf", "lbf"}, optional
        The force columns' unit; default: the unit their headers name, else
        N.  One that contradicts a header is an error.  ``force_scale``
        multiplies further.
    fz_sign : {1, -1}
        -1 for a plate that reports pressing as negative F_Z.
    negative_fz : {"error", "clip", "offset"}
        A negative normal force (beyond the conditioning's noise allowance)
        is an error, clipped to 0, or (``"offset"``) the median of the first
        0.1 s is taken off every axis first (a sensor's zero offset).
    gaps : {"error", "interpolate"}
        An interval longer than 1.5 times the median is refused, or filled by
        linear interpolation.
    conditioning : Conditioning or None
        The conditioning stage (`ddmm.population.stimuli.conditioning`; on by
        default for recordings).  None: the recording as it is, resampled by
        monotone cubic interpolation.
    name : str, optional
        Condition name (default: the file stem).
    contact : Contact, optional
        Contact geometry.
    max_force_n : float
        The largest force (N, the magnitude of F_X, F_Y, F_Z) the file may
        carry, 1 kN by default (`MAX_FORCE_N`): beyond it the file is read in
        the wrong unit.  Raise it for a rig that loads more.

    Raises
    ------
    ValueError
        Naming the file and the column, line or option of the first problem.

    Warns
    -----
    RecordingBandWarning
        When the recording is slower than 750 Hz: FA-II's band is missing.

    Examples
    --------
    >>> import pathlib, tempfile
    >>> path = pathlib.Path(tempfile.mkdtemp()) / "plate.csv"
    >>> _ = path.write_text("Time,Fx,Fy,Fz\\n" + "".join(f"{k / 1000},0,0,{-min(k / 100, 2.0)}\\n"
    ...                                                   for k in range(1000)))
    >>> scene = from_csv(path, fz_sign=-1)
    >>> scene.fs, round(float(scene.fz[-1]), 2)  # in contact from the start, before the noise is measured:
    (1000.0, 1.97)
    >>> # ... 2 N less the contact threshold (30 mN), as for a sensor of the declared noise
    """
    check_path(path)
    _check_options(fs, units, fz_sign, negative_fz, gaps, conditioning)
    mapping = _mapping(columns, recorded_fs)
    data, header, cells = _read(path, mapping)
    units, time_scale = _resolve_units(path, cells, units, time_scale)
    if recorded_fs is not None:
        if "time" in (split_unit(h)[0].lower() for h in header):
            raise ValueError(f"scene file {str(path)!r} has a time column: give recorded_fs (--fs) only for a file "
                             "without one")
        fs_in = check_positive(recorded_fs, "recorded_fs", "Hz")
    else:
        t = data.pop("time") * check_positive(time_scale, "time_scale")
        if t.size < 2:
            raise ValueError(f"scene file {str(path)!r} needs at least 2 samples, got {t.size}")
        fs_in, data = _uniform(path, t, data, gaps)
    if fs_in > MAX_FS:
        raise ValueError(f"scene file {str(path)!r} is sampled at {fs_in:g} Hz, beyond any force sensor (<= "
                         f"{MAX_FS:g} Hz): check its time column, --time-scale or --fs")
    scale = UNITS[units] * check_positive(force_scale, "force_scale")
    forces = np.column_stack([data["fx"] * scale, data["fy"] * scale, data["fz"] * scale * fz_sign])
    check_force_bound(forces, max_force_n, f"scene file {str(path)!r}", fs_in)
    forces = _negative(path, forces[:, 2], forces, negative_fz, conditioning, fs_in)
    warn_band(Path(path).name, fs_in, stacklevel=3)
    n_out = forces.shape[0] * fs / fs_in
    check_memory(64.0 * n_out, f"scene file {str(path)!r} resampled to {fs:g} Hz ({n_out:,.0f} samples)",
                 "check its time column and --time-scale")
    if conditioning is None:
        out = resample_unconditioned(forces, fs_in, fs)
    else:
        out, _ = condition_forces(forces, fs_in, fs, conditioning)
    return Scene(out[:, 0], out[:, 1], out[:, 2], fs=fs, name=name or Path(path).stem, contact=contact)


def check_force_bound(forces, max_force_n: float, where: str, fs: float | None = None) -> None:
    """Refuse forces beyond ``max_force_n`` N at any site: a unit slip, not a touch.

    ``forces`` has F_X, F_Y, F_Z in N on its last axis (samples first); the
    magnitude of each site's force is compared.  ``where`` names the input
    in the error, and ``fs`` (Hz) lets it give the time of the first
    offending sample.

    Examples
    --------
    >>> check_force_bound(np.array([[0.0, 0.5, 3.0]]), 1000.0, "plate.csv")
    >>> check_force_bound(np.array([[0.0, 0.0, 3000.0]]), 1000.0, "plate.csv")
    Traceback (most recent call last):
    ...
    ValueError: plate.csv: a force of 3000 N at sample 0, beyond max_force_n = 1000 N (--max-force): no hand contact comes near it; check the unit (mN read as N or kgf?), or raise the bound
    """
    bound = check_positive(max_force_n, "max_force_n", "N")
    forces = np.asarray(forces, dtype=float)
    if forces.size == 0 or float(np.abs(forces).max()) * math.sqrt(3.0) <= bound:  # the usual case, cheaply
        return
    magnitude = np.sqrt(np.einsum("...i,...i->...", forces, forces)).reshape(forces.shape[0], -1).max(axis=1)
    beyond = np.flatnonzero(magnitude > bound)
    if beyond.size:
        k = int(beyond[0])
        when = f"t = {k / fs:.6g} s" if fs else f"sample {k}"
        raise ValueError(f"{where}: a force of {magnitude[k]:.6g} N at {when}, beyond max_force_n = {bound:g} N "
                         "(--max-force): no hand contact comes near it; check the unit (mN read as N or kgf?), or "
                         "raise the bound")


def _resolve_units(path, cells: dict, units, time_scale) -> tuple:
    """(force unit, time scale in s): the units the matched header ``cells`` name, the options' where given; a
    clash or a unit we cannot read is an error naming the column and the option."""
    by_lower = {u.lower(): u for u in UNITS}
    named = {}
    for ours in ("fx", "fy", "fz"):
        unit = split_unit(cells[ours])[1]
        if unit is not None and unit.lower() not in by_lower:
            raise ValueError(f"scene file {str(path)!r}: column {cells[ours]!r} is in {unit!r}, not a force unit; "
                             f"allowed: {', '.join(UNITS)}")
        if unit is not None:
            named[by_lower[unit.lower()]] = ours
    if len(named) > 1:
        raise ValueError(f"scene file {str(path)!r}: the force columns name different units ({', '.join(named)})")
    header_unit = next(iter(named), None)
    if units is not None and header_unit not in (None, units):
        raise ValueError(f"scene file {str(path)!r}: units={units!r} (--units {units}) but column "
                         f"{cells[named[header_unit]]!r} is in {header_unit}; leave units out to read the header's")
    return units or header_unit or "N", _time_scale(path, cells.get("time"), time_scale)


def _time_scale(path, cell, time_scale) -> float:
    unit = None if cell is None else split_unit(cell)[1]
    if unit is None:
        return 1.0 if time_scale is None else time_scale
    if unit.lower() not in TIME_UNITS:
        raise ValueError(f"scene file {str(path)!r}: column {cell!r} is in {unit!r}, not a time unit; allowed: "
                         f"{', '.join(TIME_UNITS)}")
    scale = TIME_UNITS[unit.lower()]
    if time_scale is not None and not math.isclose(time_scale, scale):
        raise ValueError(f"scene file {str(path)!r}: time_scale={time_scale:g} (--time-scale {time_scale:g}) but "
                         f"column {cell!r} is in {unit}; leave it out to read the header's")
    return scale


def warn_band(what: str, fs_in: float, stacklevel: int = 4) -> None:
    """Warn (`RecordingBandWarning`) when a recording at ``fs_in`` Hz cannot carry FA-II's band."""
    if fs_in < FA_II_MIN_FS:
        text = (f"{what} is sampled at {fs_in:g} Hz and carries 0-{fs_in / 2:g} Hz: FA-II's band (up to 300 Hz) is "
                "missing, so FA-II respond only to its ramps")
        warnings.warn(with_cli(RecordingBandWarning(f"{text} (leave them out with afferent_types=...)"),
                               f"{text} (leave them out: --types SAI,RAI,SAII)", ("RAII",)), stacklevel=stacklevel)


def _check_options(fs, units, fz_sign, negative_fz, gaps, conditioning) -> None:
    check_positive(fs, "fs", "Hz")
    for value, name, allowed in ((units, "units", tuple(UNITS)), (negative_fz, "negative_fz", NEGATIVE_FZ),
                                 (gaps, "gaps", GAPS)):
        if value not in allowed and not (name == "units" and value is None):
            raise ValueError(f"{name}={value!r} is not allowed; allowed: {', '.join(allowed)}")
    if fz_sign not in (1, -1) or isinstance(fz_sign, bool):
        raise ValueError(f"fz_sign must be 1 or -1, got {shown(fz_sign)}")
    if conditioning is not None and not isinstance(conditioning, Conditioning):
        raise TypeError(f"conditioning must be a Conditioning or None, got {type(conditioning).__name__}")


def resample_unconditioned(forces, fs_in: float, fs: float) -> np.ndarray:
    """Forces (n, 3) at ``fs_in`` Hz onto ``fs`` Hz as a recording reads with no conditioning (N).

    Monotone cubic interpolation (offline: each output sample sees the next
    input sample): it never overshoots, so F_Z stays >= 0.

    Examples
    --------
    >>> out = resample_unconditioned(np.array([[0.0, 0.0, 0.0], [0.0, 0.0, 1.0]]), 100.0, 1000.0)
    >>> np.round(out[:, 2], 3).tolist()
    [0.0, 0.1, 0.2, 0.3, 0.4, 0.5, 0.6, 0.7, 0.8, 0.9, 1.0]
    """
    forces = as_finite_array(forces, "forces", ndim=2)
    check_positive(fs_in, "fs_in", "Hz")
    check_positive(fs, "fs", "Hz")
    t = np.arange(forces.shape[0]) / fs_in
    grid = np.arange(int(math.floor(t[-1] * fs + 1e-9)) + 1) / fs
    if t.size < 3:
        out = np.column_stack([np.interp(grid, t, col) for col in forces.T])
    else:
        from scipy.interpolate import PchipInterpolator

        out = np.asarray(PchipInterpolator(t, forces, axis=0)(grid), dtype=float)
    out[:, 2] = np.maximum(out[:, 2], 0.0)
    return out
