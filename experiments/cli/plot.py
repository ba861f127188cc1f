"""``ddmm plot``: the standard figures of a dataset."""

from __future__ import annotations

from ddmm.experiments.io import ensure_out_dir, save_figure

__all__ = ["register", "run_plot", "write_plots"]


def register(sub) -> None:
    """Add ``ddmm plot``."""
    p = sub.add_parser("plot", help="raster, PSTH, polar and force figures of a dataset "
                                    "(and a spike-count hand map when its afferents carry hand-map regions)")
    p.add_argument("file")
    p.add_argument("--out", default=None, metavar="DIR",
                   help="where the figures go (default: FILE's name with -figures, beside it: run.nc -> run-figures)")
    p.set_defaults(func=run_plot)


def write_plots(ds, out_dir) -> list:
    """Write the standard figures of a dataset (plus ``hand.png`` when it has hand-map regions); returns the paths."""
    from ddmm.experiments.plots.common import (  # matplotlib is slow to import
        plot_forces,
        plot_polar_counts,
        plot_psth,
        plot_raster,
    )
    from ddmm.population import psth

    out_dir = ensure_out_dir(out_dir)
    bin_s = max(0.005, float(ds.duration.max()) / 100.0)
    figures = {"raster.png": plot_raster(ds), "psth.png": plot_psth(psth(ds, bin_s), ds),
               "polar.png": plot_polar_counts(ds), "forces.png": plot_forces(ds)}
    if "region" in ds.coords and any(ds.region.values.astype(str) != ""):  # afferents placed on the hand map
        from ddmm.experiments.plots.hand import hand_counts, plot_hand

        figures["hand.png"] = plot_hand(ds, counts=hand_counts(ds))
    return [str(save_figure(fig, out_dir / name)) for name, fig in figures.items()]


def run_plot(args) -> int:
    from pathlib import Path

    from ddmm.population import load_dataset

    source = Path(args.file)
    out = args.out if args.out is not None else source.with_name(f"{source.stem}-figures")
    for path in write_plots(load_dataset(args.file), out):
        print(f"wrote {path}")
    return 0
