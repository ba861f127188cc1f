"""Scorecard protocols of everyday touches: releases, recruitment by loading rate, and threshold spread.

Registered through `ddmm.population.analysis.physiology.load_extensions`; the
reference ranges are ``ddmm.population.data.published._everyday_reference``.
Forces in N on the whole skin (no contact disc), +Z into the skin.  "Fires"
means at least one spike in at least half of `TRIALS` trials.  At most
`MAX_UNITS` afferents of a type are simulated (evenly spaced in the
population's order), so the hand costs what the fingertip does.

* ``everyday_release``: a press to 2 N at r N/s, a 1 s hold and a release at
  the same r, for r = 2, 4 and 8 N/s; the fraction of FA-I that fire during
  each release and FA-I's off/on count ratio at 8 N/s; a variant (4 N at
  5 N/s, a 3 s hold, a release at 4 N/s); and the 8 N/s press conditioned as
  a recording (`ddmm.population.stimuli.conditioning.condition_forces`, the
  default settings, 1 kHz in and out): its FA-I release count over the
  scene's own.
* ``everyday_loading``: presses to 2 N at 0.5-40 N/s (`LOADING_RATES`); the
  fraction of FA-I that fire while loading at 2 N/s, and the range of
  loading rates over which that fraction rises from 10% to 90% (a ratio).
* ``everyday_threshold``: each unit's vibration threshold, the smallest
  amplitude of a 1 s sinusoid on a 0.5 N preload that adds at least 3
  spikes, or a tenth of the cycles, over the preload alone (`AMPLITUDES_N`,
  steps of sqrt(2)); their q90/q10 ratio for FA-I at 40 Hz and FA-II at
  250 Hz, near each type's best frequency.
"""

from __future__ import annotations

import numpy as np

from ddmm.population.analysis import physiology as _core
from ddmm.population.analysis.physiology import Property
from ddmm.population.analysis.physiology_base import _spaced, window_counts
from ddmm.population.stimuli.scenes import Scene, Stage

__all__ = ["PROPERTIES", "PROTOCOLS", "RUNNERS", "LOADING_RATES", "AMPLITUDES_N", "TRIALS", "MAX_UNITS",
           "press_scene", "window_counts", "fires", "crossing_rate", "vibration_thresholds", "threshold_spread"]

LOADING_RATES = (0.5, 1.0, 2.0, 4.0, 8.0, 16.0, 40.0)  # N/s, to 2 N
AMPLITUDES_N = tuple(1e-5 * 2.0 ** (k / 2.0) for k in range(30))  # 0.01 mN to 0.29 N (below the preload)
TRIALS = 6
MAX_UNITS = 300
_RELEASE_RATES = (2.0, 4.0, 8.0)
_FORCE_N, _HOLD_S, _TAIL_S = 2.0, 1.0, 0.3

PROPERTIES = {name: Property(name, kind, protocol, statistic, unit) for name, kind, protocol, statistic, unit in (
    ("release_2Ns_RAI", "RAI", "everyday_release", "fraction firing at a 2 N/s release from 2 N", "1"),
    ("release_4Ns_RAI", "RAI", "everyday_release", "fraction firing at a 4 N/s release from 2 N", "1"),
    ("off_on_8Ns_RAI", "RAI", "everyday_release", "release / loading count, 8 N/s press to 2 N", "1"),
    ("release_variant_RAI", "RAI", "everyday_release",
     "fraction firing at a 4 N/s release from a 3 s hold at 4 N (variant)", "1"),
    ("release_conditioned_RAI", "RAI", "everyday_release",
     "release count through the default conditioning / on the scene, 8 N/s", "1"),
    ("recruit_2Ns_RAI", "RAI", "everyday_loading", "fraction firing while loading to 2 N at 2 N/s", "1"),
    ("recruit_range_RAI", "RAI", "everyday_loading", "range of loading rates recruiting 10% to 90% of units", "1"),
    ("threshold_spread_RAI", "RAI", "everyday_threshold", "q90/q10 of vibration thresholds at 40 Hz", "1"),
    ("threshold_spread_RAII", "RAII", "everyday_threshold", "q90/q10 of vibration thresholds at 250 Hz", "1"),
)}
PROTOCOLS = ("everyday_release", "everyday_loading", "everyday_threshold")


def press_scene(on_rate: float, off_rate: float, force_n: float = _FORCE_N, hold_s: float = _HOLD_S,
                fs: float = 1000.0):
    """A press from 0.2 s to ``force_n`` at ``on_rate`` N/s, a hold, a release at ``off_rate`` N/s, 0.3 s of rest.

    Returns ``(scene, windows)``: the loading (``"on"``) and release
    (``"off"``) windows in s, each extended by 0.1 s past its ramp's end.

    Examples
    --------
    >>> scene, windows = press_scene(4.0, 8.0)
    >>> windows["off"]
    (1.7, 2.05)
    """
    t_hold = 0.2 + force_n / on_rate
    t_off = t_hold + hold_s
    t_end = t_off + force_n / off_rate
    duration = t_end + _TAIL_S
    t = np.arange(int(round(duration * fs))) / fs
    fz = np.interp(t, [0.0, 0.2, t_hold, t_off, t_end, duration], [0.0, 0.0, force_n, force_n, 0.0, 0.0])
    zero = np.zeros_like(fz)
    stages = (Stage("loading", 0.2, t_hold), Stage("hold", t_hold, t_off), Stage("release", t_off, t_end))
    scene = Scene(zero, zero, fz, fs, f"press_{force_n:g}N_{on_rate:g}_{off_rate:g}_{hold_s:g}s", stages)
    return scene, {"on": (0.2, round(t_hold + 0.1, 9)), "off": (round(t_off, 9), round(t_end + 0.1, 9))}


def fires(counts) -> np.ndarray:
    """Whether each afferent fires: at least one spike in at least half of the trials."""
    return np.mean(counts > 0, axis=0) >= 0.5


def crossing_rate(fractions, level: float, rates=LOADING_RATES) -> float:
    """The rate at which ``fractions`` first reaches ``level``, log-interpolated (nan: never; the first rate
    if it starts above)."""
    f = np.asarray(fractions)
    above = np.flatnonzero(f >= level)
    if above.size == 0:
        return float("nan")
    i = above[0]
    if i == 0:
        return float(rates[0])
    lo, hi = np.log(rates[i - 1]), np.log(rates[i])
    return float(np.exp(lo + (hi - lo) * (level - f[i - 1]) / (f[i] - f[i - 1])))


def _units(population, kind: str):
    """At most `MAX_UNITS` afferents of ``kind``, evenly spaced in population order (None: none)."""
    return _spaced(population, (kind,), MAX_UNITS)


def _simulate(population, scenes, context):
    from ddmm.population.simulation import simulate

    return simulate(population, scenes, engine=context["engine"], seed=context["seed"], trials=TRIALS, quiet=True,
                    no_shear=context["no_shear"], record=("spikes",))


def _conditioned(scene: Scene) -> Scene:
    """``scene`` read as a recording: the default conditioning at its own rate."""
    from ddmm.population.stimuli.conditioning import condition_forces

    forces, _ = condition_forces(np.column_stack([scene.fx, scene.fy, scene.fz]), scene.fs, scene.fs)
    return Scene(forces[:, 0], forces[:, 1], forces[:, 2], scene.fs, scene.name + "_conditioned")


def _release(population, context) -> tuple:
    pop = _units(population, "RAI")
    if pop is None:
        return {}, {}
    made = [press_scene(r, r) for r in _RELEASE_RATES] + [press_scene(5.0, 4.0, force_n=4.0, hold_s=3.0)]
    scenes = [s for s, _ in made] + [_conditioned(made[-2][0])]
    ds = _simulate(pop, scenes, context)
    on = [window_counts(ds, c, w["on"]) for c, (_, w) in enumerate(made)]
    off = [window_counts(ds, c, w["off"]) for c, (_, w) in enumerate(made)]
    conditioned = window_counts(ds, len(made), made[-2][1]["off"]).sum()
    out = {"release_2Ns_RAI": float(fires(off[0]).mean()), "release_4Ns_RAI": float(fires(off[1]).mean()),
           "off_on_8Ns_RAI": float(off[2].sum() / max(on[2].sum(), 1)),
           "release_variant_RAI": float(fires(off[3]).mean()),
           "release_conditioned_RAI": float(conditioned / max(off[2].sum(), 1))}
    return out, {"dataset": ds, "windows": [w for _, w in made]}


def _loading(population, context) -> tuple:
    pop = _units(population, "RAI")
    if pop is None:
        return {}, {}
    made = [press_scene(rate, 10.0) for rate in LOADING_RATES]
    ds = _simulate(pop, [s for s, _ in made], context)
    fractions = [float(fires(window_counts(ds, c, w["on"])).mean()) for c, (_, w) in enumerate(made)]
    return ({"recruit_2Ns_RAI": fractions[LOADING_RATES.index(2.0)],
             "recruit_range_RAI": crossing_rate(fractions, 0.9) / crossing_rate(fractions, 0.1)},
            {"rates": LOADING_RATES, "fractions": fractions})


def vibration_thresholds(population, context, frequency_hz: float) -> np.ndarray:
    """Each afferent's vibration threshold (N) at ``frequency_hz`` on a 0.5 N preload (inf: none up to 0.29 N).

    ``context`` as the scorecard's (``seed``, ``engine``, ``no_shear``).
    """
    fs = 5000.0
    t = np.arange(int(fs * 1.2)) / fs
    ramp = np.minimum(t / 0.2, 1.0) * 0.5  # preload reached at 0.2 s; the sinusoid runs 0.2-1.2 s
    on = (t >= 0.2) * np.sin(2 * np.pi * frequency_hz * (t - 0.2))
    scenes = [Scene(0 * t, 0 * t, ramp + a * on, fs, f"vib_{i}") for i, a in enumerate((0.0, *AMPLITUDES_N))]
    ds = _simulate(population, scenes, context)
    counts = np.stack([window_counts(ds, c, (0.25, 1.2)).mean(axis=0) for c in range(len(scenes))])  # (amp, aff)
    enough = counts[1:] - counts[0] >= max(3.0, 0.1 * frequency_hz * 0.95)
    first = np.where(enough.any(axis=0), enough.argmax(axis=0), -1)
    return np.where(first >= 0, np.asarray(AMPLITUDES_N)[np.maximum(first, 0)], np.inf)


def threshold_spread(thresholds) -> dict:
    """q10, q90 (N) and q90/q10 of the finite thresholds, and the fraction of units that have one."""
    finite = thresholds[np.isfinite(thresholds)]
    if finite.size < 2:
        return {"q10_n": None, "q90_n": None, "q90_over_q10": None, "responding": float(finite.size / thresholds.size)}
    q10, q90 = np.quantile(finite, [0.1, 0.9])
    return {"q10_n": float(q10), "q90_n": float(q90), "q90_over_q10": float(q90 / q10),
            "responding": float(finite.size / thresholds.size)}


def _threshold(population, context) -> tuple:
    out, data = {}, {}
    for kind, frequency in (("RAI", 40.0), ("RAII", 250.0)):
        pop = _units(population, kind)
        if pop is None:
            continue
        thresholds = vibration_thresholds(pop, context, frequency)
        spread = threshold_spread(thresholds)
        out[f"threshold_spread_{kind}"] = spread["q90_over_q10"]
        data[kind] = {"frequency_hz": frequency, "thresholds_n": thresholds, **spread}
    return out, data


RUNNERS = {"everyday_release": _release, "everyday_loading": _loading, "everyday_threshold": _threshold}

_core.load_extensions()
