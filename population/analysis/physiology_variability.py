"""Trial-to-trial variability protocol of the physiology scorecard (docs/references.md rows 14, 23).

``variability``: 20 repeats of a 2 N press (0 -> 2 N at 10 N/s from 0.2 s,
a 0.6 s hold, a release at 10 N/s).  Per type (SA-I, FA-I, FA-II):

* the Fano factor (variance / mean over trials) of each afferent's
  loading-phase count (spikes in 0.2-0.45 s: the ramp and 50 ms after it),
  median over the afferents with a mean count of at least 1;
* the first-spike jitter: the SD over trials of each afferent's first spike
  in that window, median over the afferents that fire on every trial (ms).

`variability_stats` also serves the variants the rows were not tuned on
(another force, another ramp rate, other seeds; docs/model.md).  Registered
through `ddmm.population.analysis.physiology.load_extensions` (in either import order).
"""

from __future__ import annotations

import numpy as np

from ddmm.population.analysis import physiology as _core
from ddmm.population.analysis.physiology import Property, _knots, _of, _run
from ddmm.population.stimuli.scenes import Stage

__all__ = ["PROPERTIES", "PROTOCOLS", "RUNNERS", "press_scene", "variability_stats", "REPEATS"]

#: Repeats of the press.
REPEATS = 20
#: The types with rows.
TYPES = ("SAI", "RAI", "RAII")
_ONSET_S, _AFTER_S = 0.2, 0.05

PROPERTIES = {}
for _t in TYPES:
    PROPERTIES[f"fano_{_t}"] = Property(f"fano_{_t}", _t, "variability",
                                        "Fano factor of loading counts, 20 presses to 2 N (median over afferents)",
                                        "1")
    PROPERTIES[f"first_jitter_{_t}"] = Property(f"first_jitter_{_t}", _t, "variability",
                                                "first-spike jitter, 20 presses to 2 N (SD over trials, median)",
                                                "ms")
PROTOCOLS = ("variability",)


def press_scene(force_n: float = 2.0, rate_n_s: float = 10.0, name: str = "press"):
    """0 -> ``force_n`` at ``rate_n_s`` from 0.2 s, a 0.6 s hold, the release at the same rate, 0.3 s rest."""
    ramp = force_n / rate_n_s
    knots = [0.0, _ONSET_S, _ONSET_S + ramp, _ONSET_S + ramp + 0.6, _ONSET_S + 2 * ramp + 0.6,
             _ONSET_S + 2 * ramp + 0.9]
    return _knots(knots, [0.0, 0.0, force_n, force_n, 0.0, 0.0], name=name,
                  stages=(Stage("loading", _ONSET_S, _ONSET_S + ramp),))


def _counts_and_first(ds, t0, t1):
    """Per (trial, afferent): spikes in [t0, t1) and the first spike time in it (NaN without one)."""
    n_trials, n = ds.sizes["trial"], ds.sizes["afferent"]
    time, trial, aff = ds.spike_time.values, ds.spike_trial.values, ds.spike_afferent.values
    keep = (time >= t0) & (time < t1)
    counts = np.zeros((n_trials, n))
    np.add.at(counts, (trial[keep], aff[keep]), 1.0)
    first = np.full((n_trials, n), np.inf)
    np.minimum.at(first, (trial[keep], aff[keep]), time[keep])
    first[~np.isfinite(first)] = np.nan
    return counts, first


def variability_stats(ds, t0: float, t1: float) -> dict:
    """Fano factor and first-spike jitter (ms) per type of a repeated-trial dataset, window [t0, t1) s.

    Returns NaN for a type with no afferent that qualifies (mean count >= 1
    for the Fano factor, a spike on every trial for the jitter).
    """
    counts, first = _counts_and_first(ds, t0, t1)
    out = {}
    for t in TYPES:
        cols = _of(ds, t)
        if not cols.any():
            continue
        c, f = counts[:, cols], first[:, cols]
        mean = c.mean(axis=0)
        driven = mean >= 1.0
        fano = c[:, driven].var(axis=0, ddof=1) / mean[driven]
        fired = np.all(np.isfinite(f), axis=0)
        out[f"fano_{t}"] = float(np.median(fano)) if driven.any() else float("nan")
        out[f"first_jitter_{t}"] = float(np.median(np.std(f[:, fired], axis=0, ddof=1)) * 1e3) if fired.any() \
            else float("nan")
    return out


def _variability(population, context):
    types = [t for t in TYPES if np.any(population.afferent_type == t)]
    sub = population.select(np.isin(population.afferent_type, types))
    scene = press_scene()
    ds = _run(sub, [scene], context, trials=REPEATS)
    t1 = scene.stages[0].end + _AFTER_S
    return variability_stats(ds, _ONSET_S, t1), {"window_s": (_ONSET_S, t1)}


RUNNERS = {"variability": _variability}

_core.load_extensions()  # a no-op unless this module was imported before the scorecard (see `load_extensions`)
