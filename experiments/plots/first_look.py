"""The figures a physiologist looks at first: a ramp-and-hold, raster and PSTH per type, over repeated trials.

`ramp_and_hold` simulates a few afferents of each type of a population on a
ramp-and-hold (0 -> ``force_n`` at ``rate_n_per_s``, a hold, the release), ``trials`` times;
`plot_ramp_and_hold` draws, per type, the raster of every trial (trials of
one afferent together, so trial-to-trial variability shows as ragged
columns) above the PSTH, with the force on top.  Plotting takes data and
returns a Figure; nothing is written here.
"""

from __future__ import annotations

import numpy as np
from matplotlib.figure import Figure

from ddmm.experiments.plots.common import TYPE_COLOURS
from ddmm.models.afferent_types import afferent_type_codes, type_label

__all__ = ["ramp_and_hold_scene", "ramp_and_hold", "plot_ramp_and_hold"]


def ramp_and_hold_scene(force_n: float = 2.0, rate_n_per_s: float = 10.0, hold_s: float = 1.5):
    """Normal force: 0.2 s at rest, a ramp to ``force_n`` (N) at ``rate_n_per_s`` (N/s), a hold, the release, 0.3 s rest."""
    from ddmm.population import Scene, Stage

    fs, ramp = 1000.0, force_n / rate_n_per_s
    knots = np.cumsum([0.0, 0.2, ramp, hold_s, ramp, 0.3])
    t = np.arange(int(round(knots[-1] * fs))) / fs
    fz = np.interp(t, knots, [0.0, 0.0, force_n, force_n, 0.0, 0.0])
    stages = (Stage("loading", knots[1], knots[2]), Stage("hold", knots[2], knots[3]),
              Stage("release", knots[3], knots[4]))
    return Scene(np.zeros_like(t), np.zeros_like(t), fz, fs, f"ramp_hold_{force_n:g}N", stages)


def ramp_and_hold(population, *, per_type: int = 8, trials: int = 10, seed: int = 0, engine: str = "direct",
                  force_n: float = 2.0, rate_n_per_s: float = 10.0):
    """Simulate ``per_type`` afferents of each type (the first of each) on `ramp_and_hold_scene`; a Dataset."""
    from ddmm.population import simulate

    pick = np.concatenate([np.flatnonzero(population.afferent_type == kind)[:per_type] for kind in afferent_type_codes()])
    return simulate(population.select(np.sort(pick)), ramp_and_hold_scene(force_n, rate_n_per_s), engine=engine,
                    seed=seed, trials=trials, quiet=True)


def _raster(ax, ds, kind, colour):
    """Trials of each afferent of ``kind`` stacked: row = afferent * trials + trial."""
    members = np.flatnonzero(ds.afferent_type.values == kind)
    n_trials = ds.sizes["trial"]
    row_of = np.full(ds.sizes["afferent"], -1)
    row_of[members] = np.arange(members.size)
    keep = row_of[ds.spike_afferent.values] >= 0
    rows = row_of[ds.spike_afferent.values[keep]] * n_trials + ds.spike_trial.values[keep]
    ax.scatter(ds.spike_time.values[keep], rows, s=1.5, marker="|", color=colour, lw=0.6)
    ax.set_ylim(-1, members.size * n_trials)
    ax.set_ylabel(f"{type_label(kind)}\n{members.size} x {n_trials} trials", fontsize=8)
    ax.set_yticks([])


def plot_ramp_and_hold(ds, bin_s: float = 0.02) -> Figure:
    """Force, then per type a raster (all trials) and a PSTH (mean over afferents and trials)."""
    kinds = [k for k in afferent_type_codes() if np.any(ds.afferent_type.values == k)]
    fig = Figure(figsize=(7.5, 1.0 + 2.4 * len(kinds)), layout="constrained")
    axes = fig.subplots(1 + 2 * len(kinds), 1, sharex=True,
                        gridspec_kw={"height_ratios": [0.8] + [1.4, 0.8] * len(kinds)})
    axes[0].plot(ds.time.values, ds.fz.values[0], color="k", lw=1.0)
    axes[0].set_ylabel("F_Z (N)", fontsize=8)
    edges = np.arange(0.0, float(ds.duration[0]) + bin_s, bin_s)
    for i, kind in enumerate(kinds):
        colour = TYPE_COLOURS[kind]
        _raster(axes[1 + 2 * i], ds, kind, colour)
        sel = ds.afferent_type.values[ds.spike_afferent.values] == kind
        n = int(np.sum(ds.afferent_type.values == kind)) * ds.sizes["trial"]
        counts, _ = np.histogram(ds.spike_time.values[sel], edges)
        axes[2 + 2 * i].stairs(counts / (n * bin_s), edges, color=colour)
        axes[2 + 2 * i].set_ylabel("imp/s", fontsize=8)
    axes[-1].set_xlabel("time (s)")
    fig.suptitle(f"ramp and hold ({ds.condition.values[0]}): raster of every trial and PSTH per type", fontsize=10)
    return fig
