"""Scorecard protocols of the slowly adapting types: SA-II under normal force and at rest, SA-I dynamics.

Registered through `ddmm.population.analysis.physiology.load_extensions`; the
reference ranges are ``ddmm.population.data.published._slow_reference``.
Forces in N, +Z into the skin; only the SA-I and SA-II afferents of the
population are simulated.

* ``slow_rest``: 5 s of zero force.  SA-II resting rates over 0.5-5 s: their
  10th-90th percentile range and the fraction that fire; the synchrony of
  their start: the resultant length of each active unit's first-spike phase
  (first-spike time over its own mean interval), 1 when every unit starts in
  step (the population PSTH then oscillates), near 0 when phases spread.
* ``slow_normal``: normal ramps at 10 N/s to 0.5, 2 and 8 N, each held 2 s
  (no shear).  SA-II: the smallest ratio of mean hold rates 0.5 -> 2 -> 8 N.
  SA-I: the fractional fall of the population rate from the first to the
  last 0.5 s of each hold.
* ``slow_fast``: a 30 N/s ramp to 4 N and, as a variant, a 20 N/s ramp to
  2 N, each held 2 s; and a 4 N/s ramp to 4 N.  Over the SA-I that fire in
  the last 1 s of the hold: the median of their largest 1/ISI from the
  ramp's start to 0.1 s after its end (the peak), of that peak over their
  mean rate in that last second (peak/plateau), and the median plateau at
  30 N/s over the one at 4 N/s (the plateau codes force, not loading rate).
"""

from __future__ import annotations

import numpy as np

from ddmm.population.analysis import physiology as _core
from ddmm.population.analysis.physiology import Property, _knots, _of, _rates
from ddmm.population.analysis.physiology_base import peak_rates

__all__ = ["PROPERTIES", "PROTOCOLS", "RUNNERS", "hold_scene"]

_TYPES = ("SAI", "SAII")
_FORCES = (0.5, 2.0, 8.0)
_FAST = ((4.0, 30.0), (2.0, 20.0), (4.0, 4.0))  # (force N, rate N/s)
_ONSET, _HOLD = 0.2, 2.0  # s

PROPERTIES = {name: Property(name, kind, protocol, statistic, unit) for name, kind, protocol, statistic, unit in (
    ("rest_spread_SAII", "SAII", "slow_rest", "10th-90th percentile range of resting rates", "1/s"),
    ("rest_active_SAII", "SAII", "slow_rest", "fraction firing at rest", "1"),
    ("start_synchrony_SAII", "SAII", "slow_rest", "resultant length of first-spike phases at rest", "1"),
    ("normal_coding_SAII", "SAII", "slow_normal", "smallest ratio of hold rates, 0.5 -> 2 -> 8 N normal", "1"),
    ("adaptation_05N_SAI", "SAI", "slow_normal", "fractional fall, first to last 0.5 s of a 0.5 N hold", "1"),
    ("adaptation_2N_SAI", "SAI", "slow_normal", "fractional fall, first to last 0.5 s of a 2 N hold", "1"),
    ("adaptation_8N_SAI", "SAI", "slow_normal", "fractional fall, first to last 0.5 s of an 8 N hold", "1"),
    ("peak_plateau_SAI", "SAI", "slow_fast", "median peak 1/ISI over plateau rate, 30 N/s to 4 N", "1"),
    ("peak_plateau_2N_SAI", "SAI", "slow_fast", "median peak 1/ISI over plateau rate, 20 N/s to 2 N (variant)",
     "1"),
    ("peak_rate_SAI", "SAI", "slow_fast", "median peak 1/ISI in loading, 30 N/s to 4 N", "1/s"),
    ("peak_rate_2N_SAI", "SAI", "slow_fast", "median peak 1/ISI in loading, 20 N/s to 2 N (variant)", "1/s"),
    ("plateau_rate_SAI", "SAI", "slow_fast", "median plateau rate at 4 N, loaded at 30 N/s over 4 N/s", "1"),
)}
PROTOCOLS = ("slow_rest", "slow_normal", "slow_fast")


def hold_scene(force: float, rate: float, name: str):
    """A normal ramp from 0.2 s at ``rate`` N/s to ``force`` N, held 2 s (no shear)."""
    top = _ONSET + force / rate
    return _knots([0.0, _ONSET, top, top + _HOLD], [0.0, 0.0, force, force], name=name)


def _simulate(population, scenes, context):
    from ddmm.population.simulation import simulate

    types = tuple(t for t in _TYPES if np.any(population.afferent_type == t))
    return simulate(population, scenes, engine=context["engine"], seed=context["seed"], quiet=True,
                    afferent_types=types)


def _first_spikes(ds, condition, afferents):
    """First spike time (s) of each afferent in ``afferents`` in one condition (nan: none), trial 0."""
    keep = (ds.spike_condition.values == condition) & (ds.spike_trial.values == 0)
    first = np.full(ds.sizes["afferent"], np.inf)
    np.minimum.at(first, ds.spike_afferent.values[keep], ds.spike_time.values[keep])
    first = first[afferents]
    return np.where(np.isfinite(first), first, np.nan)


def _slow_rest(population, context):
    ds = _simulate(population, [_knots([0.0, 5.0], [0.0, 0.0], name="rest")], context)
    sa2 = _of(ds, "SAII")
    if not sa2.any():
        return {}, {}
    rate = _rates(ds, 0.5, 5.0)[sa2]
    active = rate > 0
    p10, p90 = np.percentile(rate, [10, 90])
    first = _first_spikes(ds, 0, np.flatnonzero(sa2))[active]
    phase = 2.0 * np.pi * first * rate[active]
    ok = np.isfinite(phase)
    sync = float(np.abs(np.mean(np.exp(1j * phase[ok])))) if ok.any() else 1.0
    out = {"rest_spread_SAII": float(p90 - p10), "rest_active_SAII": float(active.mean()),
           "start_synchrony_SAII": sync}
    return out, {"rate": rate, "first": first}


def _slow_normal(population, context):
    ds = _simulate(population, [hold_scene(f, 10.0, f"normal_{f:g}") for f in _FORCES], context)
    out, data = {}, {}
    for c, force in enumerate(_FORCES):
        h0 = _ONSET + force / 10.0
        if _of(ds, "SAII").any():
            data.setdefault("saii", []).append(float(_rates(ds, h0, h0 + _HOLD, c)[_of(ds, "SAII")].mean()))
        if _of(ds, "SAI").any():
            sa = _of(ds, "SAI")
            first, last = _rates(ds, h0, h0 + 0.5, c)[sa].mean(), _rates(ds, h0 + 1.5, h0 + 2.0, c)[sa].mean()
            name = f"adaptation_{'05' if force == 0.5 else f'{force:g}'}N_SAI"
            out[name] = float(1.0 - last / max(first, 1e-12))
    if "saii" in data:
        r = np.asarray(data["saii"])
        out["normal_coding_SAII"] = float(np.min(r[1:] / np.maximum(r[:-1], 1e-12)))
    return out, data


def _peaks(ds, condition, force, rate):
    """Peak 1/ISI in loading (to 0.1 s after the ramp) and last-second plateau rate (1/s) of the SA-I that fire on
    the plateau."""
    top = _ONSET + force / rate
    sa = np.flatnonzero(_of(ds, "SAI"))
    plateau = _rates(ds, top + _HOLD - 1.0, top + _HOLD, condition)[sa]
    peak = peak_rates(ds, condition, _ONSET, top + 0.1)
    ok = plateau > 0
    return peak[sa][ok], plateau[ok]


def _median(x) -> float:
    return float(np.median(x)) if np.size(x) else 0.0


def _slow_fast(population, context):
    ds = _simulate(population, [hold_scene(f, r, f"fast_{r:g}_{f:g}") for f, r in _FAST], context)
    if not _of(ds, "SAI").any():
        return {}, {}
    (peak4, plat4), (peak2, plat2), (_, slow4) = (_peaks(ds, c, f, r) for c, (f, r) in enumerate(_FAST))
    out = {"peak_plateau_SAI": _median(peak4 / plat4), "peak_plateau_2N_SAI": _median(peak2 / plat2),
           "peak_rate_SAI": _median(peak4), "peak_rate_2N_SAI": _median(peak2),
           "plateau_rate_SAI": _median(plat4) / max(_median(slow4), 1e-12)}
    return out, {"dataset": ds}


RUNNERS = {"slow_rest": _slow_rest, "slow_normal": _slow_normal, "slow_fast": _slow_fast}

_core.load_extensions()  # a no-op unless this module was imported before the scorecard (see `load_extensions`)
