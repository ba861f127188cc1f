"""Plotting helpers: each takes data and returns a `matplotlib.figure.Figure`.

No helper writes a file or touches pyplot's global state; the CLI saves.
"""

from __future__ import annotations

import numpy as np
from matplotlib.figure import Figure
from matplotlib.ticker import MaxNLocator

from ddmm.models.afferent_types import PAPER_TYPES, afferent_type_codes, afferent_type_info, type_label

__all__ = ["TYPE_COLOURS",  # noqa: F822 (a view of the registry: the module's __getattr__)
           "plot_response", "plot_sf_vs_theta", "plot_raster", "plot_psth", "plot_polar_counts", "plot_forces",
           "plot_dsi_histograms", "plot_preferred_rose", "plot_neurometric", "plot_pareto", "type_colour"]


def type_colour(afferent_type: str) -> str:
    """The colour of an afferent type in every figure (`ddmm.models.afferent_types.AfferentType.colour`)."""
    return afferent_type_info(afferent_type).colour


def __getattr__(name):
    if name == "TYPE_COLOURS":  # a view of the registry, whatever is registered now
        return {code: type_colour(code) for code in afferent_type_codes()}
    raise AttributeError(f"module {__name__!r} has no attribute {name!r}")


def _present(types) -> list:
    """The afferent types present, in the package's order (at least one entry for an empty figure)."""
    present = [k for k in afferent_type_codes() if np.any(np.asarray(types) == k)]
    return present or [afferent_type_codes()[0]]


def _plot_forces(ax, time, forces):
    for name, colour in (("fx", "tab:red"), ("fy", "tab:green"), ("fz", "k")):
        ax.plot(time, forces[name], color=colour, lw=1.2, label=name.upper().replace("F", "F_"))
    ax.set_ylabel("force (N)")
    ax.legend(loc="upper left", bbox_to_anchor=(1.0, 1.0), fontsize=7, frameon=False)  # outside: never on a trace


def _plot_spikes(ax, spike_times, duration, bin_s, colour, label):
    bins = np.arange(0.0, duration + bin_s, bin_s)
    counts, _ = np.histogram(spike_times, bins)
    rate = counts / bin_s
    ax.bar(bins[:-1], rate, width=bin_s, align="edge", color=colour, alpha=0.35)
    top = max(1.0, rate.max() if rate.size else 1.0)
    ax.vlines(spike_times, 1.05 * top, 1.25 * top, color=colour, lw=0.6)
    ax.set_ylim(0, 1.3 * top)
    ax.set_ylabel(f"{label}\n(imp/s)", fontsize=8)


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
    kinds = [k for k in PAPER_TYPES if k in conds[0]["spikes"]]  # the types the data carry
    fig = Figure(figsize=(5.0 * len(conds), 3.6 + 1.8 * len(kinds)), layout="constrained")
    axes = fig.subplots(2 + len(kinds), len(conds), sharex=True, squeeze=False)
    for col, cond in enumerate(conds):
        _plot_forces(axes[0, col], time, data["forces"])
        axes[0, col].set_title(cond["label"], fontsize=10)
        axes[1, col].plot(time, cond["af"], color="purple", lw=1.2)
        axes[1, col].set_ylim(-0.05, 1.05)
        axes[1, col].set_ylabel("AF(t)")
        for row, kind in enumerate(kinds, start=2):
            _plot_spikes(axes[row, col], np.asarray(cond["spikes"][kind]), duration, bin_s,
                         type_colour(kind), kind)
        axes[-1, col].set_xlabel("time (s)")
    if title:
        fig.suptitle(title)
    return fig


def plot_sf_vs_theta(sf: dict, *, title: str = "SF against tuning angle (Fig. 8)") -> Figure:
    """SF (imp/s) against θ_T for each profile and afferent type (paper Fig. 8).

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
        for kind in PAPER_TYPES:
            angles = np.array([float(a) for a in sf[profile][kind]])
            values = np.array(list(sf[profile][kind].values()), dtype=float)
            ax.plot(angles, values, "o-", ms=3, color=type_colour(kind), label=type_label(kind))
        ax.axvline(90.0, color="grey", ls=":", lw=1)
        ax.set_title(profile)
        ax.set_xlabel("θ_T (deg)")
        ax.set_xticks(range(0, 361, 90))
    axes[0].set_ylabel("SF (imp/s)")
    axes[0].legend(fontsize=8)
    fig.suptitle(title)
    return fig


def plot_raster(ds, *, condition=0, trial=0, max_afferents: int = 2000) -> Figure:
    """Spike raster sorted by afferent type, then tuning angle θ_T.

    Parameters
    ----------
    ds : xarray.Dataset
        A simulation dataset with spike events.
    condition, trial : int
        Which condition and trial to draw (positions).
    max_afferents : int
        Draw at most this many afferents (evenly subsampled per type).
    """
    types = ds.afferent_type.values
    codes = afferent_type_codes()
    order = np.lexsort((ds.theta_t.values, [codes.index(t) for t in types]))
    if order.size > max_afferents:
        order = order[np.linspace(0, order.size - 1, max_afferents).astype(int)]
    row = np.full(ds.sizes["afferent"], -1)
    row[order] = np.arange(order.size)
    sel = (ds.spike_condition.values == condition) & (ds.spike_trial.values == trial)
    aff = ds.spike_afferent.values[sel]
    keep = row[aff] >= 0
    fig = Figure(figsize=(8.0, 6.0), layout="constrained")
    ax = fig.subplots()
    lut = {kind: type_colour(kind) for kind in set(types.tolist())}  # one registry lookup a type, not a spike
    colours = [lut[t] for t in types[aff[keep]]]
    ax.scatter(ds.spike_time.values[sel][keep], row[aff[keep]], s=1.0, c=colours, marker="|", linewidths=0.5)
    for kind in afferent_type_codes():
        rows = row[(types == kind) & (row >= 0)]
        if rows.size:
            ax.axhline(rows.max() + 0.5, color="grey", lw=0.5)
            ax.text(1.01, rows.mean(), type_label(kind), transform=ax.get_yaxis_transform(), va="center",
                    color=type_colour(kind))
    ax.set_xlim(0, float(ds.duration[condition]))
    ax.set_xlabel("time (s)")
    ax.set_ylabel("afferent (by type, then θ_T)")
    ax.set_title(f"raster: {ds.condition.values[condition]}, trial {trial}")
    return fig


def _label(group) -> str:
    """A PSTH group's display label: the type's (FA-I, ...) when the group is a type code."""
    try:
        return type_label(str(group))
    except ValueError:
        return str(group)


def plot_psth(rates, forces=None) -> Figure:
    """PSTH per afferent type: ``rates`` is `ddmm.population.psth` output (condition, type, bin).

    ``forces``, a simulation Dataset, adds its F_Z above the PSTH (per condition).
    """
    codes = afferent_type_codes()
    groups = sorted(rates[rates.dims[1]].values, key=lambda g: (codes.index(g) if g in codes else len(codes), str(g)))
    top = 1 if forces is not None else 0
    fig = Figure(figsize=(8.0, 2.2 * (len(groups) + top)), layout="constrained")
    axes = fig.subplots(len(groups) + top, 1, sharex=True, squeeze=False)[:, 0]
    if top:
        for c, name in enumerate(forces.condition.values):
            axes[0].plot(forces.time.values, forces.fz.isel(condition=c).values, lw=1.0, label=str(name))
        axes[0].set_ylabel("F_Z (N)")
    for ax, group in zip(axes[top:], groups):
        for c, name in enumerate(rates.condition.values):
            ax.plot(rates.bin.values, rates.isel(condition=c).sel({rates.dims[1]: group}).values, lw=1.0, label=str(name))
        ax.set_ylabel(f"{_label(group)}\n(imp/s)")
    axes[0].legend(fontsize=7)
    axes[-1].set_xlabel("time (s)")
    bin_ms = float(rates.attrs.get("bin_s", np.nan)) * 1e3
    fig.suptitle(f"PSTH: mean rate per afferent, {bin_ms:g} ms bins, mean over trials", fontsize=10)
    return fig


def plot_polar_counts(ds, *, condition=0) -> Figure:
    """Polar plot of spike count (mean over trials) against theta_T, per type."""
    counts = ds.spike_count.isel(condition=condition).mean("trial").values
    kinds = _present(ds.afferent_type.values)
    fig = Figure(figsize=(4.0 * len(kinds), 4.0), layout="constrained")
    for i, kind in enumerate(kinds):
        ax = fig.add_subplot(1, len(kinds), i + 1, projection="polar")
        sel = ds.afferent_type.values == kind
        ax.scatter(np.deg2rad(ds.theta_t.values[sel]), counts[sel], s=4, color=type_colour(kind))
        ax.yaxis.set_major_locator(MaxNLocator(3))  # a few radial ticks: they never run into each other
        ax.tick_params(axis="y", labelsize=7)
        ax.set_title(f"{type_label(kind)} (radius: spikes)")
    fig.suptitle(f"spike count against θ_T: {ds.condition.values[condition]}")
    return fig


def plot_forces(ds) -> Figure:
    """The forces of every condition as the model consumed them (a recording's: after its conditioning)."""
    n = ds.sizes["condition"]
    fig = Figure(figsize=(8.0, 2.0 * n), layout="constrained")
    axes = fig.subplots(n, 1, sharex=True, squeeze=False)[:, 0]
    for c, ax in enumerate(axes):
        forces = {name: ds[name].isel(condition=c).values for name in ("fx", "fy", "fz")}
        _plot_forces(ax, ds.time.values, forces)
        ax.set_title(f"{ds.condition.values[c]}: the forces the model consumed", fontsize=9)
    axes[-1].set_xlabel("time (s)")
    return fig


def plot_dsi_histograms(tuning, reference: dict | None = None) -> Figure:
    """DSI histogram per afferent type (responsive afferents), with the human mean +- SD."""
    kinds = _present(tuning.afferent_type.values)
    fig = Figure(figsize=(4.0 * len(kinds), 3.2), layout="constrained")
    axes = fig.subplots(1, len(kinds), sharey=False, squeeze=False)[0]
    for ax, kind in zip(axes, kinds):
        sel = (tuning.afferent_type.values == kind) & (tuning.responsive.values == 1)
        values = tuning.dsi.values[sel]
        ax.hist(values, bins=np.linspace(0, 1, 21), color=type_colour(kind), alpha=0.7)
        if values.size:
            ax.axvline(values.mean(), color="k", lw=1.5, label=f"model {values.mean():.2f} ± {values.std():.2f}")
        if reference and kind in reference:
            mean, sd = reference[kind]
            ax.axvspan(max(0, mean - sd), mean + sd, color="grey", alpha=0.2, label=f"human {mean} ± {sd}")
            ax.axvline(mean, color="grey", ls="--")
        ax.set_title(f"{type_label(kind)} (n = {values.size})")
        ax.set_xlabel("DSI (eq. 7)")
        ax.legend(fontsize=7)
    axes[0].set_ylabel("afferents")
    return fig


def plot_preferred_rose(tuning, bins: int = 16) -> Figure:
    """Rose plot of preferred directions of tuned afferents, per type (0 radial, 90 distal)."""
    fig = Figure(figsize=(4.2 * len(afferent_type_codes()), 5.0), layout="constrained")
    edges = np.linspace(0, 2 * np.pi, bins + 1)
    for i, kind in enumerate(afferent_type_codes()):
        ax = fig.add_subplot(1, len(afferent_type_codes()), i + 1, projection="polar")
        sel = (tuning.afferent_type.values == kind) & (tuning.tuned.values == 1) & (tuning.has_preferred.values == 1)
        counts, _ = np.histogram(np.deg2rad(tuning.preferred_deg.values[sel]), edges)
        ax.bar(edges[:-1], counts, width=edges[1] - edges[0], align="edge", color=type_colour(kind), alpha=0.7)
        ax.set_xticks(np.deg2rad([0, 90, 180, 270]), ["radial", "distal", "ulnar", "proximal"], fontsize=8)
        ax.tick_params(axis="x", pad=2)
        ax.set_title(f"{type_label(kind)}: preferred directions of {int(sel.sum())} tuned\n(vector sum; axial ones "
                     "omitted)", fontsize=9, pad=22)
    return fig


def plot_neurometric(summary: dict, threshold: float | None = None) -> Figure:
    """Median decoding error against population size (one line per window), per decoder."""
    decoders = list(summary["errors"])
    fig = Figure(figsize=(4.2 * len(decoders), 3.6), layout="constrained")
    axes = fig.subplots(1, len(decoders), sharey=True, squeeze=False)[0]
    for ax, name in zip(axes, decoders):
        for window, by_n in summary["errors"][name].items():
            sizes = sorted(by_n, key=int)
            ax.plot([int(n) for n in sizes], [by_n[n]["median_deg"] for n in sizes], "o-", label=f"{window} ms")
        if threshold is not None:
            ax.axhline(threshold, color="k", ls="--", lw=1, label=f"human {threshold}°")
        ax.set_xscale("log")
        ax.set_yscale("log")
        ax.set_xlabel("afferents")
        ax.set_title(name.replace("_", " "))
    axes[0].set_ylabel("median |error| (deg)")
    axes[-1].legend(fontsize=7)
    return fig


def plot_pareto(rows) -> Figure:
    """Mean SF error against wall time per afferent-second, one line per method and engine (dt labels on the
    first engine measured)."""
    fig = Figure(figsize=(7.0, 5.0), layout="constrained")
    ax = fig.subplots()
    engines = list(dict.fromkeys(r["engine"] for r in rows))  # in the order they were measured
    styles = {e: ("os^v"[i % 4], ("-", ":", "--", "-.")[i % 4]) for i, e in enumerate(engines)}
    keys = sorted({(r["method"], r["engine"]) for r in rows})
    for method, engine in keys:
        sel = sorted((r for r in rows if r["method"] == method and r["engine"] == engine
                      and r["sf_err_mean"] is not None), key=lambda r: r["dt_ms"])
        if not sel:
            continue
        x = [r["wall_s_per_afferent_s"] * 1e6 for r in sel]
        y = [max(r["sf_err_mean"], 1e-3) for r in sel]
        ax.plot(x, y, marker=styles[engine][0], ls=styles[engine][1], label=f"{method} ({engine})")
        for r, xi, yi in zip(sel, x, y):
            if engine == engines[0]:  # dt labels on the first engine's points only, for legibility
                ax.annotate(f"{r['dt_ms']:g}", (xi, yi), fontsize=6, xytext=(3, 3), textcoords="offset points")
    ax.axhline(1.0, color="grey", ls="--", lw=1)
    ax.set_xscale("log")
    ax.set_yscale("log")
    ax.set_xlabel("wall time per afferent-second (µs)")
    ax.set_ylabel("mean |SF - SF_ref| (pulses/s)")
    ax.set_title("accuracy against cost (labels: dt in ms)")
    ax.legend(fontsize=7, ncol=2)
    return fig


def plot_scaling(cases) -> Figure:
    """Cost against work from ``ddmm bench --cases scaling``: wall time and us per afferent-second.

    ``cases`` are the bench's case dicts (``n_afferents``, ``sim_s``, ``wall_s``).
    """
    fig = Figure(figsize=(9, 3.6))
    ax, ax2 = fig.subplots(1, 2)
    for seconds, marker in ((1.0, "o"), (10.0, "s")):
        rows = sorted((c for c in cases if c["sim_s"] == seconds), key=lambda c: c["n_afferents"])
        n = np.array([c["n_afferents"] for c in rows], float)
        wall = np.array([c["wall_s"] for c in rows])
        ax.loglog(n * seconds, wall, marker=marker, label=f"{seconds:g} s scenes")
        ax2.semilogx(n * seconds, wall / (n * seconds) * 1e6, marker=marker, label=f"{seconds:g} s scenes")
    work = np.array([1e3, 1e6])
    ax.loglog(work, work * 20e-6, "k:", label="linear (20 us per afferent-second)")
    ax.set_xlabel("afferent-seconds simulated")
    ax.set_ylabel("wall time (s)")
    ax2.set_xlabel("afferent-seconds simulated")
    ax2.set_ylabel("us per afferent-second")
    ax2.set_ylim(bottom=0)
    ax.legend(fontsize=8)
    fig.suptitle("Whole pipeline, direct engine, dt = 0.1 ms (ddmm bench --cases scaling)")
    fig.tight_layout()
    return fig
