"""Export a simulation Dataset to an NWB file (Neurodata Without Borders, via pynwb; ``pip install "ddmm[nwb]"``).

Layout (core NWB types only, no extension):

* **Session clock.** Every (condition, trial) of the Dataset is one row of
  the ``trials`` table, laid out one after the other, condition-major
  (condition 0's trials 0, 1, ..., then condition 1's): trial k starts at
  ``start_time = N_k / fs`` where ``N_k`` is the number of force samples
  of the trials before it (a condition lasts ``duration * fs`` samples), and
  stops where the next one starts.  A spike ``t`` s into its trial is stored
  at ``start_time + t``; subtracting ``start_time`` again gives back ``t`` to
  within half a float64 ulp of the session time (about 1e-13 s for an hour).
* **Units** (``nwbfile.units``): one row per afferent, ``id`` = the stable
  afferent id; ``spike_times`` over all trials on the session clock;
  ``resolution`` = the integration step dt (s).  Columns ``afferent_id``,
  ``afferent_type``, ``theta_t`` (deg), ``nap``, ``k``, ``gain``, ``x_mm`` and
  ``y_mm`` (mm), ``region``, ``frame_deg`` (deg), ``noise_sigma``
  (mV/sqrt(ms)) and ``noise_cv`` (sqrt(ms)); each description names its unit.
* **Trials** (``nwbfile.trials``): ``start_time``, ``stop_time`` (s),
  ``condition`` (scene name), ``condition_index`` (position on the Dataset's
  ``condition``), ``trial`` (trial index within the condition), ``theta_r``
  (deg; 0 when the scene has no nominal shear direction), ``has_theta_r`` and
  ``stages`` (the stage labels with their times in s from the trial's start, as text).
* **Stages** (``nwbfile.intervals["stages"]``, a TimeIntervals table): one row
  per stage a trial's scene has, ``start_time``/``stop_time`` on the session
  clock, ``stage`` (label, e.g. ``stage2_dynamic``) and ``trial`` (a region of
  the trials table).
* **Stimulus**, when the Dataset recorded the forces:
  ``stimulus["fingertip_force"]``, a TimeSeries (n, 3) of fx, fy, fz in N at
  ``rate = fs`` from 0 s, each trial's condition force at its trial's place
  on the session clock; multi-site scenes add ``stimulus["site_force"]``
  (n, n_sites, 3), whose description lists the sites in order.
* **Metadata.** ``notes`` is the JSON of the Dataset's attrs (every model
  constant, engine, dt, method, seed, ddmm version); ``data_collection`` says
  in words how it was simulated; ``was_generated_by`` names ddmm and pynwb
  with their versions.  The ``subject`` says it is a simulated population of
  human afferents, not a recorded one.
"""

from __future__ import annotations

import datetime as _dt
import os
import uuid
from pathlib import Path

import numpy as np

from ddmm.population._extras import require
from ddmm.population.io import _export as ex
from ddmm.population.io._files import atomic_write, writable_parent

__all__ = ["to_nwb"]


def to_nwb(dataset, path, *, session_description: str | None = None, identifier: str | None = None,
           session_start_time: _dt.datetime | None = None) -> Path:
    """Write a simulation Dataset to an NWB file, atomically (layout in the module docstring).

    Parameters
    ----------
    dataset : xarray.Dataset
        A Dataset of `ddmm.population.simulate` or `load_dataset` with spike events.
    path : str or os.PathLike
        The ``.nwb`` file to write.  An existing file is replaced atomically:
        a failed export leaves it as it was, and no partial file.
    session_description : str, optional
        Default: the population, afferent, condition and trial counts.
    identifier : str, optional
        The file's unique identifier.  Default: a random UUID.
    session_start_time : datetime.datetime, optional
        Timezone-aware origin of the session clock.  Default: now (UTC).

    Returns
    -------
    pathlib.Path
        ``path``.

    Raises
    ------
    TypeError, ValueError
        On a bad argument (the message names it); ImportError without pynwb.

    Examples
    --------
    >>> import pathlib, tempfile
    >>> from ddmm.population import birznieks, sample_population, simulate, to_nwb
    >>> pop = sample_population("fingertip", rng=0).select(range(20))
    >>> ds = simulate(pop, birznieks(90.0), engine="direct", trials=2, quiet=True)
    >>> with tempfile.TemporaryDirectory() as tmp:
    ...     print(to_nwb(ds, pathlib.Path(tmp) / "run.nwb").name)
    run.nwb
    """
    path = _check_path(path)
    ex.check_dataset(dataset, "to_nwb")
    _check_text("session_description", session_description)
    _check_text("identifier", identifier)
    if session_start_time is not None and not (isinstance(session_start_time, _dt.datetime)
                                               and session_start_time.tzinfo is not None):
        raise TypeError(f"to_nwb: session_start_time must be a timezone-aware datetime.datetime or None, "
                        f"got {session_start_time!r}")
    pynwb = require("pynwb", "to_nwb", "nwb")
    nwbfile = _nwbfile(dataset, pynwb, session_description, identifier, session_start_time)
    starts, stops = _session_clock(dataset)
    _add_trials(nwbfile, dataset, starts, stops)
    _add_stages(nwbfile, dataset, starts)
    nwbfile.units = _units(dataset, starts)
    _add_forces(nwbfile, dataset, pynwb)

    def write(tmp):
        with pynwb.NWBHDF5IO(tmp, "w") as io:
            io.write(nwbfile)
    return atomic_write(path, write, suffix=".part.nwb")  # pynwb warns on a name not ending in .nwb


def _check_path(path) -> Path:
    if not isinstance(path, (str, os.PathLike)):
        raise TypeError(f"to_nwb: path must be a str or os.PathLike ending in .nwb, got {type(path).__name__}")
    path = Path(path)
    if path.suffix != ".nwb":
        raise ValueError(f"to_nwb: path must end in .nwb, got {str(path)!r}")
    directory, writable = writable_parent(path)
    if not writable:
        raise ValueError(f"to_nwb: cannot write path {str(path)!r}: {str(directory)!r} is not a writable directory")
    if path.is_dir():
        raise ValueError(f"to_nwb: path {str(path)!r} is a directory; allowed: a .nwb file name")
    return path


def _check_text(name: str, value) -> None:
    if value is not None and not isinstance(value, str):
        raise TypeError(f"to_nwb: {name} must be a str or None, got {type(value).__name__} {value!r}")
    if value is not None and not value.strip():
        raise ValueError(f"to_nwb: {name} must not be empty, got {value!r}")


def _nwbfile(ds, pynwb, description, identifier, start_time):
    """The NWBFile with its metadata (no data yet)."""
    from pynwb.file import Subject

    attrs = ds.attrs
    counts = f"{ds.sizes['afferent']} afferents, {ds.sizes['condition']} condition(s) x {ds.sizes['trial']} trial(s)"
    how = (f"Simulated, not recorded: ddmm {attrs.get('ddmm_version')}, engine {attrs.get('engine')}, method "
           f"{attrs.get('method')}, dt {attrs.get('dt')} s, seed {attrs.get('seed')}, no-shear reading "
           f"{attrs.get('no_shear')}. Every model constant is in notes (JSON of the Dataset attrs).")
    subject = Subject(subject_id=f"ddmm-{attrs.get('population', 'population')}", species="Homo sapiens", sex="U",
                      age="P18Y/", description="No real subject: a simulated population of tactile afferents "
                                               "modelled on recordings from adult humans (age: adult, 18 y or over).")
    return pynwb.NWBFile(
        session_description=description or f"ddmm simulation of population {attrs.get('population')!r}: {counts}",
        identifier=identifier or str(uuid.uuid4()),
        session_start_time=start_time or _dt.datetime.now(_dt.timezone.utc),
        experiment_description="Population coding of fingertip forces by tactile afferents, simulated with the "
                               "Direction-Dependent Mechanotransduction Model (DDMM).",
        keywords=["simulation", "tactile afferents", "mechanotransduction", "DDMM"],
        notes=ex.attrs_json(ds), data_collection=how, subject=subject,
        stimulus_notes="Three-axis force on the fingertip in N (+X radial, +Y distal, +Z into the skin), one "
                       "scene per condition: " + ", ".join(map(str, ds["condition"].values)),
        source_script=f"ddmm.population.io.nwb.to_nwb of ddmm {attrs.get('ddmm_version')}",
        source_script_file_name="population/nwb.py",
        was_generated_by=[["ddmm", str(attrs.get("ddmm_version"))], ["pynwb", pynwb.__version__]],
    )


def _session_clock(ds):
    """Start and stop (s) of every trial k on the session clock (module docstring)."""
    cond, _ = ex.trial_grid(ds)
    edges = np.concatenate([[0], np.cumsum([ex.n_samples(ds, c) for c in cond])]) / float(ds.attrs["fs"])
    return edges[:-1], edges[1:]


def _add_trials(nwbfile, ds, starts, stops) -> None:
    cond, trial = ex.trial_grid(ds)
    for name, description in (("condition", "scene name of the condition (unitless label)"),
                              ("condition_index", "position of the condition in the ddmm Dataset (integer)"),
                              ("trial", "trial index within the condition (integer)"),
                              ("theta_r", "nominal shear direction theta_R of the scene in degrees; 0 when "
                                          "has_theta_r is False"),
                              ("has_theta_r", "True when the scene has one nominal shear direction (boolean)"),
                              ("stages", "the scene's stages as 'label start-stop' in s from the trial's start, "
                                         "separated by '; ' (the same as intervals['stages'])")):
        nwbfile.add_trial_column(name=name, description=description)
    names, theta, has = (ds[n].values for n in ("condition", "theta_r", "has_theta_r"))
    for k, (c, t) in enumerate(zip(cond, trial)):
        stages = "; ".join(f"{label} {a:g}-{b:g}" for label, a, b in ex.stages_of(ds, c))
        nwbfile.add_trial(start_time=float(starts[k]), stop_time=float(stops[k]), condition=str(names[c]),
                          condition_index=int(c), trial=int(t), theta_r=float(theta[c]), has_theta_r=bool(has[c]),
                          stages=stages)


def _add_stages(nwbfile, ds, starts) -> None:
    """The ``stages`` TimeIntervals table, when the scenes have stages."""
    from pynwb.epoch import TimeIntervals

    cond, _ = ex.trial_grid(ds)
    rows = [(k, label, a, b) for k, c in enumerate(cond) for label, a, b in ex.stages_of(ds, c)]
    if not rows:
        return
    table = TimeIntervals(name="stages", description="Stages (phases) of each trial's scene; start_time and "
                                                     "stop_time in s on the session clock")
    table.add_column(name="stage", description="stage label, e.g. stage2_dynamic (unitless)")
    table.add_column(name="trial", description="the trial (row of the trials table)", table=nwbfile.trials)
    for k, label, a, b in rows:
        table.add_row(start_time=float(starts[k] + a), stop_time=float(starts[k] + b), stage=label, trial=int(k))
    nwbfile.add_time_intervals(table)


def _units(ds, starts):
    """The Units table: one row per afferent, its spike times over all trials on the session clock."""
    from hdmf.common import VectorData, VectorIndex
    from pynwb.misc import Units

    time, k, aff = ex.spike_order(ds, "afferent")
    spike_times = VectorData(name="spike_times", description="spike times in s on the session clock",
                             data=starts[k] + time)
    index = VectorIndex(name="spike_times_index", target=spike_times,
                        data=np.cumsum(np.bincount(aff, minlength=ds.sizes["afferent"])))
    values = ex.afferent_values(ds)
    columns = [spike_times, index,
               VectorData(name="afferent_id", description="stable afferent id (integer; equals the unit id)",
                          data=values["afferent_id"])]
    columns += [VectorData(name=name, description=f"{text} [{unit}]", data=values[name])
                for name, unit, text in ex.AFFERENT_FIELDS]
    return Units(name="units", id=values["afferent_id"], columns=columns, resolution=float(ds.attrs["dt"]),
                 description="One unit per simulated afferent; spike_times on the session clock: a spike t s into "
                             "trial k is at trials.start_time[k] + t")


def _add_forces(nwbfile, ds, pynwb) -> None:
    """``fingertip_force`` (and ``site_force`` for multi-site scenes) as stimulus TimeSeries in N."""
    from hdmf.backends.hdf5 import H5DataIO

    if "fx" not in ds:
        return
    cond, _ = ex.trial_grid(ds)
    per_condition = [ex.condition_forces(ds, c) for c in range(ds.sizes["condition"])]
    series = {"fingertip_force": ("Force applied to the fingertip in N; columns fx, fy, fz (+X radial, +Y "
                                  "distal, +Z into the skin), the summed force of all sites; each trial's "
                                  "condition force at its place on the session clock (trials table)", 0)}
    if per_condition[0][1] is not None:
        sites = "; ".join(f"{s} (x {x:g} mm, y {y:g} mm, radius {r:g} mm, region {g!r})" for s, x, y, r, g in zip(
            *(ds[n].values for n in ("site", "site_x_mm", "site_y_mm", "site_radius_mm", "site_region"))))
        series["site_force"] = (f"Force at each contact site in N, shape (time, site, axis) with axes fx, fy, "
                                f"fz; sites in order: {sites}", 1)
    for name, (description, which) in series.items():
        data = np.concatenate([per_condition[c][which] for c in cond])
        nwbfile.add_stimulus(pynwb.TimeSeries(
            name=name, data=H5DataIO(data, compression="gzip"), unit="N", rate=float(ds.attrs["fs"]),
            starting_time=0.0, description=description, continuity="continuous"))
