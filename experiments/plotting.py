"""Plotting helpers: each takes data and returns a `matplotlib.figure.Figure`.

No helper writes a file or touches pyplot's global state; the CLI saves.
"""

from __future__ import annotations

import numpy as np
from matplotlib.figure import Figure

from models.currents import AFFERENT_TYPES

__all__ = ["plot_response", "plot_sf_vs_theta"]

_TYPE_COLOURS = {"SAI": "tab:blue", "RAI": "tab:orange", "RAII": "tab:green"}


def _plot_forces(ax, time, forces):
    for name, colour in (("fx", "tab:red"), ("fy", "tab:green"), ("fz", "k")):
        ax.plot(time, forces[name], color=colour, lw=1.2, label=name.upper().replace("F", "F_"))
    ax.set_ylabel("force (N)")
    ax.legend(loc="upper right", fontsize=7, ncol=3)


def _plot_spikes(ax, spike_times, duration, bin_s, colour, label):
    bins = np.arange(0.0, duration + bin_s, bin_s)
    counts, _ = np.histogram(spike_times, bins)
    rate = counts / bin_s
    ax.bar(bins[:-1], rate, width=bin_s, align="edge", color=colour, alpha=0.35)
    top = max(1.0, rate.max() if rate.size else 1.0)
    ax.vlines(spike_times, 1.05 * top, 1.25 * top, color=colour, lw=0.6)
    ax.set_ylim(0, 1.3 * top)
    ax.set_ylabel(f"{label}\n(pulses/s)", fontsize=8)


def plot_response(data: dict, *, title: str = "", bin_s: float | None = None) -> Figure:
    """Forces, AF(t) and per-type rasters with binned histograms (paper Figs 6-7).

    Parameters
    ----------
    data : dict
        ``time`` (s), ``forces`` ({fx, fy, fz} in N), and ``conditions``: a
        list of dicts with ``label``, ``af`` (AF(t)) and ``spikes`` ({type:
        spike times in s}), typically aligned then misaligned.
    title : str
        Figure title.
    bin_s : float, optional
        Histogram bin in seconds (default: duration / 30).

    Returns
    -------
    Figure
    """
    time = np.asarray(data["time"])
    duration = float(time[-1] + (time[1] - time[0] if time.size > 1 else 0.0))
    bin_s = duration / 30.0 if bin_s is None else bin_s
    conds = data["conditions"]
    fig = Figure(figsize=(5.0 * len(conds), 9.0), layout="constrained")
    axes = fig.subplots(2 + len(AFFERENT_TYPES), len(conds), sharex=True, squeeze=False)
    for col, cond in enumerate(conds):
        _plot_forces(axes[0, col], time, data["forces"])
        axes[0, col].set_title(cond["label"], fontsize=10)
        axes[1, col].plot(time, cond["af"], color="purple", lw=1.2)
        axes[1, col].set_ylim(-0.05, 1.05)
        axes[1, col].set_ylabel("AF(t)")
        for row, kind in enumerate(AFFERENT_TYPES, start=2):
            _plot_spikes(axes[row, col], np.asarray(cond["spikes"][kind]), duration, bin_s,
                         _TYPE_COLOURS[kind], kind)
        axes[-1, col].set_xlabel("time (s)")
    if title:
        fig.suptitle(title)
    return fig


def plot_sf_vs_theta(sf: dict, *, title: str = "SF against tuning angle (Fig. 8)") -> Figure:
    """SF (pulses/s) against theta_T for each profile and afferent type (paper Fig. 8).

    Parameters
    ----------
    sf : dict
        ``{profile: {type: {"<angle deg>": sf}}}`` as printed by
        ``ddmm reproduce fig8 --json``.
    """
    profiles = list(sf)
    fig = Figure(figsize=(3.6 * len(profiles), 3.4), layout="constrained")
    axes = fig.subplots(1, len(profiles), sharey=True, squeeze=False)[0]
    for ax, profile in zip(axes, profiles):
        for kind in AFFERENT_TYPES:
            angles = np.array([float(a) for a in sf[profile][kind]])
            values = np.array(list(sf[profile][kind].values()), dtype=float)
            ax.plot(angles, values, "o-", ms=3, color=_TYPE_COLOURS[kind], label=kind)
        ax.axvline(90.0, color="grey", ls=":", lw=1)
        ax.set_title(profile)
        ax.set_xlabel("theta_T (deg)")
        ax.set_xticks(range(0, 361, 90))
    axes[0].set_ylabel("SF (pulses/s)")
    axes[0].legend(fontsize=8)
    fig.suptitle(title)
    return fig
