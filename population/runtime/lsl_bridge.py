"""The LSL bridge: force samples from an LSL stream through a streaming `Encoder` to a spike sink.

**Sample times come from LSL stamps, not from arrival.**  The encoder's clock
counts samples, so when and in what chunks samples arrive never changes a
spike: the spikes equal an offline run of the same samples (`Encoder` on the
whole array, or `from_csv` + `simulate` with the same causal conditioning),
bit for bit.  The stamps are checked by the rule of recorded streams
(``ddmm stream``'s standard input): a sample stamped at or before the one
before it is **out of order**, dropped and reported; an interval over
1.5 / fs is a **gap**, reported with its time and length, after which the
samples are taken as consecutive and the spike stamps' anchor moves on by the
gap's excess, so spikes stay on the input's clock.  A sample the encoder
refuses (a non-finite value, a normal force below the noise allowance) is
skipped and reported, and counted as a one-sample gap.

The bridge stops at the end of input (the sender withdraws its stream: LSL
then discards what the inlet has not pulled, so a sender should close only
once the bridge has caught up), when ``should_stop()`` turns true (a signal
handler's flag), or after ``duration`` seconds of input.  It stops on a
**sender that failed** too, reported with the time since its last sample:
no sample for ``timeout`` seconds once samples have come (a sender hung, or
a host or link gone), or the stream withdrawn less than `QUIET_END_S` after
its last sample, while samples were coming (a sender killed or crashed:
liblsl cannot tell that from a close, so a sender ends its input by going
quiet first, as it must anyway for the bridge to catch up).

The stamp rule is `take_stamps`, which a recorded stream (an XDF file,
`ddmm.population.io.xdf`) goes through as well.
"""

from __future__ import annotations

import math
import time
from dataclasses import dataclass, field

import numpy as np

from ddmm.population.runtime.lsl import ChunkReader, ForceStream, _pylsl
from ddmm.utils.validation import as_float_array, check_instance, check_positive, check_real

__all__ = ["GAP_FACTOR", "QUIET_END_S", "SENDER_FAILED", "BridgeSummary", "Bridge", "check_stamps", "take_stamps",
           "play_forces"]

#: An interval between stamps over this many sample periods is a gap (as for recorded streams).
GAP_FACTOR = 1.5
#: A stream withdrawn less than this many seconds after its last sample was lost mid-stream (its sender
#: killed or crashed, or closed while sending); withdrawn after a longer quiet spell, its input ended.
QUIET_END_S = 0.5
#: The ``BridgeSummary.stopped`` values of a sender that failed: no sample within the timeout, or its
#: stream lost mid-stream.
SENDER_FAILED = ("sender silent", "sender lost")


@dataclass
class BridgeSummary:
    """What a bridge did: samples consumed, spikes sent, problems found, and why it stopped.

    Attributes
    ----------
    samples, spikes, pulses : int
        Input samples taken by the encoder; spikes sent to the sink; stimulation pulses sent.
    gaps : list of (float, float)
        (stamp of the sample before the gap on this host's LSL clock, gap length) in seconds.
    out_of_order, skipped : int
        Samples dropped for stamps that do not increase; samples the encoder refused.
    stopped : str
        ``"end of input"``, ``"duration"``, ``"stopped"`` (``should_stop``), a
        failed sender (`SENDER_FAILED`: ``"sender silent"``, no sample within
        the timeout; ``"sender lost"``, its stream withdrawn mid-stream) or
        ``""`` while running.
    quiet_s : float
        With a failed sender, the seconds since its last sample when the
        bridge stopped.
    """

    samples: int = 0
    spikes: int = 0
    pulses: int = 0
    gaps: list = field(default_factory=list)
    out_of_order: int = 0
    skipped: int = 0
    stopped: str = ""
    quiet_s: float = 0.0

    @property
    def sender_failed(self) -> bool:
        """Whether the bridge stopped on a sender that failed (`SENDER_FAILED`)."""
        return self.stopped in SENDER_FAILED

    def describe(self) -> str:
        """One line for a log."""
        return (f"{self.samples:,} samples in, {self.spikes:,} spikes out, " +
                (f"{self.pulses:,} pulses out, " if self.pulses else "") + f"{len(self.gaps)} gap(s), "
                f"{self.out_of_order} out of order, {self.skipped} skipped" +
                (f" ({self.stopped})" if self.stopped else ""))


def check_stamps(stamps, last: float | None, fs: float):
    """The rule for a chunk's stamps: which samples to keep, and the gap before each kept one.

    Parameters
    ----------
    stamps : array_like, shape (n,)
        The chunk's LSL stamps in seconds (sender's clock).
    last : float or None
        Stamp of the last sample kept before this chunk (None: this is the first).
    fs : float
        Sample rate in Hz.

    Returns
    -------
    keep : ndarray of bool, shape (n,)
        False for out-of-order samples (stamp <= the last kept stamp).
    excess : ndarray of float, shape (n,)
        For a kept sample after a gap (an interval over ``GAP_FACTOR / fs``),
        the interval minus ``1 / fs``; else 0.

    Examples
    --------
    >>> keep, excess = check_stamps([0.001, 0.002, 0.0015, 0.010], 0.0, 1000.0)
    >>> keep.tolist(), excess.round(6).tolist()
    ([True, True, False, True], [0.0, 0.0, 0.0, 0.007])
    """
    stamps = as_float_array(stamps, "stamps", ndim=1)
    fs = check_positive(fs, "fs", "Hz")
    if last is not None:
        check_real(last, "last", "s")
    keep, excess = np.ones(stamps.size, bool), np.zeros(stamps.size)
    previous = -np.inf if last is None else float(last)
    step = np.diff(np.r_[previous, stamps])
    if np.all(step > 0):  # the usual case, vectorised: nothing out of order
        gap = np.isfinite(step) & (step > GAP_FACTOR / fs)
        excess[gap] = step[gap] - 1.0 / fs
        return keep, excess
    for i, stamp in enumerate(stamps):  # sequential: a dropped sample is not the "previous" one
        if not stamp > previous:
            keep[i] = False
            continue
        if np.isfinite(previous) and stamp - previous > GAP_FACTOR / fs:
            excess[i] = stamp - previous - 1.0 / fs
        previous = stamp
    return keep, excess


def take_stamps(stamps, last: float | None, fs: float, summary: BridgeSummary, report, *, limit: int | None = None,
                clock_offset_s: float = 0.0):
    """The stamp rule on a chunk, with its record and reports: what a live and a recorded stream share.

    `check_stamps` decides; each out-of-order sample is counted in
    ``summary.out_of_order`` and reported, each gap appended to
    ``summary.gaps`` (the stamp before it plus ``clock_offset_s``, and its
    length) and reported.  The kept samples are taken as consecutive.

    Parameters
    ----------
    stamps : array_like, shape (n,)
        The chunk's stamps in seconds (sender's clock).
    last : float or None
        Stamp of the last sample kept before this chunk (None: the first chunk).
    fs : float
        Sample rate in Hz.
    summary : BridgeSummary
        Where the counts and gaps go.
    report : callable
        ``report(message)``, one line for each out-of-order sample and gap.
    limit : int, optional
        The most samples to keep (the rest of the chunk is left).
    clock_offset_s : float
        Added to the gaps' stamps in ``summary`` (a live stream's offset to this host's clock).

    Returns
    -------
    index : ndarray of int
        Positions in the chunk of the samples kept, in order.
    runs : list of (int, int, float)
        ``(start, stop, excess)`` into ``index``: runs of consecutive samples,
        each after a gap whose length exceeds one period by ``excess`` s (0
        for the first run when no gap precedes it).

    Examples
    --------
    >>> summary, lines = BridgeSummary(), []
    >>> index, runs = take_stamps([0.001, 0.002, 0.0015, 0.010], 0.0, 1000.0, summary, lines.append)
    >>> index.tolist(), [(a, b, round(e, 6)) for a, b, e in runs], summary.out_of_order, len(summary.gaps)
    ([0, 1, 3], [(0, 2, 0.0), (2, 3, 0.007)], 1, 1)
    """
    check_instance(summary, "summary", BridgeSummary, "a BridgeSummary")
    if not callable(report):
        raise TypeError(f"report must be callable (report(message)), got {type(report).__name__}")
    keep, excess = check_stamps(stamps, last, fs)
    stamps = np.asarray(stamps, dtype=float)
    for i in np.flatnonzero(~keep):
        summary.out_of_order += 1
        report(f"a sample stamped {stamps[i]:.6f} s comes at or before the one before it: dropped")
    index = np.flatnonzero(keep)
    if limit is not None:
        index = index[:max(limit, 0)]
    if index.size == 0:
        return index, []
    gaps = excess[index]
    starts = sorted({0, *np.flatnonzero(gaps > 0).tolist()}) + [index.size]
    period = 1.0 / float(fs)
    runs = []
    for a, b in zip(starts[:-1], starts[1:]):
        if gaps[a] > 0:
            before = float(stamps[index[a]]) - float(gaps[a]) - period  # the stamp of the sample before the gap
            summary.gaps.append((before + clock_offset_s, float(gaps[a]) + period))
            report(f"a gap of {float(gaps[a]) + period:.6g} s after the sample stamped {before:.6f} s; "
                   "the samples are taken as consecutive and the spike stamps move on by the gap")
        runs.append((a, b, float(gaps[a])))
    return index, runs


class Bridge:
    """Pull force samples from an LSL stream, encode them, and send the spikes on.

    Parameters
    ----------
    encoder : Encoder
        The streaming encoder, made with the stream's ``fs`` and sites.
    force : ForceStream
        The open force stream (`open_force_stream`).
    sink : callable
        ``sink(positions, stamps)``: the spiking afferents' positions in the
        encoder's population and their stamps on this host's LSL clock (s);
        a `SpikeOutlet`'s ``push``, for example.
    report : callable, optional
        ``report(message)`` for each gap, out-of-order or skipped sample.
    stimulator : StimulationEncoder, optional
        Wraps ``encoder``: samples go through it, and its pulses to ``pulse_sink``.
    pulse_sink : callable, optional
        ``pulse_sink(electrode, stamps, amplitude_ua, phase_width_us)``, a `PulseOutlet`'s ``push``.

    Examples
    --------
    >>> bridge = Bridge(encoder, open_force_stream("sensor"), SpikeOutlet("spikes", encoder).push)  # doctest: +SKIP
    >>> bridge.run(duration=10.0).describe()  # doctest: +SKIP
    '10,000 samples in, 2,345 spikes out, 0 gap(s), 0 out of order, 0 skipped (duration)'
    """

    def __init__(self, encoder, force: ForceStream, sink, *, report=None, stimulator=None, pulse_sink=None):
        from ddmm.population.runtime.stream import Encoder

        check_instance(encoder, "encoder", Encoder, "an Encoder")
        check_instance(force, "force", ForceStream, "a ForceStream (from open_force_stream)")
        if (stimulator is None) != (pulse_sink is None) or (stimulator is not None and stimulator.encoder is not encoder):
            raise ValueError("stimulator and pulse_sink go together, and the stimulator must wrap this encoder")
        self.stimulator, self.pulse_sink = stimulator, pulse_sink
        if encoder.fs != force.fs:
            raise ValueError(f"the encoder's fs ({encoder.fs:g} Hz) differs from the stream's ({force.fs:g} Hz)")
        n_sites = 1 if encoder.sites is None else len(encoder.sites)
        if n_sites != force.n_sites:
            raise ValueError(f"the encoder has {n_sites} site(s), the stream {force.n_sites}")
        self.encoder, self.force, self.sink = encoder, force, sink
        self.report = report or (lambda message: None)
        self.summary = BridgeSummary()
        self._last = None  # last kept stamp, sender's clock
        self._anchor = None  # this host's LSL time of model time 0, moved on by gaps
        self._shape = (3,) if encoder.sites is None else (n_sites, 3)
        self._scale, self._gap_s = force.scale, GAP_FACTOR / force.fs  # made once: used for every sample
        self._reader = None  # the inlet's ChunkReader, made at the first poll
        _settle_garbage_collector()  # here, before the inlet opens: a collection takes tens of ms
        self._arrival = None  # time.monotonic() of the last pull that brought samples

    def poll(self, timeout: float = 0.05, limit: int | None = None) -> int:
        """Pull what has arrived (waiting up to ``timeout`` s for a first sample) and encode it.

        ``limit`` caps the samples consumed.  Returns the samples consumed;
        raises pylsl's ``LostError`` when the sender has gone.
        """
        if self._reader is None:
            self._reader = ChunkReader(self.force.inlet)
        samples, stamps = self._reader.pull(timeout)
        if len(stamps) == 0:
            return 0
        self._arrival = time.monotonic()
        return self.consume(np.asarray(samples, float), np.asarray(stamps, float), limit)

    def consume(self, samples, stamps, limit: int | None = None) -> int:
        """Encode a chunk of raw samples (stream units) with their stamps; returns the samples taken."""
        n = len(stamps)
        if n and (limit is None or limit >= n) and self._in_step(stamps):  # the usual chunk: nothing to drop
            self._push(samples * self._scale)
            self._last = float(stamps[-1])
            self.summary.samples += n
            return n
        index, runs = take_stamps(stamps, self._last, self.force.fs, self.summary, self.report, limit=limit,
                                  clock_offset_s=self.force.clock_offset_s)
        if index.size == 0:
            return 0
        if self._anchor is None:
            self._anchor = float(stamps[index[0]]) + self.force.clock_offset_s
        forces = samples[index] * self._scale
        for a, b, excess in runs:
            self._anchor += excess  # the spikes after a gap move on by its excess
            self._push(forces[a:b])
        self._last = float(stamps[index[-1]])
        self.summary.samples += index.size
        return int(index.size)

    def _in_step(self, stamps) -> bool:
        """Whether each stamp follows the one before by more than 0 and at most a gap.

        Such a chunk is what `check_stamps` keeps whole with no gap, decided
        here without its arrays; NaN stamps fail, so the rule then reports them.
        """
        if self._last is None:
            return False
        step = float(stamps[0]) - self._last
        if not 0.0 < step <= self._gap_s:
            return False
        if len(stamps) == 1:
            return True
        steps = np.diff(stamps)
        return bool(np.all(steps > 0.0) and np.all(steps <= self._gap_s))

    def _push(self, forces) -> None:
        forces = forces.reshape((-1, *self._shape))
        push = self.encoder.push if self.stimulator is None else self.stimulator.push
        try:
            spikes = push(forces)
        except ValueError:  # find the refused samples; the encoder's state is untouched by a failed push
            for row in forces:
                try:
                    self._send(push(row[None]))
                except ValueError as exc:
                    self.summary.skipped += 1
                    self._anchor += 1.0 / self.force.fs
                    self.report(f"a sample skipped: {exc}")
            return
        self._send(spikes)

    def _send(self, out) -> None:
        spikes = out if self.stimulator is None else out.spikes
        if self.stimulator is not None and out.electrode.size:
            self.pulse_sink(out.electrode, self._anchor + out.time, out.amplitude_ua, out.phase_width_us)
            self.summary.pulses += int(out.electrode.size)
        if spikes.afferent.size:
            self.sink(spikes.afferent, self._anchor + spikes.time)
            self.summary.spikes += int(spikes.afferent.size)

    def run(self, *, duration: float | None = None, should_stop=None, poll_s: float = 0.05,
            timeout: float | None = None) -> BridgeSummary:
        """Bridge until the end of input, ``should_stop()``, ``duration`` seconds of input, or a failed sender.

        ``timeout`` (s; None: wait forever) is the longest wait for a sample
        once samples have come: past it the sender has failed (``"sender
        silent"``); before the first sample the bridge waits (a sender may
        publish its stream before its device starts).  A stream withdrawn
        less than `QUIET_END_S` after its last sample failed too (``"sender
        lost"``); either is reported (``report``) with the stream's name and
        the time since its last sample.  Returns the `BridgeSummary` (also
        kept as ``summary``).

        Examples
        --------
        >>> summary = bridge.run(timeout=2.0)  # doctest: +SKIP
        >>> summary.stopped, summary.sender_failed  # doctest: +SKIP
        ('sender silent', True)
        """
        lost = _pylsl("Bridge.run").util.LostError
        limit = None if duration is None else int(round(check_positive(duration, "duration", "s") * self.force.fs))
        timeout = None if timeout is None else check_positive(timeout, "timeout", "s")
        try:
            self.force.open()
        except lost:
            self.summary.stopped = "end of input"
            return self.summary
        while True:
            if limit is not None and self.summary.samples >= limit:
                self.summary.stopped = "duration"
                break
            if should_stop is not None and should_stop():
                self.summary.stopped = "stopped"
                break
            try:
                self.poll(poll_s, None if limit is None else limit - self.summary.samples)
            except lost:
                quiet = math.inf if self._arrival is None else time.monotonic() - self._arrival
                if quiet < QUIET_END_S:
                    self._failed("sender lost", quiet, f"was lost {quiet:.3g} s after its last sample, while "
                                 "samples were coming: its sender died (or closed its stream mid-stream)")
                else:
                    self.summary.stopped = "end of input"
                break
            if timeout is not None and self._arrival is not None and time.monotonic() - self._arrival >= timeout:
                quiet = time.monotonic() - self._arrival
                self._failed("sender silent", quiet, f"sent no sample for {quiet:.3g} s since its last one (the "
                             f"timeout is {timeout:g} s): its sender has stopped")
                break
        return self.summary

    def _failed(self, stopped: str, quiet: float, what: str) -> None:
        self.summary.stopped, self.summary.quiet_s = stopped, float(quiet)
        self.report(f"LSL stream {self.force.name!r} {what}")


_SETTLED = []  # whether this process's garbage collector was settled (`_settle_garbage_collector`)


def _settle_garbage_collector() -> None:
    """Once a process: collect, then move every object alive (the model, its tables, the modules) out of
    the cyclic collector's reach (`gc.freeze`).  A full collection walked them all mid-stream, ~45 ms with
    the hand's model loaded (measured, twice in 3 s), while samples queued up; from here on it walks only
    what came after."""
    if _SETTLED:
        return
    import gc

    gc.collect()
    gc.freeze()
    _SETTLED.append(True)


def play_forces(outlet, forces, fs: float, *, should_stop=None, start: float | None = None) -> int:
    """Push ``forces`` to a force outlet in real time, each sample stamped with its due time.

    Parameters
    ----------
    outlet : pylsl.StreamOutlet
        From `open_force_outlet`.
    forces : ndarray, shape (n, 3 n_sites)
        Samples in the outlet's units.
    fs : float
        Sample rate in Hz.
    should_stop : callable, optional
        Polled between samples; True ends the playback early.
    start : float, optional
        LSL time of sample 0 (default: now).

    Returns
    -------
    int
        Samples pushed.

    Examples
    --------
    >>> play_forces(open_force_outlet("sensor", fs=100.0), np.zeros((100, 3)), 100.0)  # doctest: +SKIP
    100
    """
    if not callable(getattr(outlet, "push_chunk", None)):
        raise TypeError(f"outlet must be a pylsl.StreamOutlet (from open_force_outlet), got {type(outlet).__name__}")
    forces = np.ascontiguousarray(as_float_array(forces, "forces", ndim=2))
    fs = check_positive(fs, "fs", "Hz")
    pylsl = _pylsl("play_forces")
    t0 = pylsl.local_clock() if start is None else float(start)
    for k in range(forces.shape[0]):
        due = t0 + k / fs
        wait = due - pylsl.local_clock()
        if wait > 2e-3:
            time.sleep(wait - 1e-3)  # sleep most of the wait, spin the last millisecond
        while pylsl.local_clock() < due:
            pass
        if should_stop is not None and should_stop():
            return k
        outlet.push_chunk(forces[k:k + 1], [due])
    return int(forces.shape[0])
