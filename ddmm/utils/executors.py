"""Long-lived thread pools, one per name and process.

Starting two threads costs a few milliseconds, which a one-second hand run
paid on every call; a pool kept for the process pays it once.  A forked
child (a local process pool, Dask's nanny) inherits the pool object but not
its threads, so a pool is remade when the process id changes.
"""

from __future__ import annotations

import os
import threading
from concurrent.futures import ThreadPoolExecutor

__all__ = ["shared_executor"]

_POOLS: dict = {}
_LOCK = threading.Lock()


def shared_executor(name: str, threads: int) -> ThreadPoolExecutor:
    """The process's pool ``name`` of ``threads`` workers, made on first use (and again after a fork or
    a change of ``threads``).

    Examples
    --------
    >>> shared_executor("doc", 1).submit(sum, [1, 2]).result()
    3
    >>> shared_executor("doc", 1) is shared_executor("doc", 1)
    True
    """
    key, pid = (name, int(threads)), os.getpid()
    with _LOCK:
        pool = _POOLS.get(key)
        if pool is None or pool[0] != pid:
            pool = _POOLS[key] = (pid, ThreadPoolExecutor(max_workers=int(threads), thread_name_prefix=f"ddmm-{name}"))
        return pool[1]
