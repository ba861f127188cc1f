"""Recorded sessions in: a force stream of an XDF file (LabRecorder's), read as the live LSL bridge reads it.

A lab records its LSL streams with LabRecorder into one XDF file
(https://github.com/sccn/xdf/wiki/Specifications).  `read_xdf` takes one
force stream of it back, as ``ddmm stream --lsl-in`` takes the live one
(`ddmm.population.runtime.lsl_bridge`), so the spikes equal the live
bridge's for the same samples and stamps:

* the **raw stamps**, the sender's own: pyxdf's clock synchronisation and
  dejitter are off (the file's ``ClockOffset`` measurements are kept beside
  them, in `XdfRecording.clock_offsets`);
* the stream's **description** (channel count, numeric format, rate, the
  declared unit, the axis labels of ``desc/channels``) goes through
  `ddmm.population.runtime.lsl.read_force_info`, the live path's reading;
  ``sites`` name the sites of its channels, as ``--sites`` does live;
* the **stamps** go through `ddmm.population.runtime.lsl_bridge.take_stamps`,
  the bridge's rule: a sample stamped at or before the one before it is
  dropped; a gap (an interval over 1.5 / fs) is reported, the samples taken
  as consecutive and the spike times moved on by the gap's excess;
* a sample the streaming `Encoder` would refuse (a non-finite value, a
  normal force below the conditioning's noise allowance, a force beyond
  ``max_force_n``) is skipped, as the bridge skips it, and counted as a
  one-sample gap.

What was dropped, skipped or moved is warned once (`XdfStampWarning`) and
kept in `XdfRecording.summary`; `XdfRecording.input_clock` puts a run's
spike times back on the recording's clock, where the live bridge stamps
them.  Needs the optional extra ``ddmm[xdf]`` (pyxdf).  `save_xdf`
(`ddmm.population.io.xdf_writer`) writes a force stream as LabRecorder
would record it (for tests, demos and replays).
"""

from __future__ import annotations

import itertools
import math
import warnings
from dataclasses import dataclass

import numpy as np

from ddmm.population.io._xdf_file import _load, _XdfInfo
from ddmm.population.io.xdf_writer import _write_xdf, save_xdf  # noqa: F401 - save_xdf kept here one release
from ddmm.population.runtime.lsl import ForceStream, read_force_info
from ddmm.population.runtime.lsl_bridge import BridgeSummary, take_stamps
from ddmm.population.stimuli.conditioning import Conditioner, Conditioning, condition_forces, noise_allowance
from ddmm.population.stimuli.recordings import MAX_FORCE_N, RECORDED, UNITS, warn_band
from ddmm.population.stimuli.scenes import DEFAULT_FS, MAX_FS, Contact, Scene, Sites
from ddmm.utils.resources import check_memory
from ddmm.utils.validation import as_float_array, check_instance, check_path, check_positive, shown

__all__ = ["XdfRecording", "XdfStampWarning", "from_xdf", "read_xdf"]


class XdfStampWarning(UserWarning):
    """An XDF stream's samples were dropped, skipped or moved by the live bridge's rules."""


def _refused(forces, allowance: float, max_force_n: float) -> list:
    """(position, reason) of each sample the streaming `Encoder` refuses: its rules on one sample at a time."""
    finite = np.isfinite(forces).all(axis=(1, 2))
    clean = np.where(np.isfinite(forces), forces, 0.0)
    magnitude = np.sqrt(np.einsum("nsi,nsi->ns", clean, clean)).max(axis=1)  # per site, as check_force_bound
    low = clean[:, :, 2].min(axis=1)
    out = []
    for k in np.flatnonzero(~finite | (magnitude > max_force_n) | (low < -allowance)):
        if not finite[k]:
            out.append((int(k), "a non-finite value"))
        elif magnitude[k] > max_force_n:
            out.append((int(k), f"a force of {magnitude[k]:.6g} N, beyond max_force_n = {max_force_n:g} N"))
        else:
            out.append((int(k), f"the normal force {low[k]:g} N, below {-allowance:g} N"))
    return out


def _model_bounds(forces, counts_at, fs_in: float, fs_out: float, conditioning, n_sites):
    """The forces on the model's grid, and the model sample at which each input position of ``counts_at`` starts.

    A causal conditioning is pushed run by run (what a stream gives, chunking aside), so the model sample
    where each run starts is counted; zero-phase is offline, on the input's time base; None keeps the grid.
    """
    if conditioning is None:
        return forces, np.asarray(counts_at, dtype=np.int64)
    if conditioning.mode != "causal":
        out, _ = condition_forces(forces, fs_in, fs_out, conditioning)
        return out, np.array([math.ceil(k * fs_out / fs_in - 1e-9) for k in counts_at], dtype=np.int64)
    conditioner = Conditioner(conditioning, fs_in, fs_out, n_sites)
    edges = sorted({0, *(int(k) for k in counts_at), forces.shape[0]})
    parts, starts = [], {}
    done = 0
    for a, b in itertools.pairwise(edges):
        starts[a] = done
        out, _ = conditioner.push(forces[a:b])
        parts.append(out)
        done += out.shape[0]
    starts[forces.shape[0]] = done
    return np.concatenate(parts), np.array([starts[int(k)] for k in counts_at], dtype=np.int64)


@dataclass(frozen=True)
class XdfRecording:
    """A force stream read back from an XDF file (`read_xdf`).

    Attributes
    ----------
    scene : Scene
        The samples taken, conditioned and on the model's grid: what
        `ddmm.population.simulate` runs (`from_xdf` returns it).
    stream : ForceStream
        The stream as the live path describes it (name, source id, host,
        rate, sites, unit, sign), without an inlet; its ``clock_offset_s`` is
        0: the stamps are the sender's.
    summary : BridgeSummary
        Samples taken, gaps (the stamp before each, its length), out-of-order
        and skipped samples, as the live bridge counts them.
    reports : tuple of str
        One line for each gap, dropped or skipped sample, in order.
    first_stamp : float
        The first sample's stamp in s (the sender's clock): model time 0.
    shifts : ndarray, shape (k, 2)
        (model sample, s): from each such sample on, the spike times on the
        recording's clock move on by so many seconds (a gap's excess, a
        skipped sample's period).
    clock_offsets : ndarray, shape (m, 2)
        The file's clock-offset measurements, (time on the stream's clock,
        offset to the recorder's clock) in s, as LabRecorder measured them.
    """

    scene: Scene
    stream: ForceStream
    summary: BridgeSummary
    reports: tuple
    first_stamp: float
    shifts: np.ndarray
    clock_offsets: np.ndarray

    def input_clock(self, times) -> np.ndarray:
        """Model times (a run's ``spike_time``, s) on the recording's clock, as the live bridge stamps them.

        The first sample's stamp plus the model time, moved on by each gap
        and skipped sample before it: ``ddmm stream``'s ``t``, and the live
        spike stream's stamps less its clock offset.

        Examples
        --------
        >>> import pathlib, tempfile
        >>> stamps = 50.0 + np.arange(1000) / 1000.0
        >>> stamps[500:] += 0.25  # a quarter of a second lost in transmission
        >>> path = save_xdf(pathlib.Path(tempfile.mkdtemp()) / "s.xdf", np.tile([0.0, 0.0, 1.0], (1000, 1)),
        ...                 stamps, name="glove", fs=1000.0)
        >>> import warnings
        >>> with warnings.catch_warnings():
        ...     warnings.simplefilter("ignore")
        ...     recording = read_xdf(path, "glove")
        >>> recording.input_clock([0.1, 0.6]).round(6).tolist()
        [50.1, 50.85]
        """
        times = as_float_array(times, "times")
        steps = np.floor(times * self.scene.fs + 1e-9)
        moved = np.zeros(times.shape)
        for start, shift in self.shifts:
            moved += np.where(steps >= start, shift, 0.0)
        return self.first_stamp + times + moved


def _check_options(stream, sites, fs, recorded_fs, units, fz_sign, conditioning, contact, max_force_n):
    if stream is not None and not isinstance(stream, str):
        raise TypeError(f"stream must be a str (the stream's name) or None, got {type(stream).__name__}")
    if sites is not None:
        check_instance(sites, "sites", Sites, "a Sites or None")
        if contact is not None:
            raise ValueError("contact does not apply with sites: each site has its own footprint")
    if contact is not None:
        check_instance(contact, "contact", Contact, "a Contact or None")
    if fs is not None:
        check_positive(fs, "fs", "Hz")
        if conditioning is None:
            raise ValueError("fs (the model's rate) goes with a conditioning: without one the scene is at the "
                             "stream's rate, as a live encoder's")
    if recorded_fs is not None:
        check_positive(recorded_fs, "recorded_fs", "Hz")
    if units is not None and units not in UNITS:
        raise ValueError(f"units={units!r} is not allowed; allowed: {', '.join(UNITS)}")
    if isinstance(fz_sign, bool) or fz_sign not in (1, -1):
        raise ValueError(f"fz_sign must be 1 or -1, got {shown(fz_sign)}")
    if conditioning is not None:
        check_instance(conditioning, "conditioning", Conditioning, "a Conditioning or None")
    return check_positive(max_force_n, "max_force_n", "N")


def _force_stream(where: str, info: _XdfInfo, n_sites: int, recorded_fs, units, fz_sign) -> ForceStream:
    """The stream as the live path describes it (`read_force_info`), on the sender's clock (offset 0)."""
    rate, unit = read_force_info(where, info, n_sites, recorded_fs, units, fs_name="recorded_fs")
    if rate > MAX_FS:
        raise ValueError(f"{where} is sampled at {rate:g} Hz, beyond any force sensor (<= {MAX_FS:g} Hz)")
    return ForceStream(info.name(), info.source_id(), info.hostname(), rate, n_sites, unit, int(fz_sign), 0.0, None)


def _take(where: str, found: dict, force: ForceStream) -> tuple:
    """The samples the bridge's stamp rule takes: forces (N, shape (k, n_sites, 3)), stamps, runs, summary, reports."""
    values, stamps = np.asarray(found["time_series"]), np.asarray(found["time_stamps"], dtype=float)
    if stamps.size == 0:
        raise ValueError(f"{where} has no samples")
    if not np.isfinite(stamps).all():
        k = int(np.flatnonzero(~np.isfinite(stamps))[0])
        raise ValueError(f"{where}: sample {k} is stamped {stamps[k]!r}, not a time")
    summary, reports = BridgeSummary(), []
    index, runs = take_stamps(stamps, None, force.fs, summary, reports.append)  # the live bridge's stamp rule
    if index.size == 0:
        raise ValueError(f"{where}: no sample has an increasing stamp")
    forces = (np.asarray(values[index], dtype=float) * force.scale).reshape(index.size, force.n_sites, 3)
    return forces, stamps[index], runs, summary, reports


def _skip_refused(where, forces, stamps, runs, rate, summary, reports, allowance, max_force_n) -> tuple:
    """Skip what the `Encoder` refuses, as the bridge does: (accepted positions, {accepted position: move, s})."""
    moves = {a: excess for a, _, excess in runs if excess > 0}  # kept position -> the spike times' move there
    refused = _refused(forces, allowance, max_force_n)
    for k, reason in refused:
        summary.skipped += 1
        reports.append(f"a sample skipped (stamped {stamps[k]:.6f} s): {reason}")
        moves[k + 1] = moves.get(k + 1, 0.0) + 1.0 / rate  # a skipped sample counts as a one-sample gap
    accepted = np.setdiff1d(np.arange(len(forces)), [k for k, _ in refused])
    if accepted.size == 0:
        raise ValueError(f"{where}: every sample is refused, the first for {refused[0][1]} (check units, fz_sign "
                         "and max_force_n)")
    summary.samples, summary.stopped = len(forces), "end of input"  # as the bridge counts them
    return accepted, _moves_at(accepted, moves)


def _moves_at(accepted, moves: dict) -> dict:
    """The moves at kept positions, each put on the accepted sample that comes next (its index in ``accepted``)."""
    at = np.searchsorted(accepted, sorted(moves))
    taken = {}
    for position, key in zip(at.tolist(), sorted(moves)):
        if position < accepted.size:  # a move after the last accepted sample shifts no spike
            taken[position] = taken.get(position, 0.0) + moves[key]
    return taken


def _scene(forces, taken: dict, rate: float, model_fs: float, conditioning, sites, label: str, contact) -> tuple:
    """The scene on the model's grid, and its shifts: (model sample, s) rows from which spike times move on."""
    out, bounds = _model_bounds(forces, sorted(taken), rate, model_fs, conditioning,
                                None if sites is None else len(sites))
    if sites is None:
        scene = Scene(out[:, 0], out[:, 1], out[:, 2], fs=model_fs, name=label, contact=contact)
    else:
        scene = Scene.from_sites(out.reshape(-1, len(sites), 3), sites, fs=model_fs, name=label)
    shifts = np.array([(b, taken[k]) for b, k in zip(bounds.tolist(), sorted(taken))], dtype=float).reshape(-1, 2)
    return scene, shifts


def read_xdf(path, stream: str | None = None, *, sites: Sites | None = None, fs: float | None = None,
             recorded_fs: float | None = None, units: str | None = None, fz_sign: int = 1,
             conditioning: Conditioning | None = RECORDED, name: str | None = None, contact: Contact | None = None,
             max_force_n: float = MAX_FORCE_N) -> XdfRecording:
    """A force stream of an XDF file, read as the live LSL bridge reads it (module docstring).

    Parameters
    ----------
    path : str or Path
        The XDF file (``.xdf``, or gzipped ``.xdfz``), e.g. LabRecorder's.
    stream : str, optional
        The force stream's name; needed when the file holds several streams.
    sites : Sites, optional
        The sites of its channels (``3 len(sites)`` of them, F_X, F_Y, F_Z of
        each in turn), as ``ddmm stream --sites``; None: one site, 3 channels.
    fs : float, optional
        The model's sample rate with a conditioning (default 1000 Hz, as a
        live encoder's ``model_fs``); without one the scene is at the stream's.
    recorded_fs : float, optional
        The sample rate of an irregular-rate stream (Hz); checked against a
        regular stream's nominal rate.
    units : {"N", "mN", "gf", "kgf", "lbf"}, optional
        The force unit; default the one the stream declares, else N.
    fz_sign : {1, -1}
        -1 for a sensor that reports pressing as negative F_Z.
    conditioning : Conditioning or None
        The conditioning stage (`RECORDED` by default, as live); None: the
        samples as they are, at the stream's rate.
    name : str, optional
        Condition name (default: the stream's name).
    contact : Contact, optional
        Contact geometry of a one-site stream.
    max_force_n : float
        A sample beyond this force (N, at a site) is skipped, as live.

    Returns
    -------
    XdfRecording

    Raises
    ------
    ValueError
        One line naming the file (and the stream): not found, not XDF,
        truncated or damaged; no stream of that name (the names present are
        listed), the wrong channel count, strings instead of numbers, an
        unknown or contradicting unit, mislabelled channels; no sample left.
    MissingExtraError
        Without pyxdf: ``pip install "ddmm[xdf]"``.

    Warns
    -----
    XdfStampWarning
        Once, when samples were dropped, skipped or moved by a gap.
    RecordingBandWarning
        When the stream is slower than 750 Hz: FA-II's band is missing.

    Examples
    --------
    >>> import pathlib, tempfile
    >>> path = pathlib.Path(tempfile.mkdtemp()) / "session.xdf"
    >>> press = np.column_stack([np.zeros((500, 2)), np.linspace(0.0, 2.0, 500)])
    >>> _ = save_xdf(path, press, 10.0 + np.arange(500) / 1000.0, name="glove", fs=1000.0)
    >>> recording = read_xdf(path, "glove")
    >>> recording.stream.unit, recording.summary.samples, recording.first_stamp, recording.scene.fs
    ('N', 500, 10.0, 1000.0)
    """
    path = check_path(path)
    max_force_n = _check_options(stream, sites, fs, recorded_fs, units, fz_sign, conditioning, contact, max_force_n)
    where = f"XDF file {str(path)!r}"
    found = _load(path, where, stream)
    info = _XdfInfo(found["info"], where)
    where = f"{where}, stream {info.name()!r}"
    force = _force_stream(where, info, 1 if sites is None else len(sites), recorded_fs, units, fz_sign)
    rate, n_sites = force.fs, force.n_sites
    forces, stamps, runs, summary, reports = _take(where, found, force)
    allowance = 0.0 if conditioning is None else noise_allowance(conditioning)
    accepted, taken = _skip_refused(where, forces, stamps, runs, rate, summary, reports, allowance, max_force_n)
    forces = forces[accepted]
    if sites is None:
        forces = forces[:, 0, :]
    model_fs = rate if conditioning is None else (DEFAULT_FS if fs is None else float(fs))
    check_memory(64.0 * forces.shape[0] * n_sites * model_fs / rate, f"{where} on the model's {model_fs:g} Hz grid",
                 "check its rate, or give a lower fs")
    warn_band(f"{where}", rate, stacklevel=3)
    scene, shifts = _scene(forces, taken, rate, model_fs, conditioning, sites, name or info.name() or path.stem,
                           contact)
    offsets = np.column_stack([np.asarray(found.get("clock_times", []), dtype=float),
                               np.asarray(found.get("clock_values", []), dtype=float)]).reshape(-1, 2)
    if reports:
        warnings.warn(XdfStampWarning(
            f"{where}: {len(summary.gaps)} gap(s), {summary.out_of_order} sample(s) out of order, "
            f"{summary.skipped} skipped, taken as the live bridge takes them (the first: {reports[0]})"),
            stacklevel=2)
    return XdfRecording(scene, force, summary, tuple(reports), float(stamps[0]), shifts, offsets)

def from_xdf(path, stream: str | None = None, **options) -> Scene:
    """A scene from a force stream of an XDF file: `read_xdf` (its options) ``.scene``.

    The spikes of ``simulate`` on it equal those the live LSL bridge gives
    for the same samples and stamps; `read_xdf` also gives the time base
    (`XdfRecording.input_clock`) and what the bridge's rules dropped.

    Examples
    --------
    >>> import pathlib, tempfile
    >>> path = pathlib.Path(tempfile.mkdtemp()) / "session.xdf"
    >>> _ = save_xdf(path, np.tile([0.0, 0.0, 1.5], (800, 1)), np.arange(800) / 1000.0, name="glove", fs=1000.0,
    ...              units="N")
    >>> scene = from_xdf(path, "glove")
    >>> scene.name, scene.n_samples, scene.fs
    ('glove', 800, 1000.0)
    """
    with warnings.catch_warnings():
        warnings.simplefilter("always")  # re-raised here, so that they point at the caller
        with warnings.catch_warnings(record=True) as caught:
            recording = read_xdf(path, stream, **options)
    for w in caught:
        warnings.warn(w.message, stacklevel=2)
    return recording.scene

