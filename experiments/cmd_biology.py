"""``ddmm tuning | calibrate | decode``: the population against human data."""

from __future__ import annotations

import json
from pathlib import Path

TUNING_TRIALS = 5  # ddmm.population.analysis.tuning.DEFAULT_TRIALS, repeated so that registering the parser imports nothing heavy

from ddmm.experiments.io import atomic_write, ensure_out_dir, save_figure, save_json, seed_arg
from ddmm.experiments.paper_values import HUMAN_DIRECTION_THRESHOLD_DEG, HUMAN_DSI, HUMAN_TUNED_FRACTION
from ddmm.models.afferent_types import type_label

__all__ = ["register", "TUNING_REFERENCE", "run_tuning_stats", "decode_summary"]

TUNING_REFERENCE = {
    "tuned_fraction": {"recorded": HUMAN_TUNED_FRACTION["all"], "SAI": HUMAN_TUNED_FRACTION["SAI"],
                       "RAI": HUMAN_TUNED_FRACTION["RAI"], "RAII": "not reported", "SAII": "not reported",
                       "all": "not comparable (includes FA-II, which the 86% does not)"},
    "dsi": {"SAI": {"mean": HUMAN_DSI["SAI"][0], "sd": HUMAN_DSI["SAI"][1]},
            "RAI": {"mean": HUMAN_DSI["RAI"][0], "sd": HUMAN_DSI["RAI"][1]}, "RAII": "not reported",
            "SAII": "not reported"},
    "source": "Birznieks et al. 2001, as the DDMM paper reports it; the 86% pools SA-I, SA-II and FA-I",
    "roles": {"SAI": "fitted", "RAI": "fitted", "SAII": "prediction", "RAII": "prediction",
              "recorded": "count-weighted mix of the fitted SA-I and FA-I fractions and the SA-II prediction"},
}


def register(sub) -> None:
    """Add the tuning, calibrate and decode subcommands."""
    p = sub.add_parser("tuning", help="direction-tuning statistics against human recordings (~86%% tuned)")
    p.add_argument("--population", default="fingertip")
    p.add_argument("--seed", type=seed_arg, default=0)
    p.add_argument("--trials", type=int, default=TUNING_TRIALS, help=f"per condition (default {TUNING_TRIALS})")
    p.add_argument("--engine", choices=("brian2", "direct"), default="direct")
    p.add_argument("--correction", choices=("none", "bonferroni"), default="none")
    p.add_argument("--out", metavar="DIR")
    p.add_argument("--json", action="store_true")
    p.set_defaults(func=run_tuning)
    p = sub.add_parser("calibrate", help="refit both presets to human tuning data under the rate constraints, "
                                         "or (--target paper) the paper calibration to its Table III")
    p.add_argument("--target", choices=("presets", "paper"), default="presets",
                   help="presets (default): the physiological presets; paper: the paper's unpublished constants, "
                        "type by type (docs/model.md, 'The paper calibration')")
    p.add_argument("--seed", type=seed_arg, default=0, help="--target paper: the random search's seed")
    p.add_argument("--out", metavar="DIR", help="write calibrate.json and calibrated_{fingertip,hand}.toml "
                                                "(--target paper: paper_calibration.json) here")
    p.add_argument("--json", action="store_true")
    p.set_defaults(func=run_calibrate)
    p = sub.add_parser("decode", help="decode shear direction (vs 7.1 deg), torque or slip from ddmm.population spikes")
    p.add_argument("--task", choices=("direction", "torque", "slip"), default="direction",
                   help="direction (default), torque (torsion scenes) or slip (incipient-slip scenes)")
    p.add_argument("--trials", type=int, default=20, help="torque and slip: trials per condition, half for training")
    p.add_argument("--population", default="fingertip")
    p.add_argument("--seed", type=seed_arg, default=0)
    p.add_argument("--train", type=int, default=200, help="training trials (directions)")
    p.add_argument("--test", type=int, default=200, help="test trials (directions)")
    p.add_argument("--subsets", type=int, default=10, help="random subsets per population size")
    p.add_argument("--engine", choices=("brian2", "direct"), default="direct")
    p.add_argument("--out", metavar="DIR")
    p.add_argument("--json", action="store_true")
    p.set_defaults(func=run_decode)


def run_tuning_stats(population="fingertip", seed=0, trials=TUNING_TRIALS, engine="direct", correction="none"):
    """Simulate the five-condition protocol and return (tuning dataset, summary)."""
    from ddmm.population import load_spec, sample_population, simulate
    from ddmm.population.analysis.tuning import direction_tuning, tuning_scenes, tuning_summary

    pop = sample_population(load_spec(population), rng=seed)
    ds = simulate(pop, tuning_scenes(), engine=engine, trials=trials, seed=seed, quiet=True)
    tuning = direction_tuning(ds, correction=correction)
    return tuning, tuning_summary(tuning)


def _fmt(v, pct=False):
    if isinstance(v, str):
        return v
    return f"{100 * v:.1f}%" if pct else f"{v:.3f}"


def _row_label(kind: str) -> str:
    """A tuning table row's label: a type, or the pooled rows (the human 86% pools SA-I, SA-II and FA-I)."""
    return {"recorded": "SA-I + SA-II + FA-I", "all": "all four types"}.get(kind) or type_label(kind)


def run_tuning(args) -> int:
    out_dir = ensure_out_dir(args.out) if args.out else None
    tuning, summary = run_tuning_stats(args.population, args.seed, args.trials, args.engine, args.correction)
    result = {"tuned_fraction": summary["tuned_fraction"], "dsi": summary["dsi"], "reference": TUNING_REFERENCE,
              "n_responsive": summary["n_responsive"], "test": f"one-way ANOVA per phase, alpha 0.05, "
              f"correction {args.correction}, {args.trials} trials per condition"}
    if args.json:
        print(json.dumps(result))
    else:
        print(f"# direction tuning: {args.population}, seed {args.seed}, {result['test']}\n")
        print("| type | tuned (model) | tuned (human) | DSI model mean ± SD | DSI human |\n|---|---|---|---|---|")
        for kind in ("SAI", "RAI", "RAII", "SAII", "recorded", "all"):
            ref_f = TUNING_REFERENCE["tuned_fraction"][kind]
            d = summary["dsi"].get(kind)
            ref_d = TUNING_REFERENCE["dsi"].get(kind, "")
            print(f"| {_row_label(kind)} | {_fmt(summary['tuned_fraction'][kind], True)} | {_fmt(ref_f, True)} | "
                  + (f"{d['mean']:.2f} ± {d['sd']:.2f}" if isinstance(d, dict) else (d or ""))
                  + " | " + (f"{ref_d['mean']} ± {ref_d['sd']}" if isinstance(ref_d, dict) else str(ref_d)) + " |")
    if out_dir is not None:
        from ddmm.experiments.plotting import plot_dsi_histograms, plot_preferred_rose

        save_json(result, out_dir / "tuning.json")
        save_figure(plot_dsi_histograms(tuning, HUMAN_DSI), out_dir / "dsi_histograms.png")
        save_figure(plot_preferred_rose(tuning), out_dir / "preferred_directions.png")
    return 0


def run_calibrate(args) -> int:
    from ddmm.experiments.calibrate import adopt, calibrate, spec_to_toml

    out_dir = ensure_out_dir(args.out) if args.out else None
    if args.target == "paper":
        return _calibrate_paper(args, out_dir)
    spec, report = calibrate()
    if args.json:
        print(json.dumps(report))
    else:
        print(json.dumps({"fits": report["fits"], "validation_mean_sd": report["validation"]["mean_sd"],
                          "scorecard": report["validation"]["scorecard_all_pass"]}, indent=1))
    if out_dir is not None:
        save_json(report, out_dir / "calibrate.json")
        header = "# Written by `ddmm calibrate`; copy into population/presets/ to adopt.\n"
        for name, fitted in (("fingertip", spec), ("hand", adopt(spec, "hand"))):
            text = spec_to_toml(fitted, header)
            atomic_write(out_dir / f"calibrated_{name}.toml", lambda tmp, text=text: Path(tmp).write_text(text))
    return 0


def _calibrate_paper(args, out_dir) -> int:
    from ddmm.experiments.calibrate_paper import calibrate_paper, report

    result = report(calibrate_paper(seed=args.seed))
    print(json.dumps(result) if args.json else result["text"])
    if out_dir is not None:
        save_json({k: v for k, v in result.items() if k != "text"}, out_dir / "paper_calibration.json")
    return 0


def decode_summary(population="fingertip", seed=0, train=200, test=200, subsets=10, engine="direct"):
    """Run the decoding protocol; returns (summary dict, best settings)."""
    from ddmm.experiments.decoding import best_settings, run_decoding, summarise

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
        from ddmm.experiments.plotting import plot_neurometric

        save_json({**summary, "best": best}, out_dir / "decode.json")
        save_figure(plot_neurometric(summary, HUMAN_DIRECTION_THRESHOLD_DEG), out_dir / "neurometric.png")
    return 0


def _run_array_task(args) -> int:
    """``ddmm decode --task torque|slip``: the protocols of `ddmm.experiments.array_tasks`."""
    from ddmm.experiments.array_tasks import run_slip, run_torque

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
