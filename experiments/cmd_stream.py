"""``ddmm stream``: CSV force samples on stdin, spike events on stdout, as they happen.

Input lines are ``t,fx,fy,fz`` (seconds, and newtons unless ``--units``; a
header line is skipped).  Output lines are ``t,afferent,type``: the spike time
in the input's time base, the afferent's position in the population, and its
type.  Output is flushed after every input line, the shape a sensor driver or
stimulator bridge consumes.  A malformed line, a NaN or time going backwards
is reported on stderr and skipped; the encoder continues exactly as if it had
not come.  The samples pass through the causal conditioning stage
(``--conditioning causal``, the default: docs/recordings.md), which brings any
``--fs`` to the model's ``--model-fs``; the spikes equal ``ddmm simulate`` of
the same samples as a file.  A gap in the time stamps (an interval over 1.5 /
fs) is reported on stderr with its time and length; the rule is that samples
are consecutive (the stream's clock counts samples), so the gap closes up.
"""

from __future__ import annotations

import sys

import numpy as np

from ddmm.experiments.cmd_recordings import add_recording_options, conditioning_from_args
from ddmm.experiments.io import seed_arg

__all__ = ["register", "stream"]


def register(sub) -> None:
    """Add ``ddmm stream``."""
    p = sub.add_parser("stream", help="encode force samples from stdin into spike events on stdout")
    p.add_argument("--population", default="fingertip")
    p.add_argument("--fs", type=float, required=True, help="sample rate of the input in Hz")
    p.add_argument("--dt", type=float, default=0.1, metavar="MS")
    p.add_argument("--seed", type=seed_arg, default=0)
    p.add_argument("--engine", choices=("direct", "brian2"), default="direct")
    p.add_argument("--types", default=None, metavar="T[,T...]",
                   help="afferent types to simulate (leave FA-II out below 750 Hz)")
    p.add_argument("--contact", default=None, metavar="X,Y,R", help="contact centre and radius in mm")
    p.add_argument("--model-fs", type=float, default=1000.0, metavar="HZ",
                   help="the model's sample rate after conditioning (default 1000, as ddmm simulate's files)")
    add_recording_options(p, stream=True)
    p.set_defaults(func=run)


def _parse(line: str):
    parts = line.strip().split(",")
    if len(parts) != 4:
        raise ValueError(f"expected 4 values t,fx,fy,fz, got {len(parts)}")
    values = np.array([float(x) for x in parts])
    if not np.all(np.isfinite(values)):
        raise ValueError("non-finite value")
    return values[0], values[1:]


def stream(encoder, lines, out, err, scale=(1.0, 1.0, 1.0)) -> int:
    """Encode ``lines`` with ``encoder``, writing events to ``out`` and problems to ``err``.

    ``scale`` multiplies each sample's (fx, fy, fz): units and sign.
    """
    types = dict(zip(encoder._order, encoder._pop.afferent_type))  # by population position
    t0, last, bad = None, None, 0
    for number, line in enumerate(lines, start=1):
        if not line.strip() or (number == 1 and line[:1].isalpha()):
            continue
        try:
            t, forces = _parse(line)
            spikes = encoder.push(forces[None, :] * scale, times=[t])
        except ValueError as exc:
            bad += 1
            print(f"ddmm: line {number} skipped: {exc}", file=err, flush=True)
            continue
        if last is not None and t - last > 1.5 / encoder.fs:
            print(f"ddmm: line {number}: a gap of {t - last:.6g} s at t = {last:.6g} s; the samples are taken as "
                  "consecutive (the stream's clock counts samples)", file=err, flush=True)
        t0, last = (t if t0 is None else t0), t
        for a, ts in zip(spikes.afferent, spikes.time):
            out.write(f"{t0 + ts:.6f},{a},{types[a]}\n")
        out.flush()
    return bad


def run(args) -> int:
    from ddmm.experiments.cmd_population import _contact, _types
    from ddmm.population import load_spec, sample_population
    from ddmm.population.runtime.stream import Encoder
    from ddmm.population.stimuli.recordings import UNITS

    if args.conditioning == "zero_phase":
        raise ValueError("--conditioning zero_phase looks ahead: a stream is causal or off")
    conditioning = conditioning_from_args(args)
    encoder = Encoder(sample_population(load_spec(args.population), rng=args.seed), args.fs, dt=args.dt * 1e-3,
                      engine=args.engine, seed=args.seed, types=_types(args.types), contact=_contact(args.contact),
                      conditioning=conditioning, model_fs=None if conditioning is None else args.model_fs)
    unit = UNITS[args.units]
    stream(encoder, sys.stdin, sys.stdout, sys.stderr, scale=np.array([unit, unit, unit * args.fz_sign]))
    return 0
