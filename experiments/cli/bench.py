"""``ddmm bench``: the whole pipeline's speed and memory, each case in a fresh process (`ddmm.experiments.bench`)."""

from __future__ import annotations

import json

__all__ = ["register"]


def register(sub) -> None:
    """Add ``ddmm bench``."""
    from ddmm.experiments.bench.cases import CASES, EXTRA_CASES, GROUPS

    p = sub.add_parser("bench", help="speed and memory of the whole pipeline (fresh process per case)")
    p.add_argument("--json", action="store_true")
    p.add_argument("--out", metavar="DIR", help="write bench.json (and scaling.png for --cases scaling) here")
    p.add_argument("--cases", default=None, help="comma-separated groups (" + ", ".join(GROUPS) + "; each stands "
                   "for its cases: docs/performance.md) and cases: " + ", ".join([*CASES, *EXTRA_CASES]))
    p.set_defaults(func=run)


def run(args) -> int:
    """Run the cases ``--cases`` names (all by default), print a table or JSON, and write ``--out``."""
    from ddmm.experiments.bench.cases import CASES, EXTRA_CASES, GROUPS
    from ddmm.experiments.bench.runner import format_table, run_bench

    cases = None if args.cases is None else [c.strip() for c in args.cases.split(",")]
    allowed = [*GROUPS, *CASES, *EXTRA_CASES, *(n for g in GROUPS.values() for n in g)]
    for c in cases or []:
        if c not in allowed:
            raise ValueError(f"--cases: {c!r} is unknown; allowed: {', '.join(allowed)}")
    out_dir = None
    if args.out:
        from ddmm.experiments.io import ensure_out_dir

        out_dir = ensure_out_dir(args.out)
    result = run_bench(cases)
    print(json.dumps(result) if args.json else format_table(result))
    if out_dir is not None:
        from ddmm.experiments.io import save_figure, save_json
        from ddmm.experiments.plots.common import plot_scaling

        save_json(result, out_dir / "bench.json")
        if cases == ["scaling"]:
            save_figure(plot_scaling(result["cases"]), out_dir / "scaling.png")
    return 0
