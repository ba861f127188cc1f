"""``ddmm tuning``: direction-tuning statistics against human recordings."""

from __future__ import annotations

import json

from ddmm.experiments.cli.options import add_engine_option
from ddmm.experiments.io import ensure_out_dir, save_figure, save_json, seed_arg
from ddmm.models.afferent_types import type_label
from ddmm.population.data.published import HUMAN_DSI, HUMAN_TUNED_FRACTION

__all__ = ["TUNING_REFERENCE", "register", "run_tuning", "run_tuning_stats"]

TUNING_TRIALS = 5  # ddmm.population.analysis.tuning.DEFAULT_TRIALS, repeated so that registering the parser imports nothing heavy

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
    """Add ``ddmm tuning``."""
    p = sub.add_parser("tuning", help="direction-tuning statistics against human recordings (~86%% tuned)")
    p.add_argument("--population", default="fingertip")
    p.add_argument("--seed", type=seed_arg, default=0)
    p.add_argument("--trials", type=int, default=TUNING_TRIALS, help=f"per condition (default {TUNING_TRIALS})")
    add_engine_option(p, "direct")
    p.add_argument("--correction", choices=("none", "bonferroni"), default="none")
    p.add_argument("--out", metavar="DIR")
    p.add_argument("--json", action="store_true")
    p.set_defaults(func=run_tuning)


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
        from ddmm.experiments.plots.common import plot_dsi_histograms, plot_preferred_rose

        save_json(result, out_dir / "tuning.json")
        save_figure(plot_dsi_histograms(tuning, HUMAN_DSI), out_dir / "dsi_histograms.png")
        save_figure(plot_preferred_rose(tuning), out_dir / "preferred_directions.png")
    return 0
