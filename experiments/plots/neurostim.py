"""The stimulation figure: per electrode, the force under its field, the rates, and the pulses it received.

`plot_stimulation` draws one row per electrode of a pulses Dataset
(`ddmm.population.neurostim.stimulation_pulses`) for one condition and
trial, in three columns sharing the time axis (s):

1. the normal force under the electrode's projected field (N), with the
   contact threshold dotted;
2. the rates: the aggregate afferent rate (spikes/s per field afferent), the
   pulse rate the rule commanded (Hz) and the rate delivered, 1 / the interval
   to the electrode's previous pulse (Hz, one dot per pulse), so command and
   delivery sit on one scale;
3. the pulses: one marker per pulse at its time and amplitude (µA), with the
   electrode's amplitude range dashed.

Takes data and returns a `matplotlib.figure.Figure`; never writes a file.
"""

from __future__ import annotations

from numbers import Integral

import numpy as np
from matplotlib.figure import Figure

__all__ = ["plot_stimulation"]

_COLOURS = {"force": "k", "aggregate": "0.55", "command": "tab:blue", "delivered": "tab:orange",
            "pulse": "tab:red", "limit": "tab:red"}


def _check_index(pulses, name: str, value) -> int:
    """``value`` as a position on ``pulses``' dimension ``name``; ValueError naming ``name`` otherwise."""
    size = pulses.sizes[name]
    if isinstance(value, bool) or not isinstance(value, Integral):
        raise TypeError(f"plot_stimulation: {name} must be an integer position, got {type(value).__name__} "
                        f"{value!r}")
    if not 0 <= value < size:
        raise ValueError(f"plot_stimulation: {name} must be in 0..{size - 1} (the pulses Dataset has {size} "
                         f"{name}(s)), got {value}")
    return int(value)


def _field_label(pulses, e: int) -> str:
    """The row label: id, field and limits, e.g. ``"E1: field disc x 0 mm, y 0 mm, radius 4 mm; 20-80 µA, ..."``."""
    region = str(pulses["region"].values[e])
    if region:
        field = f"region {region}"
    else:
        x, y, r = (float(pulses[n].values[e]) for n in ("x_mm", "y_mm", "radius_mm"))
        field = f"disc x {x:g} mm, y {y:g} mm, radius {r:g} mm"
    lo, hi, width, rate, charge = (float(pulses[n].values[e]) for n in (
        "amplitude_min_ua", "amplitude_max_ua", "phase_width_us", "max_rate_hz", "charge_limit_nc"))
    return (f"{pulses['electrode'].values[e]}: field {field};  {lo:g}-{hi:g} µA, {width:g} µs/phase, "
            f"max {rate:g} Hz, max {charge:g} nC/phase")


def _draw_force(ax, time, force, threshold, label) -> None:
    ax.plot(time, force, color=_COLOURS["force"], lw=1.0)
    ax.axhline(threshold, color="0.5", ls=":", lw=0.8)
    ax.set_title(label, loc="left", fontsize=8, fontweight="bold")  # the row's label, over its first panel
    ax.set_ylabel("force (N)", fontsize=8)
    ax.set_ylim(bottom=0)


def _draw_rates(ax, time, row, t_pulse) -> None:
    """Aggregate afferent rate, commanded rate, delivered rate (1 / inter-pulse interval)."""
    ax.plot(time, row["aggregate_rate"], color=_COLOURS["aggregate"], lw=0.9)
    ax.plot(time, row["rate_command"], color=_COLOURS["command"], lw=1.0)
    if t_pulse.size > 1:
        ax.plot(t_pulse[1:], 1.0 / np.diff(t_pulse), ls="none", marker="o", ms=1.5, mew=0,
                color=_COLOURS["delivered"])
    ax.set_ylabel("rate (Hz)", fontsize=8)
    ax.set_ylim(bottom=0)


def _draw_pulses(ax, t_pulse, amplitude, limits) -> None:
    """One marker per pulse (gid ``"pulses"``), the amplitude range dashed, the axis from 0 to above the maximum."""
    for level in limits:
        ax.axhline(level, color=_COLOURS["limit"], ls="--", lw=0.8, alpha=0.7)
    ax.plot(t_pulse, amplitude, ls="none", marker="o", ms=2.0, mew=0, color=_COLOURS["pulse"], gid="pulses")
    ax.set_ylim(0, 1.15 * limits[1])
    ax.set_ylabel("amplitude (µA)", fontsize=8)
    ax.text(0.99, 0.97, f"{t_pulse.size} pulses", transform=ax.transAxes, ha="right", va="top", fontsize=6)


def _legend(fig) -> None:
    """One legend for every row, under the panels."""
    from matplotlib.lines import Line2D

    handles = [Line2D([], [], color=_COLOURS["force"], label="force under the field (N)"),
               Line2D([], [], color="0.5", ls=":", label="contact threshold (N)"),
               Line2D([], [], color=_COLOURS["aggregate"], label="afferent rate (spikes/s per field afferent)"),
               Line2D([], [], color=_COLOURS["command"], label="commanded pulse rate (Hz)"),
               Line2D([], [], color=_COLOURS["delivered"], ls="none", marker="o", ms=3,
                      label="delivered pulse rate, 1/interval (Hz)"),
               Line2D([], [], color=_COLOURS["pulse"], ls="none", marker="o", ms=3, label="pulse amplitude (µA)"),
               Line2D([], [], color=_COLOURS["limit"], ls="--", label="amplitude limits (µA)")]
    fig.legend(handles=handles, loc="outside lower center", ncol=4, fontsize=7, frameon=False)


def plot_stimulation(pulses, condition=0, trial=0) -> Figure:
    """Force, rates and pulses of every electrode for one condition and trial (module docstring).

    Parameters
    ----------
    pulses : xarray.Dataset
        A pulses Dataset (`ddmm.population.neurostim.stimulation_pulses` or
        `load_pulses`).
    condition, trial : int
        Positions on the Dataset's ``condition`` and ``trial``.

    Returns
    -------
    Figure
        One row per electrode (three columns: force, rates, pulses), time in s.

    Raises
    ------
    TypeError, ValueError
        For a non-integer or out-of-range ``condition`` or ``trial`` (the message names it).

    Examples
    --------
    >>> from ddmm.population import birznieks, make_population, simulate
    >>> from ddmm.population.neurostim import Electrode, stimulation_pulses
    >>> ds = simulate(make_population(["SAI", "RAI"]), birznieks(90.0), engine="direct", seed=0, quiet=True)
    >>> table = [Electrode("E1", 20.0, 80.0, 200.0, 300.0, 20.0, x_mm=0.0, y_mm=0.0, radius_mm=4.0),
    ...          Electrode("E2", 10.0, 60.0, 100.0, 200.0, 10.0, x_mm=5.0, y_mm=-5.0, radius_mm=3.0)]
    >>> fig = plot_stimulation(stimulation_pulses(ds, table))
    >>> len(fig.axes), fig.axes[0].get_title(loc="left")
    (6, 'E1: field disc x 0 mm, y 0 mm, radius 4 mm;  20-80 µA, 200 µs/phase, max 300 Hz, max 20 nC/phase')
    """
    c, r = _check_index(pulses, "condition", condition), _check_index(pulses, "trial", trial)
    n_e, time = pulses.sizes["electrode"], pulses["time"].values
    fig = Figure(figsize=(11.0, 1.2 + 1.5 * n_e), layout="constrained")
    axes = fig.subplots(n_e, 3, sharex=True, squeeze=False)
    mine = (pulses.pulse_condition.values == c) & (pulses.pulse_trial.values == r)
    limits = np.stack([pulses[n].values for n in ("amplitude_min_ua", "amplitude_max_ua")], axis=1)
    for e in range(n_e):
        sel = mine & (pulses.pulse_electrode.values == e)
        t_pulse = pulses.pulse_time.values[sel]
        row = {n: pulses[n].values[c, r, :, e] for n in ("aggregate_rate", "rate_command")}
        _draw_force(axes[e, 0], time, pulses.field_force.values[c, :, e], float(pulses.attrs["contact_threshold"]),
                    _field_label(pulses, e))
        _draw_rates(axes[e, 1], time, row, t_pulse)
        _draw_pulses(axes[e, 2], t_pulse, pulses.pulse_amplitude.values[sel], limits[e])
    for ax in axes[-1]:
        ax.set_xlabel("time (s)")
    axes[0, 0].set_xlim(time[0], time[-1] + (time[1] - time[0] if time.size > 1 else 0.0))
    _legend(fig)
    fig.suptitle(f"stimulation pulses: condition {c} ({pulses.condition.values[c]}), trial {r}, "
                 f"rule {pulses.attrs.get('rule', '?')}: {int(mine.sum())} pulses on {n_e} electrode(s)", fontsize=10)
    return fig
