"""Names of a package imported on first use (PEP 562), shared by every ddmm package `__init__`."""

from __future__ import annotations

from importlib import import_module


def lazy_exports(package: str, where: dict):
    """``(__all__, __getattr__, __dir__)`` for a package whose names live in its submodules.

    ``where`` maps a submodule's name (relative to ``package``) to the names
    it exports.  No exported name may equal a submodule's name: importing the
    submodule would then replace the name on the package (the tests check).
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

    return sorted(module_of), __getattr__, __dir__
