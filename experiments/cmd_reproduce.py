"""``ddmm reproduce {table2,table3,fig8,all}``: the paper's tables and figures."""

from __future__ import annotations

import json
import sys
import warnings

from ddmm.experiments.io import ensure_out_dir, save_figure, save_json
from ddmm.experiments.paper_values import PAPER_TABLE2, PAPER_TABLE3

__all__ = ["register", "format_table2", "format_table3", "format_fig8"]

_HUMAN_DSI = {"SAI": "0.23 ± 0.18", "RAI": "0.24 ± 0.18", "RAII": "not reported"}


def register(sub) -> None:
    """Add the ``reproduce`` subcommand to an argparse subparsers object."""
    p = sub.add_parser("reproduce", help="reproduce the paper's Table II, Table III and Fig. 8")
    p.add_argument("what", choices=("table2", "table3", "fig8", "all"))
    p.add_argument("--engine", choices=("brian2", "direct"), default="brian2")
    p.add_argument("--no-shear", choices=("pass", "block"), default="pass",
                   help="reading of eq. 17 below F_TH: pass (AF=1, default) or block (AF=0)")
    p.add_argument("--out", metavar="DIR", help="write PNG figures and reproduce.json here")
    p.add_argument("--json", action="store_true", help="print one JSON object instead of tables")
    p.set_defaults(func=run)


def format_table2(result: dict) -> str:
    """Markdown table of our PRSI beside the paper's."""
    from ddmm.experiments.reproduce import PROFILES
    from ddmm.models.afferent_types import PAPER_TYPES
    prsi = result["prsi"]
    lines = ["| type | " + " | ".join(f"{p} ours (paper)" for p in PROFILES) + " | human DSI |",
             "|---" * (len(PROFILES) + 2) + "|"]
    for t in PAPER_TYPES:
        cells = [f"{prsi[p][t]:.2f} ({PAPER_TABLE2[p][t]:.2f})" for p in PROFILES]
        lines.append(f"| {t} | " + " | ".join(cells) + f" | {_HUMAN_DSI[t]} |")
    return "\n".join(lines)


def format_table3(result: dict) -> str:
    """Markdown table of our SF at 75/255 deg beside the paper's."""
    from ddmm.experiments.reproduce import PROFILES
    from ddmm.models.afferent_types import PAPER_TYPES
    sf = result["sf"]
    lines = ["| type | " + " | ".join(f"{p} 75° / 255° ours (paper)" for p in PROFILES) + " |",
             "|---" * (len(PROFILES) + 1) + "|"]
    for t in PAPER_TYPES:
        cells = []
        for p in PROFILES:
            a, b = sf[p][t]["75"], sf[p][t]["255"]
            pa, pb = PAPER_TABLE3[p][t]
            cells.append(f"{a:.1f} / {b:.1f} ({pa:g} / {pb:g})")
        lines.append(f"| {t} | " + " | ".join(cells) + " |")
    return "\n".join(lines)


def format_fig8(result: dict) -> str:
    """Markdown summary of Fig. 8: peak angle, range and bipolar symmetry."""
    from ddmm.experiments.reproduce import PROFILES
    from ddmm.models.afferent_types import PAPER_TYPES
    sf = result["sf"]
    lines = ["| profile | type | peak theta_T | SF min-max (pulses/s) | SF(θ) = SF(θ+180°) |",
             "|---|---|---|---|---|"]
    for p in PROFILES:
        for t in PAPER_TYPES:
            curve = {float(a): v for a, v in sf[p][t].items()}
            peak = max(curve, key=curve.get)
            sym = all(curve[a] == curve[(a + 180.0) % 360.0] for a in curve)
            lines.append(f"| {p} | {t} | {peak:g}° | {min(curve.values()):.1f}-{max(curve.values()):.1f}"
                         f" | {'yes' if sym else 'no'} |")
    return "\n".join(lines)


def _write_figures(out_dir, what, config, result) -> list[str]:
    from ddmm.experiments.plotting import plot_response, plot_sf_vs_theta  # matplotlib is slow to import
    from ddmm.experiments.reproduce import FIGURE_SCENES, PROFILES, response_data

    written = []
    if what in ("fig8", "all"):
        sf = result["fig8"]["sf"] if what == "all" else result["sf"]
        written.append(str(save_figure(plot_sf_vs_theta(sf), out_dir / "fig8.png")))
    if what in ("table2", "table3", "all"):
        names = {"table2": ("fig6",), "table3": ("fig7",), "all": ("fig6", "fig7")}[what]
        for name in names:
            make_scene, angles = FIGURE_SCENES[name]
            for profile in PROFILES:
                data = response_data(make_scene(), profile, angles, config)
                fig = plot_response(data, title=f"{name}: {profile} (no_shear={config.no_shear})")
                written.append(str(save_figure(fig, out_dir / f"{name}_{profile}.png")))
    return written


def run(args) -> int:
    from ddmm.experiments.reproduce import ReproConfig, fig8, reproduce_all, table2, table3
    from ddmm.models.engines import SpikeCapWarning
    config = ReproConfig(engine=args.engine, no_shear=args.no_shear)
    out_dir = ensure_out_dir(args.out) if args.out else None
    compute = {"table2": table2, "table3": table3, "fig8": fig8, "all": reproduce_all}[args.what]
    with warnings.catch_warnings(record=True) as caught:
        warnings.simplefilter("always", SpikeCapWarning)
        result = compute(config)
    if any(issubclass(w.category, SpikeCapWarning) for w in caught):
        print("note: the paper's linear RA currents drive some afferents at one spike per step on Birznieks' "
              "32 N/s ramp (docs/model.md, 'How far we are from the paper')", file=sys.stderr)
    if args.json:
        print(json.dumps(result))
    else:
        parts = {"table2": result if args.what == "table2" else result.get("table2"),
                 "table3": result if args.what == "table3" else result.get("table3"),
                 "fig8": result if args.what == "fig8" else result.get("fig8")}
        header = f"engine={config.engine}, no_shear={config.no_shear}, dt={config.dt * 1e3:g} ms, k={config.k:g}"
        print(f"# DDMM reproduction ({header})\n")
        for name, fmt, title in (("table2", format_table2, "Table II: PRSI, Birznieks scene, theta_R = 90°"),
                                 ("table3", format_table3, "Table III: SF (pulses/s), press-push-lift"),
                                 ("fig8", format_fig8, "Fig. 8: SF against theta_T")):
            if parts[name] is not None:
                print(f"## {title}\n\n{fmt(parts[name])}\n")
    if out_dir is not None:
        save_json(result, out_dir / "reproduce.json")
        for path in _write_figures(out_dir, args.what, config, result):
            if not args.json:
                print(f"wrote {path}")
    return 0
