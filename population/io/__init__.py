"""Files in and out: sensor-array recordings, NWB and Neo.

- `arrays`: multi-site force recordings from NPZ, netCDF, HDF5 or a long CSV;
- `nwb`: a Dataset to an NWB file (``ddmm[nwb]``);
- `neo_export`: a Dataset to a Neo Block (``ddmm[neo]``).

A Dataset's own netCDF round trip is `ddmm.population.dataset`.
"""

from ddmm.utils.lazy import lazy_exports

_WHERE = {
    "arrays": ("from_array", "from_long_csv"),
    "array_writers": ("save_array",),
    "_long_csv": ("read_sites_csv",),
    "nwb": ("to_nwb",),
    "neo_export": ("to_neo",),
    "brian2_export": ("to_brian2",),
}
__all__, __getattr__, __dir__ = lazy_exports(__name__, _WHERE)
