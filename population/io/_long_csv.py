"""Row-by-row readers of the long force CSV and the sites table (`ddmm.population.io.arrays.from_long_csv`).

Every error is one line naming the file, the column and the line number.
"""

from __future__ import annotations

import numpy as np

from ddmm.utils.validation import check_path, parse_number

__all__ = ["TIME_TOL", "read_sites_csv", "read_long_forces", "uniform_grid"]

#: Relative tolerance on time stamps: each lies within this fraction of a step of the uniform grid.
TIME_TOL = 1e-3


def _csv_rows(path, what: str, required: tuple, optional: tuple = ()):
    """Header index and ``(line, row)`` pairs of a CSV file, blank lines skipped."""
    import csv

    where = f"{what} file {str(path)!r}"
    try:
        with open(path, newline="", encoding="utf-8") as fh:
            reader = csv.reader(fh)
            rows = [(reader.line_num, row) for row in reader if row and any(cell.strip() for cell in row)]
    except OSError as exc:
        raise ValueError(f"{where} cannot be read: {exc.strerror}") from None
    except UnicodeDecodeError as exc:
        raise ValueError(f"{where} is not UTF-8 text (byte {exc.start})") from None
    if not rows:
        raise ValueError(f"{where} is empty")
    header = [h.strip() for h in rows[0][1]]
    for col in required:
        if col not in header:
            raise ValueError(f"{where} has no column {col!r}; header: {','.join(header)}")
    if len(rows) < 2:
        raise ValueError(f"{where} has a header but no data rows")
    for line, row in rows[1:]:
        if len(row) != len(header):
            raise ValueError(f"{where}: line {line} has {len(row)} values but the header has {len(header)}")
    index = {col: header.index(col) for col in required + optional if col in header}
    return where, index, rows[1:]


def _cell_float(where: str, col: str, line: int, text: str) -> float:
    try:
        value = parse_number(text)
    except ValueError:
        raise ValueError(f"{where}: column {col!r}, line {line}: {text!r} is not a number") from None
    if not np.isfinite(value):
        raise ValueError(f"{where}: column {col!r}, line {line}: non-finite value {text.strip()!r}")
    return value


def read_sites_csv(path):
    """Sites table: ``site,x_mm,y_mm[,region][,radius_mm]``; returns (Sites fields, line of each site)."""
    check_path(path)
    where, index, rows = _csv_rows(path, "sites", ("site", "x_mm", "y_mm"), ("region", "radius_mm"))
    ids, lines, x, y, region, radius = [], {}, [], [], [], []
    for line, row in rows:
        site = row[index["site"]].strip()
        if site in lines:
            raise ValueError(f"{where}: column 'site', line {line}: duplicate site id {site!r} "
                             f"(first on line {lines[site]})")
        ids.append(site)
        lines[site] = line
        x.append(_cell_float(where, "x_mm", line, row[index["x_mm"]]))
        y.append(_cell_float(where, "y_mm", line, row[index["y_mm"]]))
        region.append(row[index["region"]].strip() if "region" in index else "")
        if "radius_mm" in index:
            radius.append(_cell_float(where, "radius_mm", line, row[index["radius_mm"]]))
            if radius[-1] <= 0:
                raise ValueError(f"{where}: column 'radius_mm', line {line}: must be > 0 mm, got {radius[-1]!r}")
    fields = {"site": ids, "x_mm": np.array(x), "y_mm": np.array(y), "region": region,
              "radius_mm": np.array(radius) if radius else None}
    return where, fields, lines


def read_long_forces(path, known: dict, allowance: float = 0.0):
    """Rows of ``time,site,fx,fy,fz``: times (s), site indices, forces (N) and line numbers; F_Z may read
    down to ``-allowance`` N (sensor noise the conditioning handles)."""
    where, index, rows = _csv_rows(path, "forces", ("time", "site", "fx", "fy", "fz"))
    n = len(rows)
    t, site, force, lines = np.empty(n), np.empty(n, dtype=int), np.empty((n, 3)), np.empty(n, dtype=int)
    for r, (line, row) in enumerate(rows):
        name = row[index["site"]].strip()
        if name not in known:
            raise ValueError(f"{where}: column 'site', line {line}: site {name!r} is not in the sites table")
        site[r], lines[r] = known[name], line
        t[r] = _cell_float(where, "time", line, row[index["time"]])
        for a, col in enumerate(("fx", "fy", "fz")):
            force[r, a] = _cell_float(where, col, line, row[index[col]])
        if force[r, 2] < -allowance:
            raise ValueError(f"{where}: column 'fz', line {line}: negative normal force {float(force[r, 2]):g} N"
                             + (f" (below the sensor-noise allowance of -{allowance:g} N)" if allowance else ""))
    return where, t, site, force, lines


def uniform_grid(where: str, times: np.ndarray, fs: float | None, t: np.ndarray, lines: np.ndarray) -> float:
    """fs of the sorted unique ``times`` (inferred, or ``fs`` checked); raises on a non-uniform step.

    ``t`` and ``lines`` are every row's time and line number, to name the first offending row.
    """
    if times.size < 2:
        if fs is None:
            raise ValueError(f"{where}: column 'time' has a single time stamp; pass fs to set the sample rate")
        return fs
    step = (times[-1] - times[0]) / (times.size - 1)
    off = np.abs(times - times[0] - step * np.arange(times.size)) / step
    if np.any(off > TIME_TOL):
        i = int(np.flatnonzero(off > TIME_TOL)[0])
        line = int(lines[np.flatnonzero(t == times[i])].min())
        raise ValueError(f"{where}: column 'time', line {line}: {float(times[i])!r} s is off the uniform grid of "
                         f"step {float(step)!r} s (sites with different time stamps, or a gap)")
    if fs is not None and abs(step * fs - 1.0) > TIME_TOL:
        raise ValueError(f"{where}: column 'time' has a step of {float(step)!r} s, which does not match fs = {fs!r} Hz")
    return 1.0 / step if fs is None else fs
