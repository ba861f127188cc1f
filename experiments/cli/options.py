"""Command-line options shared by several ``ddmm`` commands: engines, runs, scenes, output files.

Engine choices come from the engine registry (`ddmm.models.engines.registry`):
a registered engine appears in every ``--engine`` option without an edit here.
"""

from __future__ import annotations

import argparse
import math
import re
from pathlib import Path

from ddmm.experiments.cli.recording_options import (
    RECORDINGS,
    add_recording_options,
    conditioning_from_args,
    given_recording_options,
    recorded_scene,
    refuse_csv_options,
)
from ddmm.experiments.io import seed_arg
from ddmm.population.io.formats import EXTENSIONS

__all__ = ["SCENES", "add_engine_option", "add_run_options", "check_out_file", "parse_contact", "parse_directions",
           "parse_types", "population_from_args", "scenes_from_args"]

#: The synthetic scenes ``--scene`` names (besides a recording or a sensor-array file).
SCENES = ("birznieks", "press-push-lift", "rotating-shear")


def add_engine_option(p, default: str) -> None:
    """``--engine``, its choices the registered engines, its help each engine's summary."""
    from ddmm.models.engines.registry import engine_names, get_engine

    summaries = "; ".join(f"{name}: {get_engine(name).summary}" for name in engine_names())
    p.add_argument("--engine", choices=engine_names(), default=default,
                   help=f"the engine that integrates the neurons (default {default}). {summaries}")


def add_run_options(p, *, out_required: bool) -> None:
    """The options of ``ddmm simulate`` and ``ddmm plan``: population, scene, engine, step, trials, output."""
    p.add_argument("--population", default="fingertip", help="a preset (fingertip, hand, fingertip_vibration) or a spec .toml file")
    p.add_argument("--scene", default=None,
                   help=f"{', '.join(SCENES)} (default birznieks), a force .csv file, an .xdf session (LabRecorder; "
                        f"with --stream), or a sensor-array file ({', '.join(EXTENSIONS)}; a long .csv with --sites)")
    p.add_argument("--sites", default=None, metavar="SITES.csv",
                   help="sites table (site,x_mm,y_mm[,region][,radius_mm]): --scene is then a long CSV "
                        "of time,site,fx,fy,fz; with an .xdf --scene, the sites of its stream's channels "
                        "(or 'fingertips', as ddmm stream)")
    p.add_argument("--theta-r", default=None, metavar="DEG[,DEG...]",
                   help="shear direction(s) in degrees, one condition each ('none': normal only); default 90")
    p.add_argument("--contact", default=None, metavar="X,Y,R", help="contact centre and radius in mm")
    p.add_argument("--indent", default=None, metavar="KIND[:KEY=VALUE,...]|FILE.toml",
                   help="an indentation stimulus instead of --scene: ramp, sine, noise or impulse with its settings "
                        "(e.g. sine:freq_hz=250,amplitude_mm=0.02,pre_indent_mm=0.3,skin=touchsim), or a TOML "
                        "file of the same keys (docs/user-guide.md, \"Indentation\")")
    add_engine_option(p, "brian2")
    p.add_argument("--dt", type=step_ms, default=None, metavar="MS", help="integration step in ms (default 0.1)")
    p.add_argument("--method", choices=("euler", "rk2", "rk4", "izhikevich2003"), default=None,
                   help="integration scheme (default euler)")
    p.add_argument("--tolerance", type=float, default=None, metavar="PPS",
                   help="choose the cheapest dt and method whose mean SF error is within PPS pulses/s")
    p.add_argument("--trials", type=int, default=1)
    p.add_argument("--seed", type=seed_arg, default=0, help="seed of the population and the noise (default 0)")
    p.add_argument("--no-shear", choices=("smooth", "pass", "block"), default="smooth",
                   help="reading of eq. 17: the continuous transition (default) or the paper's two")
    p.add_argument("--types", default=None, metavar="T[,T...]", help="afferent types to simulate")
    p.add_argument("--quiet", action="store_true", help="no progress bar")
    p.add_argument("--scheduler", default=None, metavar="processes|ADDRESS",
                   help="run afferent blocks on Dask: a local pool of processes or a scheduler address")
    p.add_argument("--out", required=out_required, metavar="FILE.nc")
    add_recording_options(p, xdf=True)


def step_ms(text) -> float:
    """An integration step in ms (``--dt``): a positive, finite number, refused in the option's own unit."""
    import argparse
    import math

    try:
        value = float(text)
    except ValueError:
        raise argparse.ArgumentTypeError(f"must be a number of ms, got {text!r}") from None
    if not (math.isfinite(value) and value > 0.0):
        raise argparse.ArgumentTypeError(f"must be a positive number of ms, got {text}")
    return value


def parse_directions(text, default="90"):
    """The shear directions of ``--theta-r`` in degrees (None for 'none': normal force only)."""
    out = []
    for part in (text or default).split(","):
        part = part.strip()
        if part.lower() == "none":
            out.append(None)
            continue
        try:
            value = float(part)
        except ValueError:
            value = float("nan")
        if not math.isfinite(value):
            raise ValueError(f"--theta-r: {part!r} is not a finite number of degrees or 'none'")
        out.append(value)
    return out


def parse_contact(text):
    """The `Contact` of ``--contact X,Y,R`` (mm), or None."""
    from ddmm.population import Contact
    if text is None:
        return None
    try:
        x, y, r = (float(v) for v in text.split(","))
    except ValueError:
        raise ValueError(f"--contact must be X,Y,R in mm, got {text!r}") from None
    return Contact(x, y, r)


def _array_scene(args):
    """The sensor-array scene of ``--scene FILE`` (and ``--sites``), or None for any other ``--scene``."""
    suffix = Path(args.scene).suffix.lower()
    is_array = suffix in EXTENSIONS or (suffix == ".csv" and args.sites is not None)
    with_sites = suffix in RECORDINGS and RECORDINGS[suffix].sites  # --sites names a recording's channel sites
    if args.sites is not None and suffix != ".csv" and not with_sites:
        raise ValueError(f"--sites goes with a long .csv --scene (time,site,fx,fy,fz) or an .xdf one, not "
                         f"{args.scene!r}")
    if not is_array:
        return None
    if args.contact is not None:
        raise ValueError("--contact does not apply to a sensor-array scene: each site has its own footprint")
    if args.theta_r is not None:
        raise ValueError("--theta-r does not apply to a sensor-array scene: the file gives the forces")
    refuse_csv_options(args, args.scene)
    from ddmm.population import from_array, from_long_csv  # here: the readers cost a named scene 10-15 ms

    conditioning = conditioning_from_args(args)
    if suffix in EXTENSIONS:
        return from_array(args.scene, conditioning=conditioning, max_force_n=args.max_force)
    return from_long_csv(args.scene, args.sites, conditioning=conditioning, max_force_n=args.max_force)


def _indent_scene(args):
    """The indentation scene of ``--indent`` (named settings or a TOML file); no other scene option applies."""
    import tomllib

    from ddmm.population.stimuli.indentation_spec import indentation_from_dict, parse_indent_option

    for flag, value in (("--sites", args.sites), ("--theta-r", args.theta_r), ("--contact", args.contact)):
        if value is not None:
            raise ValueError(f"{flag} does not apply to an --indent stimulus: its pins and the skin give the forces")
    if args.scene is not None:
        raise ValueError(f"give either --indent or --scene, not both (--scene {args.scene!r})")
    given = given_recording_options(args)
    if given:
        raise ValueError(f"{given[0]} reads a recorded --scene and does not apply to an --indent stimulus"
                         + (": set its rate as --indent ...,fs=HZ" if given[0] == "--fs" else ""))
    if args.indent.lower().endswith(".toml"):
        try:
            with open(args.indent, "rb") as f:
                table = tomllib.load(f)
        except OSError as exc:
            raise ValueError(f"--indent {args.indent!r}: cannot read it ({exc.strerror or exc})") from None
        except tomllib.TOMLDecodeError as exc:
            raise ValueError(f"--indent {args.indent!r} is not valid TOML: {exc}") from None
    else:
        table = parse_indent_option(args.indent)
    return indentation_from_dict(table)


def scenes_from_args(args) -> list:
    """The scenes named by ``--scene``, ``--sites``, ``--theta-r`` and ``--contact``."""
    from ddmm.population import birznieks, press_push_lift, rotating_shear
    if args.indent is not None:
        return [_indent_scene(args)]
    if args.scene is None:  # the default scene; None told it apart from a --scene given beside --indent
        args = argparse.Namespace(**{**vars(args), "scene": "birznieks"})
    found = RECORDINGS.get(Path(args.scene).suffix.lower())
    if getattr(args, "stream", None) is not None and not (found and found.streams):
        raise ValueError(f"--stream picks a stream of an .xdf --scene, not of {args.scene!r}")
    array = _array_scene(args)
    if array is not None:
        return [array]
    contact = parse_contact(args.contact)
    if args.scene == "birznieks":
        return [birznieks(d, contact=contact) for d in parse_directions(args.theta_r)]
    if args.scene == "press-push-lift":
        dirs = parse_directions(args.theta_r)
        if None in dirs:
            raise ValueError("--theta-r none is only meaningful for the birznieks scene")
        return [press_push_lift(d, contact=contact) for d in dirs]
    if args.scene == "rotating-shear":
        start = parse_directions(args.theta_r, default="0")
        return [rotating_shear(start_deg=start[0] or 0.0, contact=contact)]
    recorded = recorded_scene(args, contact)
    if recorded is not None:
        return [recorded]
    raise ValueError(f"--scene {args.scene!r} is unknown; allowed: {', '.join(SCENES)}, a recording "
                     f"({', '.join(RECORDINGS)}) or a sensor-array file ({', '.join(EXTENSIONS)})"
                     f"{_closest(args.scene.replace('_', '-'), SCENES)}")


def _closest(word: str, names) -> str:
    """`` (did you mean NAME?)`` for the name nearest ``word`` (the Dataset spells scenes press_push_lift_90)."""
    import difflib

    stem = re.sub(r"[-_]\d+$", "", word)  # a condition name's direction suffix
    match = difflib.get_close_matches(stem, list(names), n=1, cutoff=0.6)
    return f" (did you mean {match[0]}?)" if match else ""


def parse_types(text):
    """The afferent types of ``--types T[,T...]`` as a tuple, or None for all."""
    return None if text is None else tuple(t.strip() for t in text.split(","))


def population_from_args(args):
    """The population of ``--population`` (a preset or a spec file), sampled with ``--seed``."""
    from ddmm.population import load_spec, sample_population
    from ddmm.population.spec import PRESETS

    if not str(args.population).endswith(".toml") and args.population not in PRESETS:
        raise ValueError(f"--population {args.population!r} is neither a preset ({', '.join(PRESETS)}) nor a "
                         f".toml file{_closest(str(args.population), PRESETS)}")
    return sample_population(load_spec(args.population), rng=args.seed)


def _same_file(a: Path, b) -> bool:
    """Whether two paths name one file (the same resolved path, or a hard or symbolic link to it)."""
    import os

    try:
        return a.resolve() == Path(b).resolve() or (a.exists() and os.path.samefile(a, b))
    except (OSError, ValueError):  # b missing or not a path: not the same file
        return False


def check_out_file(path, suffix: str = ".nc", option: str = "--out", inputs: dict | None = None) -> Path:
    """Fail before the work if ``path`` cannot be written (a probe file is created), or is one of ``inputs``.

    ``inputs`` maps how the command names each input file (``"--scene"``,
    ``"dataset"``) to its path (None where not given): an output written over
    its own input would destroy it.
    """
    import tempfile

    path = Path(path)
    if path.suffix != suffix:
        raise ValueError(f"{option} {str(path)!r} must end in {suffix}")
    for name, source in (inputs or {}).items():
        if source is not None and _same_file(path, source):
            raise ValueError(f"{option} {str(path)!r} is the input {name} {str(source)!r}: writing it would destroy "
                             "the input; choose another name")
    if not path.parent.is_dir():
        raise ValueError(f"{option} {str(path)!r}: directory {str(path.parent)!r} does not exist")
    try:
        with tempfile.NamedTemporaryFile(dir=path.parent, prefix=".ddmm-probe-"):
            pass
    except OSError as exc:
        raise ValueError(f"{option} {str(path)!r}: directory {str(path.parent)!r} is not writable "
                         f"({exc.strerror})") from None
    return path
