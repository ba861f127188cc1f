"""Skin contact mechanics: rigid flat-ended pins indenting an elastic half-space.

The skin is a linear elastic half-space (Young's modulus E, Poisson's ratio
nu).  Rigid cylindrical pins of radius a (mm) at (x, y) mm are pressed into
it by a depth (mm, >= 0 into the skin).  The stage solves, per sample, the
normal load (N) each pin in contact carries (a pin cannot pull), the normal
stress sigma_z (Pa, positive in compression) at receptor depth, its dynamic
component, and Coulomb stick-and-slip tangential loads (N) for pins moved
sideways.  Two skins are named in `SKIN_MODELS`: ``"touchsim"`` (TouchSim's
constants and approximations) and ``"default"``.

Sources: Sneddon IN (1946) Boussinesq's problem for a flat-ended cylinder,
Proc. Camb. Phil. Soc. 42:29-39 (the punch's compliance and stress field);
Johnson KL (1985) Contact Mechanics, Cambridge University Press, ch. 3
(recalled); Saal HP, Delhaye BP, Rayhaun BC, Bensmaia SJ (2017) Simulating
tactile signals from the whole hand with millisecond precision, PNAS
114:E5693-E5702, and its code (github.com/hsaal/touchsim, commit 4ec9f5c).
Frame as in `scenes`: +Z into the skin.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from ddmm.population.stimuli._contact_kernels import contact_loads, distance, rate, sigma_z_unit, surface_wave
from ddmm.utils.resources import check_memory
from ddmm.utils.validation import (
    as_finite_array,
    check_choice,
    check_instance,
    check_nonnegative,
    check_positive,
    check_real,
    shown,
)

__all__ = ["DYNAMICS", "SKIN_MODELS", "SkinMechanics", "dynamic_stress", "effective_radius", "get_skin_mechanics",
           "normal_stress", "pin_compliance", "receptor_depths", "solve_pin_loads", "stress_kernel",
           "tangential_loads"]

#: How the dynamic stress component is formed (see `dynamic_stress`).
DYNAMICS = ("derivative", "surface_wave")
_MPA = 1e6  # Pa per N/mm^2: the formulas run in N, mm and N/mm^2, results are in Pa


def _depth_pairs(value) -> tuple:
    """``receptor_depth_mm`` validated: (type code, depth > 0 mm) pairs with unique codes (may be empty)."""
    try:
        pairs = tuple((code, depth) for code, depth in value)
    except (TypeError, ValueError):
        raise ValueError(f"receptor_depth_mm must be (type code, depth mm) pairs, got {value!r}") from None
    codes = [code for code, _ in pairs]
    if not all(isinstance(c, str) for c in codes) or len(set(codes)) != len(codes):
        raise ValueError(f"receptor_depth_mm must be (type code, depth mm) pairs with unique codes, "
                         f"got {value!r}")
    for code, depth in pairs:
        check_positive(depth, f"receptor_depth_mm[{code!r}]", "mm")
    return pairs


@dataclass(frozen=True)
class SkinMechanics:
    """The skin's elastic constants and the approximations the stage applies.

    Attributes
    ----------
    name : str
        Registry name (``"touchsim"``, ``"default"`` or a user's own).
    youngs_modulus_pa : float
        Young's modulus E of the half-space in Pa (> 0).
    poisson : float
        Poisson's ratio nu, dimensionless, in [0, 0.5] (0.5: incompressible).
    friction : float
        Coulomb friction coefficient between a pin and the skin, dimensionless, >= 0.
    dynamic : str
        ``"derivative"`` (time derivative of the static stress, Pa/s) or
        ``"surface_wave"`` (TouchSim's delayed, decaying surface wave); see `dynamic_stress`.
    wave_speed_mm_s : float or None
        Surface-wave speed in mm/s (> 0) for ``"surface_wave"``; None otherwise.
    cap_pin_radius : bool
        True: an array's pin radius is capped at half its smallest pin spacing
        (TouchSim).  False: pins keep their radius and overlapping pins are refused.
    receptor_depth_mm : tuple of (str, float)
        ``(afferent type code, depth in mm)`` pairs: the depth (> 0 mm) at
        which each type reads stress; a type not named reads it at its
        registered depth (`ddmm.models.afferent_types.AfferentType.receptor_depth_mm`).
    """

    name: str
    youngs_modulus_pa: float
    poisson: float
    friction: float
    dynamic: str
    wave_speed_mm_s: float | None
    cap_pin_radius: bool
    receptor_depth_mm: tuple

    def __post_init__(self):
        check_instance(self.name, "skin name", str, "a str")
        check_positive(self.youngs_modulus_pa, "youngs_modulus_pa", "Pa")
        if not 0.0 <= check_real(self.poisson, "poisson") <= 0.5:
            raise ValueError(f"poisson must be in [0, 0.5] (0.5: incompressible skin), got {shown(self.poisson)}")
        check_nonnegative(self.friction, "friction")
        check_choice(self.dynamic, "dynamic", DYNAMICS)
        if self.dynamic == "surface_wave":
            check_positive(self.wave_speed_mm_s, "wave_speed_mm_s", "mm/s")
        elif self.wave_speed_mm_s is not None:
            raise ValueError(f"wave_speed_mm_s must be None for dynamic='derivative', got {shown(self.wave_speed_mm_s)}")
        check_instance(self.cap_pin_radius, "cap_pin_radius", bool, "a bool")
        pairs = _depth_pairs(self.receptor_depth_mm)
        object.__setattr__(self, "receptor_depth_mm", pairs)

    @property
    def modulus_n_mm2(self) -> float:
        """E in N/mm^2 (= MPa), the unit the formulas run in."""
        return self.youngs_modulus_pa / _MPA

    def depth_mm(self, afferent_type: str) -> float:
        """Depth in mm at which ``afferent_type`` (e.g. ``"SAI"``) reads stress.

        Examples
        --------
        >>> get_skin_mechanics("touchsim").depth_mm("RAI")
        1.6
        """
        from ddmm.models.afferent_types import afferent_type_info

        code = afferent_type_info(afferent_type).code  # refuses an unknown type, naming it
        return float(dict(self.receptor_depth_mm).get(code, afferent_type_info(code).receptor_depth_mm))

    def tangential_stiffness(self, radius_mm: float) -> float:
        """k_t = 8 G a / (2 - nu) in N/mm, G = E / (2 (1 + nu)): a bonded rigid flat punch (Johnson 1985; recalled).

        Examples
        --------
        >>> round(get_skin_mechanics("default").tangential_stiffness(0.5), 4)
        0.0444
        """
        g = self.modulus_n_mm2 / (2.0 * (1.0 + self.poisson))
        return 8.0 * g * check_positive(radius_mm, "radius_mm", "mm") / (2.0 - self.poisson)


#: The named skins (their constants and sources: `get_skin_mechanics`).
SKIN_MODELS = {
    "touchsim": SkinMechanics("touchsim", 50e3, 0.4, 0.5, "surface_wave", 8000.0, True,
                              (("SAI", 0.3), ("RAI", 1.6), ("RAII", 2.0), ("SAII", 1.0))),
    "default": SkinMechanics("default", 50e3, 0.5, 0.5, "derivative", None, False, ()),  # the registry's depths
}


def receptor_depths(afferent_type, skin) -> np.ndarray:
    """Each afferent's receptor depth in mm under ``skin`` (`SkinMechanics.depth_mm` of its type).

    Examples
    --------
    >>> receptor_depths(np.array(["SAI", "RAII", "SAI"]), get_skin_mechanics("touchsim")).tolist()
    [0.3, 2.0, 0.3]
    """
    afferent_type = np.asarray(afferent_type).astype(str)
    out = np.empty(afferent_type.shape)
    for code in np.unique(afferent_type):  # one lookup a type present
        out[afferent_type == code] = skin.depth_mm(str(code))
    return out


def get_skin_mechanics(skin: str) -> SkinMechanics:
    """The skin registered as ``skin`` in `SKIN_MODELS`.

    Notes
    -----
    ``"touchsim"``: TouchSim's constants and approximations (Saal et al.
    2017, PNAS 114:E5693; its code at commit 4ec9f5c): E = 0.05 MPa
    (50e3 Pa) and nu = 0.4 (``transduction.skin_touch_profile``); the
    ``"surface_wave"`` dynamics at 8000 mm/s (``circ_load_dyn_wave``); the
    pin radius capped at half the smallest spacing (``check_pin_radius``);
    receptor depths SAI 0.3, RAI 1.6, RAII 2.0 mm (its SA1, RA, PC in
    ``constants.affdepths``).  SAII has no TouchSim counterpart: 1.0 mm, the
    default skin's.  TouchSim has no friction: 0.5 here, inert unless a pin
    moves sideways.

    ``"default"``: E = 50e3 Pa, the same as TouchSim's.  nu = 0.5,
    incompressible skin: with a rigid pin on an incompressible half-space
    the normal and tangential problems uncouple exactly, which
    `tangential_loads` assumes (Johnson 1985, Contact Mechanics, ch. 3;
    recalled).  ``"derivative"`` dynamics: quasi-static elasticity, the
    dynamic stress is the static stress's time derivative, with no wave
    delay.  Pins keep their radius (overlapping pins are refused).
    Anatomical receptor depths (recalled): SAI 0.5 mm (Merkel discs at the
    epidermal-dermal junction), RAI 0.7 mm (Meissner corpuscles in the
    dermal papillae), SAII 1.0 mm (Ruffini endings in the dermis), RAII
    2.0 mm (Pacinian corpuscles in the subcutis): the registry's
    (`ddmm.models.afferent_types.AfferentType.receptor_depth_mm`).  Friction 0.5 (recalled:
    fingertip skin on smooth surfaces, roughly 0.4-1.0).

    Examples
    --------
    >>> get_skin_mechanics("default").poisson
    0.5
    """
    return SKIN_MODELS[check_choice(skin, "skin", tuple(SKIN_MODELS))]


def _xy(x_mm, y_mm, what: str) -> tuple[np.ndarray, np.ndarray]:
    """Validated 1-D, equal-length, non-empty coordinates (mm) of ``what`` (``"pin"`` or ``"point"``)."""
    x = as_finite_array(x_mm, f"{what} x_mm", ndim=1)
    y = as_finite_array(y_mm, f"{what} y_mm", ndim=1)
    if x.shape != y.shape or x.size == 0:
        raise ValueError(f"{what} x_mm and y_mm must be non-empty and of equal length; got {x.size} and {y.size}")
    return x, y


def _skin(skin) -> SkinMechanics:
    return check_instance(skin, "skin", SkinMechanics, "a SkinMechanics (e.g. get_skin_mechanics('default'))")


def effective_radius(x_mm, y_mm, radius_mm, skin) -> float:
    """The pin radius (mm) the stage uses for pins at (``x_mm``, ``y_mm``) mm.

    With ``skin.cap_pin_radius`` (TouchSim) it is ``min(radius_mm, smallest
    spacing / 2)``; otherwise ``radius_mm`` itself, and pins closer than
    ``2 * radius_mm`` are refused (touching pins, up to a relative 1e-9 of
    rounding, are not).  Coincident pins are refused by both.

    Examples
    --------
    >>> effective_radius([0, 1], [0, 0], 0.75, get_skin_mechanics("touchsim"))
    0.5
    >>> effective_radius([0, 1], [0, 0], 0.75, get_skin_mechanics("default"))
    Traceback (most recent call last):
    ValueError: pins 0 and 1 overlap: centres 1.0 mm apart, less than 2 * radius_mm = 1.5 mm ...
    """
    x, y = _xy(x_mm, y_mm, "pin")
    a = check_positive(radius_mm, "radius_mm", "mm")
    skin = _skin(skin)
    if x.size == 1:
        return a
    dist = distance(x, y, x, y)
    np.fill_diagonal(dist, np.inf)
    i, j = sorted(np.unravel_index(int(np.argmin(dist)), dist.shape))
    nearest = float(dist[i, j])
    if nearest == 0.0:
        raise ValueError(f"pins {i} and {j} coincide at ({shown(x[i])}, {shown(y[i])}) mm; give each pin its own place")
    if skin.cap_pin_radius:
        return min(a, nearest / 2.0)
    if nearest < 2.0 * a * (1.0 - 1e-9):  # touching pins (a bar's, a disc's) are 2a apart up to rounding
        raise ValueError(f"pins {i} and {j} overlap: centres {shown(nearest)} mm apart, less than 2 * radius_mm = "
                         f"{shown(2 * a)} mm (the {skin.name!r} skin keeps pin radii: use a smaller radius_mm, "
                         "more room between the pins (pitch_mm) or the 'touchsim' skin, which caps radii at half "
                         "the spacing)")
    return a


def pin_compliance(x_mm, y_mm, radius_mm, skin) -> np.ndarray:
    """Surface deflection (mm) at pin i per newton on pin j, shape (n_pins, n_pins), in mm/N.

    A rigid flat circular punch of radius a on a half-space (Sneddon 1946):
    outside it, ``w(r) = (1 - nu^2) / (pi a E) * arcsin(a / r)``; under it
    (``r <= a``, the diagonal) its own displacement ``(1 - nu^2) / (2 a E)``,
    E in N/mm^2.  Each pin's load is taken to act with that pressure
    distribution (TouchSim's approximation).  The radius is
    `effective_radius`'s.

    Examples
    --------
    >>> c = pin_compliance([0, 4], [0, 0], 0.5, get_skin_mechanics("default"))
    >>> np.round(c, 3).tolist()
    [[15.0, 1.197], [1.197, 15.0]]
    """
    skin = _skin(skin)
    a = effective_radius(x_mm, y_mm, radius_mm, skin)
    x, y = _xy(x_mm, y_mm, "pin")
    r = distance(x, y, x, y)
    scale = (1.0 - skin.poisson ** 2) / skin.modulus_n_mm2
    outside = r > a
    out = np.full(r.shape, scale / (2.0 * a))
    out[outside] = scale / (np.pi * a) * np.arcsin(a / r[outside])
    return out


def solve_pin_loads(depth_mm, x_mm, y_mm, radius_mm, skin) -> np.ndarray:
    """Normal load (N, >= 0) on each pin, shape (n_samples, n_pins), from the pins' depths (mm).

    Per sample, ``compliance[c, c] @ P_c = depth_c`` is solved over the pins
    in contact c (`pin_compliance`), the set for which no load is negative
    (a pin pulling is not touching: the skin around it is pressed below it)
    and no touching pin out of it sinks below the skin.  Pins out of contact
    carry 0.  Samples sharing a set share one solve; the others start from
    the sample before's set, whose inverse is updated as pins join or leave.
    The radius is `effective_radius`'s.

    Parameters
    ----------
    depth_mm : array_like, shape (n_samples, n_pins)
        Indentation of each pin in mm, >= 0 (into the skin).
    x_mm, y_mm : array_like, shape (n_pins,)
        Pin centres in mm.
    radius_mm : float
        Pin radius in mm, > 0.
    skin : SkinMechanics
        The skin (`get_skin_mechanics`).

    Examples
    --------
    >>> skin = get_skin_mechanics("default")
    >>> p = solve_pin_loads([[0.5, 0.0], [0.5, 0.01]], [0, 1.5], [0, 0], 0.5, skin)
    >>> np.round(p, 4).tolist()  # the second pin never reaches the skin it rests on
    [[0.0333, 0.0], [0.0333, 0.0]]
    """
    x, _ = _xy(x_mm, y_mm, "pin")
    depth = as_finite_array(depth_mm, "depth_mm", ndim=2)
    if depth.shape[1] != x.size:
        raise ValueError(f"depth_mm must have one column per pin ({x.size}), got shape {depth.shape}")
    if np.any(depth < 0.0):
        s, p = np.argwhere(depth < 0.0)[0]
        raise ValueError(f"depth_mm must be >= 0 mm (into the skin); got {shown(depth[s, p])} at sample {s}, pin {p}")
    return contact_loads(depth, pin_compliance(x_mm, y_mm, radius_mm, skin))


def _receptors(x_mm, y_mm, depth_mm) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """Validated receptor positions (mm) and depths (mm, > 0, one per point)."""
    x, y = _xy(x_mm, y_mm, "point")
    z = as_finite_array(depth_mm, "depth_mm")
    if z.ndim > 1 or z.size not in (1, x.size):
        raise ValueError(f"depth_mm must be one number or one per point ({x.size}), got shape {z.shape}")
    z = np.broadcast_to(z, x.shape)
    if np.any(z <= 0.0):
        i = int(np.flatnonzero(z <= 0.0)[0])
        raise ValueError(f"depth_mm must be > 0 mm (a receptor under the surface); got {shown(z[i])} at point {i}")
    return x, y, z


def stress_kernel(pin_x, pin_y, radius_mm, x_mm, y_mm, depth_mm) -> np.ndarray:
    """Compressive normal stress sigma_z (Pa) per newton on each pin, shape (n_pins, n_points).

    Sneddon's (1946) field of a rigid flat circular punch of radius a under
    load P, at horizontal distance r and depth z (mm): with ``xi = z / a``,
    ``rho = r / a``, ``R = sqrt((rho^2 + xi^2 - 1)^2 + 4 xi^2)``,
    ``phi = atan2(2 xi, rho^2 + xi^2 - 1)``, ``theta = atan(1 / xi)``,
    ``J1 = sin(phi / 2) / sqrt(R)``, ``J2 = sqrt(1 + xi^2) sin(3 phi / 2 - theta) / R^(3/2)``:
    ``sigma_z = P / (2 pi a^2) (J1 + xi J2)``.  On the axis this is
    ``sigma_z(0, z) = P (a^2 + 3 z^2) / (2 pi (a^2 + z^2)^2)``, which is also
    Boussinesq's point-load stress ``3 P z^3 / (2 pi d^5)`` integrated over
    the punch pressure ``P / (2 pi a sqrt(a^2 - r^2))``.  Pass the radius the
    loads were solved with (`effective_radius`).

    Parameters
    ----------
    pin_x, pin_y : array_like, shape (n_pins,)
        Pin centres in mm.
    radius_mm : float
        Pin radius in mm, > 0.
    x_mm, y_mm : array_like, shape (n_points,)
        Receptor positions in mm.
    depth_mm : float or array_like, shape (n_points,)
        Receptor depths in mm, > 0.

    Examples
    --------
    >>> k = stress_kernel([0], [0], 0.5, [0, 0], [0, 0], [0.5, 1.0])
    >>> np.round(k / 1e3, 2).tolist()  # kPa per N; the closed form gives 636.62 and 331.04
    [[636.62, 331.04]]
    """
    px, py = _xy(pin_x, pin_y, "pin")
    x, y, z = _receptors(x_mm, y_mm, depth_mm)
    a = check_positive(radius_mm, "radius_mm", "mm")
    check_memory(48.0 * px.size * x.size, f"a stress kernel of {px.size} pins x {x.size} points", "use fewer points")
    rho = distance(px, py, x, y) / a
    return _MPA / (2.0 * np.pi * a * a) * sigma_z_unit(rho, z[None, :] / a)


def _loads(loads, n_pins: int) -> np.ndarray:
    """Validated normal loads in N: finite, >= 0, shape (n_samples, n_pins)."""
    arr = as_finite_array(loads, "loads", ndim=2)
    if arr.shape[1] != n_pins:
        raise ValueError(f"loads must have one column per pin ({n_pins}), got shape {arr.shape}")
    if np.any(arr < 0.0):
        s, p = np.argwhere(arr < 0.0)[0]
        raise ValueError(f"loads must be >= 0 N (a pin cannot pull); got {shown(arr[s, p])} at sample {s}, pin {p}")
    return arr


def normal_stress(loads, pin_x, pin_y, radius_mm, x_mm, y_mm, depth_mm) -> np.ndarray:
    """Static compressive stress sigma_z (Pa) at each point, shape (n_samples, n_points): ``loads @ stress_kernel``.

    ``loads`` (N, >= 0, shape (n_samples, n_pins)) come from `solve_pin_loads`;
    the other arguments are `stress_kernel`'s.

    Examples
    --------
    >>> s = normal_stress([[0.1], [0.2]], [0], [0], 0.5, [0], [0], 1.0)
    >>> np.round(s / 1e3, 2).tolist()  # kPa
    [[33.1], [66.21]]
    """
    kernel = stress_kernel(pin_x, pin_y, radius_mm, x_mm, y_mm, depth_mm)
    arr = _loads(loads, kernel.shape[0])
    check_memory(8.0 * arr.shape[0] * kernel.shape[1], f"stress of {arr.shape[0]} samples x {kernel.shape[1]} points",
                 "use fewer samples or points")
    return arr @ kernel


def dynamic_stress(loads, pin_x, pin_y, radius_mm, x_mm, y_mm, depth_mm, fs, skin) -> np.ndarray:
    """The dynamic stress component at each point, shape (n_samples, n_points), per ``skin.dynamic``.

    ``"derivative"``: the time derivative (Pa/s) of `normal_stress`, by
    central differences inside and one-sided ones at the ends, at ``fs`` Hz.

    ``"surface_wave"`` (TouchSim's approximation): the rate of the surface
    deflection under the pins is turned back into dynamic pin loads through
    the full compliance matrix, assuming the pressure keeps its static
    distribution (Bycroft 1955, as TouchSim cites it).  The compliance is
    symmetric, so those loads are the static loads' rate (N/s) itself, which
    is computed directly (differences at the ends: the neighbouring central
    one, as TouchSim).  Each pin's rate reaches a point after the time a wave
    at ``skin.wave_speed_mm_s`` takes over the distance beyond the pin's edge
    (rounded to whole samples; none under the pin), scaled by the deflection
    decay ``arcsin(a / r) / (pi a)`` (``1 / (2 a)`` under the pin) and by
    ``1 / depth^2``.  The sum is TouchSim's quantity (N mm^-3 s^-1) times
    1e6, the factor that takes its static stress from MPa to Pa: so in
    Pa mm^-1 s^-1, not a stress rate.  A single sample has no rate (zeros).

    Parameters
    ----------
    loads, pin_x, pin_y, radius_mm, x_mm, y_mm, depth_mm
        As `normal_stress` (the radius is resolved by `effective_radius` here).
    fs : float
        Sample rate in Hz, > 0.
    skin : SkinMechanics
        The skin (`get_skin_mechanics`).

    Examples
    --------
    >>> ramp = np.linspace(0, 0.1, 5)[:, None]  # N, at 1 kHz: 25 N/s
    >>> d = dynamic_stress(ramp, [0], [0], 0.5, [0], [0], 1.0, 1000.0, get_skin_mechanics("default"))
    >>> np.round(d[:, 0] / 1e6, 3).tolist()  # MPa/s
    [8.276, 8.276, 8.276, 8.276, 8.276]
    """
    skin = _skin(skin)
    fs = check_positive(fs, "fs", "Hz")
    a = effective_radius(pin_x, pin_y, radius_mm, skin)
    px, py = _xy(pin_x, pin_y, "pin")
    x, y, z = _receptors(x_mm, y_mm, depth_mm)
    arr = _loads(loads, px.size)
    check_memory(8.0 * arr.shape[0] * x.size, f"stress of {arr.shape[0]} samples x {x.size} points",
                 "use fewer samples or points")
    if skin.dynamic == "derivative":  # linear: the rate of loads @ kernel is the loads' rate @ kernel
        return rate(arr, fs, "one_sided") @ stress_kernel(px, py, a, x, y, z)
    return _MPA * surface_wave(rate(arr, fs, "copy"), distance(px, py, x, y), a, z, fs, skin.wave_speed_mm_s)


def tangential_loads(lateral_mm, loads, radius_mm, skin) -> np.ndarray:
    """Tangential load (N) on each pin from its lateral displacement, Coulomb stick and slip, (n_samples, n_pins, 2).

    Each pin holds the skin point under it (its anchor) with the stiffness
    of a bonded rigid flat punch, ``k_t = 8 G a / (2 - nu)``, ``G = E / (2
    (1 + nu))`` (Johnson 1985; recalled): ``Q = k_t (u - anchor)``.  Where
    ``|Q|`` would exceed ``skin.friction * P`` the pin slips: the anchor is
    dragged along ``u - anchor`` until ``|Q| = friction * P``.  A pin out of
    contact (P = 0) carries no Q and its anchor is reset under it; the anchor
    starts under the pin.  The normal and tangential problems are taken as
    uncoupled (exact for nu = 0.5).

    Parameters
    ----------
    lateral_mm : array_like, shape (n_samples, n_pins, 2)
        Lateral (x, y) displacement of each pin in mm.
    loads : array_like, shape (n_samples, n_pins)
        Normal loads in N, >= 0 (`solve_pin_loads`).
    radius_mm : float
        Pin radius in mm, > 0 (`effective_radius`).
    skin : SkinMechanics
        The skin: its moduli and ``friction``.

    Examples
    --------
    >>> u = np.zeros((3, 1, 2)); u[:, 0, 0] = [0.0, 0.1, 2.0]  # mm
    >>> q = tangential_loads(u, [[0.1], [0.1], [0.1]], 0.5, get_skin_mechanics("default"))
    >>> np.round(q[:, 0, 0], 4).tolist()  # stick (k_t u), then slip at 0.5 * 0.1 N
    [0.0, 0.0044, 0.05]
    """
    skin = _skin(skin)
    k_t = skin.tangential_stiffness(radius_mm)
    u = as_finite_array(lateral_mm, "lateral_mm", ndim=3)
    p = _loads(loads, u.shape[1])
    if u.shape[2] != 2 or p.shape[0] != u.shape[0]:
        raise ValueError(f"lateral_mm must have shape (n_samples, n_pins, 2) matching loads {p.shape}, got {u.shape}")
    limit = skin.friction * p / k_t  # the largest stuck stretch, mm
    out = np.zeros(u.shape)
    anchor = u[0].copy() if u.shape[0] else None
    for t in range(u.shape[0]):
        stretch = u[t] - anchor
        length = np.hypot(stretch[:, 0], stretch[:, 1])
        slip = length > limit[t]
        scale = np.where(slip, limit[t] / np.where(slip, length, 1.0), 1.0)
        stretch *= scale[:, None]
        anchor = u[t] - stretch
        out[t] = k_t * stretch
    return out
