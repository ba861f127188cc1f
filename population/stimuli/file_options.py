"""The choices a recorded force file's reader takes, in a module with no imports.

`from_csv` and the sensor-array readers use them; the command line names them in its help without
loading the stack (``ddmm --help`` imports no numba, scipy or xarray).
"""

__all__ = ["UNITS", "NEGATIVE_FZ", "GAPS", "TIME_UNITS", "MAX_FORCE_N"]

#: Force units a file may be in, and their value in newtons.
UNITS = {"N": 1.0, "mN": 1e-3, "gf": 9.80665e-3, "kgf": 9.80665, "lbf": 4.4482216152605}
#: What to do with a negative normal force beyond sensor noise.
NEGATIVE_FZ = ("error", "clip", "offset")
#: What to do with a gap in the time column.
GAPS = ("error", "interpolate")
#: Time units a header may name, in seconds.
TIME_UNITS = {"s": 1.0, "sec": 1.0, "ms": 1e-3, "us": 1e-6, "µs": 1e-6}
#: The largest force a recording or a stream may carry at one site, in N (the magnitude of its F_X, F_Y, F_Z),
#: unless the reader is given a larger ``max_force_n`` (``--max-force``).  A whole hand's maximal grip is a few
#: hundred newtons: beyond this bound a file is read in the wrong unit (mN as kgf, say), not touched.
MAX_FORCE_N = 1000.0
