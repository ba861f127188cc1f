"""Physiology protocol: rate against tangential force magnitude (docs/references.md rows 18, 22).

Registered in the scorecard by `ddmm.population.analysis.physiology.load_extensions`.

``shear``: a normal ramp to 2 N (10 N/s from 0.1 s), held; from 1.0 s a
tangential ramp at 2 N/s to 0, 0.25, 0.5 or 1 N, held to 2.5 s.  Every
afferent's tuning angle is set to 90 deg, so the +Y scene is each
afferent's preferred direction and -Y its opposite one: AF depends on the
shear direction relative to theta_T only, so this is the same as giving
every afferent a scene along its own theta_T.  SA types are read in the
shear hold (1.6-2.5 s), FA types during the tangential ramp (1.0 s to its
end + 0.1 s).

``shear_variant``: the same at 4 N normal with the tangential ramp at 4 N/s
(no gain was set on it: a prediction).

SA rows compare each unit with itself under the normal load alone: the
statistic is the median over the units that fire under it of their rate
at each magnitude over that normal-only rate (so a row reads what the
tangential load adds or takes away, never growth from a level the
attenuation has already lowered).

Statistics of the *opposite* direction (and the preferred / opposite ratios)
use the unipolar afferents only (NAP ``selective`` or ``broad``): a bipolar
afferent's profile peaks at theta_T and at theta_T + 180 deg, so for it the
opposite direction is a preferred one, and an untuned afferent has none.
"""

from __future__ import annotations

from dataclasses import replace

import numpy as np

from ddmm.population.analysis.physiology import Property, _of, _rates, _run, load_extensions
from ddmm.population.stimuli.scenes import Scene

__all__ = ["PROPERTIES", "PROTOCOLS", "RUNNERS", "shear_scene", "MAGNITUDES_N"]

#: Shear magnitudes of the protocol, newtons.
MAGNITUDES_N = (0.25, 0.5, 1.0)
_HOLD = (1.6, 2.5)  # SA window, s
_RAMP0 = 1.0  # start of the tangential ramp, s


def _p(name, kind, protocol, statistic, unit="1"):
    return name, Property(name, kind, protocol, statistic, unit)


PROPERTIES = dict([
    _p("shear_pref_SAI", "SAI", "shear", "median per-unit rate, 1 N shear preferred / normal only (2 N)"),
    _p("shear_opp_SAI", "SAI", "shear", "median per-unit rate, 1 N shear opposite / normal only (2 N; unipolar)"),
    _p("shear_growth_SAI", "SAI", "shear", "smallest rise of the median per-unit rate / normal only, 0 -> 0.25 -> "
       "0.5 -> 1 N preferred"),
    _p("shear_fall_SAI", "SAI", "shear", "largest change of the median per-unit rate / normal only, 0 -> 0.25 -> "
       "0.5 -> 1 N opposite (unipolar)"),
    _p("shear_growth_RAI", "RAI", "shear", "smallest rise of the mean ramp count, 0 -> 0.25 -> 0.5 -> 1 N preferred"),
    _p("shear_dir_RAI", "RAI", "shear", "mean ramp count, 1 N preferred / opposite (unipolar)"),
    _p("shear_ramp_RAI", "RAI", "shear", "fraction firing late in a 2 N/s tangential ramp (0.4-1 N, preferred)"),
    _p("shear_dir_RAII", "RAII", "shear", "mean ramp count, 1 N preferred / opposite (unipolar)"),
    _p("shear_growth_SAII", "SAII", "shear", "smallest rise of the median per-unit rate / normal only, 0 -> 0.25 -> "
       "0.5 -> 1 N preferred"),
    _p("shear_variant_SAI", "SAI", "shear_variant", "4 N normal, 4 N/s shear: min(smallest rise preferred, -largest "
       "change opposite (unipolar)) of the median per-unit rate / normal only"),
    _p("shear_variant_RAI", "RAI", "shear_variant",
       "4 N normal, 4 N/s shear: smallest rise of the mean ramp count, 0 -> 0.25 -> 0.5 -> 1 N preferred"),
])
PROTOCOLS = ("shear", "shear_variant")


def shear_scene(magnitude_n: float, direction_deg: float, *, normal_n: float = 2.0, rate_n_s: float = 2.0,
                fs: float = 1000.0) -> Scene:
    """Normal ramp to ``normal_n`` (N) at 10 N/s from 0.1 s, then from 1.0 s a tangential ramp at
    ``rate_n_s`` (N/s) to ``magnitude_n`` (N) in ``direction_deg``, held; 1.0 s after the slowest ramp's end."""
    t_end = _RAMP0 + max(MAGNITUDES_N) / rate_n_s + 1.0
    t = np.arange(int(round(t_end * fs))) / fs
    fz = np.interp(t, [0.0, 0.1, 0.1 + normal_n / 10.0, t_end], [0.0, 0.0, normal_n, normal_n])
    shear = np.interp(t, [0.0, _RAMP0, _RAMP0 + magnitude_n / rate_n_s, t_end], [0.0, 0.0, magnitude_n, magnitude_n])
    rad = np.deg2rad(direction_deg)
    return Scene(shear * np.cos(rad), shear * np.sin(rad), fz, fs, f"shear_{magnitude_n:g}N_{direction_deg:g}deg")


def _measure(population, context, normal_n, rate_n_s):
    """Per type: SA mean rates in the hold, FA mean counts in the ramp, per condition (0, pref..., opp...)."""
    aligned = replace(population, theta_t=np.full(len(population), 90.0))  # +Y: everyone's preferred direction
    scenes = [shear_scene(0.0, 90.0, normal_n=normal_n, rate_n_s=rate_n_s)]
    scenes += [shear_scene(m, d, normal_n=normal_n, rate_n_s=rate_n_s) for d in (90.0, 270.0) for m in MAGNITUDES_N]
    ds = _run(aligned, scenes, context, no_shear=context["no_shear"])
    t_end = scenes[0].n_samples / scenes[0].fs
    hold = (t_end - 0.9, t_end)
    ramp = (_RAMP0, _RAMP0 + max(MAGNITUDES_N) / rate_n_s + 0.1)
    sa = np.array([_rates(ds, *hold, condition=c) for c in range(len(scenes))])
    fa = np.array([_rates(ds, *ramp, condition=c) for c in range(len(scenes))]) * (ramp[1] - ramp[0])
    late = _rates(ds, _RAMP0 + 0.4 / rate_n_s, _RAMP0 + 1.0 / rate_n_s, condition=len(MAGNITUDES_N))
    return ds, sa, fa, late


def _curves(values, mask):
    """Mean over ``mask`` at 0 then the magnitudes, preferred and opposite."""
    mean = np.mean(values[:, mask], axis=1)
    n = len(MAGNITUDES_N)
    return np.r_[mean[0], mean[1:1 + n]], np.r_[mean[0], mean[1 + n:]]


def _relative(values, mask):
    """Median over the units of ``mask`` that fire under the normal load alone of their rate over that rate, at 0
    (1) then the magnitudes, preferred and opposite (1s where no unit fires)."""
    mine = mask & (values[0] > 0)
    if not mine.any():
        return np.ones(1 + len(MAGNITUDES_N)), np.ones(1 + len(MAGNITUDES_N))
    ratio = np.median(values[:, mine] / values[0, mine], axis=1)
    n = len(MAGNITUDES_N)
    return np.r_[1.0, ratio[1:1 + n]], np.r_[1.0, ratio[1 + n:]]


def _unipolar(ds):
    """Afferents with one preferred direction (NAP selective or broad): the only ones with an opposite one."""
    return np.isin(ds.nap.values.astype(str), ("selective", "broad"))


def _ratio(a, b):
    return float(a / b) if b > 0 else (float("inf") if a > 0 else 1.0)


def _shear(population, context) -> tuple:
    ds, sa, fa, late = _measure(population, context, 2.0, 2.0)
    out, data = {}, {"sa_rate": sa, "fa_count": fa, "type": ds.afferent_type.values, "nap": ds.nap.values}
    uni = _unipolar(ds)
    if _of(ds, "SAI").any():
        pref = _relative(sa, _of(ds, "SAI"))[0]
        opp = _relative(sa, _of(ds, "SAI") & uni)[1]
        out.update(shear_pref_SAI=float(pref[-1]), shear_opp_SAI=float(opp[-1]),
                   shear_growth_SAI=float(np.diff(pref).min()), shear_fall_SAI=float(np.diff(opp).max()))
    for kind, grows in (("RAI", True), ("RAII", False)):  # FA-II code the ramp's corners, not its end value
        if _of(ds, kind).any():
            pref = _curves(fa, _of(ds, kind))[0]
            if grows:
                out[f"shear_growth_{kind}"] = float(np.diff(pref).min())
            both = _curves(fa, _of(ds, kind) & uni)
            out[f"shear_dir_{kind}"] = _ratio(both[0][-1], both[1][-1])
    if _of(ds, "RAI").any():
        out["shear_ramp_RAI"] = float(np.mean(late[_of(ds, "RAI")] > 0))
    if _of(ds, "SAII").any():
        out["shear_growth_SAII"] = float(np.diff(_relative(sa, _of(ds, "SAII"))[0]).min())
    return out, data


def _shear_variant(population, context) -> tuple:
    ds, sa, fa, _ = _measure(population, context, 4.0, 4.0)
    out = {}
    if _of(ds, "SAI").any():
        pref = _relative(sa, _of(ds, "SAI"))[0]
        opp = _relative(sa, _of(ds, "SAI") & _unipolar(ds))[1]
        out["shear_variant_SAI"] = float(min(np.diff(pref).min(), -np.diff(opp).max()))
    if _of(ds, "RAI").any():
        out["shear_variant_RAI"] = float(np.diff(_curves(fa, _of(ds, "RAI"))[0]).min())
    return out, {"sa_rate": sa, "fa_count": fa}


RUNNERS = {"shear": _shear, "shear_variant": _shear_variant}
load_extensions()  # a no-op unless this module was imported before the scorecard (see `load_extensions`)
