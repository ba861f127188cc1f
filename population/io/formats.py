"""The sensor-array file formats `from_array` and `save_array` read and write, by extension.

A module of its own, with no imports, so the command line can name them in its help without loading
the stack.
"""

__all__ = ["EXTENSIONS"]

#: Extension -> format of a sensor-array file.
EXTENSIONS = {".npz": "npz", ".nc": "netcdf", ".h5": "hdf5", ".hdf5": "hdf5"}
