"""``ddmm stream``: CSV force samples on stdin, spike events on stdout, as they happen.

Input lines are ``t,fx,fy,fz`` (seconds, newtons; a header line is
skipped).  Output lines are ``t,afferent,type``: the spike time in the input's
time base, the afferent's position in the population, and its type.  Output
is flushed after every input line, the shape a sensor driver or stimulator
bridge consumes.  A malformed line, a NaN or time going backwards is reported
on stderr and skipped; the encoder continues exactly as if it had not come.
"""

from __future__ import annotations

import sys

import numpy as np

__all__ = ["register", "stream"]


def register(sub) -> None:
    """Add ``ddmm stream``."""
    p = sub.add_parser("stream", help="encode force samples from stdin into spike events on stdout")
    p.add_argument("--population", default="fingertip")
    p.add_argument("--fs", type=float, required=True, help="sample rate of the input in Hz")
    p.add_argument("--dt", type=float, default=0.1, metavar="MS")
    p.add_argument("--seed", type=int, default=0)
    p.add_argument("--engine", choices=("direct", "brian2"), default="direct")
    p.set_defaults(func=run)


def _parse(line: str):
    parts = line.strip().split(",")
    if len(parts) != 4:
        raise ValueError(f"expected 4 values t,fx,fy,fz, got {len(parts)}")
    values = np.array([float(x) for x in parts])
    if not np.all(np.isfinite(values)):
        raise ValueError("non-finite value")
    return values[0], values[1:]


def stream(encoder, lines, out, err) -> int:
    """Encode ``lines`` with ``encoder``, writing events to ``out`` and problems to ``err``."""
    types = encoder._pop.afferent_type[np.argsort(encoder._order)]  # by population position
    t0, bad = None, 0
    for number, line in enumerate(lines, start=1):
        if not line.strip() or (number == 1 and line[:1].isalpha()):
            continue
        try:
            t, forces = _parse(line)
            spikes = encoder.push(forces[None, :], times=[t])
        except ValueError as exc:
            bad += 1
            print(f"ddmm: line {number} skipped: {exc}", file=err, flush=True)
            continue
        t0 = t if t0 is None else t0
        for a, ts in zip(spikes.afferent, spikes.time):
            out.write(f"{t0 + ts:.6f},{a},{types[a]}\n")
        out.flush()
    return bad


def run(args) -> int:
    from ddmm.population import load_spec, sample_population
    from ddmm.population.runtime.stream import Encoder

    encoder = Encoder(sample_population(load_spec(args.population), rng=args.seed), args.fs, dt=args.dt * 1e-3,
                      engine=args.engine, seed=args.seed)
    stream(encoder, sys.stdin, sys.stdout, sys.stderr)
    return 0
