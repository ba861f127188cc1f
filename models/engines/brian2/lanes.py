"""Lanes of the Brian2 engine: each concurrent run's own input files and results directory.

A lane is a private directory ``$DDMM_CACHE_DIR/brian2/lanes/<pid>_<k>_<random>``
(``mkdtemp``: mode 0700, an unpredictable name, no symlink followed) holding the
current table, the per-neuron inputs and the binary's ``results/``.  A lane
serves one run at a time and keeps its files between runs, rewritten in
place (the table through a memory map, `write_table`): writing a fresh
25 MB table and deleting it after every run made a hand x 1 s Brian2 run
3-6% slower (medians of 11 runs alternated in one process: 0.158-0.161 s
against 0.151-0.153 s).  The files go when the process exits; lanes of
processes no longer alive (killed before exiting) are removed when a new
process opens its first lane.
"""

from __future__ import annotations

import atexit
import os
import queue
import shutil
import tempfile
import threading
from contextlib import contextmanager
from pathlib import Path

import numpy as np

from ddmm.utils.cache import cache_root, private_dir

__all__ = ["lane", "write_table"]

_FREE: queue.SimpleQueue = queue.SimpleQueue()  # lanes not in use, of the process in _OWNER
_OWNER = [0]  # pid whose lanes _FREE and _MINE hold (a forked child starts afresh)
_MINE: list = []
_LOCK = threading.Lock()
_MAPS: dict = {}  # table file -> its np.memmap (`write_table`)
_KEEP_MAPPED = 1 << 22  # elements (32 MB): larger tables are unmapped after each write


def _root() -> Path:
    return (cache_root() / "brian2" / "lanes").absolute()


def _alive(pid: int) -> bool:
    try:
        os.kill(pid, 0)
    except ProcessLookupError:
        return False
    except PermissionError:  # another user's process
        return True
    return True


def _sweep() -> None:
    """Remove the lanes of processes that are no longer alive."""
    root = _root()
    if not root.is_dir():
        return
    for path in root.iterdir():
        pid = path.name.split("_")[0]
        if pid.isdigit() and int(pid) != os.getpid() and not _alive(int(pid)):
            shutil.rmtree(path, ignore_errors=True)


def _remove(pid: int) -> None:
    """At exit: remove the lanes of process ``pid`` (a forked child inherits the hook, not the lanes)."""
    if os.getpid() == pid:
        for path in _MINE:
            shutil.rmtree(path, ignore_errors=True)


def _new() -> Path:
    with _LOCK:
        pid = os.getpid()
        if _OWNER[0] != pid:  # the first lane of this process
            _OWNER[0] = pid
            _MINE.clear()
            _sweep()
            atexit.register(_remove, pid)
        root = private_dir(_root())
        # mkdtemp: an unpredictable name, mode 0700, created (never an existing path or a symlink followed)
        path = Path(tempfile.mkdtemp(prefix=f"{pid}_{len(_MINE)}_", dir=root))
        _MINE.append(path)
    (path / "results").mkdir()
    return path


@contextmanager
def lane():
    """A lane directory no other thread or process is using, for one run."""
    path = None
    while path is None:
        try:
            path = _FREE.get_nowait()
        except queue.Empty:
            path = _new()
        if not path.name.startswith(f"{os.getpid()}_") or not path.is_dir():
            path = None  # a parent's lane (after fork) or removed under us: not ours to use
    try:
        yield path
    finally:
        _FREE.put(path)


def write_table(path: Path, current, n_samples: int, n_neurons: int) -> None:
    """Write the binary's (n_samples, n_neurons) float64 current table: ``current`` with zero padding.

    The lane's file is written through a memory map kept from run to run:
    one strided copy into pages already mapped took about 0.9 ms for a
    hand block (1,000 x 3,146 into 3,168 columns), where padding a copy and
    writing it to the file took 3-5 ms.  Tables of more than `_KEEP_MAPPED`
    elements are unmapped after writing, so a lane holds at most 32 MB
    mapped between runs.  Padded neurons and samples are zeros.
    """
    shape = (int(n_samples), int(n_neurons))
    table = _MAPS.get(path)
    if table is None or table.shape != shape or not path.exists():
        _MAPS.pop(path, None)  # unmapped before the file changes size
        with open(path, "r+b" if path.exists() else "wb") as f:
            f.truncate(shape[0] * shape[1] * 8)
        table = _MAPS[path] = np.memmap(path, dtype=np.float64, mode="r+", shape=shape)
    rows, cols = current.shape
    table[:rows, :cols] = current
    table[:rows, cols:] = 0.0
    table[rows:] = 0.0
    if table.size > _KEEP_MAPPED:  # a long run's table is not held in memory between runs
        del _MAPS[path]
