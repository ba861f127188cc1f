"""Scorecard protocols of tilted loads: whether tangential load adds to a unit's response in its preferred direction.

Registered through `ddmm.population.analysis.physiology.load_extensions`; the
reference ranges are ``ddmm.population.data.published._tilt_reference``.
Forces in N on the whole skin (no contact disc), +Z into the skin; every
force ramps together from 0.1 s and is held.  Each unit is compared with
itself under the normal load alone, so the rows read what tangential load
adds or takes away, not growth from a level the attenuation has already
lowered.  In human SA-I, tangential load in a unit's preferred direction
adds to its response to the normal load and load against it subtracts
(docs/references.md row 22).

* ``tilt``: 4 N normal with the resultant tilted 20 deg from the normal
  (tangential part ``F_Z tan 20``) toward 12 directions, ramped at 20 N/s,
  against 4 N normal alone, `TRIALS` trials each, spikes summed over
  them (a unit is silenced only if it stays silent on every repetition, as
  a physiologist would judge it).  Over the units that respond to the
  normal load alone: the fraction whose response exceeds it by 10% in some
  direction (SA-I, SA-II on the plateau 0.6-1.4 s; FA-I as counts in the
  loading ramp and 0.1 s after it), and for SA-I the fraction silenced in
  its worst direction.
At most `MAX_UNITS` afferents of each type are simulated (evenly spaced in
the population's order), so the hand costs what the fingertip does.

* ``tilt_variant``: the same at 2 N normal, a 30 deg tilt toward 8
  directions, ramped at 10 N/s (no constant was set on it: a prediction).
"""

from __future__ import annotations

import numpy as np

from ddmm.population.analysis import physiology as _core
from ddmm.population.analysis.physiology import Property, _run
from ddmm.population.analysis.physiology_base import _spaced, window_counts
from ddmm.population.stimuli.scenes import Scene

__all__ = ["DIRECTIONS", "MAX_UNITS", "PROPERTIES", "PROTOCOLS", "RUNNERS", "TILT_DEG", "TRIALS", "tilt_fractions",
           "tilt_scene", "tilt_table"]

TILT_DEG = 20.0
DIRECTIONS = 12
TRIALS = 3
MAX_UNITS = 300
_FS = 1000.0
_ONSET = 0.1  # s
_PLATEAU = (0.6, 1.4)  # s

PROPERTIES = {name: Property(name, kind, protocol, statistic, "1") for name, kind, protocol, statistic in (
    ("tilt_above_SAI", "SAI", "tilt", "fraction above normal-only by 10% in some direction, 4 N tilted 20 deg"),
    ("tilt_silenced_SAI", "SAI", "tilt", "fraction silenced in the worst direction, 4 N tilted 20 deg"),
    ("tilt_above_RAI", "RAI", "tilt", "fraction above normal-only by 10% in some direction (ramp counts), 4 N"),
    ("tilt_above_SAII", "SAII", "tilt", "fraction above normal-only by 10% in some direction, 4 N tilted 20 deg"),
    ("tilt_variant_above_SAI", "SAI", "tilt_variant",
     "fraction above normal-only by 10% in some direction, 2 N tilted 30 deg (variant)"),
    ("tilt_variant_above_RAI", "RAI", "tilt_variant",
     "fraction above normal-only by 10% in some direction (ramp counts), 2 N tilted 30 deg (variant)"),
)}
PROTOCOLS = ("tilt", "tilt_variant")


def tilt_scene(normal_n: float, tilt_deg: float, direction_deg: float, rate_n_s: float = 20.0,
               duration: float = 1.5) -> Scene:
    """Every force ramped together from 0.1 s and held: ``normal_n`` (N) normal, ``normal_n tan(tilt_deg)``
    tangential toward ``direction_deg`` (deg, from +X); the normal force rises at ``rate_n_s`` (N/s).

    Examples
    --------
    >>> s = tilt_scene(4.0, 20.0, 90.0)
    >>> round(float(s.fy[-1]), 3), round(float(s.fz[-1]), 3)
    (1.456, 4.0)
    """
    t = np.arange(round(duration * _FS)) / _FS
    ramp = np.clip((t - _ONSET) * rate_n_s / normal_n, 0.0, 1.0)
    tangential = normal_n * np.tan(np.deg2rad(tilt_deg)) * ramp
    angle = np.deg2rad(direction_deg)
    return Scene(tangential * np.cos(angle), tangential * np.sin(angle), normal_n * ramp, _FS,
                 f"tilt_{normal_n:g}N_{tilt_deg:g}deg_{direction_deg:g}")


def tilt_fractions(normal_only, tilted) -> dict:
    """What tangential load adds to each unit that responds to the normal load alone.

    Parameters
    ----------
    normal_only : array, shape (n_afferents,)
        Each unit's response (count or rate) to the normal load alone.
    tilted : array, shape (n_directions, n_afferents)
        Its responses to the tilted loads.

    Returns
    -------
    dict
        ``units`` (how many respond to the normal load), the fractions of them
        ``above_10pct`` in some direction, ``halved_worst`` and
        ``silenced_worst`` in their worst one, and the medians of best and
        worst over normal-only (None where no unit responds).

    Examples
    --------
    >>> out = tilt_fractions([10.0, 10.0, 0.0], [[12.0, 9.0, 3.0], [0.0, 4.0, 1.0]])
    >>> out["units"], out["above_10pct"], out["silenced_worst"], out["halved_worst"]
    (2, 0.5, 0.5, 1.0)
    """
    base = np.asarray(normal_only, dtype=float)
    runs = np.asarray(tilted, dtype=float)
    mine = base > 0
    if not mine.any():
        return {"units": 0, "above_10pct": None, "halved_worst": None, "silenced_worst": None,
                "median_best_over_normal": None, "median_worst_over_normal": None}
    b, r = base[mine], runs[:, mine]
    return {"units": int(mine.sum()), "above_10pct": float(np.mean((r > 1.1 * b).any(axis=0))),
            "halved_worst": float(np.mean((r < 0.5 * b).any(axis=0))),
            "silenced_worst": float(np.mean((r == 0).any(axis=0))),
            "median_best_over_normal": float(np.median(r.max(axis=0) / b)),
            "median_worst_over_normal": float(np.median(r.min(axis=0) / b))}


def tilt_table(population, context, normal_n: float = 4.0, tilt_deg: float = TILT_DEG,
               directions: int = DIRECTIONS, rate_n_s: float = 20.0, trials: int = TRIALS,
               max_units: int | None = MAX_UNITS) -> dict:
    """`tilt_fractions` per type (SA-I, SA-II on the plateau; FA-I in the loading ramp) for one tilt protocol,
    on spikes summed over ``trials``, over at most ``max_units`` afferents of each type (None: all).

    ``context`` as the scorecard's (``seed``, ``engine``, ``no_shear``).
    """
    if max_units is not None:
        population = _spaced(population, ("SAI", "SAII", "RAI"), max_units)
        if population is None:
            return {}
    angles = np.arange(directions) * 360.0 / directions
    scenes = [tilt_scene(normal_n, 0.0, 0.0, rate_n_s)] + [tilt_scene(normal_n, tilt_deg, a, rate_n_s)
                                                            for a in angles]
    ds = _run(population, scenes, context, no_shear=context["no_shear"], trials=trials)
    kinds = ds.afferent_type.values
    ramp = (_ONSET, _ONSET + normal_n / rate_n_s + 0.1)
    table = {}
    for kind, window in (("SAI", _PLATEAU), ("SAII", _PLATEAU), ("RAI", ramp)):
        if np.any(kinds == kind):
            counts = np.array([window_counts(ds, c, window).sum(axis=0) for c in range(len(scenes))])
            counts = counts[:, kinds == kind]  # spikes per (condition, afferent), summed over trials
            table[kind] = tilt_fractions(counts[0], counts[1:])
    return table


def _tilt(population, context) -> tuple:
    table = tilt_table(population, context)
    out = {f"tilt_above_{kind}": row["above_10pct"] for kind, row in table.items()}
    if "SAI" in table:
        out["tilt_silenced_SAI"] = table["SAI"]["silenced_worst"]
    return out, table


def _tilt_variant(population, context) -> tuple:
    table = tilt_table(population, context, normal_n=2.0, tilt_deg=30.0, directions=8, rate_n_s=10.0)
    return {f"tilt_variant_above_{kind}": table[kind]["above_10pct"] for kind in ("SAI", "RAI") if kind in table}, table


RUNNERS = {"tilt": _tilt, "tilt_variant": _tilt_variant}

_core.load_extensions()  # a no-op unless this module was imported before the scorecard (see `load_extensions`)
