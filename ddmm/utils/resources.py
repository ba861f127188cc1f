"""Memory a job may use, checked before a large allocation: a clear refusal instead of an OOM kill.

The limit is the smallest of the process's cgroup memory limit (less what
the cgroup already uses), the host's available memory (``MemAvailable``)
and the address-space limit (``RLIMIT_AS``, ``ulimit -v``, less the
address space the process already maps); ``DDMM_MEMORY_LIMIT`` when set
(bytes, or with a K, M, G or T suffix) replaces all three: set it to run a
job that knowingly swaps.
"""

from __future__ import annotations

import os
import re
import sys
from pathlib import Path

try:
    import resource
except ImportError:  # Windows: no rlimits, no getrusage
    resource = None

__all__ = ["MEMORY_ENV", "available_bytes", "check_memory", "format_bytes", "resident_bytes"]

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


def _statm(field: int) -> int | None:
    """Field ``field`` of ``/proc/self/statm`` (0: address space, 1: resident) in bytes, or None off Linux."""
    try:
        return int(Path("/proc/self/statm").read_text().split()[field]) * os.sysconf("SC_PAGE_SIZE")
    except (OSError, ValueError, IndexError):
        return None


def _address_room() -> int | None:
    """Bytes of address space left under ``RLIMIT_AS``, or None with no limit."""
    if resource is None or not hasattr(resource, "RLIMIT_AS"):
        return None
    soft = resource.getrlimit(resource.RLIMIT_AS)[0]
    if soft == resource.RLIM_INFINITY or soft < 0:
        return None
    return max(0, soft - (_statm(0) or 0))


def resident_bytes() -> int:
    """Bytes this process holds in memory now (its resident set; the peak so far off Linux, 0 if unknown).

    Examples
    --------
    >>> resident_bytes() > 1 << 20
    True
    """
    now = _statm(1)
    if now is not None or resource is None:
        return now or 0
    peak = resource.getrusage(resource.RUSAGE_SELF).ru_maxrss
    return peak if sys.platform == "darwin" else peak * 1024  # bytes on macOS, KiB elsewhere


def available_bytes() -> int:
    """Bytes this process may allocate: `DDMM_MEMORY_LIMIT`, else the smallest of the cgroup's room, the host's
    available memory and the address space left under ``RLIMIT_AS``."""
    text = os.environ.get(MEMORY_ENV, "").strip()
    if text:
        match = re.fullmatch(r"(\d+(?:\.\d+)?)\s*([KMGT]?)B?", text, re.IGNORECASE)
        if not match:
            raise ValueError(f"{MEMORY_ENV} must be a number of bytes, optionally with K, M, G or T, got {text!r}")
        return int(float(match.group(1)) * _UNITS[match.group(2).upper()])
    known = [b for b in (_cgroup_room(), _mem_available(), _address_room()) if b is not None]
    return min(known) if known else 1 << 62


def format_bytes(n: float) -> str:
    """``n`` bytes as a message prints them: in MiB below 1 GiB, GiB below 1 TiB, else TiB.

    Examples
    --------
    >>> format_bytes(41e6), format_bytes(3 << 30), format_bytes(6.5e13)
    ('39.1 MiB', '3 GiB', '59.1 TiB')
    """
    shift, unit = next((s, u) for s, u in ((40, "TiB"), (30, "GiB"), (20, "MiB")) if n >= 1 << s or s == 20)
    return f"{n / (1 << shift):.3g} {unit}"


def check_memory(n_bytes: float, what: str, remedy: str) -> None:
    """Raise ValueError, before allocating, when ``what`` would need more than `available_bytes`.

    Examples
    --------
    >>> check_memory(1024, "a small table", "use fewer rows")  # fits: returns None
    """
    room = available_bytes()
    if n_bytes > room:
        raise ValueError(f"{what} would need about {format_bytes(n_bytes)}, more than the {format_bytes(room)} this "
                         f"process may use; {remedy} (or set {MEMORY_ENV}, e.g. {MEMORY_ENV}=64G)")
