"""Attenuation factor AF(t) and attenuated force F_A(t) (paper eqs 16-18).

``AF = r(phi) / r(0)``: the NAP boundary radius along the shear direction,
normalised so that AF = 1 when theta_R = theta_T (docs/model.md §1.3).  When the
shear magnitude F_S is at or below F_TH the paper gives two readings of "no
shear" (docs/model.md §1.5), selected by ``no_shear``:

* ``"pass"`` (default, eq. 17): AF = 1, normal loading passes unattenuated.
* ``"block"`` (the Discussion's reading): AF = 0, nothing passes until shear
  appears.
* ``"smooth"`` (ours, the populations' default): AF moves continuously from
  1 to the profile's value as F_S grows through F_TH,
  ``AF = 1 + w(F_S) (AF_profile - 1)`` with the C1 ramp
  ``w = smoothstep(F_S / (2 F_TH))`` (0 at F_S = 0, 1/2 at F_TH, 1 from
  2 F_TH on).  Under eq. 17 F_A steps within one sample when the shear
  crosses F_TH, a strong dynamic stimulus that makes every RA afferent
  burst whatever its tuning; with the ramp F_A is continuous whenever the
  forces are.

The physiological presets add a shear-magnitude term to the pressure types'
F_A (``CurrentParams.<TYPE>.shear``; `ddmm.models.reference_pipeline.shear_drive`): the same signed
stretch, scaled, so tangential force along an afferent's preferred direction
raises its drive and against it lowers it.

SA-II (Ruffini) afferents are driven by skin stretch, from forces the
attenuated *shear* (`ddmm.models.reference_pipeline.stretch_drive`); it needs no threshold, since it
vanishes with F_S.

The conventional model (CMM) is the same pipeline with AF = 1 everywhere:
profile ``"none"``.
"""

from __future__ import annotations

import numba as nb
import numpy as np

from ddmm.models._kernel_options import VECTOR_KERNEL
from ddmm.models.nap import get_profile, radius_scalar, tip_radius, validate_k
from ddmm.utils.validation import as_finite_array, check_choice, check_positive

__all__ = [
    "F_TH",
    "NO_SHEAR_READINGS",
    "UNTUNED",
    "shear_magnitude",
    "attenuation_factor",
    "af_core",
    "transition_weight",
    "blend_no_shear",
    "profile_factor",
]

#: Shear threshold F_TH in newtons below which no direction is defined (eq. 17).
F_TH = 0.1
#: The readings of "no shear": the paper's two (docs/model.md §1.5; eq. 17, "pass", is
#: the default of `models`) and our continuous one ("smooth", the populations' default).
NO_SHEAR_READINGS = ("pass", "block", "smooth")
#: Profile name of an untuned afferent, i.e. the CMM (AF = 1).
UNTUNED = "none"


def shear_magnitude(fx, fy) -> np.ndarray:
    """Resultant shear F_S = sqrt(F_X^2 + F_Y^2) in newtons (eq. 16).

    Examples
    --------
    >>> float(shear_magnitude(3.0, 4.0))
    5.0
    """
    return np.hypot(as_finite_array(fx, "fx"), as_finite_array(fy, "fy"))


def _unique_directions(fx, fy, active):
    """Unit shear vectors of the active samples, deduplicated.

    Scenes usually push in few directions, so the radius is solved once per
    distinct direction and gathered; identical inputs give identical outputs,
    so this is exact.
    """
    mag = np.hypot(fx[active], fy[active])
    unit = np.stack([fx[active] / mag, fy[active] / mag], axis=1)
    uniq, inverse = np.unique(unit, axis=0, return_inverse=True)
    return uniq[:, 0], uniq[:, 1], inverse.ravel()


def attenuation_factor(
    fx,
    fy,
    theta_t,
    profile: str,
    k=3.0,
    *,
    f_th: float = F_TH,
    no_shear: str = "pass",
) -> np.ndarray:
    """Attenuation factor AF for each sample and afferent (eqs 16-17).

    Parameters
    ----------
    fx, fy : array_like, shape (n_samples,)
        Shear force components in newtons; +X radial, +Y distal.
    theta_t : float or array_like, shape (n_afferents,)
        Tuning angles theta_T in degrees (counter-clockwise from +X).
    profile : str
        ``"selective"``, ``"broad"``, ``"bipolar"`` or ``"none"`` (CMM, AF = 1).
    k : float or array_like, shape (n_afferents,)
        Sharpness of eq. 12 (dimensionless), default 3 as in the paper.
    f_th : float
        Shear threshold F_TH in newtons (default 0.1 N, eq. 17).
    no_shear : {"pass", "block", "smooth"}
        AF when F_S <= F_TH: 1 (eq. 17) or 0 (the Discussion's reading), or
        the continuous transition of the module docstring.

    Returns
    -------
    af : ndarray, shape (n_samples, n_afferents)
        Dimensionless AF in [0, 1].

    Examples
    --------
    >>> af = attenuation_factor([0.0, 0.0], [0.05, 1.0], [90.0, 270.0], "selective")
    >>> af.round(3).tolist()
    [[1.0, 1.0], [1.0, 0.2]]
    """
    fx, fy, theta = _check_shear(fx, fy, theta_t)
    f_th = check_positive(f_th, "f_th", "N")
    check_choice(no_shear, "no_shear", NO_SHEAR_READINGS)
    return _factor(fx, fy, theta, profile, k, f_th, no_shear)


def profile_factor(fx, fy, theta_t, profile: str, k=3.0) -> np.ndarray:
    """The profile's own AF, r(phi)/r(0), wherever F_S > 0, with no threshold (1 where F_S = 0).

    SA-II's stretch drive uses it: it is multiplied by F_S, so it needs no
    threshold to vanish at zero shear.  Arguments as `attenuation_factor`.

    Examples
    --------
    >>> profile_factor([0.0, 0.0], [0.0, 0.05], [270.0], "selective").round(3).tolist()
    [[1.0], [0.2]]
    """
    fx, fy, theta = _check_shear(fx, fy, theta_t)
    return _factor(fx, fy, theta, profile, k, 0.0, "raw")


def _check_shear(fx, fy, theta_t):
    fx = as_finite_array(fx, "fx", ndim=1)
    fy = as_finite_array(fy, "fy", ndim=1)
    if fx.shape != fy.shape:
        raise ValueError(f"fx and fy must have equal length; got {fx.size} and {fy.size}")
    theta = np.atleast_1d(as_finite_array(theta_t, "theta_t"))
    if theta.ndim != 1:
        raise ValueError(f"theta_t must be a scalar or 1-D, got shape {theta.shape}")
    return fx, fy, theta


def _factor(fx, fy, theta, profile, k, f_th, mode):
    """AF under ``mode``: "pass", "block", "smooth" or "raw" (the profile wherever F_S > 0)."""
    if profile != UNTUNED:
        prof = get_profile(profile)
        k = np.broadcast_to(validate_k(k, prof), theta.shape)
    mag = shear_magnitude(fx, fy)
    active = mag > (0.0 if mode in ("smooth", "raw") else f_th)
    outside = 0.0 if (mode == "block" and profile != UNTUNED) else 1.0
    af = np.full((fx.size, theta.size), outside)
    if profile == UNTUNED:
        af[active] = 1.0
        return af
    if not np.any(active):
        return af
    ux, uy, inverse = _unique_directions(fx, fy, active)
    rad = np.deg2rad(theta)
    params = (prof.p1, prof.p2, prof.p3, prof.p4, prof.p5)
    profile_af = af_core(ux, uy, np.cos(rad), np.sin(rad), k, params, tip_radius(prof))[inverse]
    if mode == "smooth":
        profile_af = blend_no_shear(profile_af, mag[active], f_th)
    if active.all():  # the usual case: no masked copy
        return profile_af
    af[active] = profile_af
    return af


def transition_weight(f_s, f_th: float = F_TH) -> np.ndarray:
    """Weight w of the profile in the "smooth" reading: smoothstep(F_S / (2 F_TH)).

    0 at F_S = 0, 1/2 at F_TH and 1 from 2 F_TH on, with zero slope at both
    ends (F_S and F_TH in newtons).

    Examples
    --------
    >>> transition_weight([0.0, 0.1, 0.2, 1.0]).tolist()
    [0.0, 0.5, 1.0, 1.0]
    """
    x = np.clip(np.asarray(f_s, dtype=float) / (2.0 * f_th), 0.0, 1.0)
    return x * x * (3.0 - 2.0 * x)


def blend_no_shear(profile_af, f_s, f_th: float = F_TH) -> np.ndarray:
    """AF of the "smooth" reading from the profile's AF (rows: samples) and F_S (N)."""
    w = transition_weight(f_s, f_th)
    out = np.subtract(profile_af, 1.0)
    out *= w[:, None]
    out += 1.0  # = 1 + w (AF - 1), in place: the population's largest temporary
    return out


@nb.njit(cache=True, nogil=True, inline="always")
def profile_value(ux, uy, cos_t, sin_t, k, coeffs, tip):
    """One afferent's profile AF for the unit shear vector (ux, uy): the scalar `_af_kernel` and the
    fused streaming kernel share.  ``coeffs`` is the profile's (p1, p2, p3, p4, p5)."""
    p1, p2, p3, p4, p5 = coeffs
    cos_phi = ux * cos_t + uy * sin_t
    sin_phi = uy * cos_t - ux * sin_t
    r = radius_scalar(sin_phi, cos_phi, k, p1, p2, p3, p4, p5) / tip
    # For k < 1 (theta_A > 90 deg with b = 1) a profile is wider than its
    # tip is long, so r(phi) > r(0) off-axis; AF saturates at 1.
    return min(r, 1.0)


@nb.njit(**VECTOR_KERNEL)
def _af_kernel(ux, uy, cos_t, sin_t, k, coeffs, tip):
    """AF (n_directions, n_afferents); ``coeffs`` holds the per-afferent arrays p1..p5."""
    p1, p2, p3, p4, p5 = coeffs
    out = np.empty((ux.size, cos_t.size))
    for i in range(ux.size):
        for j in range(cos_t.size):
            out[i, j] = profile_value(ux[i], uy[i], cos_t[j], sin_t[j], k[j], (p1[j], p2[j], p3[j], p4[j], p5[j]),
                                      tip[j])
    return out


def af_core(ux, uy, cos_t, sin_t, k, params, tip) -> np.ndarray:
    """AF, shape (n_directions, n_afferents), for unit shear vectors (ux, uy); no validation.

    ``cos_t``, ``sin_t`` give each afferent's tip direction, ``k`` its
    sharpness, ``params`` p1..p5 and ``tip`` the tip radius (scalars or
    per-afferent arrays).  The one implementation offline and streaming share.
    """
    ux, uy = np.ravel(ux).astype(float), np.ravel(uy).astype(float)
    n = np.size(cos_t)
    per = [np.ascontiguousarray(np.broadcast_to(np.asarray(x, dtype=float), (n,))) for x in (k, *params, tip)]
    return _af_kernel(ux, uy, np.ravel(cos_t).astype(float), np.ravel(sin_t).astype(float), per[0], tuple(per[1:6]),
                      per[6])


_MOVED = ("attenuated_force", "shear_drive", "stretch_drive")  # to the reference oracle, for one release


def __getattr__(name):
    if name in _MOVED:
        from ddmm.models import reference_pipeline
        from ddmm.utils.deprecation import warn_renamed

        warn_renamed(f"ddmm.models.attenuation.{name}", f"ddmm.models.reference_pipeline.{name}")
        return getattr(reference_pipeline, name)
    raise AttributeError(f"module {__name__!r} has no attribute {name!r}")
