"""Atomic file output for the CLI: a failed run never leaves a half-written file."""

from __future__ import annotations

import argparse
import json
import os
from pathlib import Path

from ddmm.utils.files import atomic_write

__all__ = ["ensure_out_dir", "atomic_write", "save_figure", "save_json", "seed_arg", "quiet_liblsl"]

#: liblsl's configuration for a quiet run: fatal messages only (its INFO lines, and the "ERR| Stream
#: transmission broke off" it prints when a peer closes at the end of a good run, are not the user's business).
_QUIET_LSL = "[log]\nlevel = -3\n"


def ensure_out_dir(path) -> Path:
    """Create ``path`` (and parents) and check it is a writable directory.

    Raises
    ------
    ValueError
        If it exists as a file or cannot be written.
    """
    out = Path(path)
    try:
        out.mkdir(parents=True, exist_ok=True)
    except OSError as exc:
        raise ValueError(f"--out {str(path)!r} cannot be created: {exc.strerror or exc}") from None
    if not out.is_dir() or not os.access(out, os.W_OK):
        raise ValueError(f"--out {str(path)!r} is not a writable directory")
    return out


def save_figure(fig, path, dpi: int = 120) -> Path:
    """Save a matplotlib figure atomically as PNG."""
    return atomic_write(path, lambda tmp: fig.savefig(tmp, dpi=dpi, format="png"))


def save_json(obj, path) -> Path:
    """Write ``obj`` as indented JSON atomically."""
    def write(tmp):
        with open(tmp, "w") as fh:
            json.dump(obj, fh, indent=2)
            fh.write("\n")
    return atomic_write(path, write)


def seed_arg(text: str) -> int:
    """The argparse type of ``--seed``: an integer >= 0 (what numpy takes as a seed)."""
    try:
        value = int(text)
    except ValueError:
        raise argparse.ArgumentTypeError(f"must be an integer >= 0, got {text!r}") from None
    if value < 0:
        raise argparse.ArgumentTypeError(f"must be an integer >= 0 (a numpy seed), got {value}")
    return value


def quiet_liblsl(debug: bool) -> None:
    """Keep liblsl's log off the terminal (unless ``debug``, or ``LSLAPICFG`` names the user's own config).

    Call before the first LSL stream opens: liblsl reads ``LSLAPICFG`` once.  The configuration is a
    file in the temporary directory, written once.
    """
    import tempfile

    if debug or "LSLAPICFG" in os.environ:
        return
    path = Path(tempfile.gettempdir()) / "ddmm-liblsl-quiet.cfg"
    if not path.is_file() or path.read_text() != _QUIET_LSL:
        atomic_write(path, lambda tmp: Path(tmp).write_text(_QUIET_LSL))
    os.environ["LSLAPICFG"] = str(path)
