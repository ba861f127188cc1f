"""Files in and out: sensor-array recordings, NWB and Neo.

- `arrays`: multi-site force recordings from NPZ, netCDF, HDF5 or a long CSV;
- `xdf`: a force stream of a recorded LSL session (LabRecorder's XDF), read as live (``ddmm[xdf]``);
- `xdf_writer`: a force stream written as LabRecorder records one (`save_xdf`);
- `nwb`: a Dataset to an NWB file (``ddmm[nwb]``);
- `neo_export`: a Dataset to a Neo Block (``ddmm[neo]``).

A Dataset's own netCDF round trip is `ddmm.population.dataset`.
"""

from ddmm.utils.lazy import lazy_exports

_WHERE = {
    "arrays": ("from_array", "from_long_csv"),
    "array_writers": ("save_array",),
    "_long_csv": ("read_sites_csv",),
    "xdf": ("from_xdf", "read_xdf", "XdfRecording", "XdfStampWarning"),
    "xdf_writer": ("save_xdf",),
    "nwb": ("to_nwb",),
    "neo_export": ("to_neo",),
    "brian2_export": ("to_brian2",),
}
__all__, __getattr__, __dir__ = lazy_exports(__name__, _WHERE)
