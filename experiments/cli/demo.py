"""``ddmm demo``: the main job, a fingertip population on press-push-lift with data and figures."""

from __future__ import annotations

import time
import warnings

from ddmm.experiments.cli.options import add_engine_option
from ddmm.experiments.cli.plot import write_plots
from ddmm.experiments.io import ensure_out_dir, save_figure, seed_arg

__all__ = ["register", "run_demo"]


def register(sub) -> None:
    """Add ``ddmm demo``."""
    p = sub.add_parser("demo", help="the main job: fingertip population on press-push-lift, data and figures")
    p.add_argument("--out", default="ddmm-demo", metavar="DIR", help="output directory (default ./ddmm-demo)")
    add_engine_option(p, "brian2")
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
    from ddmm.experiments.plots.first_look import plot_ramp_and_hold, ramp_and_hold

    ds = ramp_and_hold(pop, seed=args.seed, engine="direct")
    return [str(save_figure(plot_ramp_and_hold(ds), out_dir / "ramp_and_hold.png"))]


def _demo_physiology_figures(data, out_dir) -> list:
    """Cycle histograms per type at 1:1 entrainment and rate against shear magnitude, from the scorecard's data."""
    from ddmm.experiments.plots.physiology import plot_cycle_histograms, plot_shear_magnitude

    makers = {"phase_locking": ("cycle_histograms.png", plot_cycle_histograms),
              "shear": ("shear_magnitude.png", plot_shear_magnitude)}
    return [str(save_figure(make(data[key]), out_dir / name)) for key, (name, make) in makers.items() if data.get(key)]


def _demo_biology(args, out_dir) -> list:
    """Tuned fraction against 86% and decoding error against 7.1 deg, with what each supports."""
    from ddmm.experiments.cli.physiology import run_scorecard
    from ddmm.experiments.cli.tuning import run_tuning_stats
    from ddmm.experiments.plots.common import plot_dsi_histograms, plot_neurometric, plot_preferred_rose
    from ddmm.experiments.validation.decoding import best_settings, run_decoding, summarise
    from ddmm.population.analysis.physiology import summarise_scorecard
    from ddmm.population.data.published import HUMAN_DIRECTION_THRESHOLD_DEG, HUMAN_DSI, HUMAN_TUNED_FRACTION

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
