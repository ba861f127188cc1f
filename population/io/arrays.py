"""Sensor-array input: multi-site force recordings from NPZ, netCDF, HDF5 or a long CSV.

A sensor array (e.g. a tactile skin of taxels) gives a force per site per
sample.  These readers turn such a file into a multi-site `Scene`
(`Scene.from_sites`), and `save_array` writes one back, so other tools and
tests can produce files.  Units are fixed: newtons, hertz, millimetres; the
frame is the scenes' one (+X radial, +Y distal, +Z into the skin, F_Z >= 0).

File layouts (chosen by extension)
----------------------------------
``.npz`` (NumPy ``savez``; read without pickle, so strings must be NumPy
unicode arrays, not object arrays).  Keys, and no others:

* ``fs`` -- scalar, sample rate in Hz (> 0); sample i is at ``i / fs`` s.
* ``forces`` -- (n_samples, n_sites, 3) float, (F_X, F_Y, F_Z) in N.
* ``x_mm``, ``y_mm`` -- (n_sites,) float, taxel centres in mm.
* ``radius_mm`` -- optional, (n_sites,) or scalar, footprint radius in mm.
* ``region`` -- optional, (n_sites,) strings, region labels (``""`` unknown).
* ``site`` -- optional, (n_sites,) unique ids (strings or integers; read as
  strings); default ``"0"``, ``"1"``, ...

``.nc`` (netCDF-4/HDF5 as written by xarray's h5netcdf engine; netCDF-3
files that xarray can open are read too).  Dimensions ``time``, ``site``,
``axis`` (length 3); variables:

* ``forces(time, site, axis)`` -- float, N, axis order F_X, F_Y, F_Z.
* ``x_mm(site)``, ``y_mm(site)`` -- float, mm.
* ``radius_mm(site)`` -- optional, float, mm (a scalar is accepted).
* ``region(site)`` -- optional, strings.
* ``site(site)`` -- optional coordinate, unique site ids.
* ``fs`` -- sample rate in Hz: a global attribute, or a scalar variable.
* ``time(time)`` -- optional coordinate in s; when present it must be
  ``t0 + i / fs`` to within 0.1% of a step.  ``axis(axis)`` -- optional
  coordinate (``save_array`` writes ``"x", "y", "z"``).

Any other variable is an error (a misspelt optional name would otherwise be
ignored silently); attributes other than ``fs`` are ignored.

``.h5`` / ``.hdf5`` (plain HDF5, e.g. from h5py): the same names as
root-level datasets -- ``forces`` (n_samples, n_sites, 3), ``x_mm``,
``y_mm``, optional ``radius_mm``, ``region`` and ``site`` (UTF-8 strings) --
and ``fs`` as a root attribute or a scalar dataset.  No other datasets.

Footprints: when ``radius_mm`` is absent, every site gets the equal-area
radius of the taxel pitch, ``taxel_radius(pitch)`` = ``pitch / sqrt(pi)``,
with the pitch estimated as the median over sites of the distance to the
nearest other site.  A one-site file must give ``radius_mm``.

What is stored: forces, fs and the sites.  A scene's name, stages and
theta_r are not; the name defaults to the file's stem.

Examples
--------
>>> import tempfile, pathlib
>>> from ddmm.population.stimuli.scenes import Scene, Sites
>>> sites = Sites([0.0, 2.5, 5.0], [0.0, 0.0, 0.0], 1.41, region=["D2d"] * 3)
>>> scene = Scene.from_sites(np.full((100, 3, 3), 0.5), sites, fs=1000.0)
>>> with tempfile.TemporaryDirectory() as tmp:
...     path = save_array(pathlib.Path(tmp) / "taxels.nc", scene)
...     back = from_array(path)
>>> back.n_sites, back.n_samples, back.fs, back.name
(3, 100, 1000.0, 'taxels')
"""

from __future__ import annotations

from pathlib import Path

import numpy as np

from ddmm.population.io._long_csv import TIME_TOL, read_long_forces, read_sites_csv, uniform_grid
from ddmm.population.io.formats import EXTENSIONS, array_format
from ddmm.population.stimuli.conditioning import Conditioning, condition_forces, noise_allowance
from ddmm.population.stimuli.recordings import MAX_FORCE_N, RECORDED, check_force_bound, warn_band
from ddmm.population.stimuli.scenes import DEFAULT_FS, Scene, Sites, taxel_radius
from ddmm.utils.resources import check_memory
from ddmm.utils.validation import check_path

from ddmm.population.io.array_writers import save_array  # noqa: F401 - re-exported from its former home

__all__ = ["EXTENSIONS", "from_array", "from_long_csv", "default_radius"]


_REQUIRED = ("fs", "forces", "x_mm", "y_mm")
_OPTIONAL = ("radius_mm", "region", "site")
#: Bytes per output sample, and per output sample and site, of conditioning a file's forces (`check_memory`
#: before it starts; measured 1.4 kB a sample at 4 sites, 2.9 kB at 16, 9.9 kB at 64).
_BYTES_PER_SAMPLE, _BYTES_PER_SITE_SAMPLE = 640.0, 160.0


def default_radius(x_mm, y_mm) -> float:
    """Footprint radius (mm) of taxels at ``(x_mm, y_mm)``: `taxel_radius` of the median nearest-neighbour distance.

    Raises
    ------
    ValueError
        With fewer than two sites, or when the median distance is 0 (sites
        on top of each other): give ``radius_mm`` instead.

    Examples
    --------
    >>> round(default_radius([0.0, 2.5, 5.0, 7.5], [0.0, 0.0, 0.0, 0.0]), 4)
    1.4105
    """
    x, y = np.asarray(x_mm, dtype=float), np.asarray(y_mm, dtype=float)
    if x.size < 2:
        raise ValueError(f"radius_mm is required with {x.size} site(s): the taxel pitch needs two or more sites")
    from scipy.spatial import cKDTree  # O(n log n): arrays can have thousands of taxels

    points = np.column_stack([x, y])
    nearest = cKDTree(points).query(points, k=2)[0][:, 1]
    pitch = float(np.median(nearest))
    if not pitch > 0:
        raise ValueError("radius_mm is required: the median nearest-neighbour distance between sites is 0 mm "
                         "(coincident sites)")
    return taxel_radius(pitch)


# --- reading -------------------------------------------------------------------------------------


def _numeric(where: str, key: str, value, shape) -> np.ndarray:
    """``value`` as a float array of ``shape`` (None entries match any length), finite, with clear errors."""
    try:
        arr = np.asarray(value, dtype=float)
    except (TypeError, ValueError):
        raise ValueError(f"{where}: field {key!r} must be numeric, got dtype {np.asarray(value).dtype}") from None
    if arr.ndim != len(shape) or any(s is not None and s != a for s, a in zip(shape, arr.shape)):
        want = "(" + ", ".join("n" if s is None else str(s) for s in shape) + ("," if len(shape) == 1 else "") + ")"
        raise ValueError(f"{where}: field {key!r} must have shape {want}, got {arr.shape}")
    bad = ~np.isfinite(arr)
    if bad.any():
        index = tuple(int(i) for i in np.argwhere(bad)[0])
        raise ValueError(f"{where}: field {key!r} has a non-finite value {float(arr[index])!r} at index {list(index)}")
    return arr


def _strings(where: str, key: str, value, n: int) -> np.ndarray:
    arr = np.asarray(value)
    if arr.shape != (n,):
        raise ValueError(f"{where}: field {key!r} must have shape ({n},) (one per site), got {arr.shape}")
    return np.array([v.decode() if isinstance(v, bytes) else str(v) for v in arr.tolist()], dtype=object)


def _check_fs(where: str, value) -> float:
    value = np.asarray(value)
    if value.shape == (1,):  # netCDF and HDF5 tools often store a scalar attribute as a 1-element array
        value = value[0]
    fs = _numeric(where, "fs", value, ())
    if not fs > 0:
        raise ValueError(f"{where}: field 'fs' must be > 0 Hz, got {float(fs)!r}")
    return float(fs)


def _scene_from_fields(where: str, fields: dict, name: str, conditioning=None, source: str | None = None,
                       max_force_n: float = MAX_FORCE_N) -> Scene:
    """Validate raw ``fields`` (the layout's names) and build the scene, conditioned when ``conditioning`` is
    given (to the model's rate: the file's, at least 1 kHz); errors name ``where``, a band warning ``source``."""
    missing = [k for k in _REQUIRED if k not in fields]
    if missing:
        raise ValueError(f"{where}: missing field {missing[0]!r}; required: {', '.join(_REQUIRED)}")
    fs = _check_fs(where, fields["fs"])
    forces = _numeric(where, "forces", fields["forces"], (None, None, 3))
    n_samples, n_sites = forces.shape[:2]
    if n_samples == 0 or n_sites == 0:
        raise ValueError(f"{where}: field 'forces' needs at least one sample and one site, got shape {forces.shape}")
    allowance = 0.0 if conditioning is None else noise_allowance(conditioning)
    negative = forces[:, :, 2] < -allowance
    if negative.any():
        k, j = (int(i) for i in np.argwhere(negative)[0])
        raise ValueError(f"{where}: field 'forces' has a negative normal force {float(forces[k, j, 2]):g} N at index "
                         f"[{k}, {j}, 2] " + (f"(below the sensor-noise allowance of -{allowance:g} N)" if allowance
                                                  else "(F_Z must be >= 0)"))
    check_force_bound(forces, max_force_n, f"{where}: field 'forces'", fs)
    x = _numeric(where, "x_mm", fields["x_mm"], (n_sites,))
    y = _numeric(where, "y_mm", fields["y_mm"], (n_sites,))
    sites = _sites(where, fields, x, y)
    warn_band(source or where, fs)
    if conditioning is not None:
        fs_out = max(fs, DEFAULT_FS)
        n_out = n_samples * fs_out / fs
        check_memory(n_out * (_BYTES_PER_SAMPLE + _BYTES_PER_SITE_SAMPLE * n_sites), f"{where} resampled to "
                     f"{fs_out:g} Hz ({n_out:,.0f} samples x {n_sites:,} sites)",
                     "check its field 'fs' (Hz) and its number of samples")
        forces, _ = condition_forces(forces, fs, fs_out, conditioning)
        fs = fs_out
    return Scene.from_sites(forces, sites, fs=fs, name=name)


def _sites(where: str, fields: dict, x: np.ndarray, y: np.ndarray) -> Sites:
    n = x.size
    if fields.get("radius_mm") is None:
        try:
            radius = default_radius(x, y)
        except ValueError as exc:
            raise ValueError(f"{where}: {exc}") from None
    else:
        raw = np.asarray(fields["radius_mm"])
        radius = _numeric(where, "radius_mm", raw, () if raw.ndim == 0 else (n,))
        if np.any(radius <= 0):
            i = int(np.flatnonzero(np.atleast_1d(radius) <= 0)[0])
            raise ValueError(f"{where}: field 'radius_mm' must be > 0 mm, got {float(np.atleast_1d(radius)[i])!r} "
                             f"at index [{i}]")
    region = None if fields.get("region") is None else _strings(where, "region", fields["region"], n)
    ids = None if fields.get("site") is None else _strings(where, "site", fields["site"], n)
    if ids is not None:
        seen = {}
        for i, s in enumerate(ids):
            if s in seen:
                raise ValueError(f"{where}: field 'site' has duplicate id {s!r} at index [{i}] "
                                 f"(first at [{seen[s]}])")
            seen[s] = i
    return Sites(x, y, radius, region=region, site_id=ids)


def _read_npz(path, where: str) -> dict:
    import zipfile

    try:
        data = np.load(path, allow_pickle=False)
        if not hasattr(data, "files"):  # a bare .npy array, not an archive of named fields
            raise ValueError("it is a single array, not an archive of named fields")
        with data:
            fields = {k: data[k] for k in data.files}
    except (OSError, ValueError, EOFError, zipfile.BadZipFile) as exc:
        raise ValueError(f"{where}: cannot be read as NPZ ({exc})") from None
    unknown = sorted(set(fields) - set(_REQUIRED) - set(_OPTIONAL))
    if unknown:
        raise ValueError(f"{where}: unknown field {unknown[0]!r}; allowed: {', '.join(_REQUIRED + _OPTIONAL)}")
    return fields


def _read_netcdf(path, where: str) -> dict:
    import xarray as xr

    try:
        with xr.open_dataset(path) as ds:
            ds = ds.load()
    except (OSError, ValueError) as exc:
        raise ValueError(f"{where}: cannot be read as netCDF ({exc})") from None
    allowed = set(_REQUIRED + _OPTIONAL) | {"time", "axis"}
    unknown = sorted(set(map(str, ds.variables)) - allowed)
    if unknown:
        raise ValueError(f"{where}: unknown variable {unknown[0]!r}; allowed: {', '.join(sorted(allowed))}")
    fields = {k: ds[k].values for k in _REQUIRED + _OPTIONAL if k in ds.variables}
    if "fs" not in fields and "fs" in ds.attrs:
        fields["fs"] = ds.attrs["fs"]
    if "forces" in ds and ds["forces"].dims != ("time", "site", "axis"):
        raise ValueError(f"{where}: variable 'forces' must have dimensions (time, site, axis), "
                         f"got {ds['forces'].dims}")
    if "time" in ds.variables and "fs" in fields:
        _check_time_coordinate(where, ds["time"].values, _check_fs(where, fields["fs"]))
    return fields


def _check_time_coordinate(where: str, time, fs: float) -> None:
    """A ``time`` coordinate must be ``t0 + i / fs`` to within `TIME_TOL` of a step."""
    t = _numeric(where, "time", time, (None,))
    off = np.abs(t - t[0] - np.arange(t.size) / fs) * fs
    if np.any(off > TIME_TOL):
        i = int(np.flatnonzero(off > TIME_TOL)[0])
        raise ValueError(f"{where}: field 'time' is not uniform at fs = {fs!r} Hz: {float(t[i])!r} s at index [{i}]")


def _read_hdf5(path, where: str) -> dict:
    import h5py

    try:
        with h5py.File(path, "r") as fh:
            unknown = sorted(set(fh.keys()) - set(_REQUIRED) - set(_OPTIONAL))
            if unknown:
                raise ValueError(f"{where}: unknown dataset {unknown[0]!r}; "
                                 f"allowed: {', '.join(_REQUIRED + _OPTIONAL)}")
            for k in fh.keys():  # only the file's own data: a link could read any file the user can
                if not isinstance(fh.get(k, getlink=True), h5py.HardLink) or not isinstance(fh[k], h5py.Dataset):
                    raise ValueError(f"{where}: {k!r} must be a dataset stored in the file, not a link or a group")
            fields = {k: fh[k][()] for k in fh.keys()}
            if "fs" not in fields and "fs" in fh.attrs:
                fields["fs"] = fh.attrs["fs"]
    except OSError as exc:
        raise ValueError(f"{where}: cannot be read as HDF5 ({exc})") from None
    return fields


_READERS = {"npz": _read_npz, "netcdf": _read_netcdf, "hdf5": _read_hdf5}


def from_array(path, *, name: str | None = None, conditioning: Conditioning | None = RECORDED,
               max_force_n: float = MAX_FORCE_N) -> Scene:
    """A multi-site scene from a sensor-array file (``.npz``, ``.nc``, ``.h5`` / ``.hdf5``).

    The layouts are in this module's docstring: forces (n_samples, n_sites, 3)
    in N, fs in Hz, taxel centres in mm and optional footprint radii, regions
    and site ids.

    Parameters
    ----------
    path : str or Path
        The file; its extension picks the format.
    name : str, optional
        Condition name (default: the file stem).
    conditioning : Conditioning or None
        The conditioning stage for recorded forces (default on, as
        `ddmm.population.stimuli.recordings.from_csv`; docs/recordings.md): the scene is at the file's
        rate, or 1 kHz if the file is slower.  None: the forces as stored
        (F_Z >= 0 required), e.g. a scene `save_array` wrote.
    max_force_n : float
        The largest force (N, magnitude) any site may carry, 1 kN by default:
        beyond it the file is in the wrong unit (as `from_csv`).

    Returns
    -------
    Scene
        With ``sites`` and ``site_forces`` set (`Scene.from_sites`).

    Raises
    ------
    ValueError
        One line naming the file, the field and the index of the first
        problem: unknown extension, unreadable file, missing or unknown field,
        wrong shape, NaN/inf, negative F_Z, duplicate site id, fs <= 0.

    Examples
    --------
    >>> import tempfile, pathlib
    >>> with tempfile.TemporaryDirectory() as tmp:
    ...     path = pathlib.Path(tmp) / "pad.npz"
    ...     np.savez(path, fs=500.0, forces=np.ones((50, 4, 3)), x_mm=[0.0, 2.0, 0.0, 2.0],
    ...              y_mm=[0.0, 0.0, 2.0, 2.0])
    ...     scene = from_array(path, conditioning=None)
    >>> scene.n_sites, round(float(scene.sites.radius_mm[0]), 4)
    (4, 1.1284)
    """
    check_path(path)
    kind = array_format(path)
    where = f"array file {str(path)!r}"
    if not Path(path).is_file():
        raise ValueError(f"{where} does not exist")
    return _scene_from_fields(where, _READERS[kind](path, where), name or Path(path).stem, conditioning,
                              max_force_n=max_force_n)


# --- long CSV ------------------------------------------------------------------------------------


def from_long_csv(forces_csv, sites_csv, *, fs: float | None = None, name: str | None = None,
                  conditioning: Conditioning | None = RECORDED, max_force_n: float = MAX_FORCE_N) -> Scene:
    """A multi-site scene from a long CSV of forces and a CSV table of sites.

    ``forces_csv`` has the header ``time,site,fx,fy,fz`` (any column order;
    other columns are ignored): one row per site per time stamp, times in s,
    forces in N, F_Z >= 0, rows in any order.  The time stamps must form one
    uniform grid shared by every site (each time stamp within 0.1% of a step
    of it); the scene starts at t = 0 for the first time stamp.

    ``sites_csv`` has the header ``site,x_mm,y_mm`` plus optional ``region``
    and ``radius_mm`` (mm): one row per site, ids unique; the scene's sites
    follow its order.  Without ``radius_mm`` the footprint is the equal-area
    radius of the median nearest-neighbour distance (`default_radius`).

    Parameters
    ----------
    forces_csv, sites_csv : str or Path
        The two files.
    fs : float, optional
        Sample rate in Hz; by default inferred from the time step, otherwise
        checked against it (needed when there is a single time stamp).
    name : str, optional
        Condition name (default: the stem of ``forces_csv``).
    conditioning : Conditioning or None
        As `from_array` (default on; None: the forces as written).
    max_force_n : float
        As `from_array`: the largest force a site may carry, N.

    Raises
    ------
    ValueError
        One line naming the file, the column and the line: a site missing
        from the table, a site without a sample at some time stamp, a
        duplicate (time, site) row or site id, a non-uniform or mismatched
        time step, NaN/inf, a negative F_Z, a malformed row.

    Examples
    --------
    >>> import tempfile, pathlib
    >>> with tempfile.TemporaryDirectory() as tmp:
    ...     forces = pathlib.Path(tmp) / "forces.csv"
    ...     sites = pathlib.Path(tmp) / "sites.csv"
    ...     _ = forces.write_text("time,site,fx,fy,fz\\n0,a,0,0,1\\n0,b,0,0,2\\n0.01,a,0,0.1,1\\n0.01,b,0,0,2\\n")
    ...     _ = sites.write_text("site,x_mm,y_mm,radius_mm\\na,0,0,1.5\\nb,3,0,1.5\\n")
    ...     scene = from_long_csv(forces, sites, conditioning=None)
    >>> scene.n_sites, scene.n_samples, round(scene.fs, 6), list(scene.sites.site_id)
    (2, 2, 100.0, ['a', 'b'])
    """
    check_path(forces_csv, "forces_csv")
    check_path(sites_csv, "sites_csv")
    if fs is not None:
        from ddmm.utils.validation import check_positive

        fs = check_positive(fs, "fs", "Hz")
    sites_where, table, site_lines = read_sites_csv(sites_csv)
    known = {s: i for i, s in enumerate(table["site"])}
    allowance = 0.0 if conditioning is None else noise_allowance(conditioning)
    where, t, site, force, lines = read_long_forces(forces_csv, known, allowance)
    times, slot = np.unique(t, return_inverse=True)
    fs = uniform_grid(where, times, fs, t, lines)
    filled = np.full((times.size, len(known)), -1, dtype=int)
    for r in range(t.size):
        k, j = slot[r], site[r]
        if filled[k, j] >= 0:
            raise ValueError(f"{where}: line {lines[r]}: duplicate row for site {table['site'][j]!r} at time "
                             f"{float(t[r])!r} s (first on line {lines[filled[k, j]]})")
        filled[k, j] = r
    if np.any(filled < 0):
        k, j = (int(i) for i in np.argwhere(filled < 0)[0])
        s = table["site"][j]
        raise ValueError(f"{where}: column 'site': site {s!r} (sites file line {site_lines[s]}) has no sample "
                         f"at time {float(times[k])!r} s")
    fields = {"fs": fs, "forces": force[filled], "x_mm": table["x_mm"], "y_mm": table["y_mm"],
              "radius_mm": table["radius_mm"], "region": table["region"], "site": table["site"]}
    # the forces are checked row by row above; what is left to fail is the sites' footprint
    return _scene_from_fields(sites_where, fields, name or Path(forces_csv).stem, conditioning, where,
                              max_force_n=max_force_n)
