"""Optional dependencies (the package's extras) imported on use, with a one-line error when missing."""

from __future__ import annotations

from importlib import import_module

__all__ = ["MissingExtraError", "require"]


class MissingExtraError(ImportError):
    """An optional dependency of one function is not installed; the message says which extra brings it."""


def require(module: str, caller: str, extra: str):
    """Import ``module`` for ``caller``, or raise `MissingExtraError` naming ``pip install "ddmm[extra]"``."""
    try:
        return import_module(module)
    except ImportError as exc:
        raise MissingExtraError(f'{caller} needs {module.partition(".")[0]}: pip install "ddmm[{extra}]"') from exc
