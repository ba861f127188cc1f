"""Spatial event plots: the spikes of a scanned surface placed back on the surface, as texture labs read them.

A spatial event plot (SEP; Johnson & Lamb 1981; Phillips, Johnson & Hsiao 1988; docs/references.md)
puts each spike at the point of the surface that lay over the unit's receptive-field centre when it fired.
In the laboratory one unit is swept over a drum many times, shifted sideways between sweeps; in simulation
each afferent under the window is one such sweep (copies of one unit placed at lateral offsets give the
drum protocol itself).

`ScanPath` is the surface's motion as `ddmm.population.stimuli.scanning.scan` makes it, with the same
parameters: the surface's centre passes under ``center_mm`` at ``duration_s / 2``, moving at ``speed_mm_s``
along ``direction_deg``, so a receptor at p lies over the surface point ``p - center - v (t - duration_s / 2)``
at time t (the surface's frame, origin at its centre).

- `spatial_events`: every spike as (surface x, surface y, time, afferent, type);
- `event_rate_map`: spikes per bin over the time the afferents' centres spent over it: the rate (imp/s) as
  a function of the surface point, NaN where none passed;
- `relief_correlation`: Pearson's r between a rate map and the surface's relief at the same points, how
  faithfully a type's spikes draw the surface (SA-I sharpest, FA-I blurred, FA-II none in the monkey's
  letter SEPs, Phillips et al. 1988).
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
import xarray as xr

from ddmm.population.stimuli.surfaces import Surface
from ddmm.utils.validation import (
    check_choice,
    check_dataset,
    check_instance,
    check_nonnegative,
    check_positive,
    check_real,
    shown,
)

__all__ = ["ScanPath", "spatial_events", "event_rate_map", "relief_correlation"]

#: Path samples per bin crossed when the dwell time is integrated (`event_rate_map`).
_DWELL_SAMPLES_PER_BIN = 8
#: Path points held at once (a block of afferents' paths): bounds the memory of a long, fast scan at fine bins.
_DWELL_POINTS = 1 << 22


@dataclass(frozen=True)
class ScanPath:
    """The motion of a scanned surface: `ddmm.population.stimuli.scanning.scan`'s parameters of the same names.

    Attributes
    ----------
    speed_mm_s : float
        Scan speed in mm/s (> 0).
    duration_s : float
        Scan length in s (> 0).
    direction_deg : float
        Direction of the surface's motion in degrees (0 = +X radial, 90 = +Y distal).
    center_mm : (float, float)
        Centre (x, y) in mm of the skin window; the surface's centre passes under it at ``duration_s / 2``.

    Examples
    --------
    >>> path = ScanPath(speed_mm_s=40.0, duration_s=1.0)
    >>> [float(q) for q in path.surface_point(0.0, 0.0, 0.75)]  # a quarter second past the centre
    [-10.0, 0.0]
    """

    speed_mm_s: float
    duration_s: float
    direction_deg: float = 0.0
    center_mm: tuple = (0.0, 0.0)

    def __post_init__(self):
        object.__setattr__(self, "speed_mm_s", check_positive(self.speed_mm_s, "speed_mm_s", "mm/s"))
        object.__setattr__(self, "duration_s", check_positive(self.duration_s, "duration_s", "s"))
        object.__setattr__(self, "direction_deg", check_real(self.direction_deg, "direction_deg", "deg"))
        try:
            centre = np.asarray(self.center_mm, dtype=float) if np.ndim(self.center_mm) == 1 else np.zeros(0)
        except (TypeError, ValueError):
            centre = np.zeros(0)
        if centre.shape != (2,) or not np.all(np.isfinite(centre)):
            raise ValueError(f"center_mm must be two finite numbers (x, y) in mm, got {self.center_mm!r}")
        object.__setattr__(self, "center_mm", (float(centre[0]), float(centre[1])))

    def surface_point(self, x_mm, y_mm, t_s) -> tuple:
        """(x, y) in mm of the surface point over the skin point (``x_mm``, ``y_mm``) at time ``t_s`` (s); the
        arguments broadcast."""
        angle = np.deg2rad(self.direction_deg)
        travel = self.speed_mm_s * (np.asarray(t_s, dtype=float) - self.duration_s / 2.0)
        return (np.asarray(x_mm, dtype=float) - self.center_mm[0] - travel * np.cos(angle),
                np.asarray(y_mm, dtype=float) - self.center_mm[1] - travel * np.sin(angle))


def spatial_events(dataset, path: ScanPath, *, condition: int = 0, latency_s: float = 0.0, afferents=None):
    """Every spike of one condition placed on the surface: the spatial event plot's points.

    Parameters
    ----------
    dataset : xarray.Dataset
        A run of `ddmm.population.simulate` on a `scan` scene.
    path : ScanPath
        The scan's motion (the parameters given to `scan`).
    condition : int
        Index of the condition (the scan) in ``dataset``.
    latency_s : float
        Response latency in s (>= 0) taken off each spike time before it is placed (a spike answers the
        surface that passed a little earlier); spikes that come out before 0 or after the scan are left out.
    afferents : array_like of int, optional
        Positions along ``dataset``'s afferent dimension to keep (e.g. those away from the window's edges);
        default all.

    Returns
    -------
    xarray.Dataset
        Dimension ``event``: ``surface_x_mm`` and ``surface_y_mm`` (mm, the surface's frame), ``time``
        (s, as simulated), ``afferent`` (position in ``dataset``), ``afferent_type`` and ``trial``.

    Examples
    --------
    >>> from ddmm.population import sample_population, simulate
    >>> from ddmm.population.stimuli.scanning import scan
    >>> from ddmm.population.stimuli.surfaces import grating
    >>> pop = sample_population("fingertip", rng=0)
    >>> near = pop.select(np.flatnonzero((abs(pop.x_mm) < 1) & (abs(pop.y_mm) < 1)))
    >>> ds = simulate(near, scan(grating(2.0), duration_s=0.1, window_mm=(3.0, 3.0), pitch_mm=0.3), seed=0, quiet=True)
    >>> ev = spatial_events(ds, ScanPath(40.0, 0.1, center_mm=(0.0, 0.0)))
    >>> sorted(ev.data_vars) == ["afferent", "afferent_type", "surface_x_mm", "surface_y_mm", "time", "trial"]
    True
    """
    ds, path = check_dataset(dataset, "dataset"), check_instance(path, "path", ScanPath, "a ScanPath")
    c, latency = _condition(ds, condition), check_nonnegative(latency_s, "latency_s", "s")
    keep = _afferent_mask(ds, afferents)
    spike_aff = ds.spike_afferent.values.astype(np.int64)
    t = ds.spike_time.values - latency
    sel = (ds.spike_condition.values == c) & keep[spike_aff] & (t >= 0.0) & (t <= path.duration_s)
    aff = spike_aff[sel]
    qx, qy = path.surface_point(ds.x_mm.values[aff], ds.y_mm.values[aff], t[sel])
    mm = {"units": "mm"}
    return xr.Dataset(
        {"surface_x_mm": ("event", qx, {**mm, "long_name": "surface x under the afferent's centre"}),
         "surface_y_mm": ("event", qy, {**mm, "long_name": "surface y under the afferent's centre"}),
         "time": ("event", ds.spike_time.values[sel], {"units": "s"}),
         "afferent": ("event", aff, {"units": "1", "long_name": "position along the run's afferent dimension"}),
         "afferent_type": ("event", ds.afferent_type.values[aff].astype(object)),
         "trial": ("event", ds.spike_trial.values[sel].astype(np.int64), {"units": "1"})},
        attrs={"speed_mm_s": path.speed_mm_s, "duration_s": path.duration_s, "direction_deg": path.direction_deg,
               "latency_s": latency})


def event_rate_map(dataset, path: ScanPath, afferent_type: str, *, bin_mm: float = 0.25, extent_mm=None,
                   condition: int = 0, latency_s: float = 0.0, afferents=None):
    """One type's firing rate as a function of the surface point under its afferents' centres.

    Each bin's rate is the type's spikes placed in it (`spatial_events`) over the time its afferents'
    centres spent over it, summed over afferents and trials: a unit that crosses a bin twice counts twice,
    one that never crosses it not at all.

    Parameters
    ----------
    dataset, path, condition, latency_s, afferents
        As `spatial_events`.
    afferent_type : str
        The type mapped (e.g. ``"SAI"``).
    bin_mm : float
        Side of a square bin in mm (> 0).
    extent_mm : (float, float, float, float), optional
        (x0, x1, y0, y1) in mm of the map in the surface's frame; default: the box the type's afferents'
        centres crossed.

    Returns
    -------
    xarray.DataArray
        Dimensions (``surface_y_mm``, ``surface_x_mm``), bin centres in mm; the rate in imp/s, NaN where no
        centre passed.  ``attrs["dwell_s"]`` is the total time over the map's bins.

    Examples
    --------
    >>> from ddmm.population import sample_population, simulate
    >>> from ddmm.population.stimuli.scanning import scan
    >>> from ddmm.population.stimuli.surfaces import dot_pattern
    >>> tip = sample_population("fingertip", rng=1)
    >>> units = tip.select(np.flatnonzero(np.hypot(tip.x_mm, tip.y_mm) < 1.5))
    >>> path = ScanPath(speed_mm_s=20.0, duration_s=0.2)
    >>> run = simulate(units, scan(dot_pattern(2.0), speed_mm_s=20.0, duration_s=0.2, window_mm=(4.0, 4.0)), seed=1,
    ...                quiet=True)
    >>> rate = event_rate_map(run, path, "SAI", bin_mm=0.5)
    >>> rate.dims, rate.attrs["units"]
    (('surface_y_mm', 'surface_x_mm'), 's-1')
    """
    events = spatial_events(dataset, path, condition=condition, latency_s=latency_s, afferents=afferents)
    ds, bin_mm = dataset, check_positive(bin_mm, "bin_mm", "mm")
    check_choice(afferent_type, "afferent_type", sorted(set(ds.afferent_type.values.astype(str))))
    chosen = np.flatnonzero(_afferent_mask(ds, afferents) & (ds.afferent_type.values.astype(str) == afferent_type))
    x, y = ds.x_mm.values[chosen], ds.y_mm.values[chosen]
    dwell, (x_edges, y_edges) = _dwell(path, x, y, bin_mm, extent_mm)
    dwell *= int(ds.sizes["trial"])
    mine = events.afferent_type.values.astype(str) == afferent_type
    counts = np.histogram2d(events.surface_y_mm.values[mine], events.surface_x_mm.values[mine], (y_edges, x_edges))[0]
    rate = np.full(dwell.shape, np.nan)
    np.divide(counts, dwell, out=rate, where=dwell > 0.0)
    centre = {"surface_y_mm": ("surface_y_mm", (y_edges[:-1] + y_edges[1:]) / 2, {"units": "mm"}),
              "surface_x_mm": ("surface_x_mm", (x_edges[:-1] + x_edges[1:]) / 2, {"units": "mm"})}
    return xr.DataArray(rate, dims=("surface_y_mm", "surface_x_mm"), coords=centre, name="rate",
                        attrs={"units": "s-1", "long_name": f"{afferent_type} rate by surface point",
                               "dwell_s": float(dwell.sum()), "bin_mm": bin_mm})


def relief_correlation(rate_map, surface) -> float:
    """Pearson's r between a rate map (`event_rate_map`) and the surface's height at the same bin centres, over
    the bins some afferent crossed: 1 for spikes that draw the relief, 0 for none.

    A map with no spatial variation (a type silent or firing alike everywhere) draws nothing: r = 0.

    Raises
    ------
    ValueError
        When fewer than 3 bins were crossed, or the surface is flat over them.

    Examples
    --------
    >>> from ddmm.population.stimuli.surfaces import grating
    >>> s = grating(2.0)
    >>> x = np.arange(-2.0, 2.0, 0.25) + 0.125
    >>> drawn = xr.DataArray(10.0 * s.height_at(x[None, :], np.zeros((3, 1))), dims=("surface_y_mm", "surface_x_mm"),
    ...                      coords={"surface_y_mm": [-0.25, 0.0, 0.25], "surface_x_mm": x})
    >>> round(relief_correlation(drawn, s), 6)
    1.0
    """
    check_instance(rate_map, "rate_map", xr.DataArray, "an xarray.DataArray from event_rate_map")
    check_instance(surface, "surface", Surface, "a Surface (e.g. letters('A') or grating(1.0))")
    if rate_map.dims != ("surface_y_mm", "surface_x_mm"):
        raise ValueError(f"rate_map must have dims ('surface_y_mm', 'surface_x_mm') (event_rate_map), got {rate_map.dims}")
    y, x = np.meshgrid(rate_map.surface_y_mm.values, rate_map.surface_x_mm.values, indexing="ij")
    crossed = np.isfinite(rate_map.values)
    if crossed.sum() < 3:
        raise ValueError(f"rate_map has {int(crossed.sum())} crossed bin(s); need at least 3")
    rate, height = rate_map.values[crossed], surface.height_at(x[crossed], y[crossed])
    if np.ptp(height) == 0.0:
        raise ValueError(f"the surface is flat (height {shown(float(height[0]))} mm) over the map's crossed bins")
    if np.ptp(rate) == 0.0:
        return 0.0
    return float(np.corrcoef(rate, height)[0, 1])


def _dwell(path, x, y, bin_mm, extent_mm) -> tuple:
    """(time in s the centres (``x``, ``y``) spent over each bin, (x edges, y edges)): each path sampled at the
    middle of steps that move it ``bin_mm / _DWELL_SAMPLES_PER_BIN`` at most, a block of afferents at a time."""
    n_steps = int(np.ceil(path.duration_s * _DWELL_SAMPLES_PER_BIN * path.speed_mm_s / bin_mm))
    step = path.duration_s / n_steps
    t = (np.arange(n_steps) + 0.5) * step
    ends = path.surface_point(x[:, None], y[:, None], t[[0, -1]][None, :])  # straight paths: their ends bound them
    edges = _edges(extent_mm, *ends, bin_mm)
    dwell = np.zeros((edges[1].size - 1, edges[0].size - 1))
    block = max(1, _DWELL_POINTS // n_steps)
    for a0 in range(0, x.size, block):
        qx, qy = path.surface_point(x[a0:a0 + block, None], y[a0:a0 + block, None], t[None, :])
        dwell += np.histogram2d(qy.ravel(), qx.ravel(), edges[::-1])[0]
    return dwell * step, edges


def _condition(ds, condition) -> int:
    n = int(ds.sizes["condition"])
    if isinstance(condition, bool) or not isinstance(condition, (int, np.integer)):
        raise TypeError(f"condition must be an int (a condition's index), got {type(condition).__name__}")
    if not 0 <= condition < n:
        raise ValueError(f"condition={int(condition)} is out of range; the dataset has {n} condition(s)")
    return int(condition)


def _afferent_mask(ds, afferents) -> np.ndarray:
    n = int(ds.sizes["afferent"])
    keep = np.zeros(n, bool)
    if afferents is None:
        keep[:] = True
        return keep
    idx = np.asarray(afferents)
    if idx.ndim != 1 or (idx.size and not np.issubdtype(idx.dtype, np.integer)):
        raise TypeError(f"afferents must be a 1-D array of int positions, got dtype {idx.dtype} and shape {idx.shape}")
    if idx.size and (idx.min() < 0 or idx.max() >= n):
        bad = int(idx[(idx < 0) | (idx >= n)][0])
        raise ValueError(f"afferents holds position {bad}; allowed 0 to {n - 1}")
    keep[idx] = True
    return keep


def _edges(extent_mm, qx, qy, bin_mm) -> tuple:
    if extent_mm is None:
        if qx.size == 0:
            raise ValueError("no afferent of that type is kept: give extent_mm or choose other afferents")
        extent = (qx.min(), qx.max() + 1e-9, qy.min(), qy.max() + 1e-9)
    else:
        extent = tuple(float(check_real(v, "extent_mm", "mm")) for v in np.asarray(extent_mm, dtype=float).ravel())
        if len(extent) != 4 or extent[1] <= extent[0] or extent[3] <= extent[2]:
            raise ValueError(f"extent_mm must be (x0, x1, y0, y1) mm with x1 > x0 and y1 > y0, got {extent_mm!r}")
    nx, ny = (max(1, int(np.ceil((hi - lo) / bin_mm - 1e-9))) for lo, hi in (extent[:2], extent[2:]))
    return extent[0] + bin_mm * np.arange(nx + 1), extent[2] + bin_mm * np.arange(ny + 1)
