"""The building blocks of the physiology scorecard's protocol modules: `Property` and the run helpers.

Every protocol module (`physiology_core` and the extensions that
`ddmm.population.analysis.physiology.load_extensions` registers) describes
its rows with `Property` (``_p`` pairs a name with one) and runs its scenes
through the same helpers: ``_knots`` (a normal-force scene through knots),
``_run`` (`ddmm.population.simulate` with the scorecard's seed and engine),
``_rates`` (mean rate per afferent in a window), ``_of`` (a type's mask), ``_spaced`` (at most
so many afferents a type), `window_counts` (spikes per trial and afferent in a window) and
`peak_rates` (each afferent's largest 1/ISI in a window).
`ddmm.population.analysis.physiology` re-exports them all.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from ddmm.population.stimuli.scenes import Scene

__all__ = ["Property", "peak_rates", "window_counts"]


@dataclass(frozen=True)
class Property:
    """One row of the scorecard: what is measured, on which type, by which protocol."""

    name: str
    afferent_type: str
    protocol: str
    statistic: str
    unit: str


def _p(name, kind, protocol, statistic, unit="1"):
    """``(name, Property)``: one entry of a protocol module's ``PROPERTIES``."""
    return name, Property(name, kind, protocol, statistic, unit)


def _knots(knots, values, *, fs=1000.0, name="scene", stages=()) -> Scene:
    """A normal-force scene through (time, force) knots, no shear."""
    t = np.arange(int(round(knots[-1] * fs))) / fs
    fz = np.interp(t, knots, values)
    return Scene(np.zeros_like(fz), np.zeros_like(fz), fz, fs, name, tuple(stages))


def _rates(ds, t0, t1, condition=0):
    """Mean rate (1/s) per afferent in [t0, t1) of one condition, averaged over trials."""
    keep = (ds.spike_condition.values == condition) & (ds.spike_time.values >= t0) & (ds.spike_time.values < t1)
    counts = np.bincount(ds.spike_afferent.values[keep], minlength=ds.sizes["afferent"])
    return counts / ds.sizes["trial"] / (t1 - t0)


def _spaced(population, kinds, max_units: int):
    """At most ``max_units`` afferents of each type in ``kinds``, evenly spaced in population order (None: none),
    so that a protocol costs on the hand what it costs on the fingertip."""
    keep = []
    for kind in kinds:
        idx = np.flatnonzero(population.afferent_type == kind)
        if idx.size > max_units:
            idx = idx[np.linspace(0, idx.size - 1, max_units).round().astype(np.int64)]
        keep.append(idx)
    keep = np.sort(np.concatenate(keep)) if keep else np.zeros(0, np.int64)
    return population.select(keep) if keep.size else None


def window_counts(ds, condition: int, window) -> np.ndarray:
    """Spikes per (trial, afferent) of one condition in ``window`` (s)."""
    t = ds.spike_time.values
    keep = (ds.spike_condition.values == condition) & (t >= window[0]) & (t < window[1])
    n_aff, n_trial = ds.sizes["afferent"], ds.sizes["trial"]
    flat = ds.spike_trial.values[keep] * n_aff + ds.spike_afferent.values[keep]
    return np.bincount(flat, minlength=n_trial * n_aff).reshape(n_trial, n_aff)


def peak_rates(ds, condition: int, t0: float, t1: float) -> np.ndarray:
    """Each afferent's largest instantaneous rate 1/ISI (1/s) among its trial-0 spikes of one condition in
    [t0, t1) s (0 with fewer than two spikes there).

    Examples
    --------
    >>> import numpy as np, xarray as xr
    >>> ds = xr.Dataset({"spike_time": ("spike", [0.10, 0.11, 0.30, 0.5]), "spike_afferent": ("spike", [0, 0, 0, 1]),
    ...                  "spike_condition": ("spike", [0, 0, 0, 0]), "spike_trial": ("spike", [0, 0, 0, 0])},
    ...                 coords={"afferent": [0, 1]})
    >>> peak_rates(ds, 0, 0.0, 1.0).round(1).tolist()
    [100.0, 0.0]
    """
    keep = (ds.spike_condition.values == condition) & (ds.spike_trial.values == 0) \
        & (ds.spike_time.values >= t0) & (ds.spike_time.values < t1)
    aff, t = ds.spike_afferent.values[keep], ds.spike_time.values[keep]
    order = np.lexsort((t, aff))
    aff, t = aff[order], t[order]
    same = aff[1:] == aff[:-1]
    peak = np.zeros(ds.sizes["afferent"])
    np.maximum.at(peak, aff[1:][same], 1.0 / np.diff(t)[same])
    return peak


def _of(ds, kind):
    """Mask of the afferents of type ``kind`` in a run's dataset."""
    return ds.afferent_type.values == kind


def _run(population, scenes, context, **kwargs):
    """`ddmm.population.simulate` with the scorecard's engine and seed (``context``), quietly."""
    from ddmm.population.simulation import simulate

    return simulate(population, scenes, engine=context["engine"], seed=context["seed"], quiet=True, **kwargs)
