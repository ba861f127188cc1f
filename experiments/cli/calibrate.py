"""``ddmm calibrate``: refit the presets to human tuning data, or the paper calibration to its tables."""

from __future__ import annotations

import json
from pathlib import Path

from ddmm.experiments.io import atomic_write, ensure_out_dir, save_json, seed_arg

__all__ = ["register", "run_calibrate"]


def register(sub) -> None:
    """Add ``ddmm calibrate``."""
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


def run_calibrate(args) -> int:
    from ddmm.experiments.calibration.presets import adopt, calibrate, spec_to_toml

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
    from ddmm.experiments.calibration.paper import calibrate_paper, report

    result = report(calibrate_paper(seed=args.seed))
    print(json.dumps(result) if args.json else result["text"])
    if out_dir is not None:
        save_json({k: v for k, v in result.items() if k != "text"}, out_dir / "paper_calibration.json")
    return 0
