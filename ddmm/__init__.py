"""ddmm: a population-coding simulator of tactile afferent arrays (the DDMM).

Three subpackages, layered one way (models <- population <- experiments),
on the helpers they share (`ddmm.utils`):

- `ddmm.models`: single-afferent physics (NAP geometry, attenuation,
  currents, Izhikevich neurons) and the engines that integrate them;
- `ddmm.population`: specs, anatomy, stimuli, simulation into an xarray
  Dataset, analysis and file I/O;
- `ddmm.experiments`: the ``ddmm`` command line, reproductions of the
  paper, calibration, validation, benchmarks and figures.

The map of every module, and where each kind of change goes, is
``docs/development.md``.

The everyday names are importable from here (on first use, so ``import
ddmm`` stays cheap):

>>> import ddmm
>>> pop = ddmm.sample_population("fingertip", rng=0)
>>> ds = ddmm.simulate(pop.select(range(20)), ddmm.birznieks(90.0), engine="direct", seed=0, quiet=True)
>>> int(ds.sizes["afferent"])
20
"""

from __future__ import annotations

import os as _os

# In a source checkout this folder holds only this file and the subpackages
# are its siblings (the project's layout); an installed copy has them inside.
if not _os.path.isdir(_os.path.join(_os.path.dirname(__file__), "models")):
    __path__.append(_os.path.dirname(_os.path.dirname(_os.path.abspath(__file__))))  # noqa: F821


def _version() -> str:
    from importlib import metadata

    try:
        return metadata.version("ddmm")
    except metadata.PackageNotFoundError:  # a source checkout that was never installed
        return "0+unknown"


__version__ = _version()

_EVERYDAY = {
    "ddmm.population": ("Population", "PopulationSpec", "Scene", "Contact", "Sites", "Stage", "birznieks",
                        "from_csv", "load_dataset", "load_spec", "make_population", "plan_run", "press_push_lift",
                        "psth", "rotating_shear", "sample_population", "save_dataset", "simulate"),
    "ddmm.population.runtime": ("Encoder",),
}
_MODULE_OF = {name: module for module, names in _EVERYDAY.items() for name in names}
__all__ = sorted(_MODULE_OF) + ["__version__"]


def __getattr__(name):
    if name not in _MODULE_OF:
        raise AttributeError(f"module 'ddmm' has no attribute {name!r}")
    from importlib import import_module

    value = getattr(import_module(_MODULE_OF[name]), name)
    globals()[name] = value
    return value


def __dir__():
    return sorted(set(globals()) | set(_MODULE_OF))
