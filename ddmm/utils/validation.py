"""Argument checks shared by the public functions of every ddmm package (raise, never assert)."""

from __future__ import annotations

import numbers
import os
import re
from pathlib import Path

import numpy as np

__all__ = ["as_float_array", "as_finite_array", "check_positive", "check_real", "check_nonnegative", "check_count",
           "check_flag", "check_choice", "check_instance", "check_dataset", "check_path", "check_rng", "check_forces",
           "parse_number", "shown"]


def shown(value) -> str:
    """A value as a message prints it: numbers plainly (``0.5``, not ``np.float64(0.5)``), anything else by repr.

    Examples
    --------
    >>> shown(np.float64(0.5)), shown(np.int64(3)), shown("x"), shown(float("nan"))
    ('0.5', '3', "'x'", 'nan')
    """
    if isinstance(value, (bool, np.bool_)) or not isinstance(value, (numbers.Number, np.number)):
        return repr(value)
    if isinstance(value, (numbers.Integral, np.integer)):
        return str(int(value))
    if isinstance(value, (numbers.Real, np.floating)):
        return repr(float(value))
    return repr(value)


def as_float_array(value, name: str, ndim: int | None = None) -> np.ndarray:
    """Return ``value`` as a float64 array (no copy of one), naming ``name`` when it is not numeric.

    Unlike `as_finite_array` it does not scan for NaN: for large arrays a
    caller has already checked.

    Raises
    ------
    TypeError
        If ``value`` is None, text or otherwise not numeric.
    ValueError
        If it has the wrong number of dimensions.

    Examples
    --------
    >>> as_float_array([1, 2], "fz").tolist()
    [1.0, 2.0]
    >>> as_float_array("x", "fz")
    Traceback (most recent call last):
    TypeError: fz must be numeric, got str
    """
    try:
        arr = np.asarray(value, dtype=float) if value is not None else None
    except (TypeError, ValueError):
        arr = None
    if arr is None:
        raise TypeError(f"{name} must be numeric, got {type(value).__name__}")
    if ndim is not None and arr.ndim != ndim:
        raise ValueError(f"{name} must be {ndim}-D, got shape {arr.shape}")
    return arr


def as_finite_array(value, name: str, ndim: int | None = None) -> np.ndarray:
    """Return ``value`` as a float64 array, raising if it holds NaN or inf.

    Raises
    ------
    TypeError
        If ``value`` is not numeric.
    ValueError
        If it has the wrong number of dimensions or a non-finite entry.
    """
    arr = as_float_array(value, name, ndim)
    if not np.all(np.isfinite(arr)):
        bad = int(np.flatnonzero(~np.isfinite(arr.ravel()))[0])
        raise ValueError(
            f"{name} must be finite; got {float(arr.ravel()[bad])} at flat index {bad}"
        )
    return arr


def check_positive(value, name: str, unit: str = "") -> float:
    """Return ``value`` as a float after checking it is finite and > 0."""
    if isinstance(value, bool) or not isinstance(value, numbers.Real):
        raise TypeError(f"{name} must be a real number, got {type(value).__name__}")
    value = float(value)
    if not np.isfinite(value) or value <= 0.0:
        suffix = f" {unit}" if unit else ""
        raise ValueError(f"{name} must be a finite number > 0{suffix}, got {shown(value)}")
    return value


def check_real(value, name: str, unit: str = "") -> float:
    """Return ``value`` as a float after checking it is a finite real number (of any sign).

    Examples
    --------
    >>> check_real(np.float64(-2.5), "start_deg")
    -2.5
    >>> check_real("up", "start_deg")
    Traceback (most recent call last):
    TypeError: start_deg must be a real number, got str
    """
    if isinstance(value, (bool, np.bool_)) or not isinstance(value, numbers.Real):
        raise TypeError(f"{name} must be a real number, got {type(value).__name__}")
    if not np.isfinite(value):
        raise ValueError(f"{name} must be a finite number{f' of {unit}' if unit else ''}, got {shown(value)}")
    return float(value)


def check_nonnegative(value, name: str, unit: str = "") -> float:
    """Return ``value`` as a float after checking it is finite and >= 0."""
    value = check_real(value, name, unit)
    if value < 0.0:
        raise ValueError(f"{name} must be a finite number >= 0{f' {unit}' if unit else ''}, got {shown(value)}")
    return value


def check_count(value, name: str, minimum: int = 1) -> int:
    """Return ``value`` as an int after checking it is an integer >= ``minimum``.

    Examples
    --------
    >>> check_count(np.int64(3), "trials")
    3
    >>> check_count(0, "trials")
    Traceback (most recent call last):
    ValueError: trials must be an integer >= 1, got 0
    """
    if isinstance(value, (bool, np.bool_)) or not isinstance(value, numbers.Integral):
        raise TypeError(f"{name} must be an integer, got {type(value).__name__} {shown(value)}")
    if value < minimum:
        raise ValueError(f"{name} must be an integer >= {minimum}, got {shown(value)}")
    return int(value)


def check_instance(value, name: str, kind, what: str):
    """Return ``value`` if it is an instance of ``kind``; TypeError saying ``what`` is allowed otherwise."""
    if not isinstance(value, kind):
        raise TypeError(f"{name} must be {what}, got {type(value).__name__}")
    return value


def check_flag(value, name: str) -> bool:
    """Return ``value`` as a bool if it is True or False (numpy's too); TypeError naming it otherwise.

    Examples
    --------
    >>> check_flag(True, "friction")
    True
    """
    if not isinstance(value, (bool, np.bool_)):
        raise TypeError(f"{name} must be True or False, got {type(value).__name__} {shown(value)}")
    return bool(value)


def check_dataset(value, name: str = "ds"):
    """Return ``value`` if it is an `xarray.Dataset` (a run of `ddmm.population.simulate`); TypeError otherwise."""
    import xarray as xr

    return check_instance(value, name, xr.Dataset, "an xarray.Dataset (e.g. from simulate or load_dataset)")


def check_path(value, name: str = "path") -> Path:
    """Return ``value`` as a `Path` after checking it is a non-empty str or os.PathLike.

    An int would otherwise reach ``open`` as a file descriptor (reading, then
    closing, whatever the process has open there).

    Examples
    --------
    >>> check_path("run.nc").name
    'run.nc'
    >>> check_path(5)
    Traceback (most recent call last):
    TypeError: path must be a file path (str or os.PathLike), got int
    """
    if not isinstance(value, (str, os.PathLike)):
        raise TypeError(f"{name} must be a file path (str or os.PathLike), got {type(value).__name__}")
    if not os.fspath(value):
        raise ValueError(f"{name} must be a file path, got an empty string")
    return Path(value)


def check_rng(value, name: str = "rng") -> np.random.Generator:
    """``numpy.random.default_rng(value)``, its refusal naming ``name`` (a Generator, an int seed >= 0 or None)."""
    allowed = "a numpy.random.Generator, an integer seed >= 0 or None"
    try:
        return np.random.default_rng(value)
    except TypeError:
        raise TypeError(f"{name} must be {allowed}, got {type(value).__name__}") from None
    except ValueError:
        raise ValueError(f"{name} must be {allowed}, got {shown(value)}") from None


def check_choice(value, name: str, allowed) -> str:
    """Return ``value`` if it is one of ``allowed``; raise otherwise."""
    if not isinstance(value, str):
        raise TypeError(f"{name} must be a str, got {type(value).__name__}")
    if value not in allowed:
        raise ValueError(f"{name}={value!r} is not allowed; allowed: {', '.join(allowed)}")
    return value


def check_forces(fx, fy, fz) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """Validate three force components in newtons (1-D, equal length, finite, F_Z >= 0)."""
    fx = as_finite_array(fx, "fx", ndim=1)
    fy = as_finite_array(fy, "fy", ndim=1)
    fz = as_finite_array(fz, "fz", ndim=1)
    if not (fx.shape == fy.shape == fz.shape):
        raise ValueError(
            f"fx, fy and fz must have equal length; got {fx.size}, {fy.size} and {fz.size}"
        )
    if fx.size == 0:
        raise ValueError("fx, fy and fz must hold at least one sample, got 0")
    if np.any(fz < 0.0):
        bad = int(np.flatnonzero(fz < 0.0)[0])
        raise ValueError(
            f"fz must be >= 0 N (compressive normal force); got {fz[bad]!r} at index {bad}"
        )
    return fx, fy, fz


_NUMBER = re.compile(r"[+-]?(\d+\.?\d*|\.\d+)([eE][+-]?\d+)?|[+-]?(inf|infinity|nan)", re.IGNORECASE)


def parse_number(text: str) -> float:
    """A decimal number written in a text file: ``float`` without its Python-only forms.

    ``float`` also takes ``"1_0"`` (10.0) and surrounding whitespace of any
    kind; a data file means neither.  Raises ValueError; ``inf`` and ``nan``
    parse (callers check finiteness with their own message).

    Examples
    --------
    >>> parse_number(" 1.5e-3 "), parse_number("-2")
    (0.0015, -2.0)
    """
    stripped = text.strip(" \t")
    if not _NUMBER.fullmatch(stripped):
        raise ValueError(f"{text!r} is not a number")
    return float(stripped)
