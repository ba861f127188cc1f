"""``ddmm stimulate``: the stimulation pulses an electrode table receives from a simulated run.

Reads a run of ``ddmm simulate`` (spikes and forces recorded) and an
electrode table (CSV or TOML: docs/stimulation.md), encodes under a named
rule, checks every pulse against its electrode's limits from the result alone
(`check_pulses`; a violation writes nothing), writes the pulses (.nc) and,
beside them, one figure per condition (``PULSES_<condition>.png``: force under
each field, aggregate afferent rate, pulses), and prints a line per electrode.
"""

from __future__ import annotations

import re

from ddmm.experiments.cli.options import check_out_file

__all__ = ["register", "run_stimulate", "RULE_OPTIONS"]

#: The rule settings the command line takes, and the rules each applies to.
RULE_OPTIONS = {"force_sat": ("linear-amplitude", "linear-frequency"), "rate_hz": ("linear-amplitude",),
                "rate_sat": ("biomimetic",), "tau": ("biomimetic",)}
#: Each option's rule setting, the factor to the rule's unit and the option's unit (ranges: rules.RANGES).
_SETTINGS = {"force_sat": ("force_sat_n", 1.0, "N"), "rate_hz": ("rate_hz", 1.0, "Hz"),
             "rate_sat": ("rate_sat_hz", 1.0, "Hz"), "tau": ("tau_s", 1e-3, "ms")}


def register(sub) -> None:
    """Add ``ddmm stimulate``."""
    p = sub.add_parser("stimulate", help="pulse trains for an electrode table from a simulated run (.nc)",
                       description="Encode a run's afferent activity (or the force under each electrode's field) "
                                   "into charge-balanced biphasic pulses within every limit of the electrode table.")
    p.add_argument("file", metavar="RUN.nc", help="dataset written by 'ddmm simulate'")
    p.add_argument("--electrodes", required=True, metavar="E.csv|E.toml", help="the electrode table")
    p.add_argument("--rule", default="biomimetic", choices=("biomimetic", "linear-amplitude", "linear-frequency"))
    p.add_argument("--out", required=True, metavar="PULSES.nc", help="pulses file (figures are written beside it)")
    p.add_argument("--force-sat", type=float, default=None, metavar="N",
                   help="linear rules: force under the field at which the output saturates, in (0.05, 500] "
                        "(default 5)")
    p.add_argument("--rate-hz", type=float, default=None, metavar="HZ",
                   help="linear-amplitude: the pulse rate, in [1, 2000] (default 100)")
    p.add_argument("--rate-sat", type=float, default=None, metavar="HZ",
                   help="biomimetic: aggregate rate (spikes/s per field afferent) giving the maximum pulse rate, "
                        "in (0, 1000] (default 100)")
    p.add_argument("--tau", type=float, default=None, metavar="MS",
                   help="biomimetic: smoothing of the aggregate rate, in (0, 1000] (default 20)")
    p.add_argument("--no-figures", action="store_true", help="write the pulses file only")
    p.set_defaults(func=run_stimulate)


def _rule(args):
    from ddmm.population.neurostim import RULES
    from ddmm.population.neurostim.rules import check_setting

    settings = {}
    for option, rules in RULE_OPTIONS.items():
        value = getattr(args, option)
        if value is None:
            continue
        flag = f"--{option.replace('_', '-')}"
        if args.rule not in rules:
            raise ValueError(f"{flag} applies to the {' and '.join(rules)} rule(s), not --rule {args.rule}")
        name, scale, unit = _SETTINGS[option]
        check_setting(flag, name, value, scale, unit)  # in the option's unit: --tau 1e15 (ms) would emit nothing
        settings[name] = value * scale
    return RULES[args.rule](**settings)


def _summary(pulses) -> list:
    lines = []
    for i, e in enumerate(pulses.electrode.values):
        mine = pulses.pulse_electrode.values == i
        amp = pulses.pulse_amplitude.values[mine]
        field = (f"region {pulses.region.values[i]}" if pulses.region.values[i] else
                 f"disc ({pulses.x_mm.values[i]:g}, {pulses.y_mm.values[i]:g}) mm r {pulses.radius_mm.values[i]:g}")
        span = f", {amp.min():.1f}-{amp.max():.1f} uA" if amp.size else ""
        lines.append(f"  {e}: {int(mine.sum()):,} pulses{span} (field: {field})")
    return lines


def run_stimulate(args) -> int:
    from ddmm.experiments.io import save_figure
    from ddmm.population import load_dataset
    from ddmm.population.neurostim import read_electrodes, save_pulses, stimulation_pulses

    out = check_out_file(args.out, ".nc", "--out", inputs={"dataset": args.file, "--electrodes": args.electrodes})
    table, rule = read_electrodes(args.electrodes), _rule(args)
    pulses = stimulation_pulses(load_dataset(args.file), table, rule)
    save_pulses(pulses, out)
    print(f"wrote {out}: {pulses.sizes['pulse']:,} pulses on {len(table)} electrode(s), rule {rule.name}; every "
          "pulse within its electrode's amplitude, charge and rate limits, none out of contact (checked)")
    print("\n".join(_summary(pulses)))
    if not args.no_figures:
        from ddmm.experiments.plots.neurostim import plot_stimulation

        for c, name in enumerate(pulses.condition.values):
            path = out.with_name(f"{out.stem}_{re.sub(r'[^A-Za-z0-9_.-]+', '_', str(name))}.png")
            save_figure(plot_stimulation(pulses, condition=c, trial=0), path)
            print(f"wrote {path}")
    return 0
