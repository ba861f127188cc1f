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

"Fires" means at least one spike in at least half of the trials.  The
scorecard's ``everyday_*`` protocols (`ddmm.population.analysis.physiology_everyday`)
are a subset of these; the rest (releases at 1, 16 and 40 N/s, the tonic types,
the CSV round trip) are in no fit and set no constant: **held out**.  They are
the protocols of docs/validation.md, "Everyday touches".
"""

from __future__ import annotations

import numpy as np

from ddmm.population.analysis.physiology_everyday import (
    LOADING_RATES,
    crossing_rate,
    fires,
    press_scene,
    threshold_spread,
    window_counts,
)
from ddmm.population.analysis.physiology_everyday import vibration_thresholds as _unit_thresholds

__all__ = ["RELEASE_RATES", "LOADING_RATES", "VIBRATION_HZ", "press_scene", "release_table", "recruitment",
           "conditioned_releases", "vibration_thresholds", "run_everyday"]

RELEASE_RATES = (1.0, 2.0, 4.0, 8.0, 16.0, 40.0)  # N/s, from a 2 N hold
VIBRATION_HZ = {"SAI": 10.0, "RAI": 40.0, "RAII": 250.0, "SAII": 10.0}  # near each type's best frequency
_TRIALS = 6


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
            on, off = (window_counts(ds, c, windows[w])[:, types == t] for w in ("on", "off"))
            rows[f"{rate:g}"] = {"fires_off": float(fires(off).mean()), "fires_on": float(fires(on).mean()),
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
        fractions = [float(fires(window_counts(ds, c, w["on"])[:, types == t]).mean()) for c, (_, w) in enumerate(made)]
        out[str(t)] = {"fires": dict(zip((f"{r:g}" for r in LOADING_RATES), fractions)),
                       "range_10_90": crossing_rate(fractions, 0.9) / crossing_rate(fractions, 0.1)}
    return out


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
        clean, conditioned = (window_counts(both, c, windows["off"]).sum() for c in (0, 1))
        out[f"{rate:g}"] = float(conditioned / clean) if clean else float("nan")
    return out


def vibration_thresholds(population, seed: int, afferent_type: str, frequency_hz: float) -> np.ndarray:
    """Each unit's vibration threshold (N) at ``frequency_hz`` on a 0.5 N preload (inf: none up to 0.29 N)."""
    sub = population.select(population.afferent_type == afferent_type)
    return _unit_thresholds(sub, {"seed": seed, "engine": "direct", "no_shear": "smooth"}, frequency_hz)


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
            "vibration": {t: {"frequency_hz": f, **threshold_spread(vibration_thresholds(pop, seed, t, f))}
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
