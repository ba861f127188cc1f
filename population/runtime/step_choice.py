"""Choosing (dt, method) for an accuracy tolerance, from a measured table.

``ddmm accuracy --write-table`` measures, for every dt and method, the mean
SF error (pulses/s) against the reference solver and the wall time per
afferent-second, and stores the direct engine's rows in
``population/data/accuracy_table.json``.  `choose_setting` returns the
cheapest row within the tolerance whose dt divides the scene's sample
interval, where cost is the integration work (right-hand-side evaluations
per ms: stages / dt), with ties going to the smaller error.  Wall times at
the table's workload size are dominated by the shared pipeline and too noisy
to rank settings whose integration work is close.
"""

from __future__ import annotations

import json
from functools import lru_cache
from importlib import resources

from ddmm.utils.validation import check_positive

__all__ = ["load_table", "choose_setting"]


@lru_cache(maxsize=1)
def load_table() -> tuple:
    """The shipped accuracy table (rows of dt_ms, method, sf_err_mean, sf_err_max, wall time)."""
    text = resources.files("ddmm.population").joinpath("data", "accuracy_table.json").read_text()
    return tuple(json.loads(text)["rows"])


def choose_setting(tolerance: float, fs: float) -> dict:
    """Cheapest table row with ``sf_err_mean <= tolerance`` whose dt divides ``1/fs``.

    Parameters
    ----------
    tolerance : float
        Largest acceptable mean SF error in pulses/s.
    fs : float
        Sample rate of the scenes in Hz.

    Returns
    -------
    dict
        The chosen row (``dt_ms``, ``method``, ``sf_err_mean``, ...).

    Raises
    ------
    ValueError
        If no measured setting meets the tolerance.

    Examples
    --------
    >>> choose_setting(1e6, 1000.0)["dt_ms"] >= 0.01
    True
    """
    tolerance = check_positive(tolerance, "tolerance", "pulses/s")
    fs = check_positive(fs, "fs", "Hz")
    rows = [r for r in load_table() if abs(round(1.0 / (fs * r["dt_ms"] * 1e-3)) * r["dt_ms"] * 1e-3 * fs - 1.0) < 1e-9]
    ok = [r for r in rows if r["sf_err_mean"] <= tolerance]
    if not ok:
        best = min(rows, key=lambda r: r["sf_err_mean"])
        raise ValueError(f"tolerance={tolerance!r} pulses/s: no measured setting meets it; the most accurate, "
                         f"dt={best['dt_ms']} ms with {best['method']}, has a mean SF error of "
                         f"{best['sf_err_mean']:.3g} pulses/s")
    return dict(min(ok, key=lambda r: (r["evals_per_ms"], r["sf_err_mean"])))
