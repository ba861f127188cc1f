"""Names of a package imported on first use (PEP 562), shared by `models` and `population`."""

from __future__ import annotations

import sys
import types
from importlib import import_module


def lazy_exports(package: str, where: dict):
    """``(__all__, __getattr__, __dir__)`` for a package whose names live in its submodules.

    ``where`` maps a submodule's name to the names it exports.
    """
    module_of = {name: module for module, names in where.items() for name in names}
    namespace = import_module(package).__dict__

    def __getattr__(name):
        if name not in module_of:
            raise AttributeError(f"module {package!r} has no attribute {name!r}")
        value = getattr(import_module(f"{package}.{module_of[name]}"), name)
        namespace[name] = value  # later lookups skip this function
        return value

    def __dir__():
        return sorted(set(namespace) | set(module_of))

    sys.modules[package].__class__ = _Package
    return sorted(module_of), __getattr__, __dir__


class _Package(types.ModuleType):
    """A package whose exported function may share its submodule's name (``population.simulate``).

    Importing a submodule sets the package attribute of that name to the
    module; an eager ``from .simulate import simulate`` in ``__init__`` used
    to overwrite it with the function.  Here the function wins the same way,
    whenever the submodule is imported.
    """

    def __setattr__(self, name, value):
        if isinstance(value, types.ModuleType) and value.__name__ == f"{self.__name__}.{name}" \
                and isinstance(getattr(value, name, None), types.FunctionType):
            value = getattr(value, name)
        super().__setattr__(name, value)
