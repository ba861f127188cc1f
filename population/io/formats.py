"""The sensor-array file formats `from_array` and `save_array` read and write, by extension.

A module of its own, with no imports, so the command line can name them in its help without loading
the stack.
"""

__all__ = ["EXTENSIONS", "array_format"]

#: Extension -> format of a sensor-array file.
EXTENSIONS = {".npz": "npz", ".nc": "netcdf", ".h5": "hdf5", ".hdf5": "hdf5"}


def array_format(path) -> str:
    """The format of a sensor-array file, from its extension (any case).

    Raises
    ------
    ValueError
        For an extension not in `EXTENSIONS`, naming the file and the allowed ones.

    Examples
    --------
    >>> array_format("pad.H5")
    'hdf5'
    """
    import os  # the standard library only: this module stays free of the stack

    suffix = os.path.splitext(str(path))[1].lower()
    if suffix not in EXTENSIONS:
        raise ValueError(f"array file {str(path)!r}: unknown extension {suffix or '(none)'!r}; "
                         f"allowed: {', '.join(EXTENSIONS)}")
    return EXTENSIONS[suffix]
