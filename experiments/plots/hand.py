"""The hand map figure: region outlines, afferents by type, and optionally a spike-count map.

Takes data and returns a `matplotlib.figure.Figure`; never writes a file.
"""

from __future__ import annotations

import numpy as np
from matplotlib.figure import Figure

from ddmm.experiments.plots.common import type_colour
from ddmm.models.afferent_types import afferent_type_codes, type_label
from ddmm.population.anatomy import hand_map

__all__ = ["plot_hand", "hand_counts"]


def _afferents(population) -> tuple:
    """(type, x, y, region) arrays of a Population or of a Dataset's afferent coordinates."""
    try:
        arrays = [np.asarray(getattr(population, name)) for name in ("afferent_type", "x_mm", "y_mm")]
    except AttributeError:
        raise TypeError(f"population must be a Population or a dataset with afferent coordinates, "
                        f"got {type(population).__name__}") from None
    region = getattr(population, "region", None)
    region = np.full(arrays[0].shape, "", dtype=object) if region is None else np.asarray(region, dtype=object)
    return (*arrays, region)


def _limits(x, y, region) -> tuple:
    """Axis limits: the outlines of the labelled regions and the afferents, 5 mm margin."""
    names = [n for n in hand_map.REGIONS if np.any(region == n)] or list(hand_map.REGIONS)
    pts = np.vstack([hand_map.outline(n) for n in names] + [np.column_stack([x, y]).reshape(-1, 2)])
    lo, hi = pts.min(axis=0) - 5.0, pts.max(axis=0) + 5.0
    return (lo[0], hi[0]), (lo[1], hi[1])


def _draw_outlines(ax) -> None:
    for name, region in hand_map.REGIONS.items():
        line = hand_map.outline(name)
        ax.plot(line[:, 0], line[:, 1], color="0.3", lw=0.7)
        ax.annotate(name, region.center_mm, fontsize=5, color="0.4", ha="center", va="center")


def hand_counts(ds) -> np.ndarray:
    """Spike count per afferent of a dataset: mean over trials, summed over conditions."""
    return ds.spike_count.mean("trial").sum("condition").values


def plot_hand(population, counts=None, ax=None) -> Figure:
    """Afferents on the hand map (hand frame, mm), coloured by type.

    Parameters
    ----------
    population : Population or xarray.Dataset
        Anything with per-afferent ``afferent_type``, ``x_mm``, ``y_mm`` and
        (optionally) ``region``, e.g. a simulation dataset.
    counts : array_like, optional
        Spike count per afferent; when given, marker area grows with the
        count and silent afferents shrink to grey dots.
    ax : matplotlib Axes, optional
        Draw into this axes (its figure is returned).

    Returns
    -------
    Figure

    Examples
    --------
    >>> from ddmm.population import sample_population
    >>> fig = plot_hand(sample_population("hand", rng=0))
    >>> fig.axes[0].get_xlabel()
    'x (mm, radial +)'
    """
    types, x, y, region = _afferents(population)
    if counts is not None:
        counts = np.asarray(counts, dtype=float)
        if counts.shape != types.shape or not np.all(np.isfinite(counts)) or np.any(counts < 0):
            raise ValueError(f"counts must be finite, >= 0 and of shape {types.shape}, got shape {counts.shape}")
    if ax is None:
        ax = Figure(figsize=(6.0, 7.0), layout="constrained").subplots()
    _draw_outlines(ax)
    active = np.ones(types.shape, bool) if counts is None else counts > 0
    if counts is not None:
        ax.scatter(x[~active], y[~active], s=0.5, color="0.75", label=f"silent ({int((~active).sum())})")
        size = 1.0 + 40.0 * counts / max(counts.max(), 1e-12)
    for kind in afferent_type_codes():
        sel = (types == kind) & active
        silent = int(np.sum((types == kind) & ~active))
        if np.any(types == kind):  # the count is every afferent of the type, the silent ones named
            ax.scatter(x[sel], y[sel], s=1.5 if counts is None else size[sel], color=type_colour(kind),
                       alpha=0.6, lw=0, label=f"{type_label(kind)} ({int(np.sum(types == kind))}"
                                              + (f", {silent} silent)" if silent else ")"))
    ax.set_xlim(*_limits(x, y, region)[0])
    ax.set_ylim(*_limits(x, y, region)[1])
    ax.set_aspect("equal")
    ax.set_xlabel("x (mm, radial +)")
    ax.set_ylabel("y (mm, distal +)")
    what = "afferents by type" if counts is None else "spike count (marker area)"
    shown = [n for n in hand_map.REGIONS if np.any(region == n)]
    where = "right hand" if not shown or len(shown) == len(hand_map.REGIONS) else \
        f"region{'s' if len(shown) > 1 else ''} {', '.join(shown)} of a right hand"
    ax.set_title(f"{where}, palmar view: {what}", fontsize=9)
    ax.legend(fontsize=7, markerscale=3, loc="lower left")
    return ax.figure
