"""Atomic file writes shared by datasets and the CLI's outputs."""

from __future__ import annotations

import os
import tempfile
from pathlib import Path

__all__ = ["atomic_write", "writable_parent"]


def _umask_mode() -> int:
    """Mode a plain ``open(..., "w")`` would give: 0o666 minus the umask."""
    mask = os.umask(0)
    os.umask(mask)
    return 0o666 & ~mask


def writable_parent(path) -> tuple[Path, bool]:
    """``(directory of path, whether it exists and can be written)``: the check before an atomic write."""
    directory = Path(path).parent if str(Path(path).parent) else Path(".")
    return directory, directory.is_dir() and os.access(directory, os.W_OK)


def atomic_write(path, write, *, suffix: str = ".part") -> Path:
    """Call ``write(tmp_path)`` then rename the temporary file onto ``path``.

    The temporary file lives in the target's directory, so the rename is
    atomic; on any error it is removed and ``path`` is left untouched.  The
    file gets the usual permissions (``mkstemp`` would leave it owner-only).
    ``suffix`` ends the temporary name (a writer may insist on an extension).
    """
    path = Path(path)
    fd, tmp = tempfile.mkstemp(dir=path.parent if str(path.parent) else ".", prefix=f".{path.name}.", suffix=suffix)
    os.close(fd)
    try:
        write(tmp)
        os.chmod(tmp, _umask_mode())
        os.replace(tmp, path)
    except BaseException:
        if os.path.exists(tmp):
            os.unlink(tmp)
        raise
    return path
