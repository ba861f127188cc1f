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
  ``afferent_type``, ``theta_t`` (deg), ``nap``, ``k``, ``gain``, ``sensitivity``, ``x_mm`` and
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
* **Stimulation pulses**, when ``pulses`` is given (a pulses Dataset of
  `ddmm.population.neurostim.stimulation_pulses` for the same run):
  ``nwbfile.intervals["stimulation_pulses"]``, a TimeIntervals table with one
  row per pulse in the Dataset's order, ``start_time`` = the start of the
  cathodic phase on the session clock (``trials.start_time[k] + pulse_time``,
  as for spikes), ``stop_time`` = ``start_time + (2 phase_width_us +
  interphase_us) * 1e-6`` (the whole biphasic pulse), and columns
  ``electrode`` (id), ``amplitude_ua`` (µA), ``phase_width_us`` and
  ``interphase_us`` (µs), ``charge_nc`` (nC per phase), ``condition`` (scene
  name, as in the trials table) and ``trial`` (trial index within the
  condition, as in the trials table).  Its description names the waveform,
  the rule and the rule's settings.  The electrode table is
  ``nwbfile.processing["stimulation"]["stimulation_electrodes"]``, a
  DynamicTable with one row per electrode: ``electrode`` (id), the projected
  field ``x_mm``, ``y_mm``, ``radius_mm`` (mm; NaN for a region field) and
  ``region`` (empty for a disc), and the limits ``amplitude_min_ua``,
  ``amplitude_max_ua`` (µA), ``phase_width_us``, ``interphase_us`` (µs),
  ``max_rate_hz`` (Hz) and ``charge_limit_nc`` (nC per phase).  A run without
  pulses writes the electrode table and no pulse table (NWB best practice:
  no empty tables).
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

from ddmm.population.io import _export as ex
from ddmm.utils.extras import require
from ddmm.utils.files import atomic_write, writable_parent

__all__ = ["to_nwb", "PAPER_DOI", "REFERENCE_START"]


#: The default of ``related_publications``: the DOI the DDMM paper gives for its data (the paper's own DOI
#: is not printed in the copy of its text the package was built from).
PAPER_DOI = "doi:10.5258/SOTON/D3758"
#: The session start of a Dataset without a ``date_created`` attribute: a fixed date, so that exports agree.
REFERENCE_START = _dt.datetime(2000, 1, 1, tzinfo=_dt.timezone.utc)


def to_nwb(dataset, path, *, session_description: str | None = None, identifier: str | None = None,
           session_start_time: _dt.datetime | None = None, pulses=None, experimenter=None,
           institution: str | None = None, related_publications=(PAPER_DOI,)) -> Path:
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
        The file's unique identifier.  Default: a UUID derived from the
        Dataset's content (spikes, afferents, conditions, attrs) and the
        pulses', so two exports of one Dataset carry the same identifier.
    session_start_time : datetime.datetime, optional
        Timezone-aware origin of the session clock.  Default: a
        ``date_created`` attribute of the Dataset when a user set one, else
        `REFERENCE_START` (2000-01-01 UTC: a simulation has no wall-clock
        start, and the Dataset carries no time stamp so that equal runs are
        identical); never "now", so exports agree.
    experimenter : str or sequence of str, optional
        Who ran the simulation, as "Last, First" (NWB best practice).
    institution : str, optional
        Where.
    related_publications : sequence of str
        DOIs or URLs (``"doi:..."``); default the DDMM paper's data DOI
        (`PAPER_DOI`); ``()`` for none.
    pulses : xarray.Dataset, optional
        Stimulation pulses of this run (`ddmm.population.neurostim.stimulation_pulses`
        or `load_pulses`), written as ``intervals["stimulation_pulses"]`` with the
        electrode table (module docstring).  Its conditions, trial count and
        sample rate must be the dataset's.

    Returns
    -------
    pathlib.Path
        ``path``.

    Raises
    ------
    TypeError, ValueError
        On a bad argument (the message names it), e.g. ``pulses`` of another
        run; ImportError without pynwb.

    Examples
    --------
    >>> import pathlib, tempfile
    >>> from ddmm.population import birznieks, sample_population, simulate, to_nwb
    >>> pop = sample_population("fingertip", rng=0).select(range(20))
    >>> ds = simulate(pop, birznieks(90.0), engine="direct", trials=2, quiet=True)
    >>> with tempfile.TemporaryDirectory() as tmp:
    ...     print(to_nwb(ds, pathlib.Path(tmp) / "run.nwb").name)
    run.nwb

    With the stimulation pulses of the same run:

    >>> from ddmm.population.neurostim import Electrode, stimulation_pulses
    >>> table = [Electrode("E1", 20.0, 80.0, 200.0, 300.0, 20.0, x_mm=0.0, y_mm=0.0, radius_mm=10.0)]
    >>> pulses = stimulation_pulses(ds, table)
    >>> with tempfile.TemporaryDirectory() as tmp:
    ...     print(to_nwb(ds, pathlib.Path(tmp) / "run.nwb", pulses=pulses).name)
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
    _check_pulses(dataset, pulses)
    archive = _archive_fields(experimenter, institution, related_publications)
    pynwb = require("pynwb", "to_nwb", "nwb")
    nwbfile = _nwbfile(dataset, pynwb, session_description, identifier or _identifier(dataset, pulses),
                       session_start_time or _start_time(dataset), archive)
    starts, stops = _session_clock(dataset)
    _add_trials(nwbfile, dataset, starts, stops)
    _add_stages(nwbfile, dataset, starts)
    nwbfile.units = _units(dataset, starts)
    _add_forces(nwbfile, dataset, pynwb)
    if pulses is not None:
        _add_stimulation(nwbfile, dataset, pulses, starts)

    _derive_object_ids(nwbfile)

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


def _archive_fields(experimenter, institution, related_publications) -> dict:
    """The optional archive metadata, checked: experimenter (tuple of str), institution, related_publications."""
    people = (experimenter,) if isinstance(experimenter, str) else tuple(experimenter or ())
    pubs = (related_publications,) if isinstance(related_publications, str) else tuple(related_publications or ())
    for name, values in (("experimenter", people), ("related_publications", pubs)):
        for value in values:
            _check_text(name, value)
    _check_text("institution", institution)
    fields = {"experimenter": list(people) or None, "institution": institution,
              "related_publications": list(pubs) or None}
    return {k: v for k, v in fields.items() if v is not None}


def _identifier(ds, pulses) -> str:
    """A UUID of the Dataset's content (and the pulses'): the same Dataset, the same identifier."""
    import hashlib

    digest = hashlib.sha256()
    for var in ("spike_time", "spike_afferent", "spike_trial", "spike_condition", "afferent"):
        digest.update(np.ascontiguousarray(ds[var].values).tobytes())
    digest.update("|".join(map(str, ds["condition"].values)).encode())
    digest.update(ex.attrs_json(ds).encode())
    if pulses is not None:
        for var in ("pulse_time", "pulse_electrode", "pulse_amplitude"):
            digest.update(np.ascontiguousarray(pulses[var].values).tobytes())
    return str(uuid.uuid5(uuid.NAMESPACE_URL, "ddmm:" + digest.hexdigest()))


def _derive_object_ids(nwbfile) -> None:
    """Object ids from the file's identifier and each object's place, not random: the same content twice.

    hdmf draws a random UUID per object and offers no way to set one after
    construction, so its private slot is written (only when it exists).
    """
    namespace = uuid.uuid5(uuid.NAMESPACE_URL, "ddmm-nwb:" + nwbfile.identifier)
    for i, obj in enumerate(nwbfile.all_children()):
        if hasattr(obj, "_AbstractContainer__object_id"):
            obj._AbstractContainer__object_id = str(uuid.uuid5(namespace, f"{i}:{type(obj).__name__}:{obj.name}"))


def _start_time(ds) -> _dt.datetime:
    """A Dataset's ``date_created`` attribute (UTC) when it has one, else `REFERENCE_START`."""
    try:
        start = _dt.datetime.fromisoformat(str(ds.attrs["date_created"]))
    except (KeyError, ValueError):
        return REFERENCE_START
    return start if start.tzinfo is not None else start.replace(tzinfo=_dt.timezone.utc)


def _nwbfile(ds, pynwb, description, identifier, start_time, archive):
    """The NWBFile with its metadata (no data yet)."""
    from pynwb.file import Subject

    attrs = ds.attrs
    counts = f"{ds.sizes['afferent']} afferents, {ds.sizes['condition']} condition(s) x {ds.sizes['trial']} trial(s)"
    how = (f"Simulated, not recorded: ddmm {attrs.get('ddmm_version')}, engine {attrs.get('engine')}, method "
           f"{attrs.get('method')}, dt {attrs.get('dt')} s, seed {attrs.get('seed')}, no-shear reading "
           f"{attrs.get('no_shear')}. Every model constant is in notes (JSON of the Dataset attrs).")
    subject = Subject(subject_id=f"ddmm-{attrs.get('population', 'population')}-seed{attrs.get('seed')}",
                      species="Homo sapiens", sex="U",
                      age="P18Y/", description="No real subject: a simulated population of tactile afferents "
                                               "modelled on recordings from adult humans (age: adult, 18 y or over).")
    return pynwb.NWBFile(
        session_description=description or f"ddmm simulation of population {attrs.get('population')!r}: {counts}",
        identifier=identifier, session_start_time=start_time, **archive,
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


def _check_pulses(ds, pulses) -> None:
    """Raise TypeError / ValueError unless ``pulses`` is None or a pulses Dataset of ``ds``'s run."""
    import xarray as xr

    if pulses is None:
        return
    if not isinstance(pulses, xr.Dataset) or pulses.attrs.get("layout") != "ddmm stimulation pulses":
        raise TypeError(f"to_nwb: pulses must be a pulses Dataset (ddmm.population.neurostim.stimulation_pulses "
                        f"or load_pulses) or None, got {type(pulses).__name__}")
    ours, theirs = [str(v) for v in ds["condition"].values], [str(v) for v in pulses["condition"].values]
    if theirs != ours:
        raise ValueError(f"to_nwb: pulses are of conditions {theirs}, the dataset's are {ours}; allowed: the "
                         "pulses of this dataset's run")
    if pulses.sizes["trial"] != ds.sizes["trial"]:
        raise ValueError(f"to_nwb: pulses have {pulses.sizes['trial']} trial(s) per condition, the dataset "
                         f"{ds.sizes['trial']}; allowed: the pulses of this dataset's run")
    if float(pulses.attrs.get("fs", np.nan)) != float(ds.attrs["fs"]):
        raise ValueError(f"to_nwb: pulses were made at fs {pulses.attrs.get('fs')} Hz, the dataset has "
                         f"{ds.attrs['fs']} Hz; allowed: the pulses of this dataset's run")
    for key in ("seed", "population"):
        if f"run_{key}" in pulses.attrs and key in ds.attrs and str(pulses.attrs[f"run_{key}"]) != str(ds.attrs[key]):
            raise ValueError(f"to_nwb: pulses come from a run with {key} {pulses.attrs[f'run_{key}']!r}, the "
                             f"dataset has {ds.attrs[key]!r}; allowed: the pulses of this dataset's run")


def _add_stimulation(nwbfile, ds, pulses, starts) -> None:
    """``intervals["stimulation_pulses"]`` and ``processing["stimulation"]["stimulation_electrodes"]``."""
    module = nwbfile.create_processing_module(
        name="stimulation", description="Stimulation computed from the simulated afferents for a nerve interface "
                                        "(ddmm.population.neurostim): the electrode table; the pulses are "
                                        "intervals['stimulation_pulses']")
    module.add(_electrode_table(pulses))
    if pulses.sizes["pulse"]:
        nwbfile.add_time_intervals(_pulse_table(ds, pulses, starts))


def _electrode_table(pulses):
    """One row per electrode: its id, projected field and pulse limits, each description naming its unit."""
    from hdmf.common import DynamicTable, VectorData

    fields = (("electrode", "electrode id (unitless label; the electrode column of intervals['stimulation_pulses'])"),
              ("x_mm", "centre x of the disc field in mm (+X radial); NaN for a region field"),
              ("y_mm", "centre y of the disc field in mm (+Y distal); NaN for a region field"),
              ("radius_mm", "radius of the disc field in mm; NaN for a region field"),
              ("region", "hand-map region (or prefix) of a region field; empty for a disc (unitless label)"),
              ("amplitude_min_ua", "amplitude of the weakest pulse in µA"),
              ("amplitude_max_ua", "amplitude of the strongest pulse in µA"),
              ("phase_width_us", "width of each phase in µs"),
              ("interphase_us", "gap between the two phases in µs"),
              ("max_rate_hz", "pulse rate limit in Hz (pulses at least 1 / max_rate_hz s apart)"),
              ("charge_limit_nc", "charge-per-phase limit in nC (amplitude x phase width)"))
    columns = [VectorData(name=name, description=text, data=[str(v) for v in pulses[name].values]
                          if name in ("electrode", "region") else pulses[name].values.astype(float))
               for name, text in fields]
    return DynamicTable(name="stimulation_electrodes", columns=columns, id=list(range(pulses.sizes["electrode"])),
                        description="Electrodes of the nerve interface: projected field (a disc in the "
                                    "population's frame or a hand-map region) and pulse limits, one row each")


def _pulse_table(ds, pulses, starts):
    """The ``stimulation_pulses`` TimeIntervals: one row per pulse on the session clock (module docstring)."""
    from hdmf.common import VectorData
    from pynwb.epoch import TimeIntervals

    e, c = pulses.pulse_electrode.values, pulses.pulse_condition.values.astype(np.int64)
    start = starts[c * ds.sizes["trial"] + pulses.pulse_trial.values] + pulses.pulse_time.values.astype(np.float64)
    width, gap = pulses.phase_width_us.values[e], pulses.interphase_us.values[e]
    data = {"start_time": ("start of the cathodic phase in s on the session clock", start),
            "stop_time": ("end of the anodic phase in s on the session clock", start + (2 * width + gap) * 1e-6),
            "electrode": ("electrode id (processing['stimulation']['stimulation_electrodes'])",
                          [str(v) for v in pulses.electrode.values[e]]),
            "amplitude_ua": ("amplitude of both phases in µA", pulses.pulse_amplitude.values.astype(float)),
            "phase_width_us": ("width of each phase in µs", width.astype(float)),
            "interphase_us": ("gap between the phases in µs", gap.astype(float)),
            "charge_nc": ("charge per phase in nC", pulses.pulse_charge.values.astype(float)),
            "condition": ("scene name of the condition (as trials.condition)",
                          [str(v) for v in ds["condition"].values[c]]),
            "trial": ("trial index within the condition (as trials.trial; integer)",
                      pulses.pulse_trial.values.astype(np.int64))}
    settings = ", ".join(f"{k[5:]} {v}" for k, v in pulses.attrs.items() if k.startswith("rule_"))
    return TimeIntervals(
        name="stimulation_pulses", id=list(range(pulses.sizes["pulse"])),
        columns=[VectorData(name=name, description=text, data=values) for name, (text, values) in data.items()],
        description=f"Stimulation pulses, one row per pulse, times in s on the session clock. Waveform: "
                    f"{pulses.attrs.get('waveform')}. Rule {pulses.attrs.get('rule')} ({settings}).")
