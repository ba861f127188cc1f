"""Figures of scanned surfaces: spatial event plots (`ddmm.population.analysis.surface_maps`)."""

from __future__ import annotations

import numpy as np
from matplotlib.figure import Figure

from ddmm.experiments.plots.common import _present, type_colour
from ddmm.models.afferent_types import type_label

__all__ = ["plot_spatial_events"]


def plot_spatial_events(events, surface=None, *, extent_mm=None, dot_size: float = 2.0) -> Figure:
    """One panel per afferent type: every spike at the surface point over its afferent's centre.

    Parameters
    ----------
    events : xarray.Dataset
        `ddmm.population.analysis.surface_maps`'s result.
    surface : Surface, optional
        Drawn under the spikes as its relief's outline (half its highest point).
    extent_mm : (float, float, float, float), optional
        (x0, x1, y0, y1) in mm shown; default: the events' box.
    dot_size : float
        Marker area in points^2.

    Returns
    -------
    matplotlib.figure.Figure

    Examples
    --------
    >>> import xarray as xr
    >>> ev = xr.Dataset({"surface_x_mm": ("event", [0.0, 1.0]), "surface_y_mm": ("event", [0.0, 0.5]),
    ...                  "afferent_type": ("event", np.array(["SAI", "RAI"], dtype=object))})
    >>> len(plot_spatial_events(ev).axes)
    2
    """
    kinds = _present(events.afferent_type.values.astype(str))
    fig = Figure(figsize=(3.2 * len(kinds), 3.0), layout="constrained")
    axes = fig.subplots(1, len(kinds), sharex=True, sharey=True, squeeze=False)[0]
    x, y = events.surface_x_mm.values, events.surface_y_mm.values
    types = events.afferent_type.values.astype(str)
    for ax, kind in zip(axes, kinds):
        if surface is not None:
            _outline(ax, surface, extent_mm if extent_mm is not None else _box(x, y))
        mine = types == kind
        ax.scatter(x[mine], y[mine], s=dot_size, color=type_colour(kind), linewidths=0)
        ax.set_title(f"{type_label(kind)} ({int(mine.sum())} spikes)", fontsize=9)
        ax.set_aspect("equal")
        ax.set_xlabel("surface x (mm)")
        if extent_mm is not None:
            ax.set_xlim(extent_mm[0], extent_mm[1])
            ax.set_ylim(extent_mm[2], extent_mm[3])
    axes[0].set_ylabel("surface y (mm)")
    return fig


def _box(x, y) -> tuple:
    if x.size == 0:
        return (-1.0, 1.0, -1.0, 1.0)
    return (float(x.min()), float(x.max()) + 1e-6, float(y.min()), float(y.max()) + 1e-6)


def _outline(ax, surface, extent) -> None:
    gx = np.linspace(extent[0], extent[1], 200)
    gy = np.linspace(extent[2], extent[3], 200)
    heights = surface.height_at(gx[None, :], gy[:, None])
    if np.ptp(heights) > 0.0:
        ax.contour(gx, gy, heights, levels=[surface.max_height_mm / 2.0], colors="0.6", linewidths=0.8)
