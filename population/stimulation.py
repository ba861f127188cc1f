"""Deprecated alias of `ddmm.population.neurostim` (renamed so that it cannot be confused with `stimuli`).

``import ddmm.population.stimulation`` and its submodules (``.electrodes``,
``.rules``, ``.pulses``, ``.encode``, ``.stream``) still work for one release,
with a `DeprecationWarning`; they are the very `neurostim` modules.
"""

import sys
from importlib import import_module

from ddmm.population import neurostim as _neurostim
from ddmm.utils.deprecation import warn_renamed

warn_renamed("ddmm.population.stimulation", "ddmm.population.neurostim (the same modules)", stacklevel=2)

for _name in ("electrodes", "rules", "pulses", "encode", "stream"):
    sys.modules[f"{__name__}.{_name}"] = import_module(f"ddmm.population.neurostim.{_name}")

__all__ = list(_neurostim.__all__)


def __getattr__(name):
    return getattr(_neurostim, name)


def __dir__():
    return sorted(__all__)
