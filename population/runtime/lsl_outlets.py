"""Lab Streaming Layer outlets of the encoders: the spike stream and the stimulation-pulse stream.

Needs the optional extra ``ddmm[lsl]``.

**The spike stream** (`SpikeOutlet`): type ``Spikes``, int32 channels,
irregular rate.  Each spike is **the afferent's id** (the ``afferent``
coordinate of `simulate`'s Dataset) **stamped with the spike's time on the
input stream's clock**: the capture stamp of the first force sample, mapped
to this host's LSL clock, plus the spike's model time (a reported gap in the
input moves the anchor by the gap's length,
`ddmm.population.runtime.lsl_bridge`).  Spikes of one step go out in
increasing id.  In the default format, ``events``, one LSL sample is one
spike; in ``batched``, one sample is a frame of a push's spikes, which
`decode_spikes` turns back into the same ids and stamps, bit for bit
(`ddmm.population.runtime.spike_formats`).  Its meta-data
(`read_spike_metadata`) give the format and describe the population (id,
type, position, region, theta_T and NAP of each afferent), the model
settings and the input stream.

**The pulse stream** (`PulseOutlet`): type ``StimulationPulses``, the
pulses of a `StimulationEncoder` (docs/stimulation.md).

The force side (the inlet, `ForceStream`, and a force outlet for tests and
replays) is `ddmm.population.runtime.lsl`.
"""

from __future__ import annotations

import ctypes
import hashlib
import time

import numpy as np

from ddmm.population.runtime.lsl import PULSE_STREAM_TYPE, SPIKE_STREAM_TYPE, ForceStream, _handle_error, _pylsl
from ddmm.population.runtime.spike_formats import SPIKE_FORMATS, decode_spikes
from ddmm.utils.validation import check_instance, check_nonnegative

__all__ = ["CLOSE_LINGER_S", "PulseOutlet", "SpikeOutlet", "decode_spikes", "read_spike_metadata"]

#: How long (s) a closing outlet with consumers stays open first.  liblsl drops the samples it has queued
#: but not yet sent when an outlet is destroyed, so a run that ends at once (``--duration``) could lose its
#: last spikes on a loaded host; one second lets the transfer threads send them.
CLOSE_LINGER_S = 1.0


def _withdraw(outlet, linger) -> None:
    """Destroy a pylsl outlet after ``linger`` seconds if an inlet is connected to it."""
    linger = check_nonnegative(linger, "linger", "s")
    if linger and outlet.have_consumers():
        time.sleep(linger)


def _text(values, fmt=str) -> str:
    return ",".join(fmt(v) for v in values)


class SpikeOutlet:
    """The spike stream of a streaming encoder (see the module docstring for its convention).

    Parameters
    ----------
    name : str
        The stream's LSL name.
    encoder : Encoder
        The encoder whose spikes go out (its population, settings and sites
        are described in the meta-data).
    force : ForceStream, optional
        The input stream (named in the meta-data).
    source_id : str, optional
        Default: derived from ``name``, the population and the seed, so a
        restarted bridge keeps its id and recorders reconnect to it.
    spike_format : str
        A name in `SPIKE_FORMATS`: ``"events"`` (default, one sample per
        spike) or ``"batched"`` (one frame per push: what keeps the whole
        hand at 1 kHz, docs/live-sensors.md).

    Examples
    --------
    >>> from ddmm.population import make_population  # doctest: +SKIP
    >>> from ddmm.population.runtime import Encoder  # doctest: +SKIP
    >>> outlet = SpikeOutlet("ddmm-doc-spikes", Encoder(make_population(["SAI"]), fs=1000.0))  # doctest: +SKIP
    """

    def __init__(self, name: str, encoder, *, force: ForceStream | None = None, source_id: str | None = None,
                 spike_format: str = "events"):
        from ddmm.population.runtime.stream import Encoder

        check_instance(name, "name", str, "a str (the stream's LSL name)")
        check_instance(encoder, "encoder", Encoder, "an Encoder")
        check_instance(force, "force", (ForceStream, type(None)), "a ForceStream or None")
        if not isinstance(spike_format, str) or spike_format not in SPIKE_FORMATS:
            raise ValueError(f"spike_format must be one of {', '.join(SPIKE_FORMATS)}, got {spike_format!r}")
        pylsl = _pylsl("SpikeOutlet")
        fmt = self.spike_format = SPIKE_FORMATS[spike_format]
        ids = encoder.population.afferent_id[encoder.positions]
        digest = hashlib.sha256(f"{name}/{encoder.population.name}/{encoder.seed}/{_text(ids)}".encode())
        self.source_id = source_id or "ddmm-spikes-" + digest.hexdigest()[:12]
        info = pylsl.StreamInfo(name, SPIKE_STREAM_TYPE, fmt.channels, pylsl.IRREGULAR_RATE, pylsl.cf_int32,
                                self.source_id)
        _describe(info.desc(), encoder, force, fmt)
        self.name = name
        self._ids = encoder.population.afferent_id.astype(np.int32)
        self._pack = fmt.pack
        self._pack(self._ids[:1], np.zeros(1))  # compiled (or loaded) now, not at the first spike
        # An irregular stream's buffer counts hundreds of samples: events, 360,000 spikes for a slow consumer.
        self._outlet = pylsl.StreamOutlet(info, max_buffered=fmt.max_buffered)
        push_n, handle = getattr(self._outlet, "do_push_chunk_n", None), _handle_error()
        # Looked up once: a push is on the latency path, once per force sample.
        self._push_n = None if push_n is None or handle is None else (push_n, self._outlet.obj, handle)

    def push(self, positions, stamps) -> None:
        """Send spikes: the afferents' positions in the encoder's population and their LSL stamps (s)."""
        positions = np.asarray(positions)
        if positions.size == 0:
            return
        ids = np.ascontiguousarray(self._ids[positions])
        stamps = np.ascontiguousarray(stamps, dtype=np.float64)
        if stamps.shape != ids.shape:
            raise ValueError(f"stamps must have one entry per spike; got {stamps.size} for {ids.size}")
        samples, stamps = self._pack(ids, stamps)  # the format's samples: one per spike, or frames
        if self._push_n is None:  # another pylsl: its public call, which copies the stamps to a list
            self._outlet.push_chunk(samples, stamps.tolist())
            return
        # pylsl's own call on the arrays as they are: a burst of 10,000 spikes costs liblsl ~2 ms, the list 1 ms more
        push_n, obj, handle = self._push_n
        handle(push_n(obj, ctypes.c_void_p(samples.ctypes.data), ctypes.c_long(samples.size),
                      ctypes.c_void_p(stamps.ctypes.data), ctypes.c_int(1)))

    def have_consumers(self) -> bool:
        """Whether any inlet is connected."""
        return bool(self._outlet.have_consumers())

    def close(self, linger: float = CLOSE_LINGER_S) -> None:
        """Withdraw the stream (consumers see it end), after ``linger`` seconds if any is connected.

        The wait lets liblsl send what it has queued: it drops those samples when an outlet is destroyed.
        """
        _withdraw(self._outlet, linger)
        self._push_n = None  # holds the outlet's handle, which dies with it
        del self._outlet


class PulseOutlet:
    """The stimulation pulses of a `StimulationEncoder` as an LSL stream.

    Type ``StimulationPulses``, irregular rate, 3 float64 channels: the
    electrode's position in the table, the amplitude (µA) and the phase width
    (µs); **one sample per pulse**, stamped like the spikes (the pulse's start
    on the input's clock).  The meta-data give the waveform, the rule and the
    electrode table (ids, fields, every limit) under ``desc/electrodes``.

    Examples
    --------
    >>> outlet = PulseOutlet("ddmm-doc-pulses", stimulator)  # doctest: +SKIP
    """

    def __init__(self, name: str, stimulator, *, source_id: str | None = None):
        from ddmm.population.neurostim.stream import StimulationEncoder

        check_instance(name, "name", str, "a str (the stream's LSL name)")
        check_instance(stimulator, "stimulator", StimulationEncoder, "a StimulationEncoder")
        pylsl = _pylsl("PulseOutlet")
        table = stimulator.table
        digest = hashlib.sha256(f"{name}/{_text(table.ids)}/{stimulator.rule!r}".encode())
        self.source_id = source_id or "ddmm-pulses-" + digest.hexdigest()[:12]
        info = pylsl.StreamInfo(name, PULSE_STREAM_TYPE, 3, pylsl.IRREGULAR_RATE, pylsl.cf_double64, self.source_id)
        desc = info.desc()
        channels = desc.append_child("channels")
        for label, unit in (("electrode", "1"), ("amplitude", "uA"), ("phase_width", "us")):
            channel = channels.append_child("channel")
            channel.append_child_value("label", label)
            channel.append_child_value("unit", unit)
        from ddmm.population.neurostim.encode import WAVEFORM

        desc.append_child_value("waveform", WAVEFORM)
        desc.append_child_value("rule", repr(stimulator.rule))
        electrodes = desc.append_child("electrodes")
        electrodes.append_child_value("id", _text(table.ids))
        for key in ("x_mm", "y_mm", "radius_mm", "region", "amplitude_min_ua", "amplitude_max_ua", "phase_width_us",
                    "max_rate_hz", "charge_limit_nc", "interphase_us"):
            electrodes.append_child_value(key, _text(getattr(e, key) for e in table))
        self.name = name
        self._outlet = pylsl.StreamOutlet(info, max_buffered=3600)

    def push(self, electrode, stamps, amplitude_ua, phase_width_us) -> None:
        """Send pulses: electrode positions, LSL stamps (s), amplitudes (µA), phase widths (µs)."""
        if len(electrode):
            rows = np.column_stack([np.asarray(electrode, float), amplitude_ua, phase_width_us])
            self._outlet.push_chunk(rows, np.asarray(stamps, float).tolist())

    def close(self, linger: float = CLOSE_LINGER_S) -> None:
        """Withdraw the stream, after ``linger`` seconds if a consumer is connected (see `SpikeOutlet.close`)."""
        _withdraw(self._outlet, linger)
        del self._outlet


def _describe(desc, encoder, force, spike_format) -> None:
    """The spike stream's meta-data: the format, the channels, the convention, the model, the input and the
    population.  A batched stream describes its frame's fields, not its 2,048 channels one by one."""
    from ddmm import __version__

    desc.append_child_value("format", spike_format.name)
    channels = desc.append_child("channels")
    for label in spike_format.labels:
        channel = channels.append_child("channel")
        channel.append_child_value("label", label)
        channel.append_child_value("type", "SpikeID" if label == "afferent_id" else "SpikeFrame")
        channel.append_child_value("unit", "1")
    if spike_format.channels > 1:
        frame = desc.append_child("frame")
        for key, value in (("capacity", str(spike_format.channels)),
                           ("layout", "count,stamp_hi,stamp_lo,afferent_id*count"), ("padding", "-1"),
                           ("stamp_bits", "IEEE-754 binary64, high word then low word, as int32")):
            frame.append_child_value(key, value)
    desc.append_child_value("convention", spike_format.convention)
    model = desc.append_child("model")
    settings = {"software": f"ddmm {__version__}", "population": encoder.population.name, "seed": str(encoder.seed),
                "engine": encoder.engine, "method": encoder.method, "dt_s": repr(encoder.dt),
                "model_fs_hz": repr(encoder.model_fs), "no_shear": encoder.no_shear,
                "conditioning": repr(encoder.conditioning)}
    for key, value in settings.items():
        model.append_child_value(key, value)
    if force is not None:
        source = desc.append_child("input")
        for key, value in (("name", force.name), ("source_id", force.source_id), ("hostname", force.hostname),
                           ("fs_hz", repr(force.fs)), ("unit", force.unit), ("fz_sign", str(force.fz_sign)),
                           ("clock_offset_s", repr(force.clock_offset_s))):
            source.append_child_value(key, value)
    pop, pos = encoder.population, encoder.positions
    afferents = desc.append_child("afferents")
    afferents.append_child_value("count", str(pos.size))
    for key, values, fmt in (("id", pop.afferent_id[pos], str), ("type", pop.afferent_type[pos], str),
                             ("x_mm", pop.x_mm[pos], repr), ("y_mm", pop.y_mm[pos], repr),
                             ("region", pop.region[pos], str), ("theta_t_deg", pop.theta_t[pos], repr),
                             ("nap", pop.nap[pos], str)):
        afferents.append_child_value(key, _text(np.asarray(values).tolist(), fmt))
    if encoder.sites is not None:
        sites = desc.append_child("sites")
        for key, values in (("id", encoder.sites.site_id), ("x_mm", encoder.sites.x_mm),
                            ("y_mm", encoder.sites.y_mm), ("radius_mm", encoder.sites.radius_mm),
                            ("region", encoder.sites.region)):
            sites.append_child_value(key, _text(np.asarray(values).tolist()))


def read_spike_metadata(info) -> dict:
    """The population and settings a spike stream describes, from its full `pylsl.StreamInfo`.

    Returns
    -------
    dict
        ``format``: the stream's format, a name in `SPIKE_FORMATS` for
        `decode_spikes` (``"events"`` for a stream that states none: ddmm
        before the batched format); ``afferents``: a dict of arrays (``id``,
        ``type``, ``x_mm``, ``y_mm``, ``region``, ``theta_t_deg``, ``nap``),
        one entry per afferent; ``model`` and ``input``: dicts of strings;
        ``sites`` (when the encoder has sites).

    Examples
    --------
    >>> inlet = pylsl.StreamInlet(pylsl.resolve_byprop("type", "Spikes")[0])  # doctest: +SKIP
    >>> meta = read_spike_metadata(inlet.info())  # doctest: +SKIP
    >>> samples, stamps = inlet.pull_chunk(timeout=1.0, max_samples=4096, as_numpy=True)  # doctest: +SKIP
    >>> ids, stamps = decode_spikes(samples, stamps, meta["format"])  # either format  # doctest: +SKIP
    """
    if not callable(getattr(info, "desc", None)):
        raise TypeError(f"info must be a pylsl.StreamInfo (e.g. inlet.info()), got {type(info).__name__}")
    desc = info.desc()
    if desc.child("afferents").empty():
        raise ValueError(f"LSL stream {info.name()!r} carries no ddmm population description")
    out = {"format": desc.child_value("format") or "events"}
    for block in ("model", "input"):
        node, values = desc.child(block), {}
        child = node.first_child()
        while not child.empty():
            values[child.name()] = child.child_value()
            child = child.next_sibling()
        out[block] = values
    out["afferents"] = _columns(desc.child("afferents"), ("id", "type", "x_mm", "y_mm", "region", "theta_t_deg", "nap"),
                                {"id": np.int64, "x_mm": float, "y_mm": float, "theta_t_deg": float})
    if not desc.child("sites").empty():
        out["sites"] = _columns(desc.child("sites"), ("id", "x_mm", "y_mm", "radius_mm", "region"),
                                {"x_mm": float, "y_mm": float, "radius_mm": float})
    return out


def _columns(node, keys, numeric) -> dict:
    columns = {}
    for key in keys:
        text = node.child_value(key)
        items = text.split(",") if text else []
        columns[key] = np.array(items, dtype=numeric.get(key, object)) if key in numeric else np.array(items, object)
    return columns

