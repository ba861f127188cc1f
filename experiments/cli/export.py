"""``ddmm export``: a simulation dataset (.nc) to a Neurodata Without Borders file (.nwb)."""

from __future__ import annotations

from ddmm.experiments.cli.options import check_out_file

__all__ = ["register", "run_export"]


def register(sub) -> None:
    """Add ``ddmm export``."""
    p = sub.add_parser("export", help="write a dataset (.nc) as an NWB file (needs the [nwb] extra)",
                       description="Export a dataset of 'ddmm simulate' to NWB: afferents as units, (condition, "
                                   "trial) pairs as trials on one clock, the forces as stimulus, optionally the "
                                   "stimulation pulses (layout: ddmm.population.io.nwb).")
    p.add_argument("file", metavar="FILE.nc", help="dataset written by 'ddmm simulate'")
    p.add_argument("--nwb", required=True, metavar="OUT.nwb", help="NWB file to write (replaced atomically)")
    p.add_argument("--pulses", default=None, metavar="PULSES.nc",
                   help="stimulation pulses of the same run (ddmm.population.neurostim.save_pulses), written as "
                        "intervals 'stimulation_pulses' with the electrode table")
    g = p.add_argument_group("archive metadata")
    g.add_argument("--experimenter", action="append", default=None, metavar="'LAST, FIRST'",
                   help="who ran the simulation (repeat for several)")
    g.add_argument("--institution", default=None, metavar="TEXT")
    g.add_argument("--related-publication", action="append", default=None, metavar="DOI",
                   help="a related publication as doi:... or a URL (repeat; default the DDMM paper's data DOI)")
    g.add_argument("--identifier", default=None, metavar="TEXT",
                   help="the file's identifier (default: derived from the dataset's content)")
    g.add_argument("--session-start-time", default=None, metavar="ISO8601",
                   help="e.g. 2026-11-25T09:30:00+00:00 (default: when the dataset was simulated)")
    p.set_defaults(func=run_export)


def _start_time(text):
    import datetime as dt

    if text is None:
        return None
    try:
        value = dt.datetime.fromisoformat(text)
    except ValueError:
        raise ValueError(f"--session-start-time {text!r} is not an ISO 8601 date-time "
                         "(e.g. 2026-11-25T09:30:00+00:00)") from None
    if value.tzinfo is None:
        raise ValueError(f"--session-start-time {text!r} needs a time zone (e.g. +00:00)")
    return value


def run_export(args) -> int:
    from ddmm.population import load_dataset, to_nwb

    out = check_out_file(args.nwb, ".nwb", "--nwb", inputs={"dataset": args.file, "--pulses": args.pulses})
    ds = load_dataset(args.file)
    pulses = None
    if args.pulses is not None:
        from ddmm.population.neurostim import load_pulses

        pulses = load_pulses(args.pulses)
    archive = {"experimenter": args.experimenter, "institution": args.institution,
               "identifier": args.identifier, "session_start_time": _start_time(args.session_start_time)}
    if args.related_publication is not None:
        archive["related_publications"] = args.related_publication
    to_nwb(ds, out, pulses=pulses, **archive)
    forces = ", stimulus fingertip_force (N)" if "fx" in ds else ""
    stimulation = "" if pulses is None else \
        f", {pulses.sizes['pulse']} stimulation pulses on {pulses.sizes['electrode']} electrode(s)"
    print(f"wrote {out} ({ds.sizes['afferent']} units, {ds.sizes['condition'] * ds.sizes['trial']} trials "
          f"= {ds.sizes['condition']} condition(s) x {ds.sizes['trial']} trial(s), {ds.sizes['spike']} spikes"
          f"{forces}{stimulation})")
    return 0
