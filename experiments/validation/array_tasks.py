"""Torque and slip decoding: the protocols behind ``ddmm decode --task torque|slip``.

**Torque** (after Loutit et al., docs/references.md row 18): torsion scenes
(`ddmm.population.stimuli.site_scenes.torsion`) of 3.5, 5.5 and 7.5 mNm, clockwise and
anticlockwise, on 2 and 4 N of normal force, on the fingertip.  Spike counts
in a window after torque onset feed a `CentroidClassifier` trained on half
the trials (independent noise draws) and tested on the other half, for
rotation direction (``accuracy``) and torque magnitude
(``magnitude_accuracy``), per window, population size (random subsets) and
afferent type.

**Slip** (after Johansson & Westling, row 19): `incipient_slip` scenes on
2 N of normal force at three tangential loading rates, each with a control
that stops at 80% of the friction limit.  A `SlipDetector` learns its
threshold on the training trials' controls; on the test trials it reports
slip onset, and its latency and false alarms are measured.  Humans raise
their grip 74 ± 9 ms after a slip, so the afferent signal must come well
before that.

Every number here is a *prediction*: nothing in the calibration sees torsion
or slip.
"""

from __future__ import annotations

import numpy as np

from ddmm.population import load_spec, sample_population, simulate
from ddmm.population.analysis.array_decode import (
    CentroidClassifier,
    SlipDetector,
    evaluate_slip,
    onset_counts,
    stage_onset,
)
from ddmm.population.stimuli.site_scenes import incipient_slip, torsion

__all__ = ["TORQUES_MNM", "NORMALS_N", "SLIP_RATES_N_S", "HUMAN_SLIP_RESPONSE_MS", "torque_scenes", "slip_scenes",
           "run_torque", "run_slip"]

TORQUES_MNM = (3.5, 5.5, 7.5)
NORMALS_N = (2.0, 4.0)
SLIP_RATES_N_S = (2.0, 4.0, 8.0)
HUMAN_SLIP_RESPONSE_MS = 74.0  # grip-to-load ratio rises 74 +- 9 ms after a slip (row 19, V)
TYPE_SETS = (("SAI",), ("RAI",), ("RAII",), ("SAII",), ("SAI", "RAI", "RAII", "SAII"))


def torque_scenes(torques=TORQUES_MNM, normals=NORMALS_N) -> list:
    """One torsion scene per (torque, normal force, direction)."""
    return [torsion(t, n, direction=d, hold_s=0.3, name=f"torque_{'ccw' if d > 0 else 'cw'}_{t:g}_{n:g}")
            for t in torques for n in normals for d in (1, -1)]


def slip_scenes(rates=SLIP_RATES_N_S, normal_n: float = 2.0) -> list:
    """For each loading rate a slip scene and its no-slip control."""
    return [incipient_slip(normal_n, load_rate_n_s=r, slip=s) for r in rates for s in (True, False)]


def _sizes(sizes, available: int) -> list:
    """The population sizes that fit, each once (None: all ``available``)."""
    out = []
    for size in sizes:
        n = available if size is None else size
        if n <= available and n not in out:
            out.append(n)
    return out


def _subsets(positions, size, n_subsets, rng) -> list:
    if size >= positions.size:
        return [positions]
    return [rng.choice(positions, size, replace=False) for _ in range(n_subsets)]


def _observations(counts, labels, trials):
    """(obs, afferent) features and labels of the given trials."""
    X = counts[:, trials].reshape(-1, counts.shape[2])
    return X, np.repeat(labels, len(trials))


def _split(n_trials: int):
    train = np.arange(n_trials // 2)
    return train, np.arange(n_trials // 2, n_trials)


def run_torque(population="fingertip", seed=0, trials=20, windows_ms=(25, 50, 100, 200), sizes=(10, 30, 100, None),
               subsets=5, engine="direct") -> dict:
    """Simulate the torque protocol and decode direction and magnitude (module docstring)."""
    pop = sample_population(load_spec(population), rng=seed)
    scenes = torque_scenes()
    ds = simulate(pop, scenes, engine=engine, trials=trials, seed=seed, quiet=True, record=("spikes",))
    onset = stage_onset(ds, "torque_ramp")
    direction = np.array([s.name.split("_")[1] for s in scenes])
    magnitude = np.array([s.name.split("_")[2] for s in scenes])
    train, test = _split(trials)
    rng, results = np.random.default_rng(seed), []
    for window in windows_ms:
        counts = onset_counts(ds, onset, window / 1e3)
        for types in TYPE_SETS:
            positions = np.flatnonzero(np.isin(ds.afferent_type.values, types))
            for size in _sizes(sizes, positions.size):
                acc = [_accuracy(counts[:, :, sub], label, train, test)
                       for sub in _subsets(positions, size, subsets, rng) for label in (direction, magnitude)]
                results.append({"window_ms": window, "n_afferents": int(size),
                                "types": list(types), "accuracy": float(np.mean(acc[0::2])),
                                "magnitude_accuracy": float(np.mean(acc[1::2]))})
    return {"task": "torque", "results": results, "role": "prediction", "chance": {"accuracy": 0.5,
            "magnitude_accuracy": 1.0 / len(TORQUES_MNM)},
            "protocol": f"{len(scenes)} torsion conditions ({', '.join(map(str, TORQUES_MNM))} mNm, cw/ccw, "
                        f"{', '.join(map(str, NORMALS_N))} N), {trials} trials each, half for training; "
                        f"population {population!r}, seed {seed}"}


def _accuracy(counts, labels, train, test) -> float:
    X, y = _observations(counts, labels, train)
    Xt, yt = _observations(counts, labels, test)
    return float(np.mean(CentroidClassifier().fit(X, y).predict(Xt) == yt))


def run_slip(population="fingertip", seed=0, trials=20, windows_ms=(5, 10, 20), sizes=(10, 30, 100, None),
             subsets=5, engine="direct") -> dict:
    """Simulate the slip protocol and measure the detector (module docstring)."""
    pop = sample_population(load_spec(population), rng=seed)
    scenes = slip_scenes()
    ds = simulate(pop, scenes, engine=engine, trials=trials, seed=seed, quiet=True, record=("spikes",))
    slip = np.array([s.name.startswith("slip") for s in scenes])
    onset = np.array([next(st.start for st in s.stages if st.label in ("slip", "hold")) for s in scenes])
    train, test = _split(trials)
    rng, results = np.random.default_rng(seed), []
    for window in windows_ms:
        for types in TYPE_SETS:
            positions = np.flatnonzero(np.isin(ds.afferent_type.values, types))
            for size in _sizes(sizes, positions.size):
                scores = [_slip_score(ds, sub, window / 1e3, slip, onset, train, test)
                          for sub in _subsets(positions, size, subsets, rng)]
                results.append({"window_ms": window, "n_afferents": int(size),
                                "types": list(types), **_mean_scores(scores)})
    return {"task": "slip", "results": results, "role": "prediction",
            "human_reference": {"grip_response_ms": HUMAN_SLIP_RESPONSE_MS, "source": "Johansson & Westling 1987"},
            "protocol": f"{len(scenes)} conditions (slip and no-slip at {', '.join(map(str, SLIP_RATES_N_S))} N/s "
                        f"on 2 N), {trials} trials each, half for training; population {population!r}, seed {seed}"}


def _slip_score(ds, afferents, window_s, slip, onset, train, test) -> dict:
    detector = SlipDetector(window_s)
    detector.fit(_trials(ds, train), slip, afferents, onset)
    times = detector.detect(_trials(ds, test))
    return evaluate_slip(times, slip, onset, ds.duration.values)


def _trials(ds, trials):
    """The dataset's spike events of the given trials, renumbered from 0."""
    keep = np.isin(ds.spike_trial.values, trials)
    out = ds.isel(spike=np.flatnonzero(keep), trial=trials)
    remap = np.full(ds.sizes["trial"], -1, np.int64)
    remap[trials] = np.arange(len(trials))
    out["spike_trial"] = ("spike", remap[ds.spike_trial.values[keep]].astype(np.int32), ds.spike_trial.attrs)
    return out


def _mean_scores(scores) -> dict:
    latencies = [s["latency_ms"] for s in scores if s["latency_ms"] is not None]
    return {"accuracy": float(np.mean([s["accuracy"] for s in scores])),
            "latency_ms": float(np.median(latencies)) if latencies else None,
            "false_alarms_per_s": float(np.mean([s["false_alarms_per_s"] for s in scores]))}
