"""Decoding shear direction: the protocol behind ``ddmm decode``.

Ramp-hold-release shear (Birznieks scene: 4 N normal, 4 tan 20 deg = 1.456 N
tangential) at directions drawn uniformly on the circle, one condition per
trial, with the population's current noise.  Training and test trials are
disjoint sets of directions and noise draws.  For each decoder, decision
window (after contact onset) and population size, the decoders are fitted on
the training trials and the absolute angular error (wrapped to [0, 180]) is
measured on the test trials; sizes below the full population pool the errors
of several random subsets.  Decoding accuracy is a *prediction*: nothing in
the calibration sees it.
"""

from __future__ import annotations

import dataclasses

import numpy as np

from ddmm.population import birznieks, sample_population, simulate
from ddmm.population.analysis.decode import DECODERS, angular_error, select_afferents
from ddmm.population.data.published import HUMAN_DIRECTION_THRESHOLD_DEG

__all__ = ["SIZES", "WINDOWS_MS", "REFERENCE", "decoding_scenes", "run_decoding", "summarise"]

SIZES = (10, 30, 100, 300, None)  # None: the whole population
WINDOWS_MS = (25, 50, 100, 125, 250)
REFERENCE = {
    "human_direction_threshold_deg": HUMAN_DIRECTION_THRESHOLD_DEG,
    "source": "Panarese & Edin 2011: force direction in the tangential plane",
    "simulated_edge_orientation_deg_within_50ms": 3.0,
    "edge_source": "simulated whole-fingertip populations decode edge orientation to about 3 deg within 50 ms",
}


def decoding_scenes(n: int, rng, prefix: str) -> list:
    """``n`` Birznieks scenes at directions drawn uniformly on the circle."""
    directions = rng.uniform(0.0, 360.0, n)
    return [dataclasses.replace(birznieks(float(d)), name=f"{prefix}_{i:04d}") for i, d in enumerate(directions)]


def _errors(decoder_cls, window_s, train, test, positions):
    sub_train, sub_test = select_afferents(train, positions), select_afferents(test, positions)
    decoded = decoder_cls(window_s).fit(sub_train).predict(sub_test)
    return angular_error(decoded.values.ravel(), np.repeat(test.theta_r.values, test.sizes["trial"]))


def run_decoding(population="fingertip", *, seed: int = 0, n_train: int = 200, n_test: int = 200,
                 subsets: int = 10, engine: str = "direct", sizes=SIZES, windows_ms=WINDOWS_MS) -> dict:
    """Errors (deg) per decoder, window (ms) and population size; see the module docstring.

    Returns
    -------
    dict
        ``{"errors": {decoder: {window_ms: {n_afferents: [errors...]}}}, "n_afferents": N}``
    """
    rng = np.random.default_rng(seed)
    pop = sample_population(population, rng=seed)
    train = simulate(pop, decoding_scenes(n_train, rng, "train"), engine=engine, seed=seed, quiet=True)
    test = simulate(pop, decoding_scenes(n_test, rng, "test"), engine=engine, seed=seed + 1, quiet=True)
    n_all = len(pop)
    errors = {name: {} for name in DECODERS}
    for window in windows_ms:
        for size in sizes:
            n = n_all if size is None or size >= n_all else int(size)
            draws = [np.arange(n_all)] if n == n_all else [np.sort(rng.choice(n_all, n, replace=False))
                                                         for _ in range(subsets)]
            for name, cls in DECODERS.items():
                errs = np.concatenate([_errors(cls, window / 1e3, train, test, p) for p in draws])
                errors[name].setdefault(str(window), {})[str(n)] = errs
    return {"errors": errors, "n_afferents": n_all}


def summarise(result: dict) -> dict:
    """Median and 90th-percentile error per decoder, window and size, plus the reference."""
    out = {name: {w: {n: {"median_deg": round(float(np.median(e)), 3),
                          "p90_deg": round(float(np.percentile(e, 90)), 3)}
                      for n, e in by_size.items()}
                  for w, by_size in by_window.items()}
           for name, by_window in result["errors"].items()}
    return {"errors": out, "reference": REFERENCE}


def best_settings(summary: dict, threshold: float = HUMAN_DIRECTION_THRESHOLD_DEG) -> dict:
    """Smallest population and shortest window whose median error reaches ``threshold`` (any decoder)."""
    hits = [(int(n), int(w), name) for name, by_w in summary["errors"].items() for w, by_n in by_w.items()
            for n, s in by_n.items() if s["median_deg"] <= threshold]
    if not hits:
        return {"smallest_population": None, "shortest_window_ms": None}
    smallest = min(hits, key=lambda h: (h[0], h[1]))
    shortest = min(hits, key=lambda h: (h[1], h[0]))
    return {"smallest_population": {"n_afferents": smallest[0], "window_ms": smallest[1], "decoder": smallest[2]},
            "shortest_window_ms": {"window_ms": shortest[1], "n_afferents": shortest[0], "decoder": shortest[2]}}
