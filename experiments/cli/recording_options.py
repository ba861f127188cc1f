"""Command-line options for recorded forces, shared by ``ddmm simulate``/``plan`` (a ``--scene FILE.csv`` or
``FILE.xdf``) and ``ddmm stream`` (samples on stdin or LSL): columns, units, sign, time base, negative force, sites
and the conditioning stage.

`RECORDINGS` is where a recorded format is registered: the extension ``--scene`` names, and its reader.
"""

from __future__ import annotations

from collections.abc import Callable
from typing import NamedTuple

__all__ = ["RECORDINGS", "RecordedFormat", "add_recording_options", "conditioning_from_args", "csv_scene",
           "given_recording_options", "recorded_scene", "refuse_csv_options", "sites_option", "xdf_scene"]

_FIELDS = ("time", "fx", "fy", "fz")
# the single-site CSV reader's options and their defaults (a sensor-array file states its own)
_CSV_ONLY = {"columns": None, "fs": None, "time_scale": None, "negative_fz": "error", "gaps": "error",
             "units": None, "fz_sign": 1}
# Conditioning field -> option attribute
_CONDITIONING = {"noise_n": "sensor_noise", "bandwidth_hz": "bandwidth", "shear_hold_n": "shear_hold",
                 "normal_hold_n": "normal_hold", "adapt_noise": "adapt_noise"}


def add_recording_options(p, *, stream: bool = False, xdf: bool = False) -> None:
    """Add the recording options to a subcommand's parser (the file-only ones unless ``stream``; ``--stream``, of
    an XDF file, with ``xdf``)."""
    from ddmm.population.stimuli.file_options import GAPS, MAX_FORCE_N, NEGATIVE_FZ, UNITS

    g = p.add_argument_group("recorded forces" + ("" if stream else " (--scene FILE.csv" +
                                                   ("|FILE.xdf)" if xdf else ")")))
    if not stream:
        g.add_argument("--columns", default=None, metavar="time=COL,fx=COL,...",
                       help="the file's column for each of time, fx, fy, fz (headers match in any case)")
        g.add_argument("--fs", type=float, default=None, metavar="HZ",
                       help="sample rate of a file without a time column")
        g.add_argument("--time-scale", type=float, default=None, metavar="S",
                       help="the time column's unit in seconds (0.001 for ms; default: the unit its header names, "
                            "as in 'Time (ms)', else 1)")
        g.add_argument("--negative-fz", choices=NEGATIVE_FZ, default="error",
                       help="a negative normal force beyond sensor noise: an error (default), clipped, or the "
                            "first 0.1 s taken as the sensor's zero offset")
        g.add_argument("--gaps", choices=GAPS, default="error", help="gaps in the time column: refused or filled")
    if xdf:
        g.add_argument("--stream", default=None, metavar="NAME",
                       help="the force stream of an .xdf --scene (a LabRecorder session), by name, read as "
                            "'ddmm stream --lsl-in' reads it live: its channels' sites from --sites, an irregular "
                            "stream's rate from --fs")
    g.add_argument("--units", choices=tuple(UNITS), default=None,
                   help="force unit of the input (default: " + ("an LSL stream's declared unit, else N)" if stream else
                                                                "the unit the headers name, as in 'Fz (mN)'" +
                                                                (", or an XDF stream declares" if xdf else "") +
                                                                ", else N)"))
    g.add_argument("--fz-sign", type=int, choices=(1, -1), default=1,
                   help="-1 for a sensor that reports pressing as negative F_Z")
    g.add_argument("--max-force", type=float, default=MAX_FORCE_N, metavar="N",
                   help=f"refuse a force beyond N newtons at a site (default {MAX_FORCE_N:g}: no hand contact comes "
                        "near; beyond it the input is in the wrong unit)")
    g.add_argument("--conditioning", choices=("causal", "zero_phase", "off"), default="causal",
                   help="the conditioning stage between the recording and the model (default causal; "
                        "zero_phase offline only; docs/recordings.md)")
    g.add_argument("--sensor-noise", type=float, default=None, metavar="N",
                   help="the sensor's noise SD in newtons, at most: the fast band is gated at 4x it, or at 4x five "
                        "times the noise measured as the samples stream, whichever is smaller (default 0.02; 0: off)")
    g.add_argument("--fixed-noise", dest="adapt_noise", action="store_const", const=False, default=None,
                   help="condition for --sensor-noise always, not for the noise the samples show")
    g.add_argument("--bandwidth", type=float, default=None, metavar="HZ", help="the sensor's bandwidth in Hz")
    g.add_argument("--shear-hold", type=float, default=None, metavar="N",
                   help="the shear hold's least width in newtons: tangential force moves only beyond +- it, "
                        "wider on a noisy slow recording (default 0.025; 0: off)")
    g.add_argument("--normal-hold", type=float, default=None, metavar="N",
                   help="the normal hold's least width in newtons: in contact, F_Z moves only beyond +- it, "
                        "wider on a noisy slow recording (default 0.025; 0: off)")


def conditioning_from_args(args):
    """The `Conditioning` the options name, or None for ``--conditioning off``."""
    from ddmm.population.stimuli.conditioning import Conditioning

    if args.conditioning == "off":
        if any(getattr(args, name) is not None for name in _CONDITIONING.values()):
            raise ValueError("--sensor-noise, --fixed-noise, --bandwidth, --shear-hold and --normal-hold set the "
                             "conditioning, which --conditioning off switches off")
        return None
    settings = {field: getattr(args, name) for field, name in _CONDITIONING.items() if getattr(args, name) is not None}
    return Conditioning(mode=args.conditioning, **settings)


def given_recording_options(args) -> list:
    """The recording options (`add_recording_options`) given away from their defaults, as the command line spells
    them (``--fs``, ``--fixed-noise``, ...)."""
    from ddmm.population.stimuli.file_options import MAX_FORCE_N

    defaults = {**_CSV_ONLY, **dict.fromkeys(_CONDITIONING.values()), "stream": None, "max_force": MAX_FORCE_N,
                "conditioning": "causal"}
    flags = {name: "--fixed-noise" if name == "adapt_noise" else f"--{name.replace('_', '-')}" for name in defaults}
    return [flags[name] for name, default in defaults.items() if getattr(args, name, default) != default]


def refuse_csv_options(args, scene: str) -> None:
    """Raise if a single-site CSV option was given for ``scene`` (a sensor-array file), which has none."""
    for name, default in _CSV_ONLY.items():
        if getattr(args, name, default) != default:
            raise ValueError(f"--{name.replace('_', '-')} applies to a single-site .csv --scene, not to the "
                             f"sensor-array scene {scene!r} (its file states forces in N, F_Z >= 0)")


def _columns(text):
    if text is None:
        return None
    out = {}
    for part in text.split(","):
        key, sep, value = part.partition("=")
        key = key.strip().lower()
        if not sep or key not in _FIELDS or not value.strip():
            raise ValueError(f"--columns: {part.strip()!r} is not NAME=COLUMN with NAME one of {', '.join(_FIELDS)}")
        out[key] = value.strip()
    return out


def csv_scene(path, args, contact):
    """The scene of a recorded force file, read with the options of `add_recording_options`."""
    from ddmm.population.stimuli.recordings import from_csv

    return from_csv(path, columns=_columns(args.columns), recorded_fs=args.fs, time_scale=args.time_scale,
                    units=args.units, fz_sign=args.fz_sign, negative_fz=args.negative_fz, gaps=args.gaps,
                    conditioning=conditioning_from_args(args), contact=contact, max_force_n=args.max_force)


def sites_option(text):
    """The `Sites` of ``--sites SITES.csv|fingertips`` (None without it): a sites table, or the five digit tips."""
    if text is None:
        return None
    if text == "fingertips":
        from ddmm.population.stimuli.site_scenes import digit_tip_sites
        return digit_tip_sites()
    from ddmm.population.io import read_sites_csv
    from ddmm.population.io.arrays import default_radius
    from ddmm.population.stimuli.scenes import Sites

    where, fields, _ = read_sites_csv(text)
    radius = fields["radius_mm"]
    if radius is None:
        try:
            radius = default_radius(fields["x_mm"], fields["y_mm"])
        except ValueError as exc:
            raise ValueError(f"{where}: {exc}") from None
    return Sites(fields["x_mm"], fields["y_mm"], radius, region=fields["region"], site_id=fields["site"])


def xdf_scene(path, args, contact):
    """The scene of a force stream in an XDF file (``--stream``), read as ``ddmm stream --lsl-in`` reads it live."""
    from ddmm.population.io.xdf import from_xdf

    for name in ("columns", "time_scale"):
        if getattr(args, name, None) is not None:
            raise ValueError(f"--{name.replace('_', '-')} applies to a .csv --scene, not to the XDF file {path!r} "
                             "(its stream header states its channels)")
    for name, default in (("negative_fz", "error"), ("gaps", "error")):
        if getattr(args, name, default) != default:
            raise ValueError(f"--{name.replace('_', '-')} applies to a .csv --scene, not to the XDF file {path!r}: "
                             "its samples take the live bridge's rules (docs/live-sensors.md)")
    sites = sites_option(args.sites)
    if sites is not None and contact is not None:
        raise ValueError("--contact does not apply with --sites: each site has its own footprint")
    return from_xdf(path, args.stream, sites=sites, recorded_fs=args.fs, units=args.units, fz_sign=args.fz_sign,
                    conditioning=conditioning_from_args(args), contact=contact, max_force_n=args.max_force)


class RecordedFormat(NamedTuple):
    """A recorded format ``--scene FILE`` reads: its reader, ``reader(path, args, contact)``, and whether
    ``--sites`` names the sites of its channels and ``--stream`` picks one of its streams."""

    reader: Callable
    sites: bool = False
    streams: bool = False


#: The recorded formats ``--scene FILE`` reads, by extension (any case).  A format is registered here, once:
#: `recorded_scene` and the options' checks follow.
RECORDINGS = {".csv": RecordedFormat(csv_scene),
              ".xdf": RecordedFormat(xdf_scene, sites=True, streams=True),
              ".xdfz": RecordedFormat(xdf_scene, sites=True, streams=True)}


def recorded_scene(args, contact):
    """The scene of ``--scene FILE`` when a format of `RECORDINGS` reads it, else None."""
    from pathlib import Path

    found = RECORDINGS.get(Path(args.scene).suffix.lower())
    if found is None:
        return None
    if args.theta_r is not None:
        raise ValueError(f"--theta-r does not apply to the recorded scene {args.scene!r}: the file gives the forces")
    return found.reader(args.scene, args, contact)
