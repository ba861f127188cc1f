"""Stimulation pulses of a simulated run (offline), their Dataset, an independent safety check, and files.

The pulses Dataset (names fixed):

* dims ``condition``, ``trial``, ``electrode``, ``time`` (model samples) and ``pulse`` (events);
* the electrode table as coords on ``electrode``: ``electrode`` (id), ``x_mm``,
  ``y_mm``, ``radius_mm`` (NaN for a region field), ``region`` (``""`` for a
  disc), ``amplitude_min_ua``, ``amplitude_max_ua``, ``phase_width_us``,
  ``max_rate_hz``, ``charge_limit_nc``, ``interphase_us``;
* events ``pulse_time`` (s, the start of the cathodic phase), ``pulse_electrode``,
  ``pulse_condition``, ``pulse_trial`` (positions), ``pulse_amplitude`` (µA),
  ``pulse_charge`` (nC per phase), sorted by condition, trial, time and electrode;
* traces ``field_force(condition, time, electrode)`` (N), and
  ``rate_command``, ``amplitude_command``, ``aggregate_rate`` on
  ``(condition, trial, time, electrode)`` (Hz, µA, spikes/s per field afferent);
* attrs: the rule and its settings, the waveform, the contact threshold, and
  the run's population, seed and version.
"""

from __future__ import annotations

import dataclasses
import os
import warnings
from pathlib import Path

import numpy as np
import xarray as xr

from ddmm.models.metrics import CONTACT_THRESHOLD
from ddmm.population.dataset import TIME_ATTRS, cf_attrs
from ddmm.population.neurostim.electrodes import ElectrodeTable, read_electrodes
from ddmm.population.neurostim.pulses import PulseKernel, contact_weights, field_weights
from ddmm.population.neurostim.rules import get_rule
from ddmm.utils.files import read_netcdf, write_netcdf
from ddmm.utils.validation import check_dataset

__all__ = ["stimulation_pulses", "check_pulses", "save_pulses", "load_pulses", "as_table", "WAVEFORM"]

WAVEFORM = ("charge-balanced biphasic: cathodic phase of phase_width_us at the amplitude, interphase_us, anodic "
            "phase of equal width and amplitude; pulse_time is the start of the cathodic phase")


def as_table(electrodes) -> ElectrodeTable:
    """An `ElectrodeTable` from a table, a sequence of `Electrode` or a CSV/TOML path."""
    if isinstance(electrodes, ElectrodeTable):
        return electrodes
    if isinstance(electrodes, (str, os.PathLike)):
        return read_electrodes(electrodes)
    if not hasattr(electrodes, "__iter__"):
        raise TypeError(f"electrodes must be an ElectrodeTable, a sequence of Electrode or a CSV/TOML path, got "
                        f"{type(electrodes).__name__}")
    return ElectrodeTable(electrodes)


def _field_forces(ds, table):
    """(condition, time, electrode): the normal force under each field, N (module docstring of `pulses`), and
    (electrode,): whether each field takes part of a site or contact disc (the whole skin of a run without contact
    geometry is no place: every field takes it)."""
    if "site" in ds.dims:
        if "site_fz" not in ds:
            raise ValueError("the dataset has sites but no per-site forces (site_fz): simulate with the forces "
                             "recorded")
        weights = field_weights(table, ds.site_x_mm.values, ds.site_y_mm.values, ds.site_radius_mm.values,
                                ds.site_region.values)
        return np.einsum("cts,es->cte", ds.site_fz.values, weights), np.any(weights > 0, axis=1)
    if "fz" not in ds:
        raise ValueError("the dataset has no forces (fz): simulate with the forces recorded")
    n_c = ds.sizes["condition"]
    contact = ([ds[f"contact_{n}"].values for n in ("x_mm", "y_mm", "radius_mm")] if "contact_radius_mm" in ds.coords
               else [np.zeros(n_c), np.zeros(n_c), np.full(n_c, np.nan)])  # no contact: the whole skin
    weights = np.stack([contact_weights(table, *(float(v[c]) for v in contact)) for c in range(n_c)])
    placed = np.isfinite(np.asarray(contact[2], float))
    return ds.fz.values[:, :, None] * weights[:, None, :], np.any(weights[placed] > 0, axis=0)


def _field_text(e) -> str:
    return f"region {e.region!r}" if e.region is not None else f"disc ({e.x_mm:g}, {e.y_mm:g}) mm r {e.radius_mm:g}"


def _check_reach(table, members, on_sites, population: str) -> None:
    """Refuse a table none of whose fields reaches an afferent of the run or a force site; warn of each such field.

    Such a table could only ever report 0 pulses.  An electrode whose field
    reaches afferents but never sees contact reports 0 pulses and is no error.

    Parameters
    ----------
    table : ElectrodeTable
    members : list of ndarray
        Per electrode, the afferents of the run inside its field (`ElectrodeTable.members`).
    on_sites : array_like of bool
        Per electrode, whether its field takes part of a force site or contact disc.
    population : str
        The run's population, for the message.
    """
    reached = np.array([len(m) > 0 for m in members]) | np.asarray(on_sites, bool)
    lost = [f"{e.id!r} ({_field_text(e)})" for e, ok in zip(table, reached) if not ok]
    shown = ", ".join(lost[:5]) + (f" and {len(lost) - 5} more" if len(lost) > 5 else "")
    if not reached.any():
        raise ValueError(f"no electrode of the table reaches an afferent of population {population!r} or a force "
                         f"site: {shown}; every field lies outside the skin the run covers, so no pulse could start")
    if lost:
        warnings.warn(f"electrode(s) {shown} reach no afferent of population {population!r} and no force site: "
                      "0 pulses there", UserWarning, stacklevel=3)


def stimulation_pulses(dataset, electrodes, rule="biomimetic") -> xr.Dataset:
    """The pulses an electrode table receives from a simulated run, under a named rule.

    Parameters
    ----------
    dataset : xarray.Dataset
        A `simulate` run with spikes and forces recorded.
    electrodes : ElectrodeTable, sequence of Electrode, or path
        The electrodes (CSV or TOML file, `read_electrodes`).
    rule : str or rule object
        ``"biomimetic"``, ``"linear-amplitude"``, ``"linear-frequency"`` or a
        configured `Biomimetic`, `LinearAmplitude`, `LinearFrequency`.

    Returns
    -------
    xarray.Dataset
        Pulses and traces (module docstring); `check_pulses` finds nothing in it.

    Raises
    ------
    ValueError
        If no field of the table reaches an afferent of the run or a force
        site: it could only report 0 pulses.  A field that reaches neither,
        beside others that do, is warned about and reports 0 pulses.

    Examples
    --------
    >>> from ddmm.population import birznieks, make_population, simulate
    >>> from ddmm.population.neurostim import Electrode
    >>> ds = simulate(make_population(["SAI", "RAI"]), birznieks(90.0), engine="direct", seed=0, quiet=True)
    >>> table = [Electrode("E1", 20.0, 80.0, 200.0, 300.0, 20.0, x_mm=0.0, y_mm=0.0, radius_mm=10.0)]
    >>> pulses = stimulation_pulses(ds, table)
    >>> bool(pulses.sizes["pulse"] > 0), check_pulses(pulses)
    (True, [])
    """
    check_dataset(dataset, "dataset")
    table, rule = as_table(electrodes), get_rule(rule)
    if "spike_time" not in dataset:
        raise ValueError("the dataset has no spike events: simulate with the spikes recorded")
    fs, dt = float(dataset.attrs["fs"]), float(dataset.attrs["dt"])
    substeps = int(round(1.0 / (fs * dt)))
    forces, on_sites = _field_forces(dataset, table)
    members = table.members(dataset.x_mm.values, dataset.y_mm.values, dataset.region.values)
    _check_reach(table, members, on_sites, str(dataset.attrs.get("population", "")))
    weights = rule.type_weights(dataset.afferent_type.values)
    n_c, n_t = dataset.sizes["condition"], dataset.sizes["trial"]
    step = np.round(dataset.spike_time.values / dt).astype(np.int64)
    cond, trial, aff = (dataset[v].values for v in ("spike_condition", "spike_trial", "spike_afferent"))
    events, traces = [], np.zeros((3, n_c, n_t, forces.shape[1], len(table)))
    for c in range(n_c):
        for r in range(n_t):
            sel = (cond == c) & (trial == r)
            kernel = PulseKernel(table, rule, fs, members, weights)
            (t, e, a), tr = kernel.advance(forces[c], step[sel] // substeps, aff[sel])
            events.append((np.full(t.size, c), np.full(t.size, r), t, e, a))
            traces[:, c, r] = tr
    return _pulses_dataset(dataset, table, rule, forces, events, traces)


def _pulses_dataset(ds, table, rule, forces, events, traces) -> xr.Dataset:
    cond, trial, time, elec, amp = (np.concatenate(col) for col in zip(*events))
    order = np.lexsort((elec, time, trial, cond))
    width = table.column("phase_width_us")
    data = {
        "pulse_time": xr.Variable("pulse", time[order], {"units": "s"}),
        "pulse_electrode": xr.Variable("pulse", elec[order].astype(np.int32), {"units": "1", "note": "position index"}),
        "pulse_condition": xr.Variable("pulse", cond[order].astype(np.int32), {"units": "1", "note": "position index"}),
        "pulse_trial": xr.Variable("pulse", trial[order].astype(np.int32), {"units": "1", "note": "position index"}),
        "pulse_amplitude": xr.Variable("pulse", amp[order], {"units": "uA"}),
        "pulse_charge": xr.Variable("pulse", amp[order] * width[elec[order]] * 1e-3, {"units": "nC",
                                                                                      "long_name": "charge per phase"}),
        "field_force": xr.Variable(("condition", "time", "electrode"), forces, {"units": "N"}),
    }
    dims = ("condition", "trial", "time", "electrode")
    for i, (name, unit) in enumerate((("rate_command", "Hz"), ("amplitude_command", "uA"), ("aggregate_rate", "Hz"))):
        data[name] = xr.Variable(dims, traces[i], {"units": unit})
    coords = {"condition": ds.condition.variable, "trial": ds.trial.variable,
              "time": xr.Variable("time", np.arange(forces.shape[1]) / float(ds.attrs["fs"]), dict(TIME_ATTRS)),
              **_electrode_coords(table)}
    attrs = {**cf_attrs("ddmm stimulation pulses", str(ds.attrs.get("population", ""))), "rule": rule.name, **{f"rule_{k}": str(v) for k, v in dataclasses.asdict(rule).items()},
             "waveform": WAVEFORM, "contact_threshold": CONTACT_THRESHOLD, "fs": float(ds.attrs["fs"]),
             **{f"run_{k}": ds.attrs[k] for k in ("population", "seed", "engine", "ddmm_version") if k in ds.attrs},
             "layout": "ddmm stimulation pulses"}
    return xr.Dataset(data, coords=coords, attrs=attrs)


def _electrode_coords(table) -> dict:
    coords = {"electrode": xr.Variable("electrode", np.array(table.ids, dtype=object), {"long_name": "electrode id"})}
    for name, unit in (("x_mm", "mm"), ("y_mm", "mm"), ("radius_mm", "mm")):
        coords[name] = xr.Variable("electrode", np.array([np.nan if getattr(e, name) is None else getattr(e, name)
                                                          for e in table], float), {"units": unit})
    coords["region"] = xr.Variable("electrode", np.array([e.region or "" for e in table], dtype=object),
                                   {"long_name": "hand-map region of a region field, empty for a disc"})
    for name, unit in (("amplitude_min_ua", "uA"), ("amplitude_max_ua", "uA"), ("phase_width_us", "us"),
                       ("max_rate_hz", "Hz"), ("charge_limit_nc", "nC"), ("interphase_us", "us")):
        coords[name] = xr.Variable("electrode", table.column(name), {"units": unit})
    return coords


def check_pulses(pulses: xr.Dataset) -> list:
    """Every limit, checked from the file alone: a list of violations (empty when all hold).

    Checks each pulse's amplitude against the electrode's range, its charge
    per phase against the limit, the interval to the electrode's previous
    pulse against ``1 / max_rate_hz`` and the pulse duration, and that the
    force under the field exceeded the contact threshold in the pulse's sample.

    Examples
    --------
    >>> check_pulses(load_pulses("pulses.nc"))  # doctest: +SKIP
    []
    """
    check_dataset(pulses, "pulses")
    problems = []
    e = pulses.pulse_electrode.values
    amp, t = pulses.pulse_amplitude.values, pulses.pulse_time.values
    lo, hi = pulses.amplitude_min_ua.values[e], pulses.amplitude_max_ua.values[e]
    width, charge = pulses.phase_width_us.values[e], pulses.charge_limit_nc.values[e]
    for i in np.flatnonzero((amp < lo) | (amp > hi)):
        problems.append(f"pulse {i}: amplitude {amp[i]:g} uA outside [{lo[i]:g}, {hi[i]:g}]")
    for i in np.flatnonzero(amp * width * 1e-3 > charge * (1 + 1e-12)):
        problems.append(f"pulse {i}: {amp[i] * width[i] * 1e-3:g} nC per phase over the limit {charge[i]:g} nC")
    key = (pulses.pulse_condition.values.astype(np.int64) * pulses.sizes["trial"] + pulses.pulse_trial.values) \
        * pulses.sizes["electrode"] + e
    order = np.lexsort((t, key))
    same = key[order][1:] == key[order][:-1]
    gap = np.diff(t[order])
    floor = np.maximum(1.0 / pulses.max_rate_hz.values, (2 * pulses.phase_width_us.values
                                                         + pulses.interphase_us.values) * 1e-6)[e[order][1:]]
    for i in np.flatnonzero(same & (gap < floor)):
        problems.append(f"pulse {order[i + 1]}: {gap[i] * 1e3:g} ms after the previous one, under {floor[i] * 1e3:g} ms")
    # A pulse within rounding of a sample boundary may be read into either sample: contact in one suffices.
    under = np.max([pulses.field_force.values[pulses.pulse_condition.values, np.clip(np.floor(
        t * float(pulses.attrs["fs"]) + d).astype(np.int64), 0, pulses.sizes["time"] - 1), e] for d in (-1e-9, 1e-9)],
        axis=0)
    for i in np.flatnonzero(under <= float(pulses.attrs["contact_threshold"])):
        problems.append(f"pulse {i}: no contact under the field ({under[i]:g} N)")
    return problems


def save_pulses(pulses: xr.Dataset, path) -> Path:
    """Write a pulses Dataset to netCDF atomically, after `check_pulses` finds nothing.

    Raises
    ------
    ValueError
        For a violation (none is written) or a directory that cannot be written.
    """
    problems = check_pulses(pulses)
    if problems:
        raise ValueError(f"refusing to write pulses that break their limits: {problems[0]} "
                         f"({len(problems)} problem(s))")
    return write_netcdf(pulses, path)


def load_pulses(path) -> xr.Dataset:
    """Read a pulses file written by `save_pulses`."""
    ds = read_netcdf(path, "pulses file")
    if ds.attrs.get("layout") != "ddmm stimulation pulses":
        raise ValueError(f"{str(path)!r} is not a ddmm pulses file (no 'layout' attribute of one)")
    return ds
