"""Memory a job may use, checked before a large allocation: a clear refusal instead of an OOM kill.

The limit is the smallest of the process's cgroup memory limit (less what
the cgroup already uses), the host's available memory (``MemAvailable``) and
``DDMM_MEMORY_LIMIT`` when set (bytes, or with a K, M, G or T suffix), which
also raises the others: set it to run a job that knowingly swaps.
"""

from __future__ import annotations

import os
import re
from pathlib import Path

__all__ = ["MEMORY_ENV", "available_bytes", "check_memory"]

MEMORY_ENV = "DDMM_MEMORY_LIMIT"
_UNITS = {"": 1, "K": 1 << 10, "M": 1 << 20, "G": 1 << 30, "T": 1 << 40}


def _read_int(path: str) -> int | None:
    try:
        text = Path(path).read_text().strip()
    except OSError:
        return None
    return int(text) if text.isdigit() else None


def _cgroup_room() -> int | None:
    """Bytes the cgroup may still allocate (v2, then v1), or None with no limit."""
    for limit, usage in (("/sys/fs/cgroup/memory.max", "/sys/fs/cgroup/memory.current"),
                         ("/sys/fs/cgroup/memory/memory.limit_in_bytes", "/sys/fs/cgroup/memory/memory.usage_in_bytes")):
        cap = _read_int(limit)
        if cap is not None and cap < (1 << 60):  # v1 writes a huge number for "no limit"
            return max(0, cap - (_read_int(usage) or 0))
    return None


def _mem_available() -> int | None:
    try:
        for line in Path("/proc/meminfo").read_text().splitlines():
            if line.startswith("MemAvailable:"):
                return int(line.split()[1]) * 1024
    except (OSError, ValueError, IndexError):
        return None
    return None


def available_bytes() -> int:
    """Bytes this process may allocate: `DDMM_MEMORY_LIMIT`, else the cgroup's room and the host's available memory."""
    text = os.environ.get(MEMORY_ENV, "").strip()
    if text:
        match = re.fullmatch(r"(\d+(?:\.\d+)?)\s*([KMGT]?)B?", text, re.IGNORECASE)
        if not match:
            raise ValueError(f"{MEMORY_ENV} must be a number of bytes, optionally with K, M, G or T, got {text!r}")
        return int(float(match.group(1)) * _UNITS[match.group(2).upper()])
    known = [b for b in (_cgroup_room(), _mem_available()) if b is not None]
    return min(known) if known else 1 << 62


def _gib(n: float) -> str:
    return f"{n / (1 << 30):.3g} GiB"


def check_memory(n_bytes: float, what: str, remedy: str) -> None:
    """Raise ValueError, before allocating, when ``what`` would need more than `available_bytes`.

    Examples
    --------
    >>> check_memory(1024, "a small table", "use fewer rows")  # fits: returns None
    """
    room = available_bytes()
    if n_bytes > room:
        raise ValueError(f"{what} would need about {_gib(n_bytes)}, more than the {_gib(room)} this process may use; "
                         f"{remedy} (or set {MEMORY_ENV}, e.g. {MEMORY_ENV}=64G)")
