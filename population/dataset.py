"""The simulation Dataset: schema, netCDF round trip, rates and PSTHs.

Schema (names are fixed):

* dims ``condition`` (one per scene), ``trial``, ``afferent``, ``spike``
  (events) and ``time`` (force samples);
* coords on ``afferent``: ``afferent`` (the stable afferent id),
  ``afferent_type``, ``theta_t`` (deg), ``nap``, ``k``, ``gain``, ``sensitivity``, ``x_mm``,
  ``y_mm``, ``noise_sigma``, ``noise_cv``, ``region`` (hand-map region, ``""``
  when unknown) and ``frame_deg`` (deg, local digit frame to hand frame); on ``condition``: ``condition`` (scene name),
  ``duration`` (s), ``theta_r`` (deg) with ``has_theta_r`` (1 when the scene
  has one nominal shear direction), and when a scene has a contact
  ``contact_x_mm``, ``contact_y_mm``, ``contact_radius_mm`` (NaN for a scene
  without), and for indentation scenes ``skin`` and ``transduction_<type>_gain``,
  ``_zero_hz``, ``_pole_hz`` (NaN for a scene without, or a type without a filter); ``time`` (s); ``stage`` (labels of the
  scenes' phases, with ``stage_start``/``stage_end(condition, stage)`` in s);
* data vars ``spike_count(condition, trial, afferent)``; the events
  ``spike_time`` (s), ``spike_afferent`` (position on ``afferent``),
  ``spike_trial`` and ``spike_condition`` (positions), sorted by condition,
  trial, time and afferent; the forces ``fx``, ``fy``, ``fz``
  ``(condition, time)`` in N, zero after a shorter scene's end;
* multi-site scenes only: dim ``site`` with coords ``site`` (id),
  ``site_x_mm``, ``site_y_mm``, ``site_radius_mm`` (footprint) and
  ``site_region``; with the forces recorded, ``site_fx``, ``site_fy``,
  ``site_fz`` ``(condition, time, site)`` in N (``fx`` etc. are their sums);
* attrs: engine, dt, method, seed, no-shear reading, package version and
  every model constant.  Every variable carries ``attrs["units"]``.
"""

from __future__ import annotations

import functools
from importlib import metadata
from pathlib import Path

import numba as nb
import numpy as np
import xarray as xr

from ddmm.models.afferent_types import afferent_type_codes, afferent_type_info, type_label
from ddmm.models.attenuation import F_TH
from ddmm.models.metrics import CONTACT_THRESHOLD
from ddmm.models.neuron import V_PEAK
from ddmm.population.anatomy.receptive_fields import RF_SUPPORT
from ddmm.utils.files import read_netcdf, write_netcdf
from ddmm.utils.validation import check_choice, check_dataset, check_positive

__all__ = ["build_dataset", "save_dataset", "load_dataset", "binned_counts", "binned_rates", "psth",
           "describe_dataset", "cf_attrs", "TIME_ATTRS"]

_HALF_POWER = "a half power of ms: UDUNITS (cf-units) parses it but keeps only integer powers; convert by hand"
#: The time coordinate's attributes: seconds from the start of a scene, CF's T axis.
TIME_ATTRS = {"units": "s", "axis": "T", "long_name": "time since the start of the scene"}


@functools.lru_cache(maxsize=1)
def _version() -> str:
    try:
        return metadata.version("ddmm")
    except metadata.PackageNotFoundError:  # running from a source tree
        return "0+unknown"


def model_attrs(population, config) -> dict:
    """Every constant that shapes the spikes, as flat netCDF-safe attrs."""
    cp = population.current
    attrs = {
        "ddmm_version": _version(), "engine": config.engine, "dt": config.dt, "method": config.method,
        "seed": config.seed, "no_shear": config.no_shear, "population": population.name,
        "frame": "+X radial, +Y distal; theta 0 radial, 90 distal, 180 ulnar, 270 proximal; theta_t in the "
                 "afferent's local digit frame, frame_deg (counterclockwise) rotates it to the hand frame",
        "f_th": F_TH, "contact_threshold": CONTACT_THRESHOLD, "v_peak": V_PEAK,
        **{f"current_{name}": "none" if value is None else value for name, value in cp.flat().items()},
        "noise_model": "white Gaussian current, (noise_sigma + noise_cv |I|)/sqrt(h) per sample of h ms",
        "rf_support": RF_SUPPORT,
        "receptive_field": population.receptive_field,
    }
    for kind in afferent_type_codes():
        params = population.neuron.get(kind, afferent_type_info(kind).neuron)
        for name in ("a", "b", "c", "d", "t_ref"):  # t_ref in s
            attrs[f"neuron_{kind}_{name}"] = getattr(params, name)
    for kind in afferent_type_codes():
        attrs[f"rf_sigma_{kind}_mm"] = afferent_type_info(kind).rf_sigma_mm
    return attrs


#: Attributes of the ``sensitivity`` coordinate.
SENSITIVITY_ATTRS = {"units": "1", "long_name": "per-unit sensitivity: multiplies the gain, divides the type's "
                                                "dead zone (1: the type's thresholds)"}


def _afferent_coords(population, index) -> dict:
    pop = population
    coords = {
        "afferent": ("afferent", pop.afferent_id[index].astype(np.int64), {"units": "1", "long_name": "afferent id"}),
        "afferent_type": ("afferent", pop.afferent_type[index].astype(object), {"long_name": "afferent type"}),
        "theta_t": ("afferent", pop.theta_t[index].astype(float), {"units": "degree"}),
        "nap": ("afferent", pop.nap[index].astype(object), {"long_name": "neural attenuation profile"}),
        "k": ("afferent", pop.k[index].astype(float), {"units": "1", "note": "0 for untuned afferents"}),
        "gain": ("afferent", pop.gain[index].astype(float), {"units": "1"}),
        "sensitivity": ("afferent", pop.sensitivity[index].astype(float), SENSITIVITY_ATTRS),
        "x_mm": ("afferent", pop.x_mm[index].astype(float), {"units": "mm"}),
        "y_mm": ("afferent", pop.y_mm[index].astype(float), {"units": "mm"}),
        "noise_sigma": ("afferent", pop.noise_sigma[index].astype(float),
                        {"units": "mV ms-0.5", "long_name": "current noise SD per sqrt(ms)", "units_note": _HALF_POWER}),
        "noise_cv": ("afferent", pop.noise_cv[index].astype(float), {"units": "ms0.5", "units_note": _HALF_POWER}),
        "region": ("afferent", pop.region[index].astype(object),
                   {"long_name": "hand-map region (ddmm.population.anatomy.hand_map), empty when unknown"}),
        "frame_deg": ("afferent", pop.frame_deg[index].astype(float),
                      {"units": "degree", "long_name": "rotation from the local digit frame to the hand frame"}),
    }
    return {k: xr.Variable(*v) for k, v in coords.items()}


def _stage_vars(scenes) -> dict:
    """Stage boundaries per condition (s); a stage a scene lacks is the empty [0, 0)."""
    labels = list(dict.fromkeys(st.label for s in scenes for st in s.stages))
    start = np.zeros((len(scenes), len(labels)))
    end = np.zeros((len(scenes), len(labels)))
    for c, scene in enumerate(scenes):
        for st in scene.stages:
            start[c, labels.index(st.label)] = st.start
            end[c, labels.index(st.label)] = st.end
    coord = xr.Variable("stage", np.array(labels, dtype=object), {"long_name": "stage label"})
    return {"stage": coord,
            "stage_start": xr.Variable(("condition", "stage"), start, {"units": "s"}),
            "stage_end": xr.Variable(("condition", "stage"), end, {"units": "s"})}


def _condition_coords(scenes) -> dict:
    theta = [0.0 if s.theta_r is None else float(s.theta_r) % 360.0 for s in scenes]
    return {
        "condition": xr.Variable("condition", np.array([s.name for s in scenes], dtype=object), {"long_name": "scene name"}),
        "duration": xr.Variable("condition", np.array([s.duration for s in scenes]), {"units": "s"}),
        "theta_r": xr.Variable("condition", np.array(theta), {"units": "degree"}),
        "has_theta_r": xr.Variable("condition", np.array([s.theta_r is not None for s in scenes], np.int8),
                                   {"units": "1"}),
        **_contact_coords(scenes),
        **_spread_coords(scenes),
    }


def _spread_coords(scenes) -> dict:
    """Per condition, what a scene's own spread records of itself (`describe()`: an indentation's skin and
    transduction); a condition without it gets NaN (numbers) or "" (text)."""
    described = [getattr(getattr(getattr(s, "sites", None), "spread", None), "describe", lambda: {})() for s in scenes]
    names = sorted({name for d in described for name in d})
    coords = {}
    for name in names:
        values = [d.get(name) for d in described]
        if all(isinstance(v, str) or v is None for v in values):
            coords[name] = xr.Variable("condition", np.array(["" if v is None else v for v in values], dtype=object))
        else:
            unit = "Hz" if name.endswith("_hz") else "1"
            coords[name] = xr.Variable("condition", np.array([np.nan if v is None else float(v) for v in values]),
                                       {"units": unit})
    return coords


def _contact_coords(scenes) -> dict:
    """``contact_x_mm``, ``contact_y_mm``, ``contact_radius_mm`` per condition when a scene has a contact (NaN: none)."""
    if all(getattr(s, "contact", None) is None for s in scenes):
        return {}
    values = np.array([[np.nan] * 3 if s.contact is None else [s.contact.x_mm, s.contact.y_mm, s.contact.radius_mm]
                       for s in scenes], dtype=float)
    return {f"contact_{name}": xr.Variable("condition", values[:, i], {"units": "mm"})
            for i, name in enumerate(("x_mm", "y_mm", "radius_mm"))}


def _events(plan, spikes, n_conditions: int):
    """Concatenate per-condition spikes, keep requested afferents, sort by (condition, trial, step,
    afferent): the four event arrays and the spike counts per (condition, trial, afferent)."""
    remap = np.full(plan.selected.size, -1, np.int64)
    remap[plan.keep] = np.arange(plan.keep.size)
    every = plan.keep.size == plan.selected.size  # the usual run keeps all it simulated: positions are final
    cols = [[], [], [], []]
    for c, parts in enumerate(spikes):
        for trial, pos, step in parts:
            aff = pos
            if not every:
                aff = remap[pos]
                ok = aff >= 0
                trial, step, aff = trial[ok], step[ok], aff[ok]
            for col, arr in zip(cols, (np.full(aff.size, c), trial, step, aff)):
                col.append(np.asarray(arr, np.int64))
    cond, trial, step, aff = (np.concatenate(c) if c else np.empty(0, np.int64) for c in cols)
    return _sorted_events(cond, trial, step, aff, n_conditions, plan.trials, plan.keep.size)


def _sorted_events(cond, trial, step, aff, n_conditions: int, n_trials: int, n_afferents: int):
    """The events sorted by condition, trial, step and afferent, and the counts (n_conditions, n_trials,
    n_afferents).

    Two counting-sort passes (by afferent, then stably by time) when the
    time slots are few against the events, as in any run with many spikes;
    else one sort of a packed key, or lexsort when that key could overflow.
    """
    n_units, n_steps = n_conditions * n_trials * n_afferents, int(step.max()) + 1 if step.size else 1
    n_slots = n_conditions * n_trials * n_steps
    if n_slots <= max(4 * cond.size, 2**20):
        cond, trial, step, aff, counts = _counting_sort(cond, trial, step, aff, n_trials, n_steps, n_afferents,
                                                        n_units, n_slots)
        return cond, trial, step, aff, counts.reshape(n_conditions, n_trials, n_afferents)
    if n_slots * n_afferents < 2**62:
        order = np.argsort(_packed(_packed(_packed(cond, trial, n_trials), step, n_steps), aff, n_afferents))
    else:  # a packed key would overflow int64
        order = np.lexsort((aff, step, trial, cond))
    cond, trial, step, aff = cond[order], trial[order], step[order], aff[order]
    counts = np.bincount(_packed(_packed(cond, trial, n_trials), aff, n_afferents), minlength=n_units)
    return cond, trial, step, aff, counts.reshape(n_conditions, n_trials, n_afferents)


@nb.njit(cache=True, nogil=True)
def _counting_sort(cond, trial, step, aff, n_trials, n_steps, n_afferents, n_units, n_slots):
    """`_sorted_events`' counting sorts: by (condition, trial, afferent), whose histogram is the spike
    counts, then stably by (condition, trial, step), which keeps afferents ascending within a step."""
    n = cond.size
    unit, counts = np.empty(n, np.int64), np.zeros(n_units, np.int64)
    for e in range(n):
        unit[e] = (cond[e] * n_trials + trial[e]) * n_afferents + aff[e]
        counts[unit[e]] += 1
    by_unit = _scatter(unit, counts, np.arange(n))
    slot = np.empty(n, np.int64)
    for e in range(n):
        slot[e] = (cond[e] * n_trials + trial[e]) * n_steps + step[e]
    order = _scatter(slot[by_unit], np.bincount(slot, minlength=n_slots), by_unit)
    return cond[order], trial[order], step[order], aff[order], counts


@nb.njit(cache=True, nogil=True, inline="always")
def _scatter(key, histogram, values):
    """``values`` placed stably in the order of ``key`` (whose per-key counts are ``histogram``)."""
    start, total = np.empty(histogram.size, np.int64), 0
    for k in range(histogram.size):
        start[k] = total
        total += histogram[k]
    out = np.empty(values.size, np.int64)
    for e in range(values.size):
        out[start[key[e]]] = values[e]
        start[key[e]] += 1
    return out


def _packed(high, low, n_low: int) -> np.ndarray:
    """``high * n_low + low`` in one new int64 array (long runs have millions of events: no temporaries)."""
    out = np.multiply(high, n_low, dtype=np.int64)
    out += low
    return out


def build_dataset(population, scenes, plan, spikes, config) -> xr.Dataset:
    """Assemble the Dataset of a run (schema in the module docstring)."""
    n_c, n_t = len(scenes), plan.trials
    cond, trial, step, aff, counts = _events(plan, spikes, n_c)
    time = step * config.dt
    counts = counts.astype(np.int32)
    data = {"spike_count": xr.Variable(("condition", "trial", "afferent"), counts, {"units": "1"})}
    if "spikes" in plan.record:
        data["spike_time"] = xr.Variable("spike", time, {"units": "s"})
        for name, arr in (("spike_afferent", aff), ("spike_trial", trial), ("spike_condition", cond)):
            data[name] = xr.Variable("spike", arr.astype(np.int32), {"units": "1", "note": "position index"})
    coords = {**_afferent_coords(population, plan.selected[plan.keep]), **_condition_coords(scenes),
              "trial": xr.Variable("trial", np.arange(n_t, dtype=np.int64), {"units": "1"})}
    if any(s.stages for s in scenes):
        stages = _stage_vars(scenes)
        coords["stage"] = stages.pop("stage")
        data.update(stages)
    if "forces" in plan.record:
        n_time = max(s.n_samples for s in scenes)
        coords["time"] = xr.Variable("time", np.arange(n_time) / scenes[0].fs, dict(TIME_ATTRS))
        for name in ("fx", "fy", "fz"):
            arr = np.zeros((n_c, n_time))
            for c, s in enumerate(scenes):
                arr[c, : s.n_samples] = getattr(s, name)
            data[name] = xr.Variable(("condition", "time"), arr, {"units": "N"})
    if scenes[0].sites is not None:
        _add_sites(scenes, coords, data, "forces" in plan.record)
    attrs = {**cf_attrs("ddmm simulation of tactile afferent spike trains", population.name),
             **model_attrs(population, config), "fs": float(scenes[0].fs), "trials": n_t}
    return xr.Dataset(data, coords=coords, attrs=attrs)


def cf_attrs(title: str, population: str) -> dict:
    """CF global attributes of the package's netCDF files (Conventions, title, source, history, ...).

    No time stamp: two runs with one seed give identical Datasets (``identical`` holds), attrs included.
    """
    return {"Conventions": "CF-1.11", "title": title,
            "institution": "simulated with ddmm (no recording institution)",
            "source": f"ddmm {_version()}: Direction-Dependent Mechanotransduction Model, population {population!r}",
            "history": f"created by ddmm {_version()} (no time stamp, so that equal runs give identical files)",
            "references": "DDMM paper, data DOI 10.5258/SOTON/D3758; docs/references.md of the ddmm package",
            "comment": "Simulated, not recorded. Spike events on the spike dimension; every model constant is an "
                       "attribute."}


def _add_sites(scenes, coords, data, forces: bool) -> None:
    """The ``site`` dimension of multi-site runs (all scenes share their sites), and per-site forces."""
    sites = scenes[0].sites
    coords["site"] = xr.Variable("site", np.asarray(sites.site_id, dtype=object), {"long_name": "site id"})
    for name, unit in (("x_mm", "mm"), ("y_mm", "mm"), ("radius_mm", "mm"), ("region", "1")):
        values = getattr(sites, name)
        coords[f"site_{name}"] = xr.Variable("site", values.astype(object) if unit == "1" else values,
                                             {"long_name": "site region"} if unit == "1" else {"units": unit})
    if forces:
        n_time = coords["time"].size
        for axis, name in enumerate(("site_fx", "site_fy", "site_fz")):
            arr = np.zeros((len(scenes), n_time, len(sites)))
            for c, s in enumerate(scenes):
                arr[c, : s.n_samples] = s.site_forces[:, :, axis]
            data[name] = xr.Variable(("condition", "time", "site"), arr, {"units": "N"})


def save_dataset(ds: xr.Dataset, path) -> Path:
    """Write ``ds`` to netCDF (HDF5) atomically: a failed write leaves no file.

    Raises
    ------
    ValueError
        If the directory does not exist or cannot be written.
    """
    check_dataset(ds)
    return write_netcdf(ds, path)


def load_dataset(path) -> xr.Dataset:
    """Read a dataset written by `save_dataset` fully into memory.

    A dataset written before units had a sensitivity gets ``sensitivity`` 1
    for every afferent (what its run used).
    """
    ds = read_netcdf(path, "dataset file")
    if "afferent" not in ds.dims or "ddmm_version" not in ds.attrs:
        array = ds.attrs.get("layout") == "ddmm sensor array"
        raise ValueError(f"dataset file {str(path)!r} is not a ddmm simulation dataset (no afferent dimension"
                         + ("; it is a sensor-array file: simulate it with 'ddmm simulate --scene FILE')"
                            if array else ")"))
    if "sensitivity" not in ds.variables:
        ds = ds.assign_coords(sensitivity=("afferent", np.ones(ds.sizes["afferent"]), SENSITIVITY_ATTRS))
    return ds


def binned_counts(ds: xr.Dataset, bin_s: float, *, t_max: float | None = None) -> xr.DataArray:
    """Spike counts per (condition, trial, afferent, bin) from the events."""
    check_dataset(ds)
    if "spike_time" not in ds:
        raise ValueError("the dataset has no spike events; simulate with record including 'spikes'")
    check_positive(bin_s, "bin_s", "s")
    t_max = float(ds.duration.max()) if t_max is None else check_positive(t_max, "t_max", "s")
    edges = np.arange(0.0, t_max + bin_s / 2, bin_s)
    n_bins = max(1, edges.size - 1)
    b = np.minimum(_bin_index(ds.spike_time.values, bin_s), n_bins - 1)
    keep = ds.spike_time.values < edges[-1]
    shape = (ds.sizes["condition"], ds.sizes["trial"], ds.sizes["afferent"], n_bins)
    out = np.zeros(shape, np.int32)
    np.add.at(out, (ds.spike_condition.values[keep], ds.spike_trial.values[keep],
                    ds.spike_afferent.values[keep], b[keep]), 1)
    centers = (np.arange(n_bins) + 0.5) * bin_s
    return xr.DataArray(out, dims=("condition", "trial", "afferent", "bin"),
                        coords={**{k: ds[k] for k in ("condition", "trial")}, **ds.afferent.coords,
                                "bin": ("bin", centers, {"units": "s"})},
                        attrs={"units": "1", "bin_s": bin_s})


def _bin_index(t, bin_s: float) -> np.ndarray:
    """Bin of each time in half-open bins ``[i, i + 1) * bin_s``; a time on an edge to rounding opens the next.

    Spike times are step counts times dt, so many fall on bin edges:
    ``5.97 // 0.01`` is 596.0, and 5.97 s would land in the bin before its
    own.  A quotient within 1e-8 bins of an integer is taken as that integer
    (Elephant's ``BinnedSpikeTrain`` tolerance, so the two bin alike).
    """
    q = np.asarray(t, np.float64) / bin_s
    nearest = np.rint(q)
    return np.floor(np.where(np.abs(q - nearest) <= 1e-8, nearest, q)).astype(np.int64)


def binned_rates(ds: xr.Dataset, bin_s: float, **kwargs) -> xr.DataArray:
    """Firing rate per (condition, trial, afferent, bin) in pulses/s.

    Examples
    --------
    >>> from ddmm.population import make_population, birznieks, simulate
    >>> ds = simulate(make_population(["SAI"]), birznieks(90.0), engine="direct", quiet=True)
    >>> binned_rates(ds, 0.1).sizes["bin"]
    5
    """
    counts = binned_counts(ds, bin_s, **kwargs)
    return (counts / bin_s).assign_attrs(units="1/s", bin_s=bin_s)


def psth(ds: xr.Dataset, bin_s: float = 0.01, *, by: str = "afferent_type") -> xr.DataArray:
    """Peri-stimulus time histogram: mean rate (imp/s) per condition, group and bin.

    Averages over trials and over the afferents of each value of ``by``
    (a coordinate on ``afferent``, e.g. ``"afferent_type"`` or ``"nap"``).
    """
    check_dataset(ds)
    check_choice(by, "by", [k for k in ds.coords if ds[k].dims == ("afferent",)])
    rates = binned_rates(ds, bin_s).mean("trial")
    return rates.groupby(by).mean("afferent").assign_attrs(units="1/s", bin_s=bin_s)


def describe_dataset(ds: xr.Dataset) -> str:
    """A short text summary (``ddmm info``)."""
    check_dataset(ds)
    lines = [f"population {ds.attrs.get('population')!r}: {ds.sizes['afferent']} afferents, "
             f"{ds.sizes['condition']} condition(s), {ds.sizes['trial']} trial(s)",
             f"engine {ds.attrs['engine']}, method {ds.attrs['method']}, dt {ds.attrs['dt'] * 1e3:g} ms, "
             f"seed {ds.attrs['seed']}, no_shear {ds.attrs['no_shear']} (eq. 17's reading below the shear "
             f"threshold; docs/model.md), ddmm {ds.attrs['ddmm_version']}"]
    present = set(ds.afferent_type.values.tolist())
    kinds = [t for t in afferent_type_codes() if t in present]
    for c, name in enumerate(ds.condition.values):
        counts = ds.spike_count.isel(condition=c)
        dur = float(ds.duration[c])
        parts = [f"{type_label(t)} {float(counts.where(ds.afferent_type == t, drop=True).mean()) / dur:.1f}"
                 for t in kinds]
        lines.append(f"- {name} ({dur:g} s): {int(counts.sum())} spikes; mean rate per afferent (imp/s): "
                     + ", ".join(parts))
    return "\n".join(lines)
