"""Everyday touches: presses and releases at 0.5-40 N/s, and each unit's vibration threshold, on unseen seeds.

``python -m ddmm.experiments.validation.everyday [--seed 7] [--json]`` measures,
on the whole fingertip (no contact disc) of a seed the calibration never saw:

* **releases**: the fraction of each type's units that fire at the release of
  a 2 N hold, at release rates of 1-40 N/s, and the off/on count ratio;
* **recruitment**: the fraction that fire while loading to 2 N at 0.5-40 N/s,
  and the range of rates over which it rises from 10% to 90% of units;
* **through the conditioning**: the same releases written as a noise-free
  1 kHz CSV and read back through the default conditioning of recordings
  (`ddmm.population.from_csv`), their FA-I counts over the scene's;
* **vibration thresholds**: each unit's smallest amplitude of a 1 s sinusoid on
  a 0.5 N preload that adds at least 3 spikes, or a tenth of the cycles, over
  the preload alone; their q90/q10 spread per type.

"Fires" means at least one spike in at least half of the trials.  Every number
is **held out**: these protocols are in no fit, and no constant was set on them.
They are the protocols of docs/validation.md, "Everyday touches".
"""

from __future__ import annotations

import numpy as np

__all__ = ["RELEASE_RATES", "LOADING_RATES", "VIBRATION_HZ", "press_scene", "release_table", "recruitment",
           "conditioned_releases", "vibration_thresholds", "run_everyday"]

RELEASE_RATES = (1.0, 2.0, 4.0, 8.0, 16.0, 40.0)  # N/s, from a 2 N hold
LOADING_RATES = (0.5, 1.0, 2.0, 4.0, 8.0, 16.0, 40.0)  # N/s, to 2 N
VIBRATION_HZ = {"SAI": 10.0, "RAI": 40.0, "RAII": 250.0, "SAII": 10.0}  # near each type's best frequency
_AMPLITUDES_N = tuple(1e-5 * 2.0 ** (k / 2.0) for k in range(30))  # 0.01 mN to 0.29 N (below the preload), x sqrt(2)
_FORCE_N, _HOLD_S, _TAIL_S, _TRIALS = 2.0, 1.0, 0.3, 6


def press_scene(on_rate: float, off_rate: float, force_n: float = _FORCE_N, fs: float = 1000.0):
    """A press to ``force_n`` at ``on_rate`` N/s, a 1 s hold, a release at ``off_rate`` N/s and 0.3 s of rest.

    Returns ``(scene, windows)``: the loading and release windows (s), each
    extended by 0.1 s past the ramp's end.
    """
    from ddmm.population import Scene, Stage

    t_on = force_n / on_rate
    t_hold = 0.2 + t_on
    t_off = t_hold + _HOLD_S
    t_end = t_off + force_n / off_rate
    duration = t_end + _TAIL_S
    t = np.arange(int(round(duration * fs))) / fs
    fz = np.interp(t, [0.0, 0.2, t_hold, t_off, t_end, duration], [0.0, 0.0, force_n, force_n, 0.0, 0.0])
    zero = np.zeros_like(fz)
    stages = (Stage("loading", 0.2, t_hold), Stage("hold", t_hold, t_off), Stage("release", t_off, t_end))
    scene = Scene(zero, zero, fz, fs, f"press_{on_rate:g}_{off_rate:g}", stages)
    return scene, {"on": (0.2, t_hold + 0.1), "off": (t_off, t_end + 0.1)}


def _counts(ds, condition: int, window) -> np.ndarray:
    """Spikes per (trial, afferent) of one condition in ``window`` (s)."""
    t = ds.spike_time.values
    keep = (ds.spike_condition.values == condition) & (t >= window[0]) & (t < window[1])
    n_aff, n_trial = ds.sizes["afferent"], ds.sizes["trial"]
    flat = ds.spike_trial.values[keep] * n_aff + ds.spike_afferent.values[keep]
    return np.bincount(flat, minlength=n_trial * n_aff).reshape(n_trial, n_aff)


def _fires(counts) -> np.ndarray:
    """Whether each afferent fires: at least one spike in at least half of the trials."""
    return np.mean(counts > 0, axis=0) >= 0.5


def _simulate(population, scenes, seed, afferent_types):
    from ddmm.population import simulate

    return simulate(population, scenes, engine="direct", seed=seed, trials=_TRIALS, quiet=True,
                    afferent_types=afferent_types, record=("spikes",))


def release_table(population, seed: int, afferent_types=("SAI", "RAI", "SAII")) -> dict:
    """Per type and release rate: the fraction that fire at the release, and the off/on count ratio.

    The press is loaded at the release's own rate, so off/on compares like with like.
    """
    made = [press_scene(rate, rate) for rate in RELEASE_RATES]
    ds = _simulate(population, [scene for scene, _ in made], seed, afferent_types)
    types = ds.afferent_type.values
    out = {}
    for t in np.unique(types):
        rows = {}
        for c, (rate, (_, windows)) in enumerate(zip(RELEASE_RATES, made)):
            on, off = (_counts(ds, c, windows[w])[:, types == t] for w in ("on", "off"))
            rows[f"{rate:g}"] = {"fires_off": float(_fires(off).mean()), "fires_on": float(_fires(on).mean()),
                                 "off_over_on": float(off.sum() / on.sum()) if on.sum() else float("nan")}
        out[str(t)] = rows
    return out


def recruitment(population, seed: int, afferent_types=("SAI", "RAI", "SAII")) -> dict:
    """Per type: the fraction that fire while loading at each rate, and the 10%-90% range of rates (a ratio)."""
    made = [press_scene(rate, 10.0) for rate in LOADING_RATES]
    ds = _simulate(population, [scene for scene, _ in made], seed, afferent_types)
    types = ds.afferent_type.values
    out = {}
    for t in np.unique(types):
        fractions = [float(_fires(_counts(ds, c, w["on"])[:, types == t]).mean()) for c, (_, w) in enumerate(made)]
        out[str(t)] = {"fires": dict(zip((f"{r:g}" for r in LOADING_RATES), fractions)),
                       "range_10_90": _crossing(fractions, 0.9) / _crossing(fractions, 0.1)}
    return out


def _crossing(fractions, level: float) -> float:
    """The loading rate (N/s) at which the fraction first reaches ``level``, log-interpolated (nan: never)."""
    f = np.asarray(fractions)
    above = np.flatnonzero(f >= level)
    if above.size == 0:
        return float("nan")
    i = above[0]
    if i == 0:
        return LOADING_RATES[0]
    lo, hi = np.log(LOADING_RATES[i - 1]), np.log(LOADING_RATES[i])
    return float(np.exp(lo + (hi - lo) * (level - f[i - 1]) / (f[i] - f[i - 1])))


def conditioned_releases(population, seed: int, tmp_dir, rates=(8.0, 16.0, 40.0)) -> dict:
    """FA-I release counts through the default conditioning of a noise-free 1 kHz CSV, over the scene's own."""
    from ddmm.population import from_csv

    out = {}
    for rate in rates:
        scene, windows = press_scene(rate, rate)
        path = f"{tmp_dir}/press_{rate:g}.csv"
        np.savetxt(path, np.column_stack([scene.time, scene.fx, scene.fy, scene.fz]), delimiter=",",
                   header="time,fx,fy,fz", comments="", fmt="%.6f")
        both = _simulate(population, [scene, from_csv(path)], seed, ("RAI",))
        clean, conditioned = (_counts(both, c, windows["off"]).sum() for c in (0, 1))
        out[f"{rate:g}"] = float(conditioned / clean) if clean else float("nan")
    return out


def vibration_thresholds(population, seed: int, afferent_type: str, frequency_hz: float) -> np.ndarray:
    """Each unit's vibration threshold (N) at ``frequency_hz`` on a 0.5 N preload (inf: none up to 0.29 N)."""
    from ddmm.population import Scene

    fs = 5000.0
    t = np.arange(int(fs * 1.2)) / fs
    ramp = np.minimum(t / 0.2, 1.0) * 0.5  # preload reached at 0.2 s; the sinusoid runs 0.2-1.2 s
    scenes = [Scene(0 * t, 0 * t, ramp + a * (t >= 0.2) * np.sin(2 * np.pi * frequency_hz * (t - 0.2)), fs,
                    f"vib_{i}") for i, a in enumerate((0.0, *_AMPLITUDES_N))]
    ds = _simulate(population, scenes, seed, (afferent_type,))
    counts = np.stack([_counts(ds, c, (0.25, 1.2)).mean(axis=0) for c in range(len(scenes))])  # (amp, aff)
    added = counts[1:] - counts[0]
    enough = added >= max(3.0, 0.1 * frequency_hz * 0.95)
    first = np.where(enough.any(axis=0), enough.argmax(axis=0), -1)
    return np.where(first >= 0, np.asarray(_AMPLITUDES_N)[np.maximum(first, 0)], np.inf)


def _spread(thresholds) -> dict:
    finite = thresholds[np.isfinite(thresholds)]
    if finite.size < 2:
        return {"q10_n": None, "q90_n": None, "q90_over_q10": None, "responding": float(finite.size / thresholds.size)}
    q10, q90 = np.quantile(finite, [0.1, 0.9])
    return {"q10_n": float(q10), "q90_n": float(q90), "q90_over_q10": float(q90 / q10),
            "responding": float(finite.size / thresholds.size)}


def run_everyday(seed: int = 7, population: str = "fingertip") -> dict:
    """Every measure of this module on one population and seed (held out)."""
    import tempfile

    from ddmm.population import sample_population

    pop = sample_population(population, rng=seed)
    with tempfile.TemporaryDirectory() as tmp:
        conditioned = conditioned_releases(pop, seed, tmp)
    return {"seed": seed, "population": population, "role": "held out",
            "releases": release_table(pop, seed), "recruitment": recruitment(pop, seed),
            "conditioned_over_scene_RAI": conditioned,
            "vibration": {t: {"frequency_hz": f, **_spread(vibration_thresholds(pop, seed, t, f))}
                          for t, f in VIBRATION_HZ.items()}}


def _print(result) -> None:
    print(f"# Everyday touches, {result['population']} seed {result['seed']} (held out: in no fit)\n")
    for t, rows in result["releases"].items():
        cells = ", ".join(f"{r} N/s {100 * v['fires_off']:.0f}% (off/on {v['off_over_on']:.2f})"
                          for r, v in rows.items())
        print(f"release {t}: {cells}")
    for t, rec in result["recruitment"].items():
        cells = ", ".join(f"{r} {100 * v:.0f}%" for r, v in rec["fires"].items())
        print(f"loading {t}: {cells}; 10-90% range {rec['range_10_90']:.2f}x")
    print("FA-I release counts through the conditioning / scene: "
          + ", ".join(f"{r} N/s {v:.2f}" for r, v in result["conditioned_over_scene_RAI"].items()))
    for t, v in result["vibration"].items():
        spread = "none" if v["q90_over_q10"] is None else (
            f"q10 {1e3 * v['q10_n']:.2f} mN, q90 {1e3 * v['q90_n']:.2f} mN, q90/q10 {v['q90_over_q10']:.1f}")
        print(f"vibration {t} at {v['frequency_hz']:g} Hz: {spread} ({100 * v['responding']:.0f}% respond)")


if __name__ == "__main__":  # pragma: no cover
    import argparse
    import json

    parser = argparse.ArgumentParser(prog="python -m ddmm.experiments.validation.everyday")
    parser.add_argument("--seed", type=int, default=7)
    parser.add_argument("--population", default="fingertip")
    parser.add_argument("--json", action="store_true")
    args = parser.parse_args()
    result = run_everyday(args.seed, args.population)
    print(json.dumps(result)) if args.json else _print(result)
