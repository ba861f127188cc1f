"""Atomic file writes shared by datasets, exports and the CLI's outputs: no half-written file."""

from __future__ import annotations

import os
import re
import socket
import tempfile
from numbers import Number
from pathlib import Path

import numpy as np

from ddmm.utils.validation import check_path

__all__ = ["atomic_write", "writable_parent", "sweep_stale_parts", "write_netcdf", "read_netcdf"]


def _umask_mode() -> int:
    """Mode a plain ``open(..., "w")`` would give: 0o666 minus the umask."""
    mask = os.umask(0)
    os.umask(mask)
    return 0o666 & ~mask


def writable_parent(path) -> tuple[Path, bool]:
    """``(directory of path, whether it exists and can be written)``: the check before an atomic write."""
    directory = Path(path).parent if str(Path(path).parent) else Path(".")
    return directory, directory.is_dir() and os.access(directory, os.W_OK)


def _tag() -> str:
    """The part of a temporary file's name that says which process on which host writes it."""
    host = re.sub(r"[^A-Za-z0-9_.]", "_", socket.gethostname()) or "host"
    return f".ddmm-{host}-{os.getpid()}-"


def _alive(pid: int) -> bool:
    try:
        os.kill(pid, 0)
    except ProcessLookupError:
        return False
    except PermissionError:  # another user's live process
        return True
    return True


def sweep_stale_parts(directory) -> list[Path]:
    """Remove temporary files in ``directory`` left by writers of this host that no longer run (a SIGKILL).

    Only names `atomic_write` makes, with this host's name and a process id
    that is gone, are removed; another host's or a live writer's are kept.
    """
    host = _tag().split("-")[1]
    pattern = re.compile(rf"^\..+\.ddmm-{re.escape(host)}-(\d+)-")
    removed = []
    for entry in Path(directory).iterdir():
        match = pattern.match(entry.name)
        if match and entry.is_file() and not _alive(int(match.group(1))):
            try:
                entry.unlink()
                removed.append(entry)
            except OSError:  # raced with another sweeper, or not ours to remove
                pass
    return removed


def _fsync(path, directory: bool = False) -> None:
    fd = os.open(path, os.O_RDONLY | (getattr(os, "O_DIRECTORY", 0) if directory else 0))
    try:
        os.fsync(fd)
    finally:
        os.close(fd)


def atomic_write(path, write, *, suffix: str = ".part") -> Path:
    """Call ``write(tmp_path)`` then rename the temporary file onto ``path``.

    The temporary file lives in the target's directory, so the rename is
    atomic; it is flushed to disk (fsync) before the rename and the directory
    after it; on any error it is removed and ``path`` is left untouched.  A
    writer killed outright (SIGKILL) cannot clean up: its file, whose name
    carries the host and process id, is swept by the next write into the same
    directory (`sweep_stale_parts`).  The file gets the usual permissions
    (``mkstemp`` would leave it owner-only).  ``suffix`` ends the temporary
    name (a writer may insist on an extension).
    """
    path = check_path(path)
    directory = path.parent if str(path.parent) else Path(".")
    sweep_stale_parts(directory)
    fd, tmp = tempfile.mkstemp(dir=directory, prefix=f".{path.name}{_tag()}", suffix=suffix)
    os.close(fd)
    try:
        write(tmp)
        os.chmod(tmp, _umask_mode())
        _fsync(tmp)
        os.replace(tmp, path)
    except BaseException:
        if os.path.exists(tmp):
            os.unlink(tmp)
        raise
    try:
        _fsync(directory, directory=True)
    except OSError:  # some file systems cannot sync a directory; the rename itself has happened
        pass
    return path


def write_netcdf(ds, path) -> Path:
    """Write an xarray Dataset to netCDF-4 (HDF5) atomically; a directory that cannot be written is a ValueError."""
    path = check_path(path)
    directory, writable = writable_parent(path)
    if not writable:
        raise ValueError(f"cannot write {str(path)!r}: {str(directory)!r} is not a writable directory")
    return atomic_write(path, lambda tmp: _to_netcdf4(ds, tmp))


def _to_netcdf4(ds, path) -> None:
    """``ds.to_netcdf(path, engine="h5netcdf")``: the same bytes, without asking Dask for its scheduler.

    ``to_netcdf`` asks an installed Dask which scheduler runs (to choose a
    file lock), which imports ``dask.distributed``: 0.15-0.25 s of a cold
    ``ddmm simulate``.  A store on an open h5netcdf file takes xarray's HDF5
    lock without asking, and `xarray.Dataset.dump_to_store` is the encoding
    and writing ``to_netcdf`` runs.  A Dataset ``to_netcdf`` would refuse or
    compute (see `_plain`) goes through ``to_netcdf`` itself.
    """
    if not _plain(ds):
        ds.to_netcdf(path, engine="h5netcdf")
        return
    import h5netcdf
    from xarray.backends import H5NetCDFStore

    with h5netcdf.File(path, "w") as file:
        ds.dump_to_store(H5NetCDFStore(file))


def _plain(ds) -> bool:
    """Whether ``ds`` passes ``to_netcdf``'s checks of names and attrs as it is (non-empty string names,
    values strings or numbers) and has nothing it would compute or declare first (Dask chunks, unlimited
    dimensions)."""
    def plain_attrs(attrs) -> bool:
        return all(isinstance(k, str) and k and isinstance(v, (str, Number, np.number)) for k, v in attrs.items())

    return (not ds.encoding.get("unlimited_dims") and plain_attrs(ds.attrs)
            and all(isinstance(name, str) and name and var.chunks is None and plain_attrs(var.attrs)
                    for name, var in ds.variables.items()))


def read_netcdf(path, what: str):
    """Read a netCDF-4 file fully into memory; a missing or unreadable file is a ValueError naming ``what``."""
    import xarray as xr

    path = check_path(path)
    if not path.is_file():
        raise ValueError(f"{what} {str(path)!r} does not exist")
    try:
        return xr.load_dataset(path, engine="h5netcdf")
    except (OSError, ValueError) as exc:
        reason = " ".join(str(exc).split())
        raise ValueError(f"{what} {str(path)!r} is not a netCDF-4 file ddmm can read ({reason})") from None
