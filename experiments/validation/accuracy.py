"""``ddmm accuracy``: what a coarser step or a cheaper method costs in fidelity.

Workload: the fingertip preset with both its noises switched off (so every run is
deterministic and comparable), on the Birznieks scene in 8 directions
(0, 45, ..., 315 deg).  Each (dt, method, engine) run goes through the whole
`ddmm.population.simulate` pipeline and is compared with the reference solver
(`ddmm.models.reference_solver`, RK4 at 5 us with exact threshold crossings, itself
checked against `scipy.integrate.solve_ivp`):

* ``sf_err_mean``, ``sf_err_max``: |SF - SF_ref| over afferent-conditions,
  pulses/s (SF over the active period, as everywhere in the package);
* ``spike_time_err_ms``: mean |t - t_ref| over spikes paired in order, on
  afferent-conditions whose counts agree (a grid spike is placed mid-step,
  at (step + 0.5) dt, the unbiased estimate of a crossing inside the step);
* ``count_mismatch``: fraction of afferent-conditions whose count differs;
* ``prsi_err``: mean |DSI - DSI_ref| over afferents (eq. 7 on 0/90/180/270);
* ``decode_err_delta_deg``: change of the mean population-vector decoding
  error over the 8 directions;
* ``wall_s_per_afferent_s``: wall seconds per simulated afferent-second
  (after an untimed warm-up, so Brian2 compiles are excluded).
"""

from __future__ import annotations

import dataclasses
import time

import numpy as np

from ddmm.models.engines import ENGINES, NumericalInstabilityError
from ddmm.models.metrics import CONTACT_THRESHOLD, direction_index
from ddmm.models.neuron import neuron_arrays, resting_state
from ddmm.models.reference_solver import reference_spike_times
from ddmm.population import birznieks, load_spec, sample_population, simulate
from ddmm.population.analysis.decode import angular_error, population_vector
from ddmm.population.simulation import population_currents

__all__ = ["DTS_MS", "METHODS", "DIRECTIONS", "REF_DT", "workload", "reference_times", "measure", "run_accuracy",
           "tolerance_table"]

DTS_MS = (1.0, 0.5, 0.25, 0.1, 0.05, 0.025, 0.01)
METHODS = ("euler", "rk2", "rk4", "izhikevich2003")
DIRECTIONS = tuple(float(d) for d in range(0, 360, 45))
REF_DT = 5e-6


def workload(population="fingertip", seed: int = 0, directions=DIRECTIONS, scene=birznieks):
    """The population with noise (and the trial excitability) off, and one scene per direction."""
    spec = load_spec(population)
    steady = spec.current.with_all_types(excite_cv=0.0)
    quiet = spec.replace(types={k: dataclasses.replace(t, noise_sigma=0.0, noise_cv=0.0) for k, t in spec.types.items()},
                         current=steady)
    return sample_population(quiet, rng=seed), [scene(d) for d in directions]


def reference_times(pop, scenes) -> list:
    """Reference spike times (s): one list per scene of one array per afferent."""
    params = neuron_arrays(pop.afferent_type, pop.neuron)
    v0, u0 = resting_state(params["b"])
    return [reference_spike_times(population_currents(pop, s), s.fs, params, v0, u0, dt_ref=REF_DT)
            for s in scenes]


def _active_counts(times_per_aff, scene) -> np.ndarray:
    active = scene.fz > CONTACT_THRESHOLD
    out = np.zeros(len(times_per_aff))
    for j, t in enumerate(times_per_aff):
        idx = np.minimum((np.asarray(t) * scene.fs).astype(int), active.size - 1)
        out[j] = np.sum(active[idx])
    return out / (active.sum() / scene.fs)


def _run_times(ds, n_aff) -> list:
    """Spike times (s) per condition and afferent, at mid-step."""
    t = ds.spike_time.values + 0.5 * ds.attrs["dt"]
    out = []
    for c in range(ds.sizes["condition"]):
        sel = ds.spike_condition.values == c
        aff, tt = ds.spike_afferent.values[sel], t[sel]
        out.append([tt[aff == j] for j in range(n_aff)])
    return out


def _pv_error(sf, pop) -> float:
    base, scale = sf.mean(axis=0), sf.std(axis=0) + 1.0
    est = np.rad2deg(population_vector(sf, pop.theta_t, pop.nap, base, scale))
    return float(angular_error(est, np.asarray(DIRECTIONS[: sf.shape[0]])).mean())


def _compare(times, ref, pop, scenes) -> dict:
    sf = np.array([_active_counts(t, s) for t, s in zip(times, scenes)])  # (condition, afferent)
    sf_ref = np.array([_active_counts(t, s) for t, s in zip(ref, scenes)])
    errors, mismatch = [], 0
    for tc, rc in zip(times, ref):
        for a, b in zip(tc, rc):
            if a.size == b.size:
                errors.append(np.abs(a - b))
            else:
                mismatch += 1
    timing = np.concatenate(errors) if errors else np.empty(0)
    cardinal = [DIRECTIONS.index(d) for d in (0.0, 90.0, 180.0, 270.0)]
    dsi = direction_index(*sf[cardinal]) if len(scenes) == len(DIRECTIONS) else np.zeros(1)
    dsi_ref = direction_index(*sf_ref[cardinal]) if len(scenes) == len(DIRECTIONS) else np.zeros(1)
    diff = np.abs(sf - sf_ref)
    return {"sf_err_mean": float(diff.mean()), "sf_err_max": float(diff.max()),
            "spike_time_err_ms": float(timing.mean() * 1e3) if timing.size else 0.0,
            "count_mismatch": mismatch / sf.size, "prsi_err": float(np.abs(dsi - dsi_ref).mean()),
            "decode_err_delta_deg": abs(_pv_error(sf, pop) - _pv_error(sf_ref, pop))
            if len(scenes) == len(DIRECTIONS) else 0.0}


def measure(pop, scenes, ref, dt_ms: float, method: str, engine: str) -> dict:
    """One row of the table (see the module docstring)."""
    row = {"dt_ms": dt_ms, "method": method, "engine": engine}
    run = dict(engine=engine, dt=dt_ms * 1e-3, method=method, seed=0, quiet=True, record=("spikes",))
    try:
        simulate(pop, scenes[:1], **run)  # warm-up: Brian2 build, numba load
        start = time.perf_counter()
        ds = simulate(pop, scenes, **run)
        wall = time.perf_counter() - start
    except NumericalInstabilityError as exc:
        return {**row, "diverged": str(exc), "wall_s_per_afferent_s": None, "sf_err_mean": None,
                "sf_err_max": None, "spike_time_err_ms": None, "count_mismatch": None, "prsi_err": None,
                "decode_err_delta_deg": None}
    afferent_s = len(pop) * sum(s.duration for s in scenes)
    return {**row, "wall_s_per_afferent_s": wall / afferent_s, **_compare(_run_times(ds, len(pop)), ref, pop, scenes)}


def run_accuracy(dts_ms=DTS_MS, methods=METHODS, engines=ENGINES, population="fingertip",
                 seed: int = 0, progress=None) -> dict:
    """The full table: every dt x method x engine against one reference."""
    pop, scenes = workload(population, seed)
    ref = reference_times(pop, scenes)
    rows = []
    for engine in engines:
        for method in methods:
            for dt in dts_ms:
                rows.append(measure(pop, scenes, ref, dt, method, engine))
                if progress is not None:
                    progress(rows[-1])
    return {"rows": rows, "workload": {"population": population, "seed": seed, "directions_deg": list(DIRECTIONS),
                                       "n_afferents": len(pop), "reference_dt_ms": REF_DT * 1e3}}


#: Right-hand-side evaluations per step: the integration work of each method.
STAGES = {"euler": 1, "rk2": 2, "rk4": 4, "izhikevich2003": 2}


def tolerance_table(result: dict, engine: str = "direct") -> list:
    """The rows `simulate(tolerance=...)` chooses from (one engine; diverged rows left out).

    Each row carries ``evals_per_ms``, the integration work (stages / dt):
    the cost the choice ranks by, since wall times at this workload size are
    dominated by the shared pipeline and too noisy to rank close settings.
    """
    keep = ("dt_ms", "method", "sf_err_mean", "sf_err_max", "wall_s_per_afferent_s")
    return [{**{k: r[k] for k in keep}, "evals_per_ms": STAGES[r["method"]] / r["dt_ms"]}
            for r in result["rows"] if r["engine"] == engine and r["sf_err_mean"] is not None]


def unseen_workload_check(tolerances=(0.3, 0.5, 1.0, 2.0, 5.0)) -> list:
    """``simulate(tolerance=...)`` on two workloads the table never saw, against the reference.

    Rotating shear from 30 and 200 deg (seed 3, every 5th afferent) and press-push-lift at
    theta_R = 60 deg (seed 4, every 40th).  Returns one row per tolerance: the choice and the
    mean SF error (pulses/s) on each workload.
    """
    from ddmm.population import press_push_lift, rotating_shear
    from ddmm.population.runtime.step_choice import choose_setting

    rot = workload("fingertip", seed=3, directions=(30.0, 200.0),
                   scene=lambda d: dataclasses.replace(rotating_shear(start_deg=d), name=f"rot{d:g}"))
    ppl = workload("fingertip", seed=4, directions=(60.0,),
                   scene=lambda d: dataclasses.replace(press_push_lift(d), name=f"ppl{d:g}"))
    cases = [(rot[0].select(np.arange(0, len(rot[0]), 5)), rot[1]), (ppl[0].select(np.arange(0, len(ppl[0]), 40)), ppl[1])]
    cases = [(pop, scenes, reference_times(pop, scenes)) for pop, scenes in cases]
    rows = []
    for tol in tolerances:
        choice = choose_setting(tol, 1000.0)
        errs = [_compare(_run_times(simulate(pop, scenes, engine="direct", tolerance=tol, seed=0, quiet=True,
                                             record=("spikes",)), len(pop)), ref, pop, scenes)["sf_err_mean"]
                for pop, scenes, ref in cases]
        rows.append({"tolerance": tol, "method": choice["method"], "dt_ms": choice["dt_ms"],
                     "rotating_shear": errs[0], "press_push_lift": errs[1]})
    return rows
