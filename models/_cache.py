"""The on-disk cache root shared by the Brian2 builds and the designed filters."""

from __future__ import annotations

import os
from pathlib import Path


def cache_root() -> Path:
    """``$DDMM_CACHE_DIR``, else ``$XDG_CACHE_HOME/ddmm``, else ``~/.cache/ddmm``."""
    root = os.environ.get("DDMM_CACHE_DIR") or os.path.join(
        os.environ.get("XDG_CACHE_HOME") or os.path.expanduser("~/.cache"), "ddmm")
    return Path(root)
