"""``ddmm reproduce {table2,table3,fig8,all,table4}``: the paper's tables and figures, cell by cell."""

from __future__ import annotations

import json
import sys
import warnings

from ddmm.experiments.cli.options import add_engine_option
from ddmm.experiments.cli.recording_options import add_recording_options
from ddmm.experiments.io import ensure_out_dir, save_figure, save_json

__all__ = ["register", "format_cells", "format_fig8"]

_WHAT = ("table2", "table3", "fig8", "all", "table4")
#: `ddmm.experiments.paper.calibrations.CALIBRATIONS`' names, here so that the help loads no model code (a test
#: checks that they agree).
CALIBRATION_NAMES = ("paper", "gains-only")


def register(sub) -> None:
    """Add the ``reproduce`` subcommand to an argparse subparsers object."""
    p = sub.add_parser("reproduce", help="reproduce the paper's Tables II-IV and Figs 6-8, cell by cell")
    p.add_argument("what", choices=_WHAT, help="table4 runs the pilot's analysis on --scene (a recording)")
    p.add_argument("--calibration", choices=CALIBRATION_NAMES, default="paper",
                   help="paper (default): the unpublished constants fitted type by type to Table III; "
                        "gains-only: only the gains, fitted to the CMM column (eq. 17 reading, contact-mean SF)")
    add_engine_option(p, "brian2")
    p.add_argument("--no-shear", choices=("pass", "block"), default=None,
                   help="override every type's reading of eq. 17 below F_TH: pass (AF=1) or block (AF=0)")
    p.add_argument("--scene", metavar="FILE.csv", help="table4: the press-push-lift recording (e.g. the authors')")
    p.add_argument("--out", metavar="DIR", help="write PNG figures and reproduce.json here")
    p.add_argument("--json", action="store_true", help="print one JSON object instead of tables")
    add_recording_options(p)
    p.set_defaults(func=run)


def _number(value) -> str:
    return "" if value is None else f"{value:.3g}" if abs(value) < 10 else f"{value:.1f}"


def format_cells(cells: list) -> str:
    """Markdown table of every cell: paper, model, relative error and role."""
    lines = ["| table | type | profile | row | paper | model | rel. error | role |", "|---|---|---|---|---|---|---|---|"]
    for c in cells:
        rel = "" if c["rel_error"] is None else "inf" if c["rel_error"] == float("inf") else f"{c['rel_error']:+.0%}"
        lines.append(f"| {c['table']} | {c['type']} | {c['profile']} | {c['row']} | {_number(c['paper'])} | "
                     f"{_number(c['model'])} | {rel} | {c['role']} |")
    return "\n".join(lines)


def format_fig8(peaks: list) -> str:
    """Markdown table of Fig. 8's peaks (a prediction: in no fit)."""
    lines = ["| type | profile | peak theta_T | off alignment (theta_R = 90°) |", "|---|---|---|---|"]
    for p in peaks:
        peak = "flat" if p["peak_theta_t"] is None else f"{p['peak_theta_t']:g}°"
        off = "" if p["off_alignment_deg"] is None else f"{p['off_alignment_deg']:g}°"
        lines.append(f"| {p['type']} | {p['profile']} | {peak} | {off} |")
    return "\n".join(lines)


def _calibration(args):
    import dataclasses

    from ddmm.experiments.paper.calibrations import CALIBRATIONS, FITTED_CELLS
    from ddmm.experiments.paper.cells import with_engine
    calibration = with_engine(CALIBRATIONS[args.calibration], args.engine)
    if args.no_shear is not None:
        calibration = {k: dataclasses.replace(c, no_shear=args.no_shear) for k, c in calibration.items()}
    return calibration, FITTED_CELLS[args.calibration]


def _describe(calibration) -> str:
    rows = []
    for kind, c in calibration.items():
        rows.append(f"{kind}: reading {c.no_shear}, SF {c.sf_definition}"
                    + (f" ({c.bin_s:g} s bins)" if c.sf_definition == "peak_bin" else "")
                    + f", ramps {c.ramp_s:g}/{c.lift_ramp_s if c.lift_ramp_s is not None else c.ramp_s:g} s, "
                      f"shear onset {c.shear_delay_s * 1e3:g} ms (Birznieks {c.birznieks_shear_delay_s * 1e3:g} ms)")
    return "\n".join(f"- {r}" for r in rows)


def _write_figures(out_dir, what, calibration, result) -> list[str]:
    from ddmm.experiments.paper.reproduce import FIGURE_SCENES, PROFILES, response_data
    from ddmm.experiments.plots.common import plot_response, plot_sf_vs_theta  # matplotlib is slow to import

    written = []
    if what in ("fig8", "all"):
        curves = result["curves"]
        sf = {p: {k: curves[k][p] for k in curves} for p in PROFILES}
        written.append(str(save_figure(plot_sf_vs_theta(sf), out_dir / "fig8.png")))
    names = {"table2": ("fig6",), "table3": ("fig7",), "all": ("fig6", "fig7")}.get(what, ())
    for name in names:
        scene_of, angles = FIGURE_SCENES[name]
        for kind, config in calibration.items():
            for profile in PROFILES:
                data = response_data(scene_of(config), profile, angles, config, afferent_types=(kind,))
                bin_s = config.bin_s if config.sf_definition == "peak_bin" else None  # the bins SF counts in
                fig = plot_response(data, title=f"{name}: {kind}, {profile} (no_shear={config.no_shear})", bin_s=bin_s)
                written.append(str(save_figure(fig, out_dir / f"{name}_{kind}_{profile}.png")))
    return written


def _compute(args, calibration, fitted) -> dict:
    from ddmm.experiments.paper.cells import reproduce_cells
    from ddmm.models.engines import SpikeCapWarning
    if args.what == "table4":
        from ddmm.experiments.paper.table4 import table4
        return table4(args.scene, calibration, args)
    tables = ("table2", "table3", "fig8") if args.what == "all" else (args.what,)
    with warnings.catch_warnings(record=True) as caught:
        warnings.simplefilter("always", SpikeCapWarning)
        result = reproduce_cells(calibration, fitted, tables)
    if any(issubclass(w.category, SpikeCapWarning) for w in caught):
        print("note: the paper's linear RA currents drive some afferents at one spike per step on a fast ramp "
              "(docs/model.md, 'How far the gains-only calibration is from the paper')", file=sys.stderr)
    return result


def run(args) -> int:
    if args.what == "table4" and args.scene is None:
        raise ValueError("ddmm reproduce table4 needs --scene FILE.csv: the press-push-lift recording to analyse")
    if args.what != "table4" and args.scene is not None:
        raise ValueError(f"--scene goes with 'ddmm reproduce table4' only; {args.what} uses the paper's synthetic "
                         "scenes")
    calibration, fitted = _calibration(args)
    out_dir = ensure_out_dir(args.out) if args.out else None
    result = _compute(args, calibration, fitted)
    public = {k: v for k, v in result.items() if k in ("cells", "fig8")}
    if args.json:
        print(json.dumps(public))
    else:
        print(f"# DDMM reproduction: calibration {args.calibration}, engine {args.engine}, dt 0.1 ms, k 3\n")
        print(_describe(calibration) + "\n")
        print("Roles: fitted = an objective of the calibration's fit; reproduced = zero or equal by symmetry; "
              "prediction = in no fit.\n")
        if public.get("cells"):
            print(format_cells(public["cells"]) + "\n")
        if "fig8" in public:
            print("## Fig. 8: SF against theta_T (prediction)\n\n" + format_fig8(public["fig8"]) + "\n")
    if out_dir is not None:
        save_json(result, out_dir / "reproduce.json")
        for path in _write_figures(out_dir, args.what, calibration, result):
            if not args.json:
                print(f"wrote {path}")
    return 0
