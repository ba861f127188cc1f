"""The core battery of the physiology scorecard: its rows, protocols and runners.

Registered in `ddmm.population.analysis.physiology` before every other
protocol module; like them it defines ``PROPERTIES``, ``PROTOCOLS`` and
``RUNNERS`` (`ddmm.population.analysis.physiology.load_extensions`).

Protocols (forces in N, +Z into the skin; the frame of `ddmm.population.stimuli.scenes`):

* ``rest``: 60 s of zero force.
* ``on_off``: a normal ramp 0 -> 4 N at 10 N/s, a 2 s hold, a release at 10 N/s.
* ``rates``: every scene the package ships (`shipped_scenes`): the largest
  instantaneous rate (1/ISI) and spikes on consecutive integration steps.
* ``force_coding``: SA-I plateaus at 1, 2 and 4 N (2 N/s ramps); RA-I
  mean rates while loading at 2, 8 and 32 N/s to 4 N.
* ``frequency``: sinusoidal normal force on a 1 N preload, 5-400 Hz, sampled
  at 5 kHz; per afferent the amplitude for one spike per cycle.
* ``direction``: the Birznieks protocol (`ddmm.population.analysis.tuning`).
* ``timing``: first-spike-latency and count (maximum-likelihood) decoders of
  direction in 125 ms, each on ensembles of 92 SA-I, SA-II and FA-I afferents
  (the size of Saal et al. 2009's sample), median over 10 ensembles; and the
  first-spike jitter of FA-I over 10 trials.
* ``continuity``: F_A across a shear that reverses through zero: the largest
  sample-to-sample step at 10 kHz over that at 1 kHz (0.1 for a continuous
  F_A with a bounded slope, 1 for a jump).
"""

from __future__ import annotations

import numpy as np

from ddmm.models.afferent_types import afferent_type_codes, is_type
from ddmm.models.attenuation import attenuation_factor
from ddmm.population.analysis.physiology_base import _knots, _of, _p, _rates, _run
from ddmm.population.stimuli.scenes import Scene, Stage, birznieks, press_push_lift, rotating_shear

__all__ = ["AMPLITUDES_N", "FREQUENCIES_HZ", "PROPERTIES", "PROTOCOLS", "RUNNERS", "TIMING_ENSEMBLE",
           "TIMING_ENSEMBLES", "on_off_scene", "shipped_scenes", "vibration_scene"]

#: The core battery, in the order rows are printed.
PROPERTIES = dict([
    _p("rest_rate_RAI", "RAI", "rest", "mean rate, 60 s of zero force", "1/s"),
    _p("rest_rate_RAII", "RAII", "rest", "mean rate, 60 s of zero force", "1/s"),
    _p("rest_rate_SAI", "SAI", "rest", "mean rate, 60 s of zero force", "1/s"),
    _p("rest_silent_SAI", "SAI", "rest", "fraction without a spike in 60 s"),
    _p("rest_rate_SAII", "SAII", "rest", "mean rate, 60 s of zero force", "1/s"),
    _p("hold_ratio_RAI", "RAI", "on_off", "hold rate / loading rate"),
    _p("release_fraction_RAI", "RAI", "on_off", "fraction firing during the release"),
    _p("off_transient_RAII", "RAII", "on_off", "fraction of spikes > 100 ms from a transient"),
    _p("hold_rate_SAI", "SAI", "on_off", "mean rate over the 4 N hold", "1/s"),
    _p("adaptation_SAI", "SAI", "on_off", "rate in the last / first 0.5 s of the hold"),
    _p("max_rate_SAI", "SAI", "rates", "largest 1/ISI on the shipped scenes", "1/s"),
    _p("max_rate_RAI", "RAI", "rates", "largest 1/ISI on the shipped scenes", "1/s"),
    _p("max_rate_RAII", "RAII", "rates", "largest 1/ISI on the shipped scenes", "1/s"),
    _p("max_rate_SAII", "SAII", "rates", "largest 1/ISI on the shipped scenes", "1/s"),
    _p("capped_spikes", "all", "rates", "spikes on consecutive integration steps"),
    _p("force_coding_SAI", "SAI", "force_coding", "smallest ratio of plateau rates, 1 -> 2 -> 4 N"),
    _p("rate_coding_RAI", "RAI", "force_coding", "smallest ratio of mean loading rates, 2 -> 8 -> 32 N/s"),
    _p("best_frequency_RAI", "RAI", "frequency",
       "frequency of the lowest one-spike-per-cycle amplitude, each unit's relative to its own best", "Hz"),
    _p("best_frequency_RAII", "RAII", "frequency",
       "frequency of the lowest one-spike-per-cycle amplitude, each unit's relative to its own best", "Hz"),
    _p("tuned_SAI", "SAI", "direction", "fraction tuned (ANOVA per phase, p < 0.05)"),
    _p("tuned_RAI", "RAI", "direction", "fraction tuned (ANOVA per phase, p < 0.05)"),
    _p("dsi_mean_SAI", "SAI", "direction", "DSI mean"),
    _p("dsi_sd_SAI", "SAI", "direction", "DSI SD"),
    _p("dsi_mean_RAI", "RAI", "direction", "DSI mean"),
    _p("dsi_sd_RAI", "RAI", "direction", "DSI SD"),
    _p("tuned_SAII", "SAII", "direction", "fraction tuned (ANOVA per phase, p < 0.05)"),
    _p("tuned_recorded", "SAI+SAII+RAI", "direction",
       "fraction tuned over the recorded types (count-weighted mix of the per-type rows)"),
    _p("latency_vs_count", "all", "timing", "median error, first-spike latency / spike count decoder, 125 ms"),
    _p("jitter_RAI", "RAI", "timing", "first-spike jitter (SD over trials, median over afferents)", "ms"),
    _p("continuity", "SAI+RAI+RAII", "continuity",
       "largest F_A step at 10 kHz / at 1 kHz, shear reversing through zero"),
])
#: The protocols, in the order they run.
PROTOCOLS = ("rest", "on_off", "rates", "force_coding", "frequency", "direction", "timing", "continuity")


def on_off_scene() -> Scene:
    """0 -> 4 N at 10 N/s from 0.2 s, a 2 s hold, release at 10 N/s, 0.5 s rest."""
    return _knots([0, 0.2, 0.6, 2.6, 3.0, 3.5], [0, 0, 4, 4, 0, 0], name="on_off",
                  stages=(Stage("loading", 0.2, 0.6), Stage("hold", 0.6, 2.6), Stage("release", 2.6, 3.0)))


def shipped_scenes() -> list:
    """Every scene generator the package ships, at its defaults (the rates protocol)."""
    scenes = [birznieks(None)] + [birznieks(d) for d in (0.0, 90.0, 180.0, 270.0)]
    return scenes + [press_push_lift(90.0), rotating_shear()]


def _rest(population, context) -> dict:
    ds = _run(population, [_knots([0.0, 60.0], [0.0, 0.0], name="rest")], context)
    rate = ds.spike_count.values[0, 0] / 60.0
    out = {f"rest_rate_{t}": float(rate[_of(ds, t)].mean()) for t in ("RAI", "RAII", "SAI", "SAII")
           if _of(ds, t).any()}
    if _of(ds, "SAI").any():
        out["rest_silent_SAI"] = float(np.mean(rate[_of(ds, "SAI")] == 0))
    return out, {"rate": rate, "type": ds.afferent_type.values}


def _transient_distance(times, transients):
    return np.min(np.abs(np.asarray(times)[:, None] - np.asarray(transients)[None, :]), axis=1)


def _on_off(population, context) -> dict:
    ds = _run(population, [on_off_scene()], context)
    load, hold, release = _rates(ds, 0.2, 0.6), _rates(ds, 0.6, 2.6), _rates(ds, 2.6, 3.0)
    out = {}
    if _of(ds, "RAI").any():
        ra = _of(ds, "RAI")
        out["hold_ratio_RAI"] = float(hold[ra].mean() / max(load[ra].mean(), 1e-12))
        out["release_fraction_RAI"] = float(np.mean(release[ra] > 0))
    if _of(ds, "RAII").any():
        ra2 = _of(ds, "RAII")[ds.spike_afferent.values]
        far = _transient_distance(ds.spike_time.values[ra2], [0.2, 0.6, 2.6, 3.0]) > 0.1
        out["off_transient_RAII"] = float(far.mean()) if far.size else 0.0
    if _of(ds, "SAI").any():
        sa = _of(ds, "SAI")
        out["hold_rate_SAI"] = float(hold[sa].mean())
        out["adaptation_SAI"] = float(_rates(ds, 2.1, 2.6)[sa].mean() / max(_rates(ds, 0.6, 1.1)[sa].mean(), 1e-12))
    return out, {"dataset": ds}


def _max_rates(ds):
    """Largest 1/ISI (1/s) per type and the number of spikes one step after another."""
    key = (ds.spike_condition.values.astype(np.int64) * ds.sizes["trial"] + ds.spike_trial.values) \
        * ds.sizes["afferent"] + ds.spike_afferent.values
    order = np.lexsort((ds.spike_time.values, key))
    key, time = key[order], ds.spike_time.values[order]
    same = key[1:] == key[:-1]
    isi = np.diff(time)[same]
    owner = (key[1:][same] % ds.sizes["afferent"]).astype(np.int64)
    dt = float(ds.attrs["dt"])
    capped = int(np.sum(isi < 1.5 * dt))
    out = {}
    for kind in afferent_type_codes():
        sel = _of(ds, kind)[owner]
        if _of(ds, kind).any():
            out[f"max_rate_{kind}"] = float(1.0 / isi[sel].min()) if np.any(sel) else 0.0
    return out, capped


def _shipped_rates(population, context) -> dict:
    out, capped = {}, 0
    for scene in shipped_scenes():
        ds = _run(population, [scene], context)
        rates, n = _max_rates(ds)
        capped += n
        for name, value in rates.items():
            out[name] = max(out.get(name, 0.0), value)
    out["capped_spikes"] = float(capped)
    return out, {}


def _force_coding(population, context) -> dict:
    out, data = {}, {}
    sa = population.select(is_type(population.afferent_type, "SAI"))
    if len(sa):
        scenes = [_knots([0, 0.1, 0.1 + f / 2.0, 2.1 + f / 2.0], [0, 0, f, f], name=f"press_{f:g}N")
                  for f in (1.0, 2.0, 4.0)]
        ds = _run(sa, scenes, context)
        plateau = np.array([_rates(ds, 1.1 + f / 2.0, 2.1 + f / 2.0, c).mean() for c, f in enumerate((1.0, 2.0, 4.0))])
        out["force_coding_SAI"] = float(np.min(plateau[1:] / np.maximum(plateau[:-1], 1e-12)))
        data["sai_plateau"] = plateau
    ra = population.select(is_type(population.afferent_type, "RAI"))
    if len(ra):
        scenes = [_knots([0, 0.1, 0.1 + 4.0 / r, 0.4 + 4.0 / r], [0, 0, 4, 4], name=f"ramp_{r:g}") for r in (2, 8, 32)]
        ds = _run(ra, scenes, context)
        # Mean rate over the ramp (spikes per second of loading), as human FA-I velocity coding is measured:
        # a ramp to one force is 16x shorter at 32 N/s than at 2 N/s, so its count need not grow.
        rates = np.array([_rates(ds, 0.1, 0.1 + 4.0 / r, c).mean() for c, r in enumerate((2, 8, 32))])
        out["rate_coding_RAI"] = float(np.min(rates[1:] / np.maximum(rates[:-1], 1e-12)))
        data["rai_loading_rates"] = rates
        data["rai_loading_counts"] = rates * 4.0 / np.array([2.0, 8.0, 32.0])
    return out, data


#: Afferents per type in the frequency protocol (FA-II's tuning is shallow near its best: with 20 the median
#: of units that differ in sensitivity could tie 150 and 200 Hz).
FREQUENCY_UNITS = 40
#: Frequencies (Hz) and amplitudes (N) of the vibration protocol.
FREQUENCIES_HZ = (5.0, 8.0, 16.0, 32.0, 64.0, 100.0, 150.0, 200.0, 250.0, 300.0, 400.0)
AMPLITUDES_N = tuple(np.geomspace(1e-4, 1.0, 33))
_VIBRATION_FS = 5000.0
_VIBRATION_S = 0.5
_VIBRATION_WINDOW = (0.1, 0.5)  # spikes are counted once the 50 ms onset has passed


def _thresholds(ds, n_freq, n_amp):
    """Per frequency and afferent, the amplitude (N) giving one spike per cycle (inf: never).

    Interpolated log-linearly between the grid amplitudes around the crossing.
    """
    n_aff = ds.sizes["afferent"]
    t0, t1 = _VIBRATION_WINDOW
    keep = (ds.spike_time.values >= t0) & (ds.spike_time.values < t1)
    counts = np.bincount(ds.spike_condition.values[keep] * n_aff + ds.spike_afferent.values[keep],
                         minlength=ds.sizes["condition"] * n_aff).reshape(n_freq, n_amp, n_aff) / ds.sizes["trial"]
    per_cycle = counts / (np.asarray(FREQUENCIES_HZ)[:, None, None] * (t1 - t0))
    log_amp = np.log(np.asarray(AMPLITUDES_N))
    out = np.full((n_freq, n_aff), np.inf)
    for f in range(n_freq):
        for j in range(n_aff):
            above = np.flatnonzero(per_cycle[f, :, j] >= 1.0)
            if above.size == 0:
                continue
            i = above[0]
            if i == 0:
                out[f, j] = AMPLITUDES_N[0]
                continue
            lo, hi = per_cycle[f, i - 1, j], per_cycle[f, i, j]
            w = (1.0 - lo) / (hi - lo) if hi > lo else 1.0
            out[f, j] = np.exp(log_amp[i - 1] + w * (log_amp[i] - log_amp[i - 1]))
    return out


def vibration_scene(frequency_hz: float, amplitude_n: float, name: str) -> Scene:
    """A sinusoid on a 1 N preload at 5 kHz, its amplitude rising over 50 ms (raised cosine)."""
    t = np.arange(int(round(_VIBRATION_S * _VIBRATION_FS))) / _VIBRATION_FS
    envelope = np.where(t < 0.05, 0.5 - 0.5 * np.cos(np.pi * t / 0.05), 1.0)
    fz = 1.0 + amplitude_n * envelope * np.sin(2 * np.pi * frequency_hz * t)
    zero = np.zeros_like(t)
    return Scene(zero, zero, fz, _VIBRATION_FS, name, (Stage("steady", _VIBRATION_WINDOW[0], _VIBRATION_WINDOW[1]),))


def _relative_log(thresholds) -> np.ndarray:
    """Log thresholds (frequency, afferent) relative to each afferent's own lowest; afferents that never lock
    are dropped.

    Units differ in sensitivity (`ddmm.population.Population.sensitivity`): each one's curve is its shape
    times its own scale, and a median of absolute thresholds picks a different unit at each frequency.
    Relative to its own best, every unit's curve is its shape alone.
    """
    with np.errstate(invalid="ignore"):
        logs = np.log(thresholds)
        keep = np.isfinite(logs).any(axis=0)
        return logs[:, keep] - np.min(logs[:, keep], axis=0)


def _frequency(population, context) -> dict:
    out, data = {}, {}
    for kind in ("RAI", "RAII"):
        idx = np.flatnonzero(population.afferent_type == kind)
        if idx.size == 0:
            continue
        pick = np.random.default_rng(context["seed"]).choice(idx, min(idx.size, FREQUENCY_UNITS), replace=False)
        sub = population.select(np.sort(pick))
        scenes = [vibration_scene(f, a, f"vib_{f:g}_{i}") for f in FREQUENCIES_HZ for i, a in enumerate(AMPLITUDES_N)]
        ds = _run(sub, scenes, context, record=("spikes",))
        thresholds = _thresholds(ds, len(FREQUENCIES_HZ), len(AMPLITUDES_N))
        curve = np.exp(np.median(_relative_log(thresholds), axis=1))  # median over afferents, inf-safe
        out[f"best_frequency_{kind}"] = float(FREQUENCIES_HZ[int(np.argmin(curve))])
        data[kind] = curve
    return out, data


def _direction(population, context) -> dict:
    from ddmm.population.analysis.tuning import direction_tuning, tuning_scenes, tuning_summary

    ds = _run(population, tuning_scenes(), context, trials=5)
    tuning = direction_tuning(ds)
    summary = tuning_summary(tuning)
    out = {}
    for kind in ("SAI", "RAI", "SAII"):
        if isinstance(summary["tuned_fraction"].get(kind), float):
            out[f"tuned_{kind}"] = summary["tuned_fraction"][kind]
    for kind in ("SAI", "RAI"):
        if isinstance(summary["dsi"].get(kind), dict):
            out[f"dsi_mean_{kind}"] = summary["dsi"][kind]["mean"]
            out[f"dsi_sd_{kind}"] = summary["dsi"][kind]["sd"]
    if isinstance(summary["tuned_fraction"]["recorded"], float):
        out["tuned_recorded"] = summary["tuned_fraction"]["recorded"]
    return out, {"tuning": tuning}


#: Afferents per decoded ensemble and ensembles in the timing protocol: the 92 afferents of
#: Saal, Vijayakumar & Johansson 2009 (docs/references.md row 13), drawn from the types they recorded.
TIMING_ENSEMBLE = 92
TIMING_ENSEMBLES = 10


def _timing(population, context) -> dict:
    from dataclasses import replace

    from ddmm.population.analysis.decode import FirstSpikeLatency, MaximumLikelihood, angular_error, select_afferents

    rng = np.random.default_rng(context["seed"])
    pool = np.flatnonzero(np.isin(population.afferent_type, ("SAI", "RAI", "SAII")))
    picks = [np.sort(rng.choice(pool, min(pool.size, TIMING_ENSEMBLE), replace=False))
             for _ in range(TIMING_ENSEMBLES)]
    used = np.unique(np.concatenate(picks))
    sub = population.select(used)

    def make(n, p):
        return [replace(birznieks(float(d)), name=f"{p}{i}") for i, d in enumerate(rng.uniform(0, 360, n))]

    train, test = _run(sub, make(150, "train"), context), _run(sub, make(120, "test"), context)
    err = {"FirstSpikeLatency": [], "MaximumLikelihood": []}
    for pick in picks:
        local = np.searchsorted(used, pick)
        tr, te = select_afferents(train, local), select_afferents(test, local)
        for cls in (FirstSpikeLatency, MaximumLikelihood):
            decoded = cls(0.125).fit(tr).predict(te).values.ravel()
            err[cls.__name__].append(float(np.median(angular_error(decoded, te.theta_r.values))))
    median = {k: float(np.median(v)) for k, v in err.items()}
    out = {"latency_vs_count": median["FirstSpikeLatency"] / max(median["MaximumLikelihood"], 1e-9)}
    out.update(_jitter(population, context))
    return out, {"errors_deg": median}


def _jitter(population, context) -> dict:
    """Median over RA-I afferents of the SD of their first-spike time over 10 Birznieks trials (ms)."""
    ra = population.select(is_type(population.afferent_type, "RAI"))
    if not len(ra):
        return {}
    ds = _run(ra, [birznieks(90.0)], context, trials=10)
    first = np.full((10, len(ra)), np.nan)
    for trial in range(10):
        keep = ds.spike_trial.values == trial
        times, aff = ds.spike_time.values[keep][::-1], ds.spike_afferent.values[keep][::-1]
        first[trial, aff] = times  # reversed: the earliest spike is written last
    fired = np.all(np.isfinite(first), axis=0)
    return {"jitter_RAI": float(np.median(np.std(first[:, fired], axis=0, ddof=1)) * 1e3) if fired.any() else 0.0}


def _max_step(population, fs, no_shear):
    """Largest sample-to-sample F_A step (N) when the shear reverses through zero, sampled at ``fs``."""
    t = np.arange(int(round(0.4 * fs))) / fs
    fy = np.cos(2 * np.pi * t / 0.4)  # 1 N distal, through zero at 0.1 s, proximal, back through 0.3 s
    fz = np.full_like(t, 2.0)
    worst = 0.0
    tuned = np.flatnonzero((population.nap != "none") & (~is_type(population.afferent_type, "SAII")))
    for profile in np.unique(population.nap[tuned]):
        cols = tuned[population.nap[tuned] == profile][:200]
        af = attenuation_factor(np.zeros_like(t), fy, population.theta_t[cols], str(profile), population.k[cols],
                                no_shear=no_shear)
        worst = max(worst, float(np.max(np.abs(np.diff(af * fz[:, None], axis=0)))))
    return worst


def _continuity(population, context) -> dict:
    """Largest F_A step at 10 kHz over that at 1 kHz: ~0.1 when F_A is continuous, ~1 at a jump."""
    fine, coarse = (_max_step(population, fs, context["no_shear"]) for fs in (10_000.0, 1_000.0))
    return {"continuity": fine / coarse if coarse > 0 else 0.0}, {"step_10khz_n": fine, "step_1khz_n": coarse}


RUNNERS = {"rest": _rest, "on_off": _on_off, "rates": _shipped_rates, "force_coding": _force_coding,
           "frequency": _frequency, "direction": _direction, "timing": _timing, "continuity": _continuity}
