"""Helpers shared by every layer of the package: argument checks, memory, threads, files, caches, extras.

This is the one place where code used across `ddmm.models`, `ddmm.population`
and `ddmm.experiments` lives; each name here is public and documented, so no
package reaches into another's private modules.  It sits below `models` and
imports nothing else of ddmm.

- `validation`: checks at the public boundary (`check_positive`,
  `check_choice`, `parse_number`, ...) and `shown`, a number as messages print it;
- `resources`: `check_memory`, a clear refusal before a large allocation;
- `executors`: `shared_executor`, one thread pool per name and process;
- `files`: `atomic_write` and the netCDF helpers: no half-written file;
- `cache`: `cache_root`, the on-disk cache of Brian2 builds and designed filters;
- `extras`: `require` and `MissingExtraError` for optional dependencies;
- `lazy`: `lazy_exports`, the PEP 562 names every package ``__init__`` uses;
- `deprecation`: `renamed_keyword`, an old keyword accepted for one release with a warning.
"""

from ddmm.utils.lazy import lazy_exports

_WHERE = {
    "validation": ("as_finite_array", "check_choice", "check_forces", "check_positive", "parse_number", "shown"),
    "resources": ("MEMORY_ENV", "available_bytes", "check_memory", "format_bytes", "resident_bytes"),
    "executors": ("shared_executor",),
    "files": ("atomic_write", "read_netcdf", "sweep_stale_parts", "writable_parent", "write_netcdf"),
    "cache": ("cache_root", "private_dir"),
    "extras": ("MissingExtraError", "require"),
    "deprecation": ("renamed_keyword",),
    "lazy": ("lazy_exports",),
}
__all__, __getattr__, __dir__ = lazy_exports(__name__, _WHERE)
