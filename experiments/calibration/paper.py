"""``ddmm calibrate --target paper``: fit the paper's unpublished constants to its Tables II-III, type by type.

The equations stay the paper's (eqs 1-6, 9-19; no added mechanism, no
variability).  What the paper leaves open is fitted, for each type on its
own (a type's cells depend on its own constants only):

* discrete: the reading of eq. 17 below F_TH (``pass`` | ``block``) and the SF
  definition (``contact_mean`` | ``peak_bin``, `ddmm.models.metrics.SF_DEFINITIONS`);
* continuous: the gain (eqs 1-3), RA-I's / RA-II's derivative cut-off, the
  press-push-lift press/push ramp, lift ramp and shear onset into the push
  ramp, and the shear onset into Birznieks' loading ramp.

The objective is the largest relative error over the type's *fitted* cells
plus a tenth of their mean: the cells not fixed by symmetry, Table II's
selective and broad PRSI and Table III's SF at 75 and 255 deg of the
selective and broad profiles with their SF Diff, bipolar and CMM at 75 deg.
Fig. 8 is held out: a prediction.  SF
is a step function of the constants, so the search is a seeded random
sample of the box followed by coordinate descent on fixed grids from the best
points: deterministic for a seed.

Run::

    ddmm calibrate --target paper [--out DIR] [--seed 0]

It prints each type's best setting and cells; the committed values are
`ddmm.experiments.paper.calibrations.PAPER_CALIBRATION`.
"""

from __future__ import annotations

import dataclasses
import itertools
import math

import numpy as np

from ddmm.experiments.paper.cells import paper_value, type_cells
from ddmm.experiments.paper.reproduce import ReproConfig
from ddmm.models.afferent_types import PAPER_TYPES, afferent_type_info
from ddmm.models.current_params import CurrentParams
from ddmm.utils.deprecation import renamed_keyword

__all__ = ["FIT_CELLS", "READINGS", "DEFINITIONS", "type_config", "objective", "fit_type", "calibrate_paper",
           "config_fields", "report"]

#: The cells each type's fit uses: the non-symmetric ones of Table II (PRSI: Birznieks' shear onset sets it) and
#: Table III.
FIT_CELLS = (("II", "selective", "PRSI"), ("II", "broad", "PRSI")) \
    + tuple(("III", p, row) for p in ("selective", "broad") for row in ("SF (75°)", "SF (255°)", "SF Diff")) \
    + (("III", "bipolar", "SF (75°)"), ("III", "cmm", "SF (75°)"))
READINGS = ("pass", "block")
DEFINITIONS = ("contact_mean", "peak_bin")
_CUTOFF = ("RAI", "RAII")  # the types whose cut-off is fitted
# The unit box's axes: gain factor (log, 0.01-50 at the reference ramp), cut-off (Hz), ramp, lift (s),
# shear onset (fraction of the push ramp), Birznieks shear onset (s).
_BOX = ((math.log(0.01), math.log(50.0)), (5.0, 80.0), (0.1, 4.0), (0.1, 5.0), (0.0, 0.9), (0.0, 0.1))
# The cut-off's range per type.  RA-I's fits ended at the 80 Hz edge (75.6 Hz, one cell 20% off); up to
# 300 Hz every RA-I cell is met.  RA-II's best (29 Hz) lies inside the first range, kept so that its fit
# (and SA-I's, which has no cut-off) is unchanged.
_CUTOFF_BOX = {"RAI": (5.0, 300.0), "RAII": (5.0, 80.0)}
_GRIDS = (61, 16, 40, 50, 10, 11)
_POLISH_SIGMAS = (0.08, 0.04, 0.02, 0.01)
_REFERENCE_RAMP_S = 2.0


def _order(kind: str) -> int:
    """The derivative order of a type's drive (`AfferentType.derivative_order`): a ramp's drive scales as
    ``ramp_s ** -order``."""
    return afferent_type_info(kind).derivative_order


def type_config(kind: str, u, reading: str, definition: str, base: ReproConfig = ReproConfig()) -> ReproConfig:
    """The `ReproConfig` of one type at a point ``u`` of the unit box (6 coordinates in [0, 1])."""
    u = np.clip(np.asarray(u, dtype=float), 0.0, 1.0)
    box = list(_BOX)
    box[1] = _CUTOFF_BOX.get(kind, box[1])
    v = [lo + x * (hi - lo) for x, (lo, hi) in zip(u, box)]
    ramp = v[2]
    # the gain is scaled with the ramp so that one coordinate sets the ramp's drive whatever its length
    gain = CurrentParams().gain(kind) * math.exp(v[0]) * (ramp / _REFERENCE_RAMP_S) ** _order(kind)
    fields = {"gain": round(float(gain), 6)}
    if kind in _CUTOFF:
        fields["cutoff_hz"] = round(float(v[1]), 3)
    return dataclasses.replace(base, no_shear=reading, sf_definition=definition,
                               current_params=base.current_params.with_type(kind, **fields),
                               ramp_s=round(float(ramp), 4), lift_ramp_s=round(float(v[3]), 4),
                               shear_delay_s=round(float(v[4] * ramp), 4),
                               birznieks_shear_delay_s=round(float(v[5]), 4))


def objective(kind: str, config: ReproConfig, cells=FIT_CELLS) -> tuple:
    """(max + mean / 10 of the relative errors over ``cells``, the model's cells)."""
    values, _ = type_cells(kind, config)
    errors = [abs(values[key] - paper_value(kind, key)) / abs(paper_value(kind, key)) for key in cells]
    return max(errors) + 0.1 * float(np.mean(errors)), values


def _descend(kind, u, score, reading, definition, sweeps=4):
    """Coordinate descent on fixed grids from ``u``."""
    u, best = np.array(u, dtype=float), score(u)
    for _ in range(sweeps):
        improved = False
        for axis, n in enumerate(_GRIDS):
            if axis == 1 and kind not in _CUTOFF:
                continue
            for x in np.linspace(0.0, 1.0, n):
                trial = u.copy()
                trial[axis] = x
                value = score(trial)
                if value < best - 1e-12:
                    u, best, improved = trial, value, True
        if not improved:
            break
    return best, u


def _polish(u, best, score, rng, trials: int = 150):
    """Random steps around ``u`` of shrinking size, keeping improvements: the grids miss narrow steps of SF."""
    for sigma in _POLISH_SIGMAS:
        for _ in range(trials):
            trial = np.clip(u + rng.normal(0.0, sigma, u.size), 0.0, 1.0)
            value = score(trial)
            if value < best:
                best, u = value, trial
    return best, u


def fit_type(kind: str, reading: str, definition: str, *, seed: int = 0, n_random: int = 400,
             n_starts: int = 3, engine: str = "direct") -> dict:
    """The best setting of one type for one reading and SF definition.

    A seeded random sample of ``n_random`` points of the unit box, coordinate
    descent from the best ``n_starts``, then random steps of shrinking size
    around the best and a last descent.
    """
    base = ReproConfig(engine=engine)

    def score(u):
        return objective(kind, type_config(kind, u, reading, definition, base))[0]

    rng = np.random.default_rng(seed)
    sample = sorted(((score(u), tuple(u)) for u in rng.random((n_random, len(_BOX)))), key=lambda r: r[0])
    best, u = min((_descend(kind, start, score, reading, definition) for _, start in sample[:n_starts]),
                  key=lambda r: r[0])
    _, u = _polish(u, best, score, rng)
    best, u = _descend(kind, u, score, reading, definition)
    config = type_config(kind, u, reading, definition, base)
    return {"type": kind, "reading": reading, "definition": definition, "objective": round(best, 4),
            "config": config, "cells": objective(kind, config)[1]}


@renamed_keyword("types", "afferent_types")
def calibrate_paper(*, seed: int = 0, n_random: int = 400, afferent_types=PAPER_TYPES, engine: str = "direct") -> dict:
    """Fit every type under every reading and SF definition; keep each type's best.

    Returns ``{"calibration": {type: ReproConfig}, "trials": [fit_type results]}``.
    """
    trials = [fit_type(kind, reading, definition, seed=seed, n_random=n_random, engine=engine)
              for kind, reading, definition in itertools.product(afferent_types, READINGS, DEFINITIONS)]
    best = {kind: min((t for t in trials if t["type"] == kind), key=lambda t: t["objective"])
            for kind in afferent_types}
    return {"calibration": {kind: best[kind]["config"] for kind in afferent_types}, "trials": trials}


def config_fields(config: ReproConfig, kind: str) -> dict:
    """The fitted fields of one type's `ReproConfig` (what `PAPER_CALIBRATION` states)."""
    params = config.current_params.type_params(kind)
    current = {"gain": params.gain, **({"cutoff_hz": params.cutoff_hz} if kind in _CUTOFF else {})}
    return {"no_shear": config.no_shear, "sf_definition": config.sf_definition, "ramp_s": config.ramp_s,
            "lift_ramp_s": config.lift_ramp_s, "shear_delay_s": config.shear_delay_s,
            "birznieks_shear_delay_s": config.birznieks_shear_delay_s, "current_params": current}


def report(result: dict) -> dict:
    """A JSON-ready summary of `calibrate_paper`'s result, with ``text`` to print."""
    trials = [{"type": t["type"], "reading": t["reading"], "definition": t["definition"],
               "objective": t["objective"]} for t in result["trials"]]
    types = {}
    lines = ["# ddmm calibrate --target paper (fitted: the non-symmetric cells of Tables II-III; objective = "
             "max + mean/10 of their relative errors)", ""]
    for kind, config in result["calibration"].items():
        best = min((t for t in result["trials"] if t["type"] == kind), key=lambda t: t["objective"])
        cells = {f"{k[0]} {k[1]} {k[2]}": round(v, 4) for k, v in best["cells"].items()}
        types[kind] = {"objective": best["objective"], "config": config_fields(config, kind), "cells": cells}
        lines.append(f"{kind}: objective {best['objective']:.3f}; {config_fields(config, kind)}")
    lines += ["", "trials (type, reading, SF definition, objective):"]
    lines += [f"  {t['type']} {t['reading']} {t['definition']}: {t['objective']:.3f}" for t in trials]
    lines += ["", "Copy the configurations into ddmm.experiments.paper.calibrations.PAPER_CALIBRATION to adopt."]
    return {"types": types, "trials": trials, "text": "\n".join(lines)}
