"""``ddmm accuracy``: the accuracy-cost table, its Pareto plot, and the shipped tolerance table."""

from __future__ import annotations

import json
from importlib import resources

from ddmm.experiments.io import ensure_out_dir, save_figure, save_json

__all__ = ["register", "format_rows"]


def register(sub) -> None:
    """Add ``ddmm accuracy``."""
    p = sub.add_parser("accuracy", help="what a coarser dt or a cheaper method costs in fidelity")
    p.add_argument("--engines", default=None, help="comma-separated engines (default every registered one)")
    p.add_argument("--dts", default=None, metavar="MS,..", help="steps in ms (default 1 ... 0.01)")
    p.add_argument("--methods", default=None, help="comma-separated methods (default all four)")
    p.add_argument("--out", metavar="DIR", help="write accuracy.json and pareto.png here")
    p.add_argument("--json", action="store_true")
    p.add_argument("--write-table", action="store_true",
                   help="store the direct engine's rows as the table simulate(tolerance=...) uses")
    p.set_defaults(func=run)


def format_rows(rows) -> str:
    """Markdown table of the measured rows."""
    head = ("| dt (ms) | method | engine | µs per afferent-s | SF err mean / max (pps) | timing err (ms) "
            "| count mismatch | ΔDSI | Δdecode (deg) |\n|---|---|---|---|---|---|---|---|---|")
    lines = [head]
    for r in rows:
        if r["sf_err_mean"] is None:
            lines.append(f"| {r['dt_ms']:g} | {r['method']} | {r['engine']} | diverged (NaN) | | | | | |")
            continue
        lines.append(f"| {r['dt_ms']:g} | {r['method']} | {r['engine']} | {r['wall_s_per_afferent_s'] * 1e6:.1f} | "
                     f"{r['sf_err_mean']:.3f} / {r['sf_err_max']:.2f} | {r['spike_time_err_ms']:.3f} | "
                     f"{r['count_mismatch']:.3f} | {r['prsi_err']:.4f} | {r['decode_err_delta_deg']:.3f} |")
    return "\n".join(lines)


def _split(text, cast=str):
    return None if text is None else tuple(cast(x.strip()) for x in text.split(","))


def run(args) -> int:
    from ddmm.experiments.validation.accuracy import DTS_MS, run_accuracy, tolerance_table
    from ddmm.models.engines import ENGINES, METHODS
    from ddmm.utils.validation import check_choice

    engines, methods = _split(args.engines) or ENGINES, _split(args.methods) or METHODS
    for e in engines:
        check_choice(e, "--engines", ENGINES)
    for m in methods:
        check_choice(m, "--methods", METHODS)
    out_dir = ensure_out_dir(args.out) if args.out else None
    result = run_accuracy(_split(args.dts, float) or DTS_MS, methods, engines)
    shaped = {"rows": [{k: r[k] for k in ("dt_ms", "method", "engine", "wall_s_per_afferent_s", "sf_err_mean",
                                          "sf_err_max", "spike_time_err_ms", "count_mismatch", "prsi_err",
                                          "decode_err_delta_deg")} for r in result["rows"]],
              "workload": result["workload"]}
    print(json.dumps(shaped) if args.json else format_rows(result["rows"]))
    if out_dir is not None:
        from ddmm.experiments.plots.common import plot_pareto

        save_json(shaped, out_dir / "accuracy.json")
        save_figure(plot_pareto(result["rows"]), out_dir / "pareto.png")
    if args.write_table:
        path = resources.files("ddmm.population").joinpath("data", "accuracy_table.json")
        save_json({"rows": tolerance_table(result), "workload": result["workload"],
                   "written_by": "ddmm accuracy --write-table"}, path)
    return 0
