"""Generate the reference pages ``docs/cli.md`` and ``docs/api.md`` from the code, so they cannot drift.

``python -m ddmm.experiments.docs_reference [DIR]`` rewrites both pages (default
``docs/``); ``tests/test_docs.py`` fails when a committed page differs from
what this module generates.
"""

from __future__ import annotations

import importlib
import inspect
import os
import pkgutil
import sys
from contextlib import contextmanager
from pathlib import Path

__all__ = ["cli_reference", "api_reference", "write_references"]

_WIDTH = "100"  # argparse wraps help at $COLUMNS: fixed, so the page is the same on every terminal
_PACKAGES = ("ddmm.models", "ddmm.population")


@contextmanager
def _columns():
    saved = os.environ.get("COLUMNS")
    os.environ["COLUMNS"] = _WIDTH
    try:
        yield
    finally:
        if saved is None:
            del os.environ["COLUMNS"]
        else:
            os.environ["COLUMNS"] = saved


def cli_reference() -> str:
    """The ``ddmm`` command line as Markdown: the top-level help, then every subcommand's.

    Examples
    --------
    >>> "## ddmm simulate" in cli_reference()
    True
    """
    from ddmm.experiments.cli import build_parser

    with _columns():
        parser = build_parser()
        sub = next(a for a in parser._actions if a.__class__.__name__ == "_SubParsersAction")
        parts = ["# Command-line reference", "",
                 "Generated from the argument parsers by `python -m ddmm.experiments.docs_reference`; "
                 "a test fails when this page and the parsers disagree.", "",
                 "```text", parser.format_help().rstrip(), "```", ""]
        for name, command in sub.choices.items():
            parts += [f"## ddmm {name}", "", "```text", command.format_help().rstrip(), "```", ""]
    return "\n".join(parts)


def _public_modules(package: str) -> list:
    """The package, then its public submodules and subpackages at any depth (no leading underscore), by name."""
    pkg = importlib.import_module(package)
    names = sorted(m.name for m in pkgutil.walk_packages(pkg.__path__, prefix=f"{package}.")
                   if not any(part.startswith("_") for part in m.name.split(".")))
    return [pkg] + [importlib.import_module(name) for name in names]


def _summary(obj) -> str:
    doc = inspect.getdoc(obj) or ""
    return " ".join(doc.split("\n\n")[0].split())


class _Default:
    """A parameter default shown by a short name (a long repr would bury the signature)."""

    def __init__(self, text: str):
        self.text = text

    def __repr__(self):
        return self.text


def _signature(obj) -> str:
    try:
        sig = inspect.signature(obj)
    except (TypeError, ValueError):
        return ""
    params = [p.replace(default=_Default(f"{type(p.default).__name__}()"))
              if p.default is not p.empty and len(repr(p.default)) > 40 else p for p in sig.parameters.values()]
    return str(sig.replace(parameters=params))


def _entry(module, name: str) -> str:
    obj = getattr(module, name)
    obj = getattr(obj, "py_func", obj)  # a numba kernel: document the Python function it compiles
    if inspect.isfunction(obj) or inspect.isclass(obj):
        signature = _signature(obj)
        kind = "class " if inspect.isclass(obj) else ""
        return f"- `{kind}{name}{signature}`: {_summary(obj)}"
    return f"- `{name}`: constant ({type(obj).__name__})"


def api_reference() -> str:
    """The public API as Markdown: each public module's summary and its ``__all__``, with signatures.

    Examples
    --------
    >>> "`ddmm.population.runtime.stream`" in api_reference()
    True
    """
    parts = ["# API reference", "",
             "Every public module of `ddmm.models` (single-afferent physics and engines) and `ddmm.population` "
             "(specs, sampling, simulation, datasets, and the anatomy, stimuli, runtime, analysis and io "
             "subpackages), with the names it exports. Generated from the "
             "docstrings by `python -m ddmm.experiments.docs_reference`; the docstrings themselves (numpydoc, "
             "with examples that the tests run) are the full reference: `help(ddmm.population.simulate)`.", ""]
    for package in _PACKAGES:
        for module in _public_modules(package):
            exported = list(getattr(module, "__all__", []))
            parts += [f"## `{module.__name__}`", "", _summary(module), ""]
            if hasattr(module, "__path__") and module.__name__ not in _PACKAGES:
                continue  # a subpackage re-exports its modules' names, listed with each module
            parts += [_entry(module, name) for name in exported] + ([""] if exported else [])
    return "\n".join(parts)


def write_references(directory) -> list:
    """Write ``cli.md`` and ``api.md`` into ``directory``; returns the paths."""
    directory = Path(directory)
    paths = []
    for name, text in (("cli.md", cli_reference()), ("api.md", api_reference())):
        paths.append(directory / name)
        paths[-1].write_text(text)
    return paths


if __name__ == "__main__":  # pragma: no cover
    for path in write_references(sys.argv[1] if len(sys.argv) > 1 else "docs"):
        print(f"wrote {path}")
