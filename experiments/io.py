"""Atomic file output for the CLI: a failed run never leaves a half-written file."""

from __future__ import annotations

import json
import os
import tempfile
from pathlib import Path

__all__ = ["ensure_out_dir", "atomic_write", "save_figure", "save_json"]


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


def atomic_write(path, write) -> Path:
    """Call ``write(tmp_path)`` then rename the temporary file onto ``path``.

    The temporary file lives in the target's directory, so the rename is
    atomic; on any error it is removed and ``path`` is left untouched.
    """
    path = Path(path)
    fd, tmp = tempfile.mkstemp(dir=path.parent, prefix=f".{path.name}.", suffix=".part")
    os.close(fd)
    try:
        write(tmp)
        os.replace(tmp, path)
    except BaseException:
        if os.path.exists(tmp):
            os.unlink(tmp)
        raise
    return path


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
