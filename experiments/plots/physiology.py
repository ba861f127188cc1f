"""Figures of the physiology scorecard: each helper takes a protocol's data and returns a Figure."""

from __future__ import annotations

import numpy as np
from matplotlib.figure import Figure

from ddmm.experiments.plots.common import TYPE_COLOURS, plot_dsi_histograms
from ddmm.models.afferent_types import afferent_type_codes, type_label
from ddmm.population.analysis.physiology import FREQUENCIES_HZ

__all__ = ["plot_rest", "plot_on_off", "plot_force_coding", "plot_frequency_tuning", "plot_timing",
           "plot_cycle_histograms", "plot_shear_magnitude", "plot_recruitment", "plot_threshold_spread",
           "physiology_figures"]


def plot_rest(data: dict) -> Figure:
    """Resting rate of every afferent (60 s of zero force), by type."""
    fig = Figure(figsize=(6.0, 3.2), layout="constrained")
    ax = fig.add_subplot()
    kinds = [k for k in afferent_type_codes() if np.any(data["type"] == k)]
    for i, kind in enumerate(kinds):
        rate = data["rate"][data["type"] == kind]
        ax.scatter(np.full(rate.size, i) + np.linspace(-0.3, 0.3, rate.size), rate, s=4,
                   color=TYPE_COLOURS[kind])
    ax.set_xticks(range(len(kinds)), kinds)
    ax.set_ylabel("rate at rest (imp/s)")
    ax.set_title("rest: 60 s of zero force")
    return fig


def plot_on_off(data: dict, bin_s: float = 0.02) -> Figure:
    """PSTH per type on the on/off protocol (0 -> 4 N at 10 N/s, 2 s hold, release), with the force."""
    ds = data["dataset"]
    kinds = [k for k in afferent_type_codes() if np.any(ds.afferent_type.values == k)]
    fig = Figure(figsize=(7.0, 1.6 * (len(kinds) + 1)), layout="constrained")
    axes = fig.subplots(len(kinds) + 1, 1, sharex=True)
    axes[0].plot(ds.time.values, ds.fz.values[0], color="k")
    axes[0].set_ylabel("F_Z (N)")
    edges = np.arange(0.0, float(ds.duration[0]) + bin_s, bin_s)
    for ax, kind in zip(axes[1:], kinds):
        own = ds.afferent_type.values[ds.spike_afferent.values] == kind
        counts, _ = np.histogram(ds.spike_time.values[own], edges)
        ax.bar(edges[:-1], counts / bin_s / np.sum(ds.afferent_type.values == kind), width=bin_s, align="edge",
               color=TYPE_COLOURS[kind])
        ax.set_ylabel(f"{type_label(kind)}\n(imp/s)", fontsize=8)
    axes[-1].set_xlabel("time (s)")
    return fig


def plot_force_coding(data: dict) -> Figure:
    """SA-I plateau rate against normal force, FA-I mean rate while loading against force rate."""
    fig = Figure(figsize=(8.0, 3.2), layout="constrained")
    a, b = fig.subplots(1, 2)
    if "sai_plateau" in data:
        a.plot([1, 2, 4], data["sai_plateau"], "o-", color=TYPE_COLOURS["SAI"])
    a.set_xlabel("normal force (N)")
    a.set_ylabel("SA-I plateau rate (imp/s)")
    if "rai_loading_rates" in data:
        b.set_yscale("log")
        _rate_axis(b, [2, 8, 32], np.maximum(data["rai_loading_rates"], 0.1))
    b.set_xlabel("force rate (N/s)")
    b.set_ylabel("FA-I mean rate while loading (imp/s)")
    return fig


def _rate_axis(ax, rates, values) -> None:
    """FA-I ``values`` against force ``rates`` (N/s) on a log axis labelled at the rates themselves."""
    ax.semilogx(rates, values, "o-", color=TYPE_COLOURS["RAI"])
    ax.set_xticks(rates, [f"{r:g}" for r in rates])
    ax.xaxis.set_minor_formatter("")


def plot_frequency_tuning(data: dict) -> Figure:
    """Median amplitude for one spike per cycle against frequency (log-log), per type."""
    fig = Figure(figsize=(5.5, 3.6), layout="constrained")
    ax = fig.add_subplot()
    for kind, curve in data.items():
        curve = np.asarray(curve, dtype=float)
        finite = np.isfinite(curve)
        ax.loglog(np.asarray(FREQUENCIES_HZ)[finite], curve[finite], "o-", color=TYPE_COLOURS[kind],
                  label=type_label(kind))
    # the human best bands (docs/references.md row 8)
    ax.axvspan(8, 64, color=TYPE_COLOURS["RAI"], alpha=0.1)
    ax.axvspan(200, 300, color=TYPE_COLOURS["RAII"], alpha=0.1)
    ax.set_xlabel("frequency (Hz), 1 N preload; shaded: the human best band")
    ax.set_ylabel("amplitude for 1 spike/cycle (N)")
    ax.legend()
    return fig


def plot_timing(data: dict) -> Figure:
    """Median decoding error of the first-spike-latency and count decoders at 125 ms."""
    fig = Figure(figsize=(4.5, 3.2), layout="constrained")
    ax = fig.add_subplot()
    names = list(data["errors_deg"])
    ax.bar(names, [data["errors_deg"][n] for n in names], color=["tab:gray", "tab:blue"])
    ax.set_ylabel("median error (deg), 125 ms")
    return fig


def plot_cycle_histograms(data: dict, bins: int = 20) -> Figure:
    """Cycle histograms: spike phase within the stimulus cycle, one panel per type at one frequency each.

    Parameters
    ----------
    data : dict
        Type code -> ``{"frequency_hz": float, "phases": array of phases in cycles, [0, 1)}`` (the
        ``phase_locking`` protocol's data; other keys are ignored).
    bins : int
        Bins per cycle.
    """
    kinds = [k for k in afferent_type_codes() if k in data and "phases" in data[k]]
    fig = Figure(figsize=(3.2 * max(len(kinds), 1), 3.0), layout="constrained")
    axes = np.atleast_1d(fig.subplots(1, max(len(kinds), 1), squeeze=False)[0])
    edges = np.linspace(0.0, 1.0, bins + 1)
    for ax, kind in zip(axes, kinds):
        phases = np.asarray(data[kind]["phases"], dtype=float)
        counts, _ = np.histogram(phases, edges)
        ax.bar(edges[:-1], counts / max(phases.size, 1), width=1.0 / bins, align="edge", color=TYPE_COLOURS[kind])
        vs = float(abs(np.exp(2j * np.pi * phases).mean())) if phases.size else float("nan")
        ax.set_title(f"{type_label(kind)}, {data[kind]['frequency_hz']:g} Hz at 1:1 (VS {vs:.2f})", fontsize=9)
        ax.set_xlabel("phase (cycles)")
    axes[0].set_ylabel("fraction of spikes")
    return fig


def plot_shear_magnitude(data: dict) -> Figure:
    """Response against tangential force magnitude on a 2 N press, in the preferred and the opposite direction.

    One panel per type: SA types show the median hold rate (1/s), FA types the mean count during the
    tangential ramp (the ``shear`` protocol of `ddmm.population.analysis.physiology_shear`); the
    opposite direction over unipolar afferents when ``nap`` is given (as the scorecard's rows).

    Parameters
    ----------
    data : dict
        The ``shear`` protocol's data: ``sa_rate`` and ``fa_count`` (conditions x afferents: no shear, then
        each magnitude preferred, then each opposite), ``type`` (type code per afferent) and optionally
        ``nap`` (profile name per afferent).

    Examples
    --------
    >>> import numpy as np
    >>> rate = np.arange(14.0).reshape(7, 2)
    >>> fig = plot_shear_magnitude({"sa_rate": rate, "fa_count": rate, "type": np.array(["SAI", "RAI"])})
    >>> len(fig.axes)
    2
    """
    from ddmm.population.analysis.physiology_shear import MAGNITUDES_N

    types = np.asarray(data["type"]).astype(str)
    nap = np.asarray(data.get("nap", np.full(types.size, "selective"))).astype(str)
    unipolar = np.isin(nap, ("selective", "broad"))
    kinds = [k for k in afferent_type_codes() if np.any(types == k)]
    fig = Figure(figsize=(3.0 * max(len(kinds), 1), 3.0), layout="constrained")
    axes = np.atleast_1d(fig.subplots(1, max(len(kinds), 1), squeeze=False)[0])
    x, n = np.r_[0.0, MAGNITUDES_N], len(MAGNITUDES_N)
    for ax, kind in zip(axes, kinds):
        slow = kind.startswith("SA")
        values = np.asarray(data["sa_rate" if slow else "fa_count"], dtype=float)
        stat = np.median if slow else np.mean
        pref = stat(values[:, types == kind], axis=1)
        opp = stat(values[:, (types == kind) & unipolar], axis=1) if np.any((types == kind) & unipolar) else pref * np.nan
        for curve, part, style, label in ((pref, pref[1:1 + n], "-o", "preferred"),
                                          (opp, opp[1 + n:], "--s", "opposite (unipolar)")):
            ax.plot(x, np.r_[curve[0], part], style, color=TYPE_COLOURS[kind], label=label, ms=4)
        ax.set_title(f"{type_label(kind)} (n = {int(np.sum(types == kind))})", fontsize=9)
        ax.set_xlabel("tangential force (N)")
        ax.set_ylabel("median hold rate (1/s)" if slow else "mean ramp count")
    axes[0].legend(fontsize=8, frameon=False)
    return fig


def plot_recruitment(data: dict) -> Figure:
    """Fraction of FA-I firing while loading to 2 N against the loading rate (log axis)."""
    fig = Figure(figsize=(4.5, 3.2), layout="constrained")
    ax = fig.subplots()
    _rate_axis(ax, data["rates"], data["fractions"])
    ax.set_ylim(-0.02, 1.02)
    ax.set_xlabel("loading rate (N/s)")
    ax.set_ylabel("FA-I firing while loading")
    return fig


def plot_threshold_spread(data: dict) -> Figure:
    """Each unit's vibration threshold, sorted (the cumulative distribution), per type; log axis."""
    fig = Figure(figsize=(4.5, 3.2), layout="constrained")
    ax = fig.subplots()
    for kind, entry in data.items():
        thr = np.sort(entry["thresholds_n"][np.isfinite(entry["thresholds_n"])]) * 1e3
        if thr.size:
            ax.semilogx(thr, np.arange(1, thr.size + 1) / thr.size, drawstyle="steps-post", color=TYPE_COLOURS[kind],
                        label=f"{type_label(kind)} at {entry['frequency_hz']:g} Hz")
    ax.set_xlabel("vibration threshold (mN, 0.5 N preload)")
    ax.set_ylabel("fraction of units")
    ax.legend(fontsize=8, frameon=False)
    return fig


def physiology_figures(data: dict, human_dsi: dict) -> dict:
    """File name -> Figure for every protocol that ran and has a figure."""
    makers = {"rest": ("rest.png", plot_rest), "on_off": ("on_off_psth.png", plot_on_off),
              "force_coding": ("force_coding.png", plot_force_coding),
              "frequency": ("frequency_tuning.png", plot_frequency_tuning), "timing": ("timing.png", plot_timing),
              "phase_locking": ("cycle_histograms.png", plot_cycle_histograms),
              "shear": ("shear_magnitude.png", plot_shear_magnitude),
              "everyday_loading": ("recruitment.png", plot_recruitment),
              "everyday_threshold": ("threshold_spread.png", plot_threshold_spread)}
    out = {name: make(data[protocol]) for protocol, (name, make) in makers.items() if data.get(protocol)}
    if data.get("direction"):
        out["tuning_dsi.png"] = plot_dsi_histograms(data["direction"]["tuning"], human_dsi)
    return out
