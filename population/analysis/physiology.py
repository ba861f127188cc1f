"""A physiology scorecard: a fixed battery of protocols against human microneurography.

`score_physiology` runs the protocols a population needs and returns one row
per property: its afferent type, protocol, statistic, the model's value, the
reference range and its source, the role (``fitted`` when ``ddmm calibrate``
uses it, ``constrained`` when it bounds the fit, ``held out`` when no
objective ever saw it) and pass/fail.  The reference ranges are data, passed
in (`Reference`); the package's own live in ``population/data/published.py``.

The rows come from protocol modules: the core battery (`physiology_core`:
rest, on/off, rates, force and frequency coding, direction, timing,
continuity), then every module of `EXTENSIONS`, each registered by
`load_extensions`.  Their shared helpers live in `physiology_base`; every
name of both is importable from here as well.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from ddmm.models.afferent_types import afferent_type_codes
from ddmm.population.analysis import physiology_core as _core

# Importable here, where protocol modules, figures and tests have always found them.
from ddmm.population.analysis.physiology_base import Property, _knots, _of, _p, _rates, _run  # noqa: F401
from ddmm.population.analysis.physiology_core import (  # noqa: F401
    _VIBRATION_FS,
    _VIBRATION_S,
    _VIBRATION_WINDOW,
    AMPLITUDES_N,
    FREQUENCIES_HZ,
    TIMING_ENSEMBLE,
    TIMING_ENSEMBLES,
    _continuity,
    _direction,
    _force_coding,
    _frequency,
    _jitter,
    _max_rates,
    _max_step,
    _on_off,
    _rest,
    _shipped_rates,
    _thresholds,
    _timing,
    _transient_distance,
    on_off_scene,
    shipped_scenes,
    vibration_scene,
)
from ddmm.population.sampling import Population
from ddmm.utils.validation import check_instance

__all__ = ["Reference", "Property", "PROPERTIES", "PROTOCOLS", "shipped_scenes", "score_physiology",
           "summarise_scorecard"]


@dataclass(frozen=True)
class Reference:
    """A reference range for one property.

    Attributes
    ----------
    low, high : float
        Inclusive bounds on the model's value (``inf`` for none).
    source : str
        Where the range comes from (a row of docs/references.md and its citation).
    role : {"fitted", "constrained", "held out"}
        How the calibration uses it.
    mark : {"V", "V2", "R"}
        Read in the source, read in a secondary source, or recalled (R rows
        become broad ranges).
    """

    low: float
    high: float
    source: str
    role: str
    mark: str = "R"

    def __post_init__(self):
        if self.role not in ("fitted", "constrained", "held out"):
            raise ValueError(f"role={self.role!r} is not allowed; allowed: fitted, constrained, held out")
        if not self.low <= self.high:
            raise ValueError(f"low={self.low!r} must be <= high={self.high!r}")


#: Every row, in the order rows are printed: the core battery's, then each extension's.
PROPERTIES = dict(_core.PROPERTIES)
#: The protocols, in the order they run.
PROTOCOLS = _core.PROTOCOLS
_RUNNERS = dict(_core.RUNNERS)


#: Protocol modules beyond the core battery, in the order their protocols run.
EXTENSIONS = ("physiology_vibration", "physiology_variability", "physiology_slow", "physiology_fields",
              "physiology_shear", "physiology_everyday", "physiology_tilt")
_MERGED: set = set()


def load_extensions() -> None:
    """Add the rows of every module of `EXTENSIONS` not added yet (idempotent).

    A protocol module (``ddmm.population.analysis.<name>``) defines
    ``PROPERTIES`` (name -> `Property`), ``PROTOCOLS`` (names, in the order
    they run) and ``RUNNERS`` (protocol name -> ``runner(population,
    context) -> (values, data)``), and may import this module's helpers
    (`_run`, `_rates`, `_of`, `_knots`).  This module loads them when it is
    imported; a protocol module imported first (it imports this module
    before defining its names) calls this function at its end.
    """
    from importlib import import_module

    for name in EXTENSIONS:
        module = import_module(f"ddmm.population.analysis.{name}")
        if name not in _MERGED and hasattr(module, "RUNNERS"):  # not while it is still being imported
            _extend(module)
            _MERGED.add(name)


def _extend(module) -> None:
    global PROTOCOLS
    clash = (set(module.PROPERTIES) & set(PROPERTIES)) | (set(module.PROTOCOLS) & set(PROTOCOLS))
    if clash:
        raise RuntimeError(f"{module.__name__} redefines {sorted(clash)}")
    PROPERTIES.update(module.PROPERTIES)
    PROTOCOLS = PROTOCOLS + tuple(module.PROTOCOLS)
    _RUNNERS.update(module.RUNNERS)


def _select(population, properties):
    names = list(PROPERTIES) if properties is None else list(properties)
    for name in names:
        if name not in PROPERTIES:
            raise ValueError(f"unknown property {name!r}; allowed: {', '.join(PROPERTIES)}")
    present = set(np.unique(population.afferent_type).tolist())
    for name in names:
        needed = PROPERTIES[name].afferent_type
        if needed != "all" and not set(needed.split("+")) & present:
            raise ValueError(f"property {name!r} needs {needed} afferents; population {population.name!r} has "
                             f"{', '.join(t for t in afferent_type_codes() if t in present)}")
    return names


def score_physiology(population, references: dict, *, properties=None, seed: int = 0, engine: str = "direct",
                     no_shear: str = "smooth"):
    """Run the battery on a population; returns (rows, per-protocol data for figures).

    Parameters
    ----------
    population : Population
        The afferents (e.g. ``sample_population("fingertip", rng=0)``).
    references : dict
        `Reference` per property name (``ddmm.population.data.published.PHYSIOLOGY_REFERENCE``).
    properties : sequence of str, optional
        Names from `PROPERTIES` (default: all).
    seed : int
        Noise seed of every protocol.
    engine : {"direct", "brian2"}
    no_shear : str
        Reading of eq. 17 for every protocol.

    Returns
    -------
    rows : list of dict
        ``name, type, protocol, statistic, unit, value, low, high, source, role, mark, pass``.
    data : dict
        Protocol name -> what its figure needs.

    Raises
    ------
    ValueError
        For an unknown property, a missing reference, or a population lacking a type a property needs.
    """
    check_instance(population, "population", Population, "a Population (e.g. from sample_population)")
    check_instance(references, "references", dict, "a dict of Reference by property name (PHYSIOLOGY_REFERENCE)")
    names = _select(population, properties)
    missing = [n for n in names if n not in references]
    if missing:
        raise ValueError(f"no reference range for property {missing[0]!r}")
    values, data = _measure(population, names, {"seed": seed, "engine": engine, "no_shear": no_shear})
    return [_row(name, values.get(name), references[name], population) for name in names], data


def _measure(population, names, context):
    """Run, in `PROTOCOLS` order, each protocol that one of ``names`` needs; returns (values, data per protocol)."""
    values, data = {}, {}
    for protocol in PROTOCOLS:
        if any(PROPERTIES[n].protocol == protocol for n in names):
            values_p, data[protocol] = _RUNNERS[protocol](population, context)
            values.update(values_p)
    return values, data


def _row(name, value, ref, population) -> dict:
    """The scorecard row of property ``name``: the model's ``value`` against the `Reference` ``ref``."""
    if value is None:
        raise ValueError(f"property {name!r} could not be measured on population {population.name!r}")
    prop = PROPERTIES[name]
    return {"name": name, "type": prop.afferent_type, "protocol": prop.protocol,
            "statistic": prop.statistic, "unit": prop.unit, "value": float(value), "low": ref.low,
            "high": ref.high, "source": ref.source, "role": ref.role, "mark": ref.mark,
            "pass": bool(ref.low <= value <= ref.high)}


def summarise_scorecard(rows) -> str:
    """One line: passes out of rows, by role, and the failing properties.

    Examples
    --------
    >>> summarise_scorecard([{"name": "a", "role": "fitted", "pass": True},
    ...                      {"name": "b", "role": "held out", "pass": False}])
    'physiology: 1/2 properties pass (fitted 1/1, held out 0/1); failing: b'
    """
    if not isinstance(rows, (list, tuple)) or not all(isinstance(row, dict) for row in rows):
        raise TypeError(f"rows must be a list of scorecard rows (dicts, from score_physiology), got "
                        f"{type(rows).__name__}")
    roles = {}
    for row in rows:
        n, k = roles.get(row["role"], (0, 0))
        roles[row["role"]] = (n + int(row["pass"]), k + 1)
    parts = ", ".join(f"{role} {n}/{k}" for role, (n, k) in roles.items())
    failing = [row["name"] for row in rows if not row["pass"]]
    line = f"physiology: {sum(r['pass'] for r in rows)}/{len(rows)} properties pass ({parts})"
    return line + (f"; failing: {', '.join(failing)}" if failing else "")


load_extensions()
