"""``ddmm decode``: shear direction, torque or slip decoded from population spikes."""

from __future__ import annotations

import json

from ddmm.experiments.cli.options import add_engine_option
from ddmm.experiments.io import ensure_out_dir, save_figure, save_json, seed_arg
from ddmm.models.afferent_types import type_label
from ddmm.population.data.published import HUMAN_DIRECTION_THRESHOLD_DEG

__all__ = ["decode_summary", "register", "run_decode"]


def register(sub) -> None:
    """Add ``ddmm decode``."""
    p = sub.add_parser("decode", help="decode shear direction (vs 7.1 deg), torque or slip from ddmm.population spikes")
    p.add_argument("--task", choices=("direction", "torque", "slip"), default="direction",
                   help="direction (default), torque (torsion scenes) or slip (incipient-slip scenes)")
    p.add_argument("--trials", type=int, default=20, help="torque and slip: trials per condition, half for training")
    p.add_argument("--population", default="fingertip")
    p.add_argument("--seed", type=seed_arg, default=0)
    p.add_argument("--train", type=int, default=200, help="training trials (directions)")
    p.add_argument("--test", type=int, default=200, help="test trials (directions)")
    p.add_argument("--subsets", type=int, default=10, help="random subsets per population size")
    add_engine_option(p, "direct")
    p.add_argument("--out", metavar="DIR")
    p.add_argument("--json", action="store_true")
    p.set_defaults(func=run_decode)


def decode_summary(population="fingertip", seed=0, train=200, test=200, subsets=10, engine="direct"):
    """Run the decoding protocol; returns (summary dict, best settings)."""
    from ddmm.experiments.validation.decoding import best_settings, run_decoding, summarise

    for name, value in (("--train", train), ("--test", test), ("--subsets", subsets)):
        if value < 1:
            raise ValueError(f"{name} must be >= 1, got {value}")
    summary = summarise(run_decoding(population, seed=seed, n_train=train, n_test=test, subsets=subsets,
                                     engine=engine))
    return summary, best_settings(summary)


def run_decode(args) -> int:
    if args.task != "direction":
        return _run_array_task(args)
    out_dir = ensure_out_dir(args.out) if args.out else None
    summary, best = decode_summary(args.population, args.seed, args.train, args.test, args.subsets, args.engine)
    if args.json:
        print(json.dumps({**summary, "best": best}))
    else:
        print(f"# decoding shear direction: {args.population}, seed {args.seed}; median / p90 error (deg)\n")
        for name, by_w in summary["errors"].items():
            sizes = list(next(iter(by_w.values())))
            print(f"## {name}\n\n| window (ms) | " + " | ".join(f"n = {n}" for n in sizes) + " |")
            print("|---" * (len(sizes) + 1) + "|")
            for w, by_n in by_w.items():
                print(f"| {w} | " + " | ".join(f"{by_n[n]['median_deg']:.1f} / {by_n[n]['p90_deg']:.1f}"
                                              for n in sizes) + " |")
            print()
        print(f"human threshold {HUMAN_DIRECTION_THRESHOLD_DEG} deg; reached first by: {json.dumps(best)}")
    if out_dir is not None:
        from ddmm.experiments.plots.common import plot_neurometric

        save_json({**summary, "best": best}, out_dir / "decode.json")
        save_figure(plot_neurometric(summary, HUMAN_DIRECTION_THRESHOLD_DEG), out_dir / "neurometric.png")
    return 0


def _run_array_task(args) -> int:
    """``ddmm decode --task torque|slip``: the protocols of `ddmm.experiments.validation.array_tasks`."""
    from ddmm.experiments.validation.array_tasks import run_slip, run_torque

    if args.trials < 2:
        raise ValueError(f"--trials must be >= 2 (half train, half test), got {args.trials}")
    out_dir = ensure_out_dir(args.out) if args.out else None
    run = run_torque if args.task == "torque" else run_slip
    result = run(args.population, seed=args.seed, trials=args.trials, subsets=args.subsets, engine=args.engine)
    if args.json:
        print(json.dumps(result))
    else:
        extra = ("magnitude_accuracy",) if args.task == "torque" else ("latency_ms", "false_alarms_per_s")
        print(f"# decoding {args.task} [prediction: never fitted]: {result['protocol']}\n")
        print("| window (ms) | types | n | accuracy | " + " | ".join(extra) + " |\n" + "|---" * (4 + len(extra)) + "|")
        for r in result["results"]:
            values = ["-" if r[k] is None else f"{r[k]:.3g}" for k in extra]
            print(f"| {r['window_ms']} | {'+'.join(type_label(t) for t in r['types'])} | {r['n_afferents']} | {r['accuracy']:.3f} | "
                  + " | ".join(values) + " |")
    if out_dir is not None:
        save_json(result, out_dir / f"decode_{args.task}.json")
    return 0
