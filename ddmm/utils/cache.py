"""The on-disk cache root shared by the Brian2 builds and the designed filters."""

from __future__ import annotations

import os
import stat
from pathlib import Path


def cache_root() -> Path:
    """``$DDMM_CACHE_DIR``, else ``$XDG_CACHE_HOME/ddmm``, else ``~/.cache/ddmm``."""
    root = os.environ.get("DDMM_CACHE_DIR") or os.path.join(
        os.environ.get("XDG_CACHE_HOME") or os.path.expanduser("~/.cache"), "ddmm")
    return Path(root)


def private_dir(path) -> Path:
    """``path`` created if missing (mode 0700, parents too) and checked to be safe to build and run from.

    Raises
    ------
    ValueError
        If ``path`` is a symlink, not a directory, or writable by other users
        (another user could replace a binary the engine then runs): a private
        directory inside a sticky shared one, such as the system temporary
        directory, is fine.
    """
    path = Path(path)
    path.mkdir(mode=0o700, parents=True, exist_ok=True)
    info = os.lstat(path)
    if stat.S_ISLNK(info.st_mode) or not stat.S_ISDIR(info.st_mode):
        raise ValueError(f"cache directory {str(path)!r} must be a directory, not a symlink (set DDMM_CACHE_DIR)")
    if info.st_mode & (stat.S_IWGRP | stat.S_IWOTH):
        raise ValueError(f"cache directory {str(path)!r} is writable by other users (mode {stat.S_IMODE(info.st_mode):o}):"
                         f" run 'chmod go-w {path}' or set DDMM_CACHE_DIR to a private directory")
    return path
