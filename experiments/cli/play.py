"""``ddmm play``: a scene's forces published as an LSL force stream in real time (a test sensor)."""

from __future__ import annotations

import sys
import time

import numpy as np

from ddmm.experiments.cli.stream import stop_on_signals
from ddmm.experiments.io import seed_arg

__all__ = ["register", "run_play"]


def register(sub) -> None:
    """Add ``ddmm play``."""
    p = sub.add_parser("play", help="publish a scene's forces as an LSL force stream in real time (a test sensor)")
    p.add_argument("--lsl-out", required=True, metavar="NAME", help="the force stream's LSL name")
    p.add_argument("--scene", default="press-push-lift", choices=("birznieks", "press-push-lift", "rotating-shear"))
    p.add_argument("--theta-r", type=float, default=90.0, metavar="DEG", help="shear direction in degrees")
    p.add_argument("--fs", type=float, default=1000.0, metavar="HZ", help="the stream's sample rate (default 1000)")
    p.add_argument("--units", default="N", choices=("N", "mN", "gf"), help="the stream's force unit (declared)")
    p.add_argument("--noise", type=float, default=0.0, metavar="N", help="white sensor noise SD in newtons")
    p.add_argument("--seed", type=seed_arg, default=0)
    p.add_argument("--repeat", type=int, default=1, help="times to play the scene (default 1)")
    p.add_argument("--wait", type=float, default=120.0, metavar="S",
                   help="seconds to wait for a consumer before playing (default 120: a first run compiles the "
                        "model's kernels before it connects); after playing it waits up to 1 s for it to catch up")
    p.set_defaults(func=run_play)


def run_play(args) -> int:
    from ddmm.experiments.io import quiet_liblsl

    quiet_liblsl(getattr(args, "debug", False))  # before liblsl starts
    from ddmm.population import birznieks, press_push_lift, rotating_shear
    from ddmm.population.runtime.lsl import open_force_outlet
    from ddmm.population.runtime.lsl_bridge import play_forces
    from ddmm.population.stimuli.recordings import UNITS

    make = {"birznieks": birznieks, "press-push-lift": press_push_lift,
            "rotating-shear": lambda d: rotating_shear(start_deg=d)}[args.scene]
    if args.repeat < 1 or args.noise < 0 or not args.fs > 0:
        raise ValueError(f"--repeat must be >= 1, --noise >= 0 and --fs > 0; got {args.repeat}, {args.noise:g}, "
                         f"{args.fs:g}")
    scene = make(args.theta_r)
    t = np.arange(int(scene.duration * args.fs)) / args.fs
    forces = np.column_stack([np.interp(t, scene.time, f) for f in (scene.fx, scene.fy, scene.fz)])
    forces = np.tile(forces, (args.repeat, 1))
    forces += np.random.default_rng(args.seed).normal(0.0, args.noise, forces.shape)
    outlet = open_force_outlet(args.lsl_out, fs=args.fs, units=args.units)
    deadline = time.monotonic() + args.wait
    print(f"ddmm: waiting up to {args.wait:g} s for a consumer of LSL stream {args.lsl_out!r}", file=sys.stderr,
          flush=True)
    while not outlet.have_consumers() and time.monotonic() < deadline:
        time.sleep(0.01)
    print(f"ddmm: playing {scene.name} ({forces.shape[0] / args.fs:g} s at {args.fs:g} Hz, {args.units}) on LSL "
          f"stream {args.lsl_out!r}", file=sys.stderr, flush=True)
    with stop_on_signals() as should_stop:
        pushed = play_forces(outlet, forces / UNITS[args.units], args.fs, should_stop=should_stop)
        time.sleep(min(args.wait, 1.0))  # LSL drops what a consumer has not pulled when the outlet closes
    print(f"ddmm: played {pushed:,} samples", file=sys.stderr, flush=True)
    return 0
