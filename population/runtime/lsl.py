"""Lab Streaming Layer (LSL) streams: a live force stream in (the outlets of spikes and pulses:
`ddmm.population.runtime.lsl_outlets`).

Needs the optional extra ``ddmm[lsl]`` (pylsl, which bundles liblsl);
without it, every function here raises an ImportError that names the
install command.

**The force stream** a sensor publishes: ``3 n_sites`` numeric channels,
(F_X, F_Y, F_Z) of each site in turn, at a regular rate (an irregular stream
needs ``fs``).  Units are read from the XDF meta-data
(``desc/channels/channel/unit``: N, mN, gf, kgf, lbf, or their names) or
given as ``units``; channel labels that name axes (``Fx``, ``force_z``, ...)
are checked to be in that order.  `open_force_stream` resolves it by name.

**The spike stream** and its convention: `ddmm.population.runtime.lsl_outlets`.

**A force outlet** for tests, demos and replaying recordings:
`open_force_outlet`.
"""

from __future__ import annotations

import ctypes
import hashlib
import re
import time
from dataclasses import dataclass

import numpy as np

from ddmm.population.stimuli.recordings import UNITS
from ddmm.utils.extras import require
from ddmm.utils.validation import check_count, check_instance, check_positive, shown

__all__ = ["SPIKE_STREAM_TYPE", "FORCE_STREAM_TYPE", "PULSE_STREAM_TYPE", "ForceStream", "ChunkReader",
           "open_force_stream", "open_force_outlet", "lsl_clock"]

SPIKE_STREAM_TYPE = "Spikes"
PULSE_STREAM_TYPE = "StimulationPulses"
FORCE_STREAM_TYPE = "Force"
#: Unit names a force stream may declare, case-insensitively, and the unit of `UNITS` each means.
UNIT_NAMES = {**{u.lower(): u for u in UNITS}, "newton": "N", "newtons": "N", "millinewton": "mN",
              "millinewtons": "mN", "gram-force": "gf", "kilogram-force": "kgf", "pound-force": "lbf"}
_ROUND_S = 0.25  # one resolve round, s
_NUMERIC = {1: "float32", 2: "double64", 4: "int32", 5: "int16", 6: "int8", 7: "int64"}


def _pylsl(caller: str):
    return require("pylsl", caller, "lsl")


def lsl_clock() -> float:
    """This host's LSL clock in seconds (``pylsl.local_clock``), the clock stamps are given in."""
    return float(_pylsl("lsl_clock").local_clock())


@dataclass(frozen=True)
class ForceStream:
    """A resolved force stream, opened for reading.

    Attributes
    ----------
    name, source_id, hostname : str
        The stream's identity as LSL reports it.
    fs : float
        Sample rate in Hz (the stream's nominal rate, or the one given).
    n_sites : int
        Force sites (the stream has ``3 n_sites`` channels).
    unit : str
        The force unit of the samples (a key of `ddmm.population.stimuli.recordings.UNITS`).
    fz_sign : int
        -1 for a sensor that reports pressing as negative F_Z.
    clock_offset_s : float
        What to add to the stream's stamps to read them on this host's LSL
        clock (LSL's time correction, measured when the stream opened).
    inlet : pylsl.StreamInlet
        The open inlet (no clock processing: stamps are the sender's).
    """

    name: str
    source_id: str
    hostname: str
    fs: float
    n_sites: int
    unit: str
    fz_sign: int
    clock_offset_s: float
    inlet: object

    @property
    def scale(self) -> np.ndarray:
        """Per-channel factor to newtons in the package's frame (units and sign), shape (3 n_sites,)."""
        one = np.array([1.0, 1.0, float(self.fz_sign)]) * UNITS[self.unit]
        return np.tile(one, self.n_sites)

    def open(self, timeout: float = 5.0) -> None:
        """Start receiving: samples pushed from now on arrive (a sender waiting for consumers starts)."""
        self.inlet.open_stream(timeout=timeout)

    def close(self) -> None:
        """Close the inlet (the stream itself belongs to its sender)."""
        self.inlet.close_stream()


def _resolve(pylsl, name: str, source_id: str | None, timeout: float):
    predicate = f"name='{name}'" + ("" if source_id is None else f" and source_id='{source_id}'")
    deadline, found = time.monotonic() + timeout, []
    while not found and time.monotonic() < deadline:
        # Short rounds: liblsl (1.18.0b6) takes some timeouts near 0.5 s as 5.5 s, and a round ends early when found.
        found = pylsl.resolve_bypred(predicate, 1, min(_ROUND_S, max(deadline - time.monotonic(), 0.01)))
    if not found:
        raise ValueError(f"no LSL stream named {name!r}" + ("" if source_id is None else f" with source id "
                         f"{source_id!r}") + f" found within {timeout:g} s (is its sender running on this network?)")
    if len({(s.source_id(), s.hostname()) for s in found}) > 1:
        ids = ", ".join(sorted(repr(s.source_id()) for s in found))
        raise ValueError(f"{len(found)} LSL streams are named {name!r} (source ids {ids}): give a source id")
    return found[0]


def _channel_units_labels(info) -> tuple[list, list]:
    units, labels = [], []
    channel = info.desc().child("channels").child("channel")
    while not channel.empty():
        units.append(channel.child_value("unit").strip())
        labels.append(channel.child_value("label").strip())
        channel = channel.next_sibling("channel")
    return units, labels


def _stream_unit(where: str, declared: list, units: str | None) -> str:
    """The unit: the one the stream declares (all channels alike) or the one given; they must agree."""
    names = {u for u in declared if u}
    unknown = sorted(u for u in names if u.lower() not in UNIT_NAMES)
    if unknown:
        raise ValueError(f"{where} declares the force unit {unknown[0]!r}; known: {', '.join(UNITS)}")
    found = {UNIT_NAMES[u.lower()] for u in names}
    if len(found) > 1:
        raise ValueError(f"{where} declares mixed force units {sorted(found)}: one unit for all channels")
    if units is not None and units not in UNITS:
        raise ValueError(f"units={units!r} is not allowed; allowed: {', '.join(UNITS)}")
    if units is not None and found and units not in found:
        raise ValueError(f"{where} declares its forces in {found.pop()}, not units={units!r}")
    return units or (found.pop() if found else "N")


def _check_labels(where: str, labels: list) -> None:
    """Channel labels that all name an axis (``Fx``, ``D2d_fz``, ``force_Y``) must run x, y, z per site."""
    axes = [re.search(r"([xyz])$", label.lower()) for label in labels]
    if not labels or not all(labels) or not all(axes):
        return
    for i, match in enumerate(axes):
        if match.group(1) != "xyz"[i % 3]:
            raise ValueError(f"{where}: channel {i} is labelled {labels[i]!r}, but channels must be "
                             f"F_X, F_Y, F_Z of each site in turn (channel {i} is F_{'XYZ'[i % 3]})")


def _stream_rate(where: str, nominal: float, fs: float | None, fs_name: str = "fs") -> float:
    if nominal <= 0.0:
        if fs is None:
            raise ValueError(f"{where} has an irregular rate: give its sample rate ({fs_name})")
        return check_positive(fs, fs_name, "Hz")
    if fs is not None and abs(check_positive(fs, fs_name, "Hz") - nominal) > 1e-3 * nominal:
        raise ValueError(f"{fs_name}={float(fs):g} Hz disagrees with the nominal rate {nominal:g} Hz of {where}")
    return float(nominal)


def force_channel_labels(n_sites: int, site_ids=None) -> list:
    """The channel labels of a force stream: ``Fx, Fy, Fz`` per site, as ``<site>_Fx, ...`` with ``site_ids``.

    Examples
    --------
    >>> force_channel_labels(2, ["D2d", "D3d"])
    ['D2d_Fx', 'D2d_Fy', 'D2d_Fz', 'D3d_Fx', 'D3d_Fy', 'D3d_Fz']
    """
    n_sites = check_count(n_sites, "n_sites")
    sites = [str(s) for s in site_ids] if site_ids is not None else None
    if sites is not None and len(sites) != n_sites:
        raise ValueError(f"site_ids must name {n_sites} site(s), got {len(sites)}")
    return [(f"{sites[site]}_" if sites else "") + f"F{axis}" for site in range(n_sites) for axis in "xyz"]


def read_force_info(where: str, info, n_sites: int, fs: float | None, units: str | None,
                    fs_name: str = "fs") -> tuple[float, str]:
    """(sample rate in Hz, force unit) of a force stream's description, checked: the one reading of it.

    A live stream's ``pylsl.StreamInfo`` and a recorded one's (an XDF stream
    header, `ddmm.population.io.xdf`) go through here alike: the channel count
    (``3 n_sites``), a numeric format, the rate (``fs`` for an irregular
    stream), the declared unit and the axis labels (``desc/channels``).
    ``info`` answers ``channel_count()``, ``channel_format()`` (liblsl's
    code), ``nominal_srate()`` and ``desc()`` as pylsl's does; ``where``
    names the stream in the errors, ``fs_name`` the argument that gives ``fs``.

    Examples
    --------
    >>> read_force_info("LSL stream 'glove'", stream_info, 1, None, None)  # doctest: +SKIP
    (1000.0, 'mN')
    """
    if info.channel_count() != 3 * n_sites:
        raise ValueError(f"{where} has {info.channel_count()} channels; {n_sites} site(s) need "
                         f"{3 * n_sites} (F_X, F_Y, F_Z per site)")
    if info.channel_format() not in _NUMERIC:
        raise ValueError(f"{where} carries strings, not forces (a numeric channel format is needed)")
    rate = _stream_rate(where, float(info.nominal_srate()), fs, fs_name)
    declared, labels = _channel_units_labels(info)
    unit = _stream_unit(where, declared, units)
    _check_labels(where, labels)
    return rate, unit


def open_force_stream(name: str, *, n_sites: int = 1, fs: float | None = None, units: str | None = None,
                      fz_sign: int = 1, source_id: str | None = None, timeout: float = 5.0) -> ForceStream:
    """Resolve a force stream by name, check it, and make an inlet on it.

    The inlet receives samples from its ``open()`` (`Bridge.run` opens it),
    so a model can be set up first without the sender's samples piling up.

    Parameters
    ----------
    name : str
        The stream's LSL name.
    n_sites : int
        Force sites the stream carries (``3 n_sites`` channels).
    fs : float, optional
        Sample rate in Hz: needed for an irregular-rate stream, checked
        against a regular stream's nominal rate.
    units : str, optional
        Force unit (a key of ``UNITS``); default what the stream declares, else N.
    fz_sign : {1, -1}
        -1 for a sensor that reports pressing as negative F_Z.
    source_id : str, optional
        Pick one of several streams of this name.
    timeout : float
        Seconds to wait for the stream to resolve and open.

    Raises
    ------
    ValueError
        No such stream within ``timeout``, several, a wrong channel count
        or format, an unknown or contradicting unit, mislabelled channels.

    Examples
    --------
    >>> outlet = open_force_outlet("ddmm-doc-forces", fs=1000.0, units="mN")  # doctest: +SKIP
    >>> stream = open_force_stream("ddmm-doc-forces", timeout=2.0)  # doctest: +SKIP
    >>> stream.unit, stream.fs  # doctest: +SKIP
    ('mN', 1000.0)
    """
    check_instance(name, "name", str, "a str (the stream's LSL name)")
    pylsl = _pylsl("open_force_stream")
    timeout = check_positive(timeout, "timeout", "s")
    if isinstance(n_sites, bool) or not isinstance(n_sites, (int, np.integer)) or n_sites < 1:
        raise ValueError(f"n_sites must be a positive integer, got {shown(n_sites)}")
    if fz_sign not in (1, -1):
        raise ValueError(f"fz_sign must be 1 or -1, got {shown(fz_sign)}")
    found = _resolve(pylsl, name, source_id, timeout)
    inlet = pylsl.StreamInlet(found, max_buflen=360, recover=False)
    try:
        rate, unit = read_force_info(f"LSL stream {name!r}", inlet.info(timeout=timeout), int(n_sites), fs, units)
        # Ask once now: the first correction takes a few exchanges, and a pull waiting on it would stall.
        offset = inlet.time_correction(timeout=timeout)
    except Exception:
        inlet.close_stream()
        raise
    return ForceStream(name, found.source_id(), found.hostname(), rate, int(n_sites), unit, int(fz_sign),
                       float(offset), inlet)


def open_force_outlet(name: str, *, fs: float, n_sites: int = 1, units: str = "N", source_id: str | None = None,
                      site_ids=None):
    """A force outlet as `open_force_stream` reads it: ``3 n_sites`` float64 channels at ``fs``.

    For a synthetic sensor, a replayed recording or a test; the channels are
    labelled ``Fx, Fy, Fz`` (``<site>_Fx``, ... with ``site_ids``) with
    ``units`` declared, in the XDF meta-data's ``desc/channels``.

    Returns
    -------
    pylsl.StreamOutlet
        Push (n, 3 n_sites) chunks with ``push_chunk(samples, stamps)``.

    Examples
    --------
    >>> outlet = open_force_outlet("ddmm-doc-sensor", fs=100.0, units="mN")  # doctest: +SKIP
    """
    check_instance(name, "name", str, "a str (the stream's LSL name)")
    rate, n_sites = check_positive(fs, "fs", "Hz"), check_count(n_sites, "n_sites")
    pylsl = _pylsl("open_force_outlet")
    if units not in UNITS:
        raise ValueError(f"units={units!r} is not allowed; allowed: {', '.join(UNITS)}")
    labels = force_channel_labels(n_sites, site_ids)
    sid = source_id or "ddmm-force-" + hashlib.sha256(f"{name}/{fs}/{n_sites}/{units}".encode()).hexdigest()[:12]
    info = pylsl.StreamInfo(name, FORCE_STREAM_TYPE, 3 * n_sites, rate, pylsl.cf_double64, sid)
    channels = info.desc().append_child("channels")
    for label in labels:
        channel = channels.append_child("channel")
        channel.append_child_value("label", label)
        channel.append_child_value("unit", units)
        channel.append_child_value("type", "Force")
    info.desc().append_child("acquisition").append_child_value("manufacturer", "ddmm")
    return pylsl.StreamOutlet(info)


class ChunkReader:
    """Pull an inlet's samples as they come, into buffers kept between pulls.

    ``pull(timeout)`` waits up to ``timeout`` s for a first sample, then
    takes whatever else has arrived, up to ``max_samples``, without waiting
    for more (liblsl's own chunk pull waits for a full buffer).  Unlike
    pylsl's ``pull_chunk(min_samples=1)``, it allocates nothing per pull.

    Parameters
    ----------
    inlet : pylsl.StreamInlet
        An inlet on a numeric stream.
    max_samples : int
        The most samples one pull returns.

    Examples
    --------
    >>> reader = ChunkReader(inlet)  # doctest: +SKIP
    >>> samples, stamps = reader.pull(0.05)  # views, valid until the next pull  # doctest: +SKIP
    """

    def __init__(self, inlet, max_samples: int = 1024):
        self.inlet, self.max_samples = inlet, int(max_samples)
        n_channels, dtype = int(inlet.channel_count), getattr(inlet, "np_dtype", None)
        self._samples = np.empty((self.max_samples, n_channels), dtype=dtype)
        self._stamps = np.empty(self.max_samples)
        self._error, self._handle = ctypes.c_int(), _handle_error()
        raw = getattr(inlet, "do_pull_chunk", None), getattr(inlet, "obj", None), self._handle, dtype
        # The raw call fills numeric buffers; a string stream, or a pylsl without it, takes the public call.
        self._raw = None if any(r is None for r in raw) or self.max_samples < 2 else raw[:2]
        # One sample's place, and all the rest's, in the buffers: the two pulls' arguments, made once.
        data, stamps, size = self._samples.ctypes.data, self._stamps.ctypes.data, self._samples.itemsize
        self._first = (ctypes.c_void_p(data), ctypes.c_void_p(stamps), ctypes.c_size_t(n_channels),
                       ctypes.c_size_t(1))
        self._rest = (ctypes.c_void_p(data + n_channels * size), ctypes.c_void_p(stamps + self._stamps.itemsize),
                      ctypes.c_size_t(n_channels * (self.max_samples - 1)), ctypes.c_size_t(self.max_samples - 1))
        self._per_sample, self._none = n_channels, ctypes.c_double(0.0)

    def pull(self, timeout: float):
        """(samples, stamps) arrived by ``timeout`` s: views of the buffers, overwritten by the next pull.

        Raises pylsl's ``LostError`` when the sender has gone.
        """
        if self._raw is None:
            return self.inlet.pull_chunk(timeout=timeout, max_samples=self.max_samples, min_samples=1,
                                         as_numpy=True)
        pull, obj = self._raw
        n = pull(obj, *self._first, ctypes.c_double(timeout), ctypes.byref(self._error))
        self._handle(self._error)
        if n:
            n += pull(obj, *self._rest, self._none, ctypes.byref(self._error))
            self._handle(self._error)
        n //= self._per_sample
        return self._samples[:n], self._stamps[:n]


def _handle_error():
    try:
        from pylsl.util import handle_error
    except ImportError:
        return None
    return handle_error
