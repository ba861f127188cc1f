"""Neural attenuation profiles (NAPs): geometry of paper Table I and eqs 9-12.

A NAP is the closed curve of eq. 9 in the shear plane,

    p1 * (|k X| + |p2 Y - p3| - p4) - p5 Y = 0,

rotated so that its tip points at the tuning angle theta_T (docs/model.md §1.1:
the paper's eqs 10-11 put the tip on the rotated Y axis, its text puts the
tip at theta_T).  Along a ray at angle phi from the tip axis, X = r sin(phi)
and Y = r cos(phi), so eq. 9 is piecewise *linear* in the radius r and each
piece is solved exactly (`boundary_radius`).  Eq. 8's F_Y/F_X is never used:
it divides by zero for the most common push direction, F_X = 0.

Angles are radians here; the public population API speaks degrees.
"""

from __future__ import annotations

from dataclasses import dataclass
from functools import lru_cache

import numba as nb
import numpy as np

from ddmm.utils.validation import as_finite_array, as_float_array

__all__ = [
    "NAPProfile",
    "PROFILES",
    "PROFILE_NAMES",
    "get_profile",
    "validate_k",
    "k_from_selectivity",
    "selectivity_from_k",
    "boundary_radius",
    "radius_core",
    "radius_scalar",
    "tip_radius",
]


@dataclass(frozen=True)
class NAPProfile:
    """Parameters of one neural attenuation profile (paper Table I).

    Attributes
    ----------
    name : str
        ``"selective"``, ``"broad"`` or ``"bipolar"``.
    p1, p2, p3, p4, p5 : float
        Shape parameters of eq. 9 (dimensionless), Table I.
    b : float
        Aspect constant of eq. 12, ``k = b / tan(theta_A / 2)``.  b = 1 for
        the bipolar and selective profiles and b = 3 for the broad one, so the
        drawn tip half-angle equals theta_A / 2 (docs/model.md §1.4).
    k_min : float
        Smallest admissible sharpness k (Table I footnote: broad needs
        k >= 1.8); 0 means any k > 0.
    """

    name: str
    p1: float
    p2: float
    p3: float
    p4: float
    p5: float
    b: float
    k_min: float = 0.0


#: Table I of the paper, with the eq. 12 aspect constants of docs/model.md §1.4.
PROFILES: dict[str, NAPProfile] = {
    "bipolar": NAPProfile("bipolar", 1.0, 1.0, 0.0, 1.0, 0.0, b=1.0),
    "selective": NAPProfile("selective", 1.0, 2.0, 0.2, 0.8, 1.0, b=1.0),
    "broad": NAPProfile("broad", -1.0, 2.0, 1.2, 1.4, 1.0, b=3.0, k_min=1.8),
}
PROFILE_NAMES: tuple[str, ...] = tuple(PROFILES)


def get_profile(profile: str | NAPProfile) -> NAPProfile:
    """Return the `NAPProfile` named ``profile``.

    Parameters
    ----------
    profile : str or NAPProfile
        ``"selective"``, ``"broad"`` or ``"bipolar"`` (or a profile, returned
        unchanged).

    Raises
    ------
    ValueError
        If the name is unknown.

    Examples
    --------
    >>> get_profile("broad").k_min
    1.8
    """
    if isinstance(profile, NAPProfile):
        return profile
    if not isinstance(profile, str):
        raise TypeError(f"profile must be a str, got {type(profile).__name__}")
    try:
        return PROFILES[profile]
    except KeyError:
        raise ValueError(
            f"profile={profile!r} is unknown; allowed: {', '.join(PROFILE_NAMES)}"
        ) from None


def validate_k(k, profile: str | NAPProfile) -> np.ndarray:
    """Check sharpness values ``k`` for ``profile`` and return them as floats.

    Raises
    ------
    ValueError
        If any k is not finite, is <= 0, or (broad) is below 1.8.
    """
    prof = get_profile(profile)
    k = as_float_array(k, "k")
    bad = ~np.isfinite(k) | (k <= 0.0) | (k < prof.k_min)
    if np.any(bad):
        first = k[bad].flat[0]
        need = f">= {prof.k_min}" if prof.k_min > 0 else "> 0"
        raise ValueError(
            f"k={float(first)!r} is not allowed for the {prof.name} profile; k must be finite and {need}"
        )
    return k


def k_from_selectivity(theta_a_deg, profile: str | NAPProfile):
    """Sharpness k from the selectivity range theta_A (paper eq. 12).

    ``k = b / tan(theta_A / 2)`` with the profile's aspect constant b.

    Parameters
    ----------
    theta_a_deg : float or array_like
        Selectivity range theta_A in degrees, strictly inside (0, 180).
    profile : str or NAPProfile
        Profile whose b to use.

    Returns
    -------
    k : float or ndarray
        Dimensionless sharpness.

    Raises
    ------
    ValueError
        If theta_A is outside (0, 180) degrees, or gives a broad k < 1.8.

    Examples
    --------
    >>> round(float(k_from_selectivity(36.87, "selective")), 3)
    3.0
    """
    prof = get_profile(profile)
    theta = as_float_array(theta_a_deg, "theta_a_deg")
    bad = ~np.isfinite(theta) | (theta <= 0.0) | (theta >= 180.0)
    if np.any(bad):
        raise ValueError(
            f"theta_a_deg={float(theta[bad].flat[0])!r} deg is outside the open interval (0, 180) deg"
        )
    k = prof.b / np.tan(np.deg2rad(theta) / 2.0)
    validate_k(k, prof)
    return k[()] if k.ndim == 0 else k


def selectivity_from_k(k, profile: str | NAPProfile):
    """Selectivity range theta_A in degrees from k (inverse of eq. 12).

    Examples
    --------
    >>> round(float(selectivity_from_k(3.0, "broad")), 1)
    90.0
    """
    prof = get_profile(profile)
    k = validate_k(k, prof)
    theta = np.rad2deg(2.0 * np.arctan(prof.b / k))
    return theta[()] if theta.ndim == 0 else theta


def boundary_radius(sin_phi, cos_phi, profile: str | NAPProfile, k) -> np.ndarray:
    """Radius of the NAP boundary along rays at angle phi from the tip axis.

    Closed form of eq. 9 (docs/model.md §1.2).  With ``s = |sin phi|`` and
    ``c = cos phi`` the two linear pieces are

    * ``p2 c r >= p3``:  ``r = p1 (p3 + p4) / (p1 k s + p1 p2 c - p5 c)``
    * ``p2 c r <  p3``:  ``r = p1 (p4 - p3) / (p1 k s - p1 p2 c - p5 c)``

    and the smallest positive root that satisfies its own piece's condition is
    the boundary seen from the origin.  Inputs broadcast against each other
    (e.g. samples ``(T, 1)`` against afferents ``(1, N)``).

    Parameters
    ----------
    sin_phi, cos_phi : array_like
        Sine and cosine of phi = theta_R - theta_T (dimensionless).  Passing
        them, not phi, lets callers build them from force components without
        any trigonometry or division by F_X.
    profile : str or NAPProfile
        The profile.
    k : float or array_like
        Sharpness (dimensionless), validated by `validate_k`.

    Returns
    -------
    r : ndarray
        Boundary radius in the profile's normalised units (> 0, finite).

    Examples
    --------
    >>> phi = np.deg2rad(90.0)
    >>> round(float(boundary_radius(np.sin(phi), np.cos(phi), "bipolar", 3.0)), 3)
    0.333
    """
    prof = get_profile(profile)
    k = validate_k(k, prof)
    r = _radius_ufunc()(as_finite_array(sin_phi, "sin_phi"), as_finite_array(cos_phi, "cos_phi"), k,
                        prof.p1, prof.p2, prof.p3, prof.p4, prof.p5)
    if not np.all(np.isfinite(r)):  # pragma: no cover - geometry guarantees a root
        raise FloatingPointError(f"no boundary root for the {prof.name} profile")
    return r


def _radius(sin_phi, cos_phi, k, p1, p2, p3, p4, p5):
    """The closed form of eq. 9 along one ray (scalars); see `boundary_radius`.

    The one implementation: compiled as the scalar `radius_scalar` (used by
    the attenuation kernel) and as the ufunc `radius_core`, so every path
    does the same arithmetic.  A piece whose denominator is 0 has no root.
    """
    s = abs(sin_phi)
    ks = k * s
    d_hi = p1 * ks + (p1 * p2 - p5) * cos_phi
    d_lo = p1 * ks - (p1 * p2 + p5) * cos_phi
    r = np.inf
    if d_hi != 0.0:
        r_hi = p1 * (p3 + p4) / d_hi
        if np.isfinite(r_hi) and r_hi > 0.0 and p2 * cos_phi * r_hi >= p3:
            r = r_hi
    if d_lo != 0.0:
        r_lo = p1 * (p4 - p3) / d_lo
        if np.isfinite(r_lo) and r_lo > 0.0 and p2 * cos_phi * r_lo < p3 and r_lo < r:
            r = r_lo
    return r


radius_scalar = nb.njit(cache=True, nogil=True)(_radius)


@lru_cache(maxsize=1)
def _radius_ufunc():
    """`_radius` as a ufunc, built on first use (building it costs 0.2 s of every start otherwise)."""
    return nb.vectorize(["float64(float64, float64, float64, float64, float64, float64, float64, float64)"],
                        cache=True)(_radius)


def __getattr__(name):
    """``radius_core``: `boundary_radius` without validation, as a ufunc (profile parameters broadcast)."""
    if name == "radius_core":
        return _radius_ufunc()
    raise AttributeError(f"module {__name__!r} has no attribute {name!r}")


def tip_radius(profile: str | NAPProfile) -> float:
    """Boundary radius at the tip (phi = 0): 1 for bipolar and selective, 13/15 for broad.

    AF is normalised by this value so that AF = 1 at alignment (docs/model.md §1.3).

    Examples
    --------
    >>> round(tip_radius("broad"), 4)
    0.8667
    """
    prof = get_profile(profile)
    return _tip_radius(prof.p1, prof.p2, prof.p3, prof.p4, prof.p5, max(prof.k_min, 1.0))


@lru_cache(maxsize=16)
def _tip_radius(p1, p2, p3, p4, p5, k) -> float:
    return float(radius_scalar(0.0, 1.0, k, p1, p2, p3, p4, p5))  # the same arithmetic as the ufunc
