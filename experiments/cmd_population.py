"""``ddmm simulate | plan | info | plot | demo``: population runs from the command line."""

from __future__ import annotations

import math
import time
import warnings
from pathlib import Path

from ddmm.experiments.cmd_recordings import (add_recording_options, conditioning_from_args, csv_scene,
                                            refuse_csv_options)
from ddmm.experiments.io import ensure_out_dir, save_figure, seed_arg
from ddmm.population.io.arrays import EXTENSIONS

__all__ = ["ENGINE_HELP", "check_out_file", "register", "register_demo", "scenes_from_args", "write_plots"]

ENGINE_HELP = ("brian2 (default: Brian2's C++ standalone device, compiled once per shape) or direct (the numba "
               "integrator: the same spikes bit for bit, no C++ compile, usually faster)")

SCENES = ("birznieks", "press-push-lift", "rotating-shear")


def _add_run_options(p, *, out_required: bool) -> None:
    p.add_argument("--population", default="fingertip", help="fingertip, hand or a spec .toml file")
    p.add_argument("--scene", default="birznieks",
                   help=f"{', '.join(SCENES)}, a force .csv file, or a sensor-array file "
                        f"({', '.join(EXTENSIONS)}; a long .csv with --sites)")
    p.add_argument("--sites", default=None, metavar="SITES.csv",
                   help="sites table (site,x_mm,y_mm[,region][,radius_mm]): --scene is then a long CSV "
                        "of time,site,fx,fy,fz")
    p.add_argument("--theta-r", default=None, metavar="DEG[,DEG...]",
                   help="shear direction(s) in degrees, one condition each ('none': normal only); default 90")
    p.add_argument("--contact", default=None, metavar="X,Y,R", help="contact centre and radius in mm")
    p.add_argument("--engine", choices=("brian2", "direct"), default="brian2", help=ENGINE_HELP)
    p.add_argument("--dt", type=float, default=None, metavar="MS", help="integration step in ms (default 0.1)")
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
    add_recording_options(p)


def register(sub) -> None:
    """Add the population subcommands."""
    p = sub.add_parser("simulate", help="simulate a population on a scene into a netCDF dataset")
    _add_run_options(p, out_required=True)
    p.set_defaults(func=run_simulate)
    p = sub.add_parser("plan", help="print what a simulate run would compute and skip")
    _add_run_options(p, out_required=False)
    p.set_defaults(func=run_plan)
    p = sub.add_parser("info", help="summarise a dataset file")
    p.add_argument("file")
    p.set_defaults(func=run_info)
    p = sub.add_parser("plot", help="raster, PSTH, polar and force figures of a dataset "
                                    "(and a spike-count hand map when its afferents carry hand-map regions)")
    p.add_argument("file")
    p.add_argument("--out", required=True, metavar="DIR")
    p.set_defaults(func=run_plot)
    register_demo(sub)


def _directions(text, default="90"):
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


def _contact(text):
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
    from ddmm.population import from_array, from_long_csv
    suffix = Path(args.scene).suffix.lower()
    is_array = suffix in EXTENSIONS or (suffix == ".csv" and args.sites is not None)
    if args.sites is not None and suffix != ".csv":
        raise ValueError(f"--sites goes with a long .csv --scene (time,site,fx,fy,fz), not {args.scene!r}")
    if not is_array:
        return None
    if args.contact is not None:
        raise ValueError("--contact does not apply to a sensor-array scene: each site has its own footprint")
    if args.theta_r is not None:
        raise ValueError("--theta-r does not apply to a sensor-array scene: the file gives the forces")
    refuse_csv_options(args, args.scene)
    conditioning = conditioning_from_args(args)
    if suffix in EXTENSIONS:
        return from_array(args.scene, conditioning=conditioning)
    return from_long_csv(args.scene, args.sites, conditioning=conditioning)


def scenes_from_args(args) -> list:
    """The scenes named by ``--scene``, ``--sites``, ``--theta-r`` and ``--contact``."""
    from ddmm.population import birznieks, press_push_lift, rotating_shear
    array = _array_scene(args)
    if array is not None:
        return [array]
    contact = _contact(args.contact)
    if args.scene == "birznieks":
        return [birznieks(d, contact=contact) for d in _directions(args.theta_r)]
    if args.scene == "press-push-lift":
        dirs = _directions(args.theta_r)
        if None in dirs:
            raise ValueError("--theta-r none is only meaningful for the birznieks scene")
        return [press_push_lift(d, contact=contact) for d in dirs]
    if args.scene == "rotating-shear":
        start = _directions(args.theta_r, default="0")
        return [rotating_shear(start_deg=start[0] or 0.0, contact=contact)]
    if args.scene.lower().endswith(".csv"):
        if args.theta_r is not None:
            raise ValueError(f"--theta-r does not apply to the recorded scene {args.scene!r}: the file gives the "
                             "forces")
        return [csv_scene(args.scene, args, contact)]
    raise ValueError(f"--scene {args.scene!r} is unknown; allowed: {', '.join(SCENES)}, a .csv file or a "
                     f"sensor-array file ({', '.join(EXTENSIONS)})")


def _types(text):
    return None if text is None else tuple(t.strip() for t in text.split(","))


def _population(args):
    from ddmm.population import load_spec, sample_population
    return sample_population(load_spec(args.population), rng=args.seed)


def check_out_file(path, suffix: str = ".nc", option: str = "--out") -> Path:
    """Fail before the work if ``path`` cannot be written (a probe file is created)."""
    import tempfile

    path = Path(path)
    if path.suffix != suffix:
        raise ValueError(f"{option} {str(path)!r} must end in {suffix}")
    if not path.parent.is_dir():
        raise ValueError(f"{option} {str(path)!r}: directory {str(path.parent)!r} does not exist")
    try:
        with tempfile.NamedTemporaryFile(dir=path.parent, prefix=".ddmm-probe-"):
            pass
    except OSError as exc:
        raise ValueError(f"{option} {str(path)!r}: directory {str(path.parent)!r} is not writable "
                         f"({exc.strerror})") from None
    return path


def run_simulate(args) -> int:
    from ddmm.population import save_dataset, simulate
    out = check_out_file(args.out)
    pop, scenes = _population(args), scenes_from_args(args)
    start = time.perf_counter()
    ds = simulate(pop, scenes, engine=args.engine, dt=None if args.dt is None else args.dt * 1e-3,
                  method=args.method, tolerance=args.tolerance, trials=args.trials, seed=args.seed,
                  no_shear=args.no_shear, types=_types(args.types), quiet=args.quiet, scheduler=args.scheduler)
    save_dataset(ds, out)
    if not args.quiet:
        choice = f"; {ds.attrs['tolerance_choice']}" if "tolerance_choice" in ds.attrs else ""
        print(f"wrote {out} ({ds.sizes['afferent']} afferents, {ds.sizes['spike']} spikes{choice}; "
              f"wall time {time.perf_counter() - start:.1f} s)")
    return 0


def run_plan(args) -> int:
    from ddmm.population import plan_run
    pop, scenes = _population(args), scenes_from_args(args)
    the_plan = plan_run(pop, scenes, trials=args.trials, no_shear=args.no_shear, types=_types(args.types),
                        engine=args.engine, scheduler=args.scheduler)
    print(the_plan.describe(pop, scenes))
    if args.tolerance is not None:
        from ddmm.population.runtime.step_choice import choose_setting

        row = choose_setting(args.tolerance, scenes[0].fs)
        print(f"tolerance {args.tolerance:g} pulses/s: dt={row['dt_ms']:g} ms, method={row['method']} "
              f"(measured mean SF error {row['sf_err_mean']:.3g} pulses/s)")
    return 0


def run_info(args) -> int:
    from ddmm.population import describe_dataset, load_dataset
    print(describe_dataset(load_dataset(args.file)))
    return 0


def write_plots(ds, out_dir) -> list:
    """Write the standard figures of a dataset (plus ``hand.png`` when it has hand-map regions); returns the paths."""
    from ddmm.experiments.plotting import (  # matplotlib is slow to import
        plot_forces,
        plot_polar_counts,
        plot_psth,
        plot_raster,
    )
    from ddmm.population import psth

    out_dir = ensure_out_dir(out_dir)
    bin_s = max(0.005, float(ds.duration.max()) / 100.0)
    figures = {"raster.png": plot_raster(ds), "psth.png": plot_psth(psth(ds, bin_s)),
               "polar.png": plot_polar_counts(ds), "forces.png": plot_forces(ds)}
    if "region" in ds.coords and any(ds.region.values.astype(str) != ""):  # afferents placed on the hand map
        from ddmm.experiments.plot_hand import hand_counts, plot_hand

        figures["hand.png"] = plot_hand(ds, counts=hand_counts(ds))
    return [str(save_figure(fig, out_dir / name)) for name, fig in figures.items()]


def run_plot(args) -> int:
    from ddmm.population import load_dataset
    for path in write_plots(load_dataset(args.file), args.out):
        print(f"wrote {path}")
    return 0


def register_demo(sub) -> None:
    """Add ``ddmm demo``."""
    p = sub.add_parser("demo", help="the main job: fingertip population on press-push-lift, data and figures")
    p.add_argument("--out", default="ddmm-demo", metavar="DIR", help="output directory (default ./ddmm-demo)")
    p.add_argument("--engine", choices=("brian2", "direct"), default="brian2", help=ENGINE_HELP)
    p.add_argument("--seed", type=seed_arg, default=0)
    p.add_argument("--quiet", action="store_true")
    p.set_defaults(func=run_demo)


def run_demo(args) -> int:
    from ddmm.models.engines import SpikeCapWarning
    from ddmm.population import describe_dataset, load_spec, press_push_lift, sample_population, save_dataset, simulate
    out_dir = ensure_out_dir(args.out)
    pop = sample_population(load_spec("fingertip"), rng=args.seed)
    scene = press_push_lift(90.0)
    start = time.perf_counter()
    with warnings.catch_warnings(record=True) as caught:
        warnings.simplefilter("always", SpikeCapWarning)
        ds = simulate(pop, scene, engine=args.engine, seed=args.seed, quiet=args.quiet)
    wall = time.perf_counter() - start
    written = [save_dataset(ds, out_dir / "demo.nc"), *write_plots(ds, out_dir)]
    print(f"# ddmm demo: {len(pop)} fingertip afferents on press-push-lift (theta_R = 90 deg, distal push)\n")
    print(describe_dataset(ds))
    print(f"\nsimulated {len(pop) * scene.duration:,.0f} afferent-seconds in {wall:.2f} s ({args.engine} engine)")
    capped = [w for w in caught if issubclass(w.category, SpikeCapWarning)]
    if capped:
        print(f"warning: in {len(capped)} time block(s) afferents spiked on consecutive steps (SpikeCapWarning)")
    for w in caught:
        if not issubclass(w.category, SpikeCapWarning):
            warnings.warn_explicit(w.message, w.category, w.filename, w.lineno)
    written += _demo_first_look(pop, args, out_dir)
    written += _demo_biology(args, out_dir)
    for path in written:
        print(f"wrote {path}")
    return 0


def _demo_first_look(pop, args, out_dir) -> list:
    """What a physiologist looks at first: a 2 N ramp-and-hold, 8 afferents per type, 10 trials."""
    from ddmm.experiments.plot_first_look import plot_ramp_and_hold, ramp_and_hold

    ds = ramp_and_hold(pop, seed=args.seed, engine="direct")
    return [str(save_figure(plot_ramp_and_hold(ds), out_dir / "ramp_and_hold.png"))]


def _demo_physiology_figures(data, out_dir) -> list:
    """Cycle histograms per type at 1:1 entrainment and rate against shear magnitude, from the scorecard's data."""
    from ddmm.experiments.plot_physiology import plot_cycle_histograms, plot_shear_magnitude

    makers = {"phase_locking": ("cycle_histograms.png", plot_cycle_histograms),
              "shear": ("shear_magnitude.png", plot_shear_magnitude)}
    return [str(save_figure(make(data[key]), out_dir / name)) for key, (name, make) in makers.items() if data.get(key)]


def _demo_biology(args, out_dir) -> list:
    """Tuned fraction against 86% and decoding error against 7.1 deg, with what each supports."""
    from ddmm.experiments.cmd_biology import run_tuning_stats
    from ddmm.experiments.cmd_physiology import run_scorecard
    from ddmm.experiments.decoding import best_settings, run_decoding, summarise
    from ddmm.experiments.paper_values import HUMAN_DIRECTION_THRESHOLD_DEG, HUMAN_DSI, HUMAN_TUNED_FRACTION
    from ddmm.experiments.plotting import plot_dsi_histograms, plot_neurometric, plot_preferred_rose
    from ddmm.population.analysis.physiology import summarise_scorecard

    # The battery compiles a Brian2 project per protocol shape (minutes on a fresh machine); the
    # engines give identical spikes (tests hold them to it), so the summary uses the direct one.
    rows, data = run_scorecard("fingertip", args.seed, engine="direct")
    print("\n## Physiology (`ddmm physiology` for the table; direct engine)\n")
    print(summarise_scorecard(rows))
    written = _demo_physiology_figures(data, out_dir)
    tuning, summary = run_tuning_stats("fingertip", args.seed, engine=args.engine)
    frac = summary["tuned_fraction"]
    pooled = frac["recorded"]
    print("\n## Direction tuning (5 force directions x 5 trials, ANOVA per phase, p < 0.05 in either)\n")
    print(f"tuned: SA-I {100 * frac['SAI']:.1f}% (human 93%), FA-I {100 * frac['RAI']:.1f}% (83%) [both fitted]; "
          f"SA-II {100 * frac['SAII']:.1f}% [prediction]; over the recorded types SA-I + SA-II + FA-I "
          f"{100 * pooled:.1f}% (human {100 * HUMAN_TUNED_FRACTION['all']:.0f}%)")
    print("-> Like human recordings, the simulated fingertip is dominated by direction-tuned afferents. The pooled "
          "fraction is the count-weighted mix of the fitted SA-I and FA-I fractions and the predicted SA-II one, "
          "so it is not an independent test; only SA-II's own fraction is a prediction.")
    result = summarise(run_decoding("fingertip", seed=args.seed, n_train=150, n_test=100, subsets=3,
                                    engine=args.engine, windows_ms=(25, 50, 125), sizes=(10, 30, 92, None)))
    ml = result["errors"]["maximum_likelihood"]["125"][str(len(tuning.afferent))]
    human = result["errors"]["maximum_likelihood"]["125"]["92"]
    best = best_settings(result)
    print("\n## Decoding shear direction (150 training, 100 test directions, uniform on the circle)\n")
    print(f"median error {ml['median_deg']:.2f} deg (90th percentile {ml['p90_deg']:.2f}) from all "
          f"{len(tuning.afferent)} afferents within 125 ms of contact (maximum likelihood); human threshold "
          f"{HUMAN_DIRECTION_THRESHOLD_DEG} deg")
    print(f"with a human-sized sample of 92 afferents (random subsets, as in the recordings): median error "
          f"{human['median_deg']:.2f} deg (90th percentile {human['p90_deg']:.2f})")
    small, short = best["smallest_population"], best["shortest_window_ms"]
    if small is None:
        print("7.1 deg is not reached by any decoder, population size or window in this run")
    else:
        print(f"7.1 deg is reached with as few as {small['n_afferents']} afferents ({small['window_ms']} ms window, "
              f"{small['decoder']}) and within {short['window_ms']} ms ({short['n_afferents']} afferents)")
    print("-> The population carries enough to discriminate shear direction as finely as humans do, within the "
          "loading phase. This is an ideal-observer prediction, never fitted; the brain need not reach it.")
    return written + [save_figure(plot_dsi_histograms(tuning, HUMAN_DSI), out_dir / "dsi_histograms.png"),
            save_figure(plot_preferred_rose(tuning), out_dir / "preferred_directions.png"),
            save_figure(plot_neurometric(result, HUMAN_DIRECTION_THRESHOLD_DEG), out_dir / "neurometric.png")]
