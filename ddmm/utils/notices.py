"""Warnings that know how the command line says them.

A warning raised inside the package names Python arguments (``afferent_types=...``); the ``ddmm``
command prints it as one ``ddmm: warning: ...`` line that names the options instead (`cli_text`),
and not at all once the user has followed it (`only_for_types`).
"""

from __future__ import annotations

__all__ = ["with_cli", "cli_text", "only_for_types"]


def with_cli(warning: Warning, cli: str, only_for_types: tuple = ()) -> Warning:
    """``warning`` with its command-line wording and the afferent types it concerns (empty: all runs).

    Examples
    --------
    >>> w = with_cli(UserWarning("use afferent_types=..."), "use --types", ("RAII",))
    >>> str(w), cli_text(w), only_for_types(w)
    ('use afferent_types=...', 'use --types', ('RAII',))
    """
    warning.ddmm_cli, warning.ddmm_types = cli, tuple(only_for_types)
    return warning


def cli_text(warning) -> str:
    """The warning's command-line wording, on one line (its message where it has none)."""
    return " ".join(str(getattr(warning, "ddmm_cli", warning)).split())


def only_for_types(warning) -> tuple:
    """The afferent types the warning concerns: it is moot for a run that simulates none of them."""
    return tuple(getattr(warning, "ddmm_types", ()))
