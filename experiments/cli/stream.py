"""``ddmm stream``: live forces in, spike events out, as they happen.

Input: CSV lines ``t,fx,fy,fz`` on standard input (one ``fx,fy,fz`` triple
per site with ``--sites``; seconds, and newtons unless ``--units``; a header
line is skipped), or an LSL force stream (``--lsl-in NAME``: 3 channels per
site, its rate and units from the stream, docs/live-sensors.md).  Output:
CSV lines ``t,afferent,type`` on standard output (the afferent's id, its
type), flushed after every input chunk, or an LSL spike stream
(``--lsl-out NAME``: one int32 sample per spike holding the afferent id;
with ``--lsl-spike-format batched``, one frame of int32 per push carrying
the same ids and stamps, `ddmm.population.runtime.spike_formats`).

**Time base.**  On standard output ``t`` is on the input's clock, in both
modes: the first sample's time (the first CSV column, or the LSL stamp the
sender gave it) plus the spike's model time, moved on by each gap.  A spike
at ``t`` was caused by the samples up to ``t``.  An LSL spike stream is
stamped on this host's LSL clock instead (the input's clock plus LSL's
measured offset, ``clock_offset_s`` in its metadata), as LSL consumers need.

The samples pass through the causal conditioning stage (``--conditioning
causal``, the default: docs/recordings.md), which brings the input's rate to
the model's ``--model-fs``; the spikes equal ``ddmm simulate`` of the same
samples as a file.  A malformed line, a NaN or time going backwards is
reported on stderr and skipped; a gap in the stamps (an interval over
1.5 / fs) is reported with its time and length, the samples are taken as
consecutive and the spike times move on by the gap.  It stops at the end of
input, on SIGINT/SIGTERM, or after ``--duration`` seconds of input, and
prints a one-line summary on stderr.  An LSL sender that fails -- no sample
for ``--lsl-timeout`` seconds (default 2) once samples have come, or its
stream lost mid-stream (a sender killed) -- is reported on stderr with the time since its last sample;
what was produced is written, and the exit status is `SENDER_FAILED_STATUS`
(3), apart from 0 (done) and 2 (an error).

``ddmm play`` (`ddmm.experiments.cli.play`) publishes a scene's forces as an
LSL force stream in real time: a synthetic sensor for trying ``--lsl-in``.
"""

from __future__ import annotations

import os
import signal
import sys
from contextlib import contextmanager

import numpy as np

from ddmm.experiments.cli.options import add_engine_option, step_ms
from ddmm.experiments.cli.recording_options import add_recording_options, conditioning_from_args, sites_option
from ddmm.experiments.io import quiet_liblsl, seed_arg
from ddmm.population.runtime.spike_formats import SPIKE_FORMATS

__all__ = ["SENDER_FAILED_STATUS", "bounded_lines", "register", "stop_on_signals", "stream"]

#: The exit status of ``ddmm stream --lsl-in`` when its sender failed (silent past --lsl-timeout, or lost).
SENDER_FAILED_STATUS = 3


def register(sub) -> None:
    """Add ``ddmm stream``."""
    p = sub.add_parser("stream", help="encode live force samples (stdin or LSL) into spike events (stdout or LSL)",
                       epilog=f"exit status: 0 at the end of input, on a signal or after --duration; 2 on an error; "
                              f"{SENDER_FAILED_STATUS} when the LSL sender failed (no sample for --lsl-timeout "
                              "seconds, or its stream lost mid-stream), after what was produced is written")
    p.add_argument("--population", default="fingertip")
    p.add_argument("--fs", type=float, default=None,
                   help="sample rate of the input in Hz (required on stdin; an LSL stream states its own)")
    p.add_argument("--dt", type=step_ms, default=0.1, metavar="MS", help="integration step in ms (default 0.1)")
    p.add_argument("--seed", type=seed_arg, default=0)
    add_engine_option(p, "direct")
    p.add_argument("--types", default=None, metavar="T[,T...]",
                   help="afferent types to simulate (leave FA-II out below 750 Hz)")
    p.add_argument("--contact", default=None, metavar="X,Y,R", help="contact centre and radius in mm")
    p.add_argument("--sites", default=None, metavar="SITES.csv|fingertips",
                   help="force sites: a sites table (site,x_mm,y_mm[,region][,radius_mm]) or 'fingertips' "
                        "(the five digit tips); the input then has fx,fy,fz per site")
    p.add_argument("--model-fs", type=float, default=1000.0, metavar="HZ",
                   help="the model's sample rate after conditioning (default 1000, as ddmm simulate's files)")
    p.add_argument("--duration", type=float, default=None, metavar="S", help="stop after S seconds of input")
    p.add_argument("--threads", type=int, default=None, metavar="N",
                   help="threads a push runs on (default: DDMM_NUM_THREADS if set; else one with --lsl-in on a "
                        "host of at most two cores, where the sender and the consumers need the other; else every "
                        "core)")
    g = p.add_argument_group("Lab Streaming Layer (extra ddmm[lsl])")
    g.add_argument("--lsl-in", default=None, metavar="NAME", help="read forces from the LSL stream of this name")
    g.add_argument("--lsl-source-id", default=None, metavar="ID", help="pick one of several streams of that name")
    g.add_argument("--lsl-out", default=None, metavar="NAME", help="publish spikes as an LSL stream of this name")
    g.add_argument("--lsl-spike-format", default=None, choices=tuple(SPIKE_FORMATS),
                   help="the spike stream's samples: 'events', one per spike (default), or 'batched', one frame "
                        "of up to 2,048 int32 per push, decoded by decode_spikes (the whole hand at 1 kHz; "
                        "docs/live-sensors.md)")
    g.add_argument("--resolve-timeout", type=float, default=5.0, metavar="S",
                   help="seconds to wait for the input stream (default 5)")
    g.add_argument("--lsl-timeout", type=float, default=2.0, metavar="S",
                   help="seconds without a sample, once samples have come, after which the sender has failed: "
                        f"reported, and exit status {SENDER_FAILED_STATUS} (default 2; 0: wait forever)")
    g.add_argument("--electrodes", default=None, metavar="E.csv|E.toml",
                   help="an electrode table: stimulation pulses go out on --lsl-pulses (docs/stimulation.md)")
    g.add_argument("--rule", default="biomimetic", choices=("biomimetic", "linear-amplitude", "linear-frequency"),
                   help="the stimulation encoding rule (with --electrodes)")
    g.add_argument("--lsl-pulses", default=None, metavar="NAME", help="publish the pulses as an LSL stream")
    add_recording_options(p, stream=True)
    p.set_defaults(func=run)


def _parse(line: str, n_values: int):
    from ddmm.utils.validation import parse_number  # as the file readers parse: '1_0' is not 10

    parts = line.strip().split(",")
    if len(parts) != n_values:
        raise ValueError(f"expected {n_values} values t,fx,fy,fz{',...' if n_values > 4 else ''}, got {len(parts)}")
    values = np.array([parse_number(x) for x in parts])
    if not np.all(np.isfinite(values)):
        raise ValueError("non-finite value")
    return values[0], values[1:]


def bounded_lines(source, max_chars: int):
    """The lines of ``source`` (a text stream, or any iterable of lines), none read beyond ``max_chars``.

    A longer line, or one holding a NUL character, raises ValueError naming
    it: a binary or runaway input (``< /dev/zero``) is refused, not read
    whole into memory.
    """
    readline = getattr(source, "readline", None)
    lines = iter(source) if readline is None else iter(lambda: readline(max_chars + 1), "")
    for number, line in enumerate(lines, start=1):
        if len(line) > max_chars:
            raise ValueError(f"standard input: line {number} is longer than {max_chars:,} characters, not a line of "
                             "t,fx,fy,fz (a binary input?)")
        if "\x00" in line:
            raise ValueError(f"standard input: line {number} holds a NUL character: the input is not text")
        yield line


def csv_sink(encoder, out, force=None):
    """A sink writing ``t,afferent,type`` lines (afferent id, type) to ``out``, flushed per call.

    ``t`` is on the input's clock: for an LSL ``force`` stream the bridge's
    stamps (this host's clock) less the stream's ``clock_offset_s``.
    """
    ids, types = encoder.population.afferent_id, encoder.population.afferent_type
    shift_s = 0.0 if force is None else -force.clock_offset_s

    def sink(positions, stamps):
        out.write("".join(f"{t + shift_s:.6f},{ids[a]},{types[a]}\n" for a, t in zip(positions, stamps)))
        out.flush()
    return sink


def stream(encoder, lines, out, err, scale=(1.0, 1.0, 1.0), sink=None, duration=None) -> int:
    """Encode CSV ``lines`` with ``encoder``, sending spikes to ``sink`` (default: lines on ``out``).

    ``scale`` multiplies each sample's (fx, fy, fz): units and sign.  Returns the lines skipped.
    """
    from ddmm.population.runtime.lsl_bridge import GAP_FACTOR

    sink = sink or csv_sink(encoder, out)
    n_sites = 1 if encoder.sites is None else len(encoder.sites)
    shape = (1, 3) if encoder.sites is None else (1, n_sites, 3)
    limit = None if duration is None else int(round(duration * encoder.fs))
    anchor, last, bad, taken = None, None, 0, 0  # anchor: the input's time of the model's t = 0
    max_chars = 64 * (1 + 3 * n_sites) + 256  # room for any decimal notation of each value
    for number, line in enumerate(bounded_lines(lines, max_chars), start=1):
        if not line.strip() or (number == 1 and line[:1].isalpha()):
            continue
        try:
            t, forces = _parse(line, 1 + 3 * n_sites)
            spikes = encoder.push((forces.reshape(-1, 3) * scale).reshape(shape), times=[t])
        except ValueError as exc:
            bad += 1
            print(f"ddmm: line {number} skipped: {exc}", file=err, flush=True)
            continue
        if last is not None and t - last > GAP_FACTOR / encoder.fs:
            print(f"ddmm: line {number}: a gap of {t - last:.6g} s at t = {last:.6g} s; the samples are taken as "
                  "consecutive and the spike times move on by the gap", file=err, flush=True)
            anchor += t - last - 1.0 / encoder.fs  # as the LSL bridge: spikes stay beside their samples
        anchor, last, taken = (t if anchor is None else anchor), t, taken + 1
        if spikes.afferent.size:
            sink(spikes.afferent, anchor + spikes.time)
        if limit is not None and taken >= limit:
            break
    return bad


@contextmanager
def stop_on_signals():
    """A flag that SIGINT and SIGTERM set (instead of ending the process), for a clean stop."""
    flag = []
    handler = lambda *_: flag.append(True)  # noqa: E731 - the smallest signal handler
    previous = {s: signal.signal(s, handler) for s in (signal.SIGINT, signal.SIGTERM)}
    try:
        yield lambda: bool(flag)
    finally:
        for s, h in previous.items():
            signal.signal(s, h)


def _encoder(args, fs, sites):
    from ddmm.experiments.cli.options import parse_contact, parse_types
    from ddmm.population import load_spec, sample_population
    from ddmm.population.runtime.stream import Encoder

    conditioning = conditioning_from_args(args)
    return Encoder(sample_population(load_spec(args.population), rng=args.seed), fs, dt=args.dt * 1e-3,
                   engine=args.engine, seed=args.seed, afferent_types=parse_types(args.types),
                   contact=parse_contact(args.contact),
                   sites=sites, conditioning=conditioning, model_fs=None if conditioning is None else args.model_fs,
                   max_force_n=args.max_force, threads=encoder_threads(args.threads, live=args.lsl_in is not None))


def encoder_threads(threads, *, live: bool):
    """The encoder's threads for ``--threads`` (None: the default).  A parallel push waits at its end for
    every thread, and on a 2-core host a live sender and the spikes' consumers take a core from it now and
    then: measured with the whole hand over LSL, one thread gave a p99 of 0.63-0.86 ms in 9 runs, two
    0.50-3.87 ms in 11 (docs/live-sensors.md)."""
    if threads is not None:
        return threads
    if live and not os.environ.get("DDMM_NUM_THREADS") and (os.cpu_count() or 1) <= 2:
        return 1
    return None


def run(args) -> int:
    from ddmm.population.stimuli.recordings import UNITS

    if args.conditioning == "zero_phase":
        raise ValueError("--conditioning zero_phase looks ahead: a stream is causal or off")
    if args.duration is not None and not args.duration > 0:
        raise ValueError(f"--duration must be > 0 s, got {args.duration:g}")
    if args.threads is not None and args.threads < 1:
        raise ValueError(f"--threads must be >= 1, got {args.threads}")
    if args.lsl_in is None and (args.lsl_source_id is not None):
        raise ValueError("--lsl-source-id goes with --lsl-in")
    if args.lsl_out is None and args.lsl_spike_format is not None:
        raise ValueError("--lsl-spike-format goes with --lsl-out")
    if (args.electrodes is None) != (args.lsl_pulses is None) or (args.electrodes and args.lsl_in is None):
        raise ValueError("--electrodes and --lsl-pulses go together, with --lsl-in")
    if args.lsl_timeout is not None and not args.lsl_timeout >= 0:  # NaN too
        raise ValueError(f"--lsl-timeout must be >= 0 s (0: wait forever), got {args.lsl_timeout:g}")
    sites = sites_option(args.sites)
    if args.lsl_in is not None or args.lsl_out is not None:
        quiet_liblsl(getattr(args, "debug", False))
    if args.lsl_in is not None:
        return _run_lsl(args, sites)
    if args.fs is None:
        raise ValueError("--fs is required when the input is standard input (an LSL stream states its rate)")
    encoder = _encoder(args, args.fs, sites)
    unit = UNITS[args.units or "N"]
    sink, outlet = _spike_sink(args, encoder, None)
    with stop_on_signals():
        stream(encoder, sys.stdin, sys.stdout, sys.stderr, scale=np.array([unit, unit, unit * args.fz_sign]),
               sink=sink, duration=args.duration)
    if outlet is not None:
        outlet.close()
    return 0


def _spike_sink(args, encoder, force):
    if args.lsl_out is None:  # stdout: the input's clock in both modes (the bridge's stamps are this host's)
        return csv_sink(encoder, sys.stdout, force), None
    from ddmm.population.runtime.lsl_outlets import SpikeOutlet

    outlet = SpikeOutlet(args.lsl_out, encoder, force=force, spike_format=args.lsl_spike_format or "events")
    print(f"ddmm: publishing spikes of {len(encoder.positions):,} afferents on LSL stream {args.lsl_out!r} "
          f"(type Spikes, {outlet.spike_format.name} format, source id {outlet.source_id})", file=sys.stderr,
          flush=True)
    return outlet.push, outlet


def _stimulator(args, encoder):
    """The stimulation encoder and its pulse outlet (``--electrodes``), or (None, None)."""
    if args.electrodes is None:
        return None, None
    from ddmm.population.neurostim import StimulationEncoder, read_electrodes
    from ddmm.population.runtime.lsl_outlets import PulseOutlet

    stimulator = StimulationEncoder(encoder, read_electrodes(args.electrodes), args.rule)
    stimulator.warm_up()  # before its stream appears: a consumer that sees it finds the bridge ready
    outlet = PulseOutlet(args.lsl_pulses, stimulator)
    print(f"ddmm: publishing {args.rule} pulses of {len(stimulator.table)} electrode(s) on LSL stream "
          f"{args.lsl_pulses!r} (type StimulationPulses, source id {outlet.source_id})", file=sys.stderr, flush=True)
    return stimulator, outlet


def _run_lsl(args, sites) -> int:
    from ddmm.population.runtime.lsl import open_force_stream
    from ddmm.population.runtime.lsl_bridge import Bridge

    force = open_force_stream(args.lsl_in, n_sites=1 if sites is None else len(sites), fs=args.fs,
                              units=args.units, fz_sign=args.fz_sign, source_id=args.lsl_source_id,
                              timeout=args.resolve_timeout)
    print(f"ddmm: reading LSL stream {force.name!r} from {force.hostname} ({3 * force.n_sites} channels, "
          f"{force.fs:g} Hz, {force.unit})", file=sys.stderr, flush=True)
    try:
        encoder = _encoder(args, force.fs, sites)
        stimulator, pulses = _stimulator(args, encoder)
        if stimulator is None:
            encoder.warm_up()  # before the inlet opens and the spikes' stream appears
        sink, outlet = _spike_sink(args, encoder, force)
        bridge = Bridge(encoder, force, sink, report=lambda m: print(f"ddmm: {m}", file=sys.stderr, flush=True),
                        stimulator=stimulator, pulse_sink=None if pulses is None else pulses.push)
        with stop_on_signals() as should_stop:
            summary = bridge.run(duration=args.duration, should_stop=should_stop,
                                 timeout=args.lsl_timeout if args.lsl_timeout > 0 else None)
    finally:
        force.close()
    for stream_out in (outlet, pulses):
        if stream_out is not None:
            stream_out.close()
    print(f"ddmm: stream ended: {summary.describe()}", file=sys.stderr, flush=True)
    if summary.samples == 0 and summary.stopped == "end of input":
        print("ddmm: the sender closed its stream before a sample reached us (it must wait for its consumer: "
              "LSL drops what an inlet has not pulled)", file=sys.stderr, flush=True)
    return SENDER_FAILED_STATUS if summary.sender_failed else 0


