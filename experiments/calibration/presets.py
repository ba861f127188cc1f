"""``ddmm calibrate``: fit the presets' free parameters to human tuning data, under rate constraints.

Fitted (per type, SA-I and FA-I, to Birznieks et al. 2001 as the paper reports it):

* tuned fraction (SA-I 93%, FA-I 83%), DSI mean (0.23, 0.24) and SD (0.18, 0.18);
* by the untuned fraction (NAP ``none``), the bipolar share of tuned
  afferents and the broad share of tuned unipolar ones of each type, and
  for SA-I the transducer: **log compression**
  ``SAI.i_sat``, with ``SAI.gain`` tied so that an aligned afferent's drive at
  4 N stays 18 mV/ms (about 40 pulses/s before adaptation).  Without
  compression the 5:1 AF ratio and the steep regular-spiking f-I curve give
  unipolar SA-I a DSI far above 0.23.
* FA-I's gain ``RAI.gain`` is *fixed* at 6.35: tuning barely identifies it (the
  DSI mean moves 0.249 -> 0.243 as the gain goes 4.5 -> 8), so Nelder-Mead
  wandered between runs (6.3 and 10.6); at 10.6 the transducer saturates at
  32 N/s and the first-spike code is lost (a held-out row then fails).

**Constrained** (a penalty in the objective, checked on the fitted type): rest
silence, the on/off response (hold rate, adaptation, release), and rates below
500 pulses/s with no spike on consecutive steps on every shipped scene:
scorecard properties 1-3 (`ddmm.population.analysis.physiology`).

**Fixed, not fitted** (values in the presets, reasons in docs/model.md): the
stage structure and time constants (with the shear-magnitude term, whose
opponent weights were set by hand); theta_A ranges; gain spread (CV 0.3); noise;
FA-II copies FA-I's NAP mix; SA-II's NAP mix, bias and gain.

**Held out** (never in an objective): the overall fraction, SA-II and FA-II
statistics, force coding, frequency tuning, timing, continuity, everything
on the hand preset (same values) and all decoding.

Every evaluation uses common random numbers (fixed population and noise
seeds), so the objective is deterministic and Nelder-Mead converges.
"""

from __future__ import annotations

import dataclasses
import json

import numpy as np
from scipy.optimize import minimize

from ddmm.models.afferent_types import afferent_type_codes, afferent_type_info
from ddmm.population import load_spec, sample_population, simulate
from ddmm.population.analysis.physiology import PROPERTIES, score_physiology
from ddmm.population.analysis.tuning import DEFAULT_TRIALS, direction_tuning, tuning_scenes, tuning_summary
from ddmm.population.data.published import HUMAN_DSI, HUMAN_TUNED_FRACTION, PHYSIOLOGY_REFERENCE

__all__ = ["TARGETS", "FIT_SEEDS", "VALIDATION_SEEDS", "CONSTRAINTS", "apply_parameters", "type_statistics",
           "constraint_penalty", "fit_type", "validate", "calibrate", "spec_to_toml"]

TARGETS = {kind: {"tuned": HUMAN_TUNED_FRACTION[kind], "dsi_mean": HUMAN_DSI[kind][0], "dsi_sd": HUMAN_DSI[kind][1]}
           for kind in ("SAI", "RAI")}
#: Population seeds pooled during the fit, and the five held-out seeds of the check.
FIT_SEEDS = (1000, 1001, 1002, 1003, 1004)
VALIDATION_SEEDS = (0, 1, 2, 3, 4)
#: Scorecard protocols whose properties constrain the fit (docs/references.md, checks 1-3).
CONSTRAINTS = ("rest", "on_off", "rates")
# The tuned fraction's tolerance is the tightest: at 0.02 the fit gave it up for the DSI and sat 1.3
# tolerances under the human 93% (0.904 on held-out seeds; one seed's SA-I fell out of its range).
_TOLERANCE = {"tuned": 0.01, "dsi_mean": 0.015, "dsi_sd": 0.025}
_SAI_ON_CURRENT = 18.0  # mV/ms at 4 N aligned: ~40 pulses/s before adaptation


def _nap(untuned: float, bipolar: float, broad: float = 0.5) -> dict:
    tuned = 1.0 - untuned
    return {"selective": tuned * (1 - bipolar) * (1 - broad), "broad": tuned * (1 - bipolar) * broad,
            "bipolar": tuned * bipolar, "none": untuned}


def apply_parameters(spec, kind: str, params: dict):
    """The spec with one type's fitted parameters set.

    ``params``: ``untuned``, ``bipolar`` and ``broad`` fractions, and ``i_sat``
    (SAI) or ``gain`` (RAI).
    """
    nap = _nap(params["untuned"], params["bipolar"], params.get("broad", 0.5))
    tspec = dataclasses.replace(spec.types[kind], nap=nap)
    current = spec.current
    if "i_sat" in params:  # SA-I's free parameter; FA-I's is its gain
        i_sat = params["i_sat"]
        gain = i_sat * np.expm1(_SAI_ON_CURRENT / i_sat) / 4.0
        current = current.with_type(kind, gain=round(float(gain), 6), i_sat=round(float(i_sat), 6))
    else:
        current = current.with_type(kind, gain=round(float(params["gain"]), 6))
    return spec.replace(types={**spec.types, kind: tspec}, current=current)


def type_statistics(spec, kind=None, seeds=FIT_SEEDS, trials=DEFAULT_TRIALS, engine="direct") -> dict:
    """Tuning summary pooled over population seeds (one type, or all when ``kind`` is None)."""
    if kind is not None:
        spec = spec.replace(types={kind: spec.types[kind]})
    parts = []
    for seed in seeds:
        pop = sample_population(spec, rng=seed)
        ds = simulate(pop, tuning_scenes(), engine=engine, trials=trials, seed=seed, quiet=True)
        parts.append(direction_tuning(ds))
    import xarray as xr

    return tuning_summary(xr.concat(parts, "afferent"))


def constraint_penalty(spec, kind: str, seed: int = FIT_SEEDS[0]) -> float:
    """Sum of the constraint violations of one type, each relative to its range (0 when all hold)."""
    pop = sample_population(spec.replace(types={kind: spec.types[kind]}), rng=seed)
    names = [n for n, p in PROPERTIES.items() if p.protocol in CONSTRAINTS and p.afferent_type in (kind, "all")]
    rows, _ = score_physiology(pop, PHYSIOLOGY_REFERENCE, properties=names, seed=seed)
    total = 0.0
    for row in rows:
        scale = max(abs(row["high"]) if np.isfinite(row["high"]) else 1.0, abs(row["low"]), 1.0)
        total += (max(row["low"] - row["value"], 0.0) + max(row["value"] - row["high"], 0.0)) / scale
    return total


def _objective(theta, spec, kind, seeds):
    params = _unpack(theta, kind, spec)
    trial_spec = apply_parameters(spec, kind, params)
    stats = type_statistics(trial_spec, kind, seeds)
    got = {"tuned": stats["tuned_fraction"][kind], "dsi_mean": stats["dsi"][kind]["mean"],
           "dsi_sd": stats["dsi"][kind]["sd"]}
    misfit = sum(((got[k] - TARGETS[kind][k]) / _TOLERANCE[k]) ** 2 for k in got)
    return misfit + 1e3 * constraint_penalty(trial_spec, kind)


def _unpack(theta, kind, spec):
    shares = {"untuned": float(np.clip(theta[0], 0.0, 0.6)), "bipolar": float(np.clip(theta[1], 0.0, 0.9)),
              "broad": float(np.clip(theta[2], 0.0, 1.0))}
    if kind in _FREE_I_SAT:
        return {**shares, "i_sat": spec.current.type_params(kind).i_sat}
    return {**shares, "gain": RAI_GAIN}


#: The types whose log-compression scale is free in the fit (the others' gain is fixed).
_FREE_I_SAT = ("SAI",)
#: FA-I's gain, fixed (see the module docstring), (mV/ms)/(N/s).
RAI_GAIN = 6.35


def fit_type(spec, kind: str, *, seeds=FIT_SEEDS, max_evaluations: int = 120) -> dict:
    """Nelder-Mead fit of one type's parameters (4 for SA-I, 3 for FA-I) to its three targets."""
    start = {"SAI": [0.04, 0.3, 0.5], "RAI": [0.18, 0.2, 0.5]}[kind]
    steps = {"SAI": [0.05, 0.15, 0.25], "RAI": [0.05, 0.15, 0.25]}[kind]
    simplex = np.array(start) + np.vstack([np.zeros(len(start)), np.diag(steps)])
    res = minimize(_objective, start, args=(spec, kind, seeds), method="Nelder-Mead",
                   options={"maxfev": max_evaluations, "xatol": 1e-3, "fatol": 1e-2, "initial_simplex": simplex})
    params = _unpack(res.x, kind, spec)
    return {**{k: round(v, 4) for k, v in params.items()}, "objective": round(float(res.fun), 3),
            "evaluations": int(res.nfev)}


def validate(spec, seeds=VALIDATION_SEEDS, scorecard: bool = True) -> dict:
    """Tuning statistics (and the scorecard) of the full spec on held-out seeds: per seed and mean +- SD."""
    runs = [type_statistics(spec, None, (seed,)) for seed in seeds]
    out = {"per_seed": runs, "mean_sd": {}, "scorecard_all_pass": {}}
    keys = [("tuned_fraction", k) for k in ("all", "recorded") + afferent_type_codes()]
    keys += [("dsi", k, m) for k in afferent_type_codes() for m in ("mean", "sd")]
    for key in keys:
        values = []
        for r in runs:
            v = r[key[0]].get(key[1], "absent")
            values.append(v[key[2]] if len(key) == 3 and v != "absent" else v)
        values = [v for v in values if v != "absent"]
        if values:
            out["mean_sd"][".".join(key)] = [round(float(np.mean(values)), 4), round(float(np.std(values, ddof=1)), 4)]
    for seed in seeds if scorecard else ():
        rows, _ = score_physiology(sample_population(spec, rng=seed), PHYSIOLOGY_REFERENCE, seed=seed)
        out["scorecard_all_pass"][str(seed)] = {"all_pass": all(r["pass"] for r in rows),
                                                "failing": [r["name"] for r in rows if not r["pass"]]}
    return out


def calibrate(base_spec="fingertip") -> tuple:
    """Fit SA-I and FA-I, copy FA-I's NAP mix to FA-II, validate; returns (spec, report)."""
    spec = load_spec(base_spec)
    fits = {}
    for kind in ("SAI", "RAI"):
        fits[kind] = fit_type(spec, kind)
        spec = apply_parameters(spec, kind, fits[kind])
    spec = spec.replace(types={**spec.types, "RAII": dataclasses.replace(spec.types["RAII"], nap=spec.types["RAI"].nap)})
    return spec, {"fits": fits, "validation": validate(spec)}


def adopt(spec, target="hand"):
    """``target``'s spec with the fitted current stage and NAP mixes of ``spec`` (the hand reuses the fingertip's)."""
    other = load_spec(target)
    types = {k: dataclasses.replace(t, nap=spec.types[k].nap) if k in spec.types else t for k, t in other.types.items()}
    return other.replace(current=spec.current, types=types)


def _toml_value(value) -> str:
    if isinstance(value, str):
        return json.dumps(value)
    if isinstance(value, (tuple, list)):
        return "[" + ", ".join(_toml_value(v) for v in value) + "]"
    if isinstance(value, dict):
        return "{ " + ", ".join(f"{k} = {_toml_value(v)}" for k, v in value.items()) + " }"
    return repr(float(value)) if isinstance(value, float) else repr(value)  # shortest exact repr


def _where_toml(spec) -> list:
    """The [map] or [region] table of a spec."""
    if spec.map is not None:
        regions = [f"regions = {_toml_value(spec.map.regions)}"] if spec.map.regions else []
        return ["[map]", f"name = {_toml_value(spec.map.name)}", *regions]
    name = [f"name = {_toml_value(spec.region.name)}"] if spec.region.name else []
    return ["[region]", f"center_mm = {_toml_value(spec.region.center_mm)}",
            f"semi_axes_mm = {_toml_value(spec.region.semi_axes_mm)}", *name]


def _count_toml(t) -> list:
    """The count or density line of a type (none when a map sets the counts)."""
    if t.count is not None:
        return [f"count = {t.count}"]
    return [] if t.density_per_cm2 is None else [f"density_per_cm2 = {t.density_per_cm2}"]


def _current_toml(current) -> list:
    """The [current] lines: its shared fields, then a [current.<TYPE>] table of each type's departures from the
    type's registered defaults."""
    lines = [f"{name} = {_toml_value(getattr(current, name))}" for name in ("cutoff_hz", "filter_order", "i_sat")
             if getattr(current, name) is not None]
    for kind, params in current.types:
        default = afferent_type_info(kind).current
        lines += ["", f"[current.{kind}]"]
        lines += [f"{f.name} = {_toml_value(getattr(params, f.name))}" for f in dataclasses.fields(params)
                  if getattr(params, f.name) != getattr(default, f.name) and getattr(params, f.name) is not None]
    return lines


def spec_to_toml(spec, header: str = "") -> str:
    """TOML text of a spec (the layout `ddmm.population.spec` reads)."""
    lines = [header.rstrip(), f"name = {_toml_value(spec.name)}", f"description = {_toml_value(spec.description)}",
             f"receptive_field = {_toml_value(spec.receptive_field)}", "", *_where_toml(spec), "", "[current]"]
    for kind, params in spec.neuron.items():
        lines[-1:-1] = [f"[neuron.{kind}]", *(f"{k} = {_toml_value(v)}" for k, v in dataclasses.asdict(params).items()), ""]
    lines += _current_toml(spec.current)
    for kind, t in spec.types.items():
        lines += ["", f"[types.{kind}]", *_count_toml(t),
                  f"noise_sigma = {_toml_value(t.noise_sigma)}", f"noise_cv = {_toml_value(t.noise_cv)}",
                  f"gain_cv = {_toml_value(t.gain_cv)}", f"sensitivity_sd = {_toml_value(t.sensitivity_sd)}",
                  f"theta_t = {_toml_value({k: v for k, v in dataclasses.asdict(t.theta_t).items() if v not in ((), 0.0) or k == 'distribution'})}",
                  f"nap = {_toml_value(dict(t.nap))}", f"[types.{kind}.sharpness]"]
        for profile, dist in t.sharpness.items():
            lines.append(f"{profile} = {_toml_value({k: v for k, v in dataclasses.asdict(dist).items() if v != ()})}")
    return "\n".join(lines).lstrip() + "\n"
