"""``ddmm physiology``: the population against human microneurography, one row per property."""

from __future__ import annotations

import json
import math

from ddmm.experiments.cli.options import add_engine_option
from ddmm.experiments.io import ensure_out_dir, save_figure, save_json, seed_arg
from ddmm.models.afferent_types import type_label
from ddmm.population.data.published import HUMAN_DSI

__all__ = ["register", "run_scorecard", "scorecard_json"]


def register(sub) -> None:
    """Add ``ddmm physiology``."""
    p = sub.add_parser("physiology", help="scorecard of the population against human afferent physiology")
    p.add_argument("--population", default="fingertip", help="a preset (fingertip, hand, fingertip_vibration) or a spec .toml file")
    p.add_argument("--seed", type=seed_arg, default=0, help="population and noise seed (default 0)")
    p.add_argument("--properties", default=None, metavar="NAME[,NAME...]",
                   help="comma-separated property names (default: all; docs/validation.md lists them)")
    add_engine_option(p, "direct")
    p.add_argument("--out", metavar="DIR", help="write scorecard.json and one figure per protocol here")
    p.add_argument("--json", action="store_true")
    p.set_defaults(func=run_physiology)


def run_scorecard(population="fingertip", seed=0, properties=None, engine="direct"):
    """Sample the population and score it; returns (rows, protocol data)."""
    from ddmm.population import load_spec, sample_population
    from ddmm.population.analysis.physiology import score_physiology
    from ddmm.population.data.published import PHYSIOLOGY_REFERENCE

    pop = sample_population(load_spec(population), rng=seed)
    return score_physiology(pop, PHYSIOLOGY_REFERENCE, properties=properties, seed=seed, engine=engine)


def _finite(x):
    return x if math.isfinite(x) else None  # JSON has no infinity: an open bound is null


def scorecard_json(rows) -> dict:
    """The ``--json`` object: ``{"properties": [...], "all_pass": bool}``."""
    keys = ("name", "type", "protocol", "statistic", "unit", "value", "low", "high", "source", "role", "mark", "pass")
    props = [{k: (_finite(r[k]) if k in ("value", "low", "high") else r[k]) for k in keys} for r in rows]
    return {"properties": props, "all_pass": all(r["pass"] for r in rows)}


def _type(code) -> str:
    """A row's type as displayed: FA-I for RAI, ... (rows of several types keep their text)."""
    try:
        return type_label(code)
    except ValueError:
        return str(code)


def _bound(row):
    high = "inf" if not math.isfinite(row["high"]) else f"{row['high']:g}"
    return f"[{row['low']:g}, {high}]"


def run_physiology(args) -> int:
    names = None if args.properties is None else [n.strip() for n in args.properties.split(",") if n.strip()]
    out_dir = ensure_out_dir(args.out) if args.out else None
    rows, data = run_scorecard(args.population, args.seed, names, args.engine)
    result = scorecard_json(rows)
    if args.json:
        print(json.dumps(result))
    else:
        print(f"# physiology scorecard: {args.population}, seed {args.seed} (roles: fitted = a calibration "
              "objective, constrained = bounds it, held out = never used)\n")
        print("| property | type | protocol | statistic | model | reference | role | pass | source |")
        print("|---|---|---|---|---|---|---|---|---|")
        for r in rows:
            print(f"| {r['name']} | {_type(r['type'])} | {r['protocol']} | {r['statistic']} | {r['value']:.4g} "
                  f"{'' if r['unit'] == '1' else r['unit']} | {_bound(r)} ({r['mark']}) | {r['role']} | "
                  f"{'pass' if r['pass'] else 'FAIL'} | {r['source']} |")
        from ddmm.population.analysis.physiology import summarise_scorecard

        print("\n" + summarise_scorecard(rows))
    if out_dir is not None:
        from ddmm.experiments.plots.physiology import physiology_figures

        save_json(result, out_dir / "scorecard.json")
        for name, fig in physiology_figures(data, HUMAN_DSI).items():
            save_figure(fig, out_dir / name)
    return 0
