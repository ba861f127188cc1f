"""The parts a population spec is built from: tuning-angle and sharpness distributions, a region, a map.

Each is a frozen dataclass that validates itself, raising a `ValueError`
that names the spec key (``theta_t.kappa``, ``region.semi_axes_mm``, ...);
`ddmm.population.spec` assembles them into a `PopulationSpec`.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

from ddmm.models.nap import PROFILE_NAMES
from ddmm.population.anatomy import hand_map
from ddmm.utils.deprecation import renamed_keyword
from ddmm.utils.validation import shown

__all__ = [
    "DEFAULT_SHARPNESS", "MAPS", "AngleDistribution", "MapSpec", "Region", "SharpnessDistribution", "merge_tables",
]

#: Maps a spec may name in ``[map]``.
MAPS = ("hand",)
_ANGLE_KINDS = ("uniform", "von_mises", "fixed", "list")
_SHARP_KINDS = ("fixed", "uniform", "list")


def fail(key: str, message: str):
    """Raise the spec's `ValueError`: ``"<key>: <message>"``."""
    raise ValueError(f"{key}: {message}")


#: Top-level tables whose keys may name an afferent type, in either spelling ("SAI" or "SA-I").
_TYPE_KEYED = ("types", "current", "neuron")
#: Tables that exclude each other: a derived spec that gives one drops the base's other.
_EXCLUSIVE = {"map": "region", "region": "map"}


def _type_code(key: str, normalize) -> str:
    try:
        return normalize(key)
    except ValueError:  # a shared key of [current] (cutoff_hz, ...), not a type
        return key


def _merge(base: dict, over: dict) -> dict:
    """``over`` laid on ``base``: tables merge key by key, any other value replaces."""
    out = dict(base)
    for key, value in over.items():
        old = out.get(key)
        out[key] = _merge(old, value) if isinstance(old, dict) and isinstance(value, dict) else value
    return out


def merge_tables(base: dict, over: dict, normalize) -> dict:
    """A derived spec's TOML structure: ``over``'s keys laid on ``base``'s, table by table.

    Type tables match whatever spelling each side uses (``normalize``, e.g.
    `ddmm.models.afferent_types.normalize_type`, maps a name to its code), and a
    ``[map]`` in ``over`` replaces the base's ``[region]`` (and the reverse).
    """
    def keyed(data):
        return {k: ({_type_code(t, normalize): v for t, v in val.items()} if k in _TYPE_KEYED
                    and isinstance(val, dict) else val) for k, val in data.items()}
    base, over = keyed(base), keyed(over)
    for key, other in _EXCLUSIVE.items():
        if key in over:
            base.pop(other, None)
    return _merge(base, over)


def finite(key: str, value, *, positive=False, nonneg=False) -> float:
    """``value`` as a float, refused (`fail`) unless a finite number (``positive``: > 0, ``nonneg``: >= 0)."""
    if isinstance(value, bool) or not isinstance(value, (int, float)):
        fail(key, f"must be a number, got {shown(value)}")
    value = float(value)
    if not math.isfinite(value) or (positive and value <= 0) or (nonneg and value < 0):
        need = "> 0" if positive else ">= 0" if nonneg else "finite"
        fail(key, f"must be {need}, got {shown(value)}")
    return value


@dataclass(frozen=True)
class AngleDistribution:
    """Distribution of tuning angles theta_T (degrees).

    Attributes
    ----------
    distribution : {"uniform", "von_mises", "fixed", "list"}
        Uniform on the circle; a von Mises mixture (``mean_deg`` may list
        several means, with ``weights``); one fixed angle (``value_deg``); or
        an explicit list cycled over the afferents (``values_deg``).
    mean_deg : tuple of float
        Von Mises mean(s) in degrees.
    kappa : float
        Von Mises concentration (dimensionless, >= 0; 0 is uniform).
    weights : tuple of float
        Mixture weights (default equal).
    value_deg : float
        The fixed angle.
    values_deg : tuple of float
        The explicit angles.
    """

    distribution: str = "uniform"
    mean_deg: tuple = (0.0,)
    kappa: float = 0.0
    weights: tuple = ()
    value_deg: float = 0.0
    values_deg: tuple = ()

    def __post_init__(self):
        key = "theta_t"
        if self.distribution not in _ANGLE_KINDS:
            fail(f"{key}.distribution", f"unknown distribution {self.distribution!r}; allowed: {', '.join(_ANGLE_KINDS)}")
        means = self.mean_deg if isinstance(self.mean_deg, (tuple, list)) else (self.mean_deg,)
        object.__setattr__(self, "mean_deg", tuple(finite(f"{key}.mean_deg", m) for m in means))
        finite(f"{key}.kappa", self.kappa, nonneg=True)
        weights = tuple(finite(f"{key}.weights", w, nonneg=True) for w in self.weights)
        if weights and (len(weights) != len(self.mean_deg) or not math.isclose(sum(weights), 1.0, abs_tol=1e-6)):
            fail(f"{key}.weights", f"need one weight per mean, summing to 1; got {weights}")
        object.__setattr__(self, "weights", weights)
        finite(f"{key}.value_deg", self.value_deg)
        object.__setattr__(self, "values_deg", tuple(finite(f"{key}.values_deg", v) for v in self.values_deg))
        if self.distribution == "list" and not self.values_deg:
            fail(f"{key}.values_deg", "a list distribution needs at least one angle")


@dataclass(frozen=True)
class SharpnessDistribution:
    """Distribution of NAP sharpness, given as theta_A (degrees) or as k.

    Attributes
    ----------
    distribution : {"fixed", "uniform", "list"}
        One value, uniform on [low, high], or an explicit list cycled.
    of : {"theta_a", "k"}
        Whether the numbers are selectivity ranges theta_A in degrees
        (converted by eq. 12) or sharpness k.
    value, low, high : float
        Parameters of the fixed and uniform forms.
    values : tuple of float
        The explicit values.
    """

    distribution: str = "fixed"
    of: str = "k"
    value: float = 3.0
    low: float = 0.0
    high: float = 0.0
    values: tuple = ()

    def __post_init__(self):
        if self.distribution not in _SHARP_KINDS:
            fail("sharpness.distribution", f"unknown distribution {self.distribution!r}; allowed: {', '.join(_SHARP_KINDS)}")
        if self.of not in ("theta_a", "k"):
            fail("sharpness.of", f"must be 'theta_a' or 'k', got {self.of!r}")
        for name in ("value", "low", "high"):
            finite(f"sharpness.{name}", getattr(self, name))
        object.__setattr__(self, "values", tuple(finite("sharpness.values", v) for v in self.values))
        if self.distribution == "uniform" and not self.low < self.high:
            fail("sharpness", f"uniform needs low < high, got low={shown(self.low)}, high={shown(self.high)}")
        if self.distribution == "list" and not self.values:
            fail("sharpness.values", "a list distribution needs at least one value")


#: Default sharpness per profile: the paper's k = 3 (broad needs k >= 1.8).
DEFAULT_SHARPNESS = {name: SharpnessDistribution(value=3.0) for name in PROFILE_NAMES}


@dataclass(frozen=True)
class Region:
    """An ellipse on the fingertip (mm): centre and semi-axes along X (radial) and Y (distal).

    ``name`` optionally labels it with the hand-map region it stands for
    (``"D2d"`` for the fingertip preset); its afferents then carry that
    region and its ``frame_deg``, while positions stay in this local frame.
    """

    center_mm: tuple = (0.0, 0.0)
    semi_axes_mm: tuple = (7.0, 9.0)
    name: str = ""

    def __post_init__(self):
        if not isinstance(self.name, str) or (self.name and self.name not in hand_map.REGIONS):
            fail("region.name", f"{self.name!r} is not a hand-map region; allowed: '', {', '.join(hand_map.REGIONS)}")
        if len(self.center_mm) != 2 or len(self.semi_axes_mm) != 2:
            fail("region", "center_mm and semi_axes_mm need two numbers each")
        object.__setattr__(self, "center_mm", tuple(finite("region.center_mm", v) for v in self.center_mm))
        object.__setattr__(self, "semi_axes_mm",
                           tuple(finite("region.semi_axes_mm", v, positive=True) for v in self.semi_axes_mm))

    @property
    def area_cm2(self) -> float:
        """Area of the ellipse in cm^2."""
        a, b = self.semi_axes_mm
        return math.pi * a * b / 100.0

    @property
    def frame_deg(self) -> float:
        """Rotation (deg) from the local frame to the hand frame: the named region's, else 0."""
        return hand_map.REGIONS[self.name].frame_deg if self.name else 0.0


@dataclass(frozen=True)
class MapSpec:
    """Afferents placed by a map of the hand (`ddmm.population.anatomy.hand_map`).

    Attributes
    ----------
    name : {"hand"}
        The map.
    regions : tuple of str
        Regions to populate, in map order whatever the order given (default:
        every region).
    """

    name: str = "hand"
    regions: tuple = ()

    def __post_init__(self):
        if self.name not in MAPS:
            fail("map.name", f"unknown map {self.name!r}; allowed: {', '.join(MAPS)}")
        if isinstance(self.regions, str) or not isinstance(self.regions, (tuple, list)):
            fail("map.regions", f"must be a list of region names, got {self.regions!r}")
        for name in self.regions:
            if name not in hand_map.REGIONS:
                fail("map.regions", f"{name!r} is not a region of the map; allowed: {', '.join(hand_map.REGIONS)}")
        object.__setattr__(self, "regions", tuple(n for n in hand_map.REGIONS if n in self.regions))

    def region_names(self) -> tuple:
        """The regions populated, in map order."""
        return self.regions or hand_map.region_names()

    @renamed_keyword("types", "afferent_types")
    def counts(self, afferent_types) -> dict:
        """Afferents per region and type, {region: {type: count}} (`hand_map.region_counts`)."""
        return hand_map.region_counts(tuple(afferent_types), self.region_names())
