"""A map of the glabrous (palmar) skin of a right hand: regions, densities, counts.

Pure data and geometry (numpy only).  Every length is in mm, every angle in
degrees, in ONE hand frame:

* +X radial (toward the thumb), +Y distal along the index finger (D2), so a
  palmar view of the right hand has the thumb on the right;
* the origin is the centre of the index fingertip pad ``D2d``, which is the
  ellipse of the ``fingertip`` preset (semi-axes 9 mm radial, 12 mm distal):
  a fingertip population lies on ``D2d`` without any shift.

Regions: the digits D1 (thumb) to D5 (little finger) with distal (``D2d``),
middle (``D2m``) and proximal (``D2p``) segments (the thumb has no middle
one: ``D1d``, ``D1p``), and four palm regions: ``palm_distal`` (the pads
under the finger bases), ``thenar``, ``palm_central`` and ``hypothenar``.
Distal segments are ellipses, the other segments rectangles along the digit,
the palm regions convex polygons that share edges with the finger bases and
with each other (a point on a shared edge belongs to the region listed first).

Each region has a ``frame_deg``: the counterclockwise rotation from its
digit's local frame (+X radial, +Y distal along that digit) to the hand
frame; 0 for D2 and the palm, slightly positive for the ulnar fingers (their
tips point ulnarly), strongly negative for the thumb.  The map is flat and
schematic: the thumb's palmar surface really faces partly sideways.

Sizes are adult anthropometry **recalled, not read in a source** (segment
lengths between palmar creases and widths of a medium adult hand, about
183 mm from wrist crease to the D3 tip and 80 mm palm breadth).  The
densities are docs/references.md row 16 (Johansson & Vallbo 1979): fingertip 241
and palm 58 units/cm² (V), the rest of a finger from the ratio
fingertip : rest of finger : palm = 4.2 : 1.6 : 1, i.e. 58 x 1.6 = 92.8
units/cm²; the split between types (FA-I 141, SA-I 70, FA-II 21, SA-II 9 of
241 at the fingertip, R) is used for every region, as no stored source gives
it elsewhere.  Counts per region: the region total is the all-type density
times the area, rounded to the nearest whole afferent, split between the
types by largest remainder.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from ddmm.models.afferent_types import afferent_type_codes, afferent_type_info
from ddmm.utils.deprecation import renamed_keyword
from ddmm.utils.validation import as_float_array, check_count, check_instance, check_real, check_rng, shown

# TYPES and TYPE_SHARE are views of the registry (the module's __getattr__).
__all__ = ["Ellipse", "Polygon", "HandRegion", "KINDS", "TYPES", "DENSITY_PER_CM2", "TYPE_SHARE",  # noqa: F822
           "REGIONS", "region_names", "get_region", "region_at", "sample_in_region", "region_counts",
           "region_table", "outline"]

#: Region kinds, each with its own density.
KINDS = ("fingertip", "finger", "palm")
#: Afferents per cm², all types (docs/references.md row 16): fingertip and palm read (V), finger = palm x 1.6.
DENSITY_PER_CM2 = {"fingertip": 241.0, "finger": 58.0 * 1.6, "palm": 58.0}


def _shares() -> dict:
    """Each mapped type's share of a region's afferents (`AfferentType.density_share`; the fingertip's, row 16:
    SA-I 70, FA-I 141, FA-II 21, SA-II 9 of 241), in registration order."""
    return {code: afferent_type_info(code).density_share
            for code in afferent_type_codes(lambda kind: kind.density_share is not None)}


def __getattr__(name):
    # Views of the registry, whatever is registered now: the types on the map, in the package's order, and their
    # shares.
    if name == "TYPES":
        return tuple(_shares())
    if name == "TYPE_SHARE":
        return _shares()
    raise AttributeError(f"module {__name__!r} has no attribute {name!r}")


def _rotation(deg: float) -> np.ndarray:
    t = np.deg2rad(deg)
    return np.array([[np.cos(t), -np.sin(t)], [np.sin(t), np.cos(t)]])


def _xy(x_mm, y_mm, name="x_mm, y_mm"):
    x, y = as_float_array(x_mm, "x_mm"), as_float_array(y_mm, "y_mm")
    if x.shape != y.shape:
        raise ValueError(f"{name}: x_mm and y_mm must have the same shape, got {x.shape} and {y.shape}")
    return x, y


@dataclass(frozen=True)
class Ellipse:
    """An ellipse: centre (mm), semi-axes (mm) along its own X and Y, rotated by ``angle_deg``.

    Examples
    --------
    >>> e = Ellipse((0.0, 0.0), (9.0, 12.0))
    >>> round(e.area_mm2, 1), e.contains([0.0, 9.5], [11.9, 0.0]).tolist()
    (339.3, [True, False])
    """

    center_mm: tuple
    semi_axes_mm: tuple
    angle_deg: float = 0.0

    def __post_init__(self):
        for key, pair in (("center_mm", self.center_mm), ("semi_axes_mm", self.semi_axes_mm)):
            v = np.asarray(pair, dtype=float)
            if v.shape != (2,) or not np.all(np.isfinite(v)) or (key == "semi_axes_mm" and np.any(v <= 0)):
                need = " > 0" if key == "semi_axes_mm" else ""
                raise ValueError(f"{key} must be two finite numbers{need}, got {pair!r}")
            object.__setattr__(self, key, tuple(float(c) for c in v))
        object.__setattr__(self, "angle_deg", float(self.angle_deg))

    @property
    def area_mm2(self) -> float:
        """Area in mm²."""
        return float(np.pi * self.semi_axes_mm[0] * self.semi_axes_mm[1])

    @property
    def centroid_mm(self) -> tuple:
        """Centre (x, y) in mm."""
        return tuple(float(v) for v in self.center_mm)

    def _local(self, x, y):
        d = np.stack([x - self.center_mm[0], y - self.center_mm[1]])
        u, v = np.tensordot(_rotation(-self.angle_deg), d, axes=1)
        return u / self.semi_axes_mm[0], v / self.semi_axes_mm[1]

    def contains(self, x_mm, y_mm) -> np.ndarray:
        """Whether each point lies in the closed ellipse."""
        u, v = self._local(*_xy(x_mm, y_mm))
        return u**2 + v**2 <= 1.0

    def sample(self, n: int, rng) -> np.ndarray:
        """``n`` uniform points, shape (n, 2), in mm."""
        radius, angle = np.sqrt(rng.uniform(0, 1, n)), rng.uniform(0, 2 * np.pi, n)
        local = np.stack([self.semi_axes_mm[0] * radius * np.cos(angle), self.semi_axes_mm[1] * radius * np.sin(angle)])
        return (_rotation(self.angle_deg) @ local).T + np.asarray(self.center_mm, float)

    def outline(self, n: int = 73) -> np.ndarray:
        """Closed outline, shape (n, 2), in mm."""
        t = np.linspace(0, 2 * np.pi, n)
        local = np.stack([self.semi_axes_mm[0] * np.cos(t), self.semi_axes_mm[1] * np.sin(t)])
        return (_rotation(self.angle_deg) @ local).T + np.asarray(self.center_mm, float)


@dataclass(frozen=True)
class Polygon:
    """A convex polygon, vertices (mm) counterclockwise.

    Examples
    --------
    >>> sq = Polygon(((0.0, 0.0), (2.0, 0.0), (2.0, 2.0), (0.0, 2.0)))
    >>> sq.area_mm2, sq.centroid_mm, sq.contains([1.0, 3.0], [1.0, 1.0]).tolist()
    (4.0, (1.0, 1.0), [True, False])
    """

    vertices_mm: tuple

    def __post_init__(self):
        v = np.asarray(self.vertices_mm, dtype=float)
        if v.ndim != 2 or v.shape[1] != 2 or v.shape[0] < 3 or not np.all(np.isfinite(v)):
            raise ValueError(f"vertices_mm must be three or more finite (x, y) pairs, got shape {v.shape}")
        edges = np.roll(v, -1, axis=0) - v
        turns = edges[:, 0] * np.roll(edges, -1, axis=0)[:, 1] - edges[:, 1] * np.roll(edges, -1, axis=0)[:, 0]
        if np.any(turns <= 0):
            raise ValueError("vertices_mm must form a convex polygon listed counterclockwise")
        object.__setattr__(self, "vertices_mm", tuple(tuple(float(c) for c in p) for p in v))

    def _triangles(self):
        """Fan triangles from vertex 0 and their areas."""
        v = np.asarray(self.vertices_mm)
        a, b, c = v[0], v[1:-1], v[2:]
        cross = (b[:, 0] - a[0]) * (c[:, 1] - a[1]) - (b[:, 1] - a[1]) * (c[:, 0] - a[0])
        return a, b, c, 0.5 * cross

    @property
    def area_mm2(self) -> float:
        """Area in mm²."""
        return float(self._triangles()[3].sum())

    @property
    def centroid_mm(self) -> tuple:
        """Area centroid (x, y) in mm."""
        a, b, c, area = self._triangles()
        centres = (a + b + c) / 3.0
        return tuple(float(v) for v in (centres * area[:, None]).sum(axis=0) / area.sum())

    def contains(self, x_mm, y_mm) -> np.ndarray:
        """Whether each point lies in the closed polygon."""
        x, y = _xy(x_mm, y_mm)
        v = np.asarray(self.vertices_mm)
        inside = np.ones(x.shape, dtype=bool)
        for (x0, y0), (x1, y1) in zip(v, np.roll(v, -1, axis=0)):
            inside &= (x1 - x0) * (y - y0) - (y1 - y0) * (x - x0) >= 0.0
        return inside

    def sample(self, n: int, rng) -> np.ndarray:
        """``n`` uniform points, shape (n, 2), in mm."""
        a, b, c, area = self._triangles()
        tri = rng.choice(area.size, size=n, p=area / area.sum())
        r1, r2 = rng.uniform(0, 1, n), rng.uniform(0, 1, n)
        flip = r1 + r2 > 1.0
        r1, r2 = np.where(flip, 1.0 - r1, r1), np.where(flip, 1.0 - r2, r2)
        return a + r1[:, None] * (b[tri] - a) + r2[:, None] * (c[tri] - a)

    def outline(self, n: int = 0) -> np.ndarray:
        """Closed outline (the vertices, first repeated), shape (m + 1, 2), in mm; ``n`` is unused."""
        v = np.asarray(self.vertices_mm)
        return np.vstack([v, v[:1]])


@dataclass(frozen=True)
class HandRegion:
    """One region of the hand map.

    Attributes
    ----------
    name : str
        ``"D2d"``, ``"thenar"``, ...
    kind : {"fingertip", "finger", "palm"}
        Selects the density (`DENSITY_PER_CM2`).
    shape : Ellipse or Polygon
        Outline in the hand frame (mm).
    frame_deg : float
        Counterclockwise rotation (degrees) from the digit's local frame to
        the hand frame (0 for D2 and the palm).
    """

    name: str
    kind: str
    shape: object
    frame_deg: float = 0.0

    def __post_init__(self):
        check_instance(self.name, "name", str, "a str")
        if self.kind not in KINDS:
            raise ValueError(f"kind={self.kind!r} is unknown; allowed: {', '.join(KINDS)}")
        check_instance(self.shape, "shape", (Ellipse, Polygon), "an Ellipse or a Polygon")
        check_real(self.frame_deg, "frame_deg", "degrees")

    @property
    def area_mm2(self) -> float:
        """Area in mm²."""
        return self.shape.area_mm2

    @property
    def center_mm(self) -> tuple:
        """Centre (x, y) in mm (the area centroid)."""
        return self.shape.centroid_mm


# Finger bases lie on one arc (the palmar digital creases): centre x and radius in mm; its top is set so
# that D2's base midpoint is at y = -59 mm (D2p 25 + D2m 22 mm below the pad centre at the origin).
_ARC_CENTER_X, _ARC_RADIUS = -18.0, 73.5
# Fingers (recalled anthropometry): x (mm) of the ulnar and radial ends of the base on the arc,
# frame_deg, then (length, width) in mm of the proximal, middle and distal segments.
_FINGERS = {
    "D2": ((-9.5, 9.5), 0.0, ((25.0, 19.0), (22.0, 17.0), (24.0, 18.0))),
    "D3": ((-29.0, -10.5), 3.0, ((27.0, 19.0), (25.0, 18.0), (25.0, 18.0))),
    "D4": ((-47.5, -30.0), 8.0, ((25.0, 18.0), (24.0, 17.0), (24.0, 17.0))),
    "D5": ((-64.0, -48.5), 14.0, ((20.0, 16.0), (17.0, 15.0), (21.0, 15.0))),
}
# Thumb: base centre (mm) on the thenar eminence, frame_deg, proximal and distal (length, width) in mm.
_THUMB = ((22.0, -95.0), -45.0, ((30.0, 22.0), None, (28.0, 21.0)))
_WRIST_Y = -160.0  # distal wrist crease (mm)


def _arc_drop(x: float) -> float:
    return _ARC_RADIUS - float(np.sqrt(_ARC_RADIUS**2 - (x - _ARC_CENTER_X) ** 2))


_ARC_TOP_Y = -59.0 + (_arc_drop(-9.5) + _arc_drop(9.5)) / 2.0


def _base_chord(digit: str) -> tuple:
    """(ulnar, radial) ends of a digit's base, hand frame (mm)."""
    if digit == "D1":
        centre, deg, ((_, width), _, _) = _THUMB
        half = _rotation(deg) @ np.array([width / 2, 0.0])
        return np.asarray(centre) - half, np.asarray(centre) + half
    return tuple(np.array([x, _ARC_TOP_Y - _arc_drop(x)]) for x in _FINGERS[digit][0])


def _digit_regions(digit: str) -> list:
    """The segments of one digit, proximal first: quadrilaterals from the base, an ellipse at the tip."""
    deg, segments = _THUMB[1:] if digit == "D1" else _FINGERS[digit][1:]
    axis, across = _rotation(deg) @ np.array([0.0, 1.0]), _rotation(deg) @ np.array([1.0, 0.0])
    ulnar, radial = _base_chord(digit)
    start = (ulnar + radial) / 2
    bottom, regions = (ulnar, radial), []
    for suffix, seg in zip("pm", segments[:2]):
        if seg is None:
            continue
        top = start + seg[0] * axis
        corners = (*bottom, top + seg[1] / 2 * across, top - seg[1] / 2 * across)
        regions.append(HandRegion(digit + suffix, "finger", Polygon(tuple(map(tuple, corners))), deg))
        start, bottom = top, corners[:1:-1]
    length, width = segments[2]
    centre = tuple(start + length / 2 * axis)
    regions.append(HandRegion(digit + "d", "fingertip", Ellipse(centre, (width / 2, length / 2), deg), deg))
    return regions


def _palm_regions() -> list:
    """Four convex palm regions sharing edges with the digit bases and with each other."""
    top = [c for d in ("D2", "D3", "D4", "D5") for c in _base_chord(d)[::-1]]  # radial to ulnar
    thumb_ulnar, thumb_radial = (tuple(c) for c in _base_chord("D1"))
    split, wrist = thumb_ulnar[1], _WRIST_Y  # palm_distal ends proximally at the thumb web
    ulnar = (float(top[-1][0]) - 0.5, split)
    shapes = {
        "palm_distal": [ulnar, thumb_ulnar, *map(tuple, top)],
        "thenar": [(-2.0, split), (-14.0, wrist), (12.0, wrist), (25.0, -140.0), thumb_radial, thumb_ulnar],
        "palm_central": [(-34.0, split), (-36.0, wrist), (-14.0, wrist), (-2.0, split)],
        "hypothenar": [ulnar, (-63.0, -130.0), (-50.0, wrist), (-36.0, wrist), (-34.0, split)],
    }
    return [HandRegion(name, "palm", Polygon(_ccw(v))) for name, v in shapes.items()]


def _ccw(vertices) -> tuple:
    """The vertices listed counterclockwise (reversed when clockwise)."""
    v = np.asarray(vertices, float)
    signed = np.sum(v[:, 0] * np.roll(v[:, 1], -1) - np.roll(v[:, 0], -1) * v[:, 1])
    return tuple(map(tuple, v if signed > 0 else v[::-1]))


#: Every region of the map, digits D1-D5 (distal first) then the palm.
REGIONS = {r.name: r for d in ("D1", *_FINGERS) for r in _digit_regions(d)[::-1]} | {r.name: r for r in _palm_regions()}


def region_names(kind: str | None = None) -> tuple:
    """Region names in map order, optionally only one kind.

    Examples
    --------
    >>> region_names("fingertip")
    ('D1d', 'D2d', 'D3d', 'D4d', 'D5d')
    """
    if kind is not None and kind not in KINDS:
        raise ValueError(f"kind={kind!r} is unknown; allowed: {', '.join(KINDS)}")
    return tuple(n for n, r in REGIONS.items() if kind is None or r.kind == kind)


def get_region(name: str) -> HandRegion:
    """The region called ``name``.

    Raises
    ------
    ValueError
        Naming an unknown region.
    """
    if not isinstance(name, str) or name not in REGIONS:
        raise ValueError(f"name={name!r} is not a region of the hand map; allowed: {', '.join(REGIONS)}")
    return REGIONS[name]


def region_at(x_mm, y_mm) -> np.ndarray:
    """The region of each point (hand frame, mm); ``""`` outside every region.

    A point on an edge two regions share gets the one listed first in `REGIONS`.

    Examples
    --------
    >>> region_at([0.0, 0.0, 200.0], [0.0, -23.0, 0.0]).tolist()
    ['D2d', 'D2m', '']
    """
    x, y = _xy(x_mm, y_mm)
    out = np.full(x.shape, "", dtype=object)
    for name, region in reversed(REGIONS.items()):
        out[region.shape.contains(x, y)] = name
    return out


def sample_in_region(name: str, n: int, rng=None) -> np.ndarray:
    """``n`` points uniform in region ``name``, shape (n, 2), hand frame (mm).

    Parameters
    ----------
    name : str
        A region of the map.
    n : int
        Number of points (>= 0).
    rng : numpy.random.Generator, int or None
        Randomness.

    Examples
    --------
    >>> pts = sample_in_region("thenar", 5, rng=0)
    >>> pts.shape, set(region_at(pts[:, 0], pts[:, 1]))
    ((5, 2), {'thenar'})
    """
    region = get_region(name)
    if isinstance(n, bool) or not isinstance(n, (int, np.integer)) or n < 0:
        raise ValueError(f"n must be a whole number >= 0, got {shown(n)}")
    return region.shape.sample(int(n), check_rng(rng))


def _largest_remainder(total: int, shares: dict) -> dict:
    raw = {k: total * s / sum(shares.values()) for k, s in shares.items()}
    counts = {k: int(np.floor(v)) for k, v in raw.items()}
    order = sorted(raw, key=lambda k: -(raw[k] - counts[k]))  # stable: ties keep TYPES order
    for k in order[: total - sum(counts.values())]:
        counts[k] += 1
    return counts


@renamed_keyword("types", "afferent_types")
def region_counts(afferent_types=None, regions=None) -> dict:
    """Afferents per region and type: {region: {type: count}}.

    The region total is ``DENSITY_PER_CM2[kind] x area`` rounded to the
    nearest whole afferent; it is split between all four types by largest
    remainder of `TYPE_SHARE`, then only ``afferent_types`` are kept (so a type's
    counts never depend on which other types are asked for).

    Parameters
    ----------
    afferent_types : sequence of str or None
        Afferent types to keep, in any order (returned in `TYPES` order;
        None: every type on the map).
    regions : sequence of str or None
        Regions to count (default: all, in map order).

    Examples
    --------
    >>> region_counts(regions=["D2d"])
    {'D2d': {'SAI': 238, 'RAI': 479, 'RAII': 71, 'SAII': 30}}
    """
    shares = _shares()
    afferent_types = tuple(shares) if afferent_types is None else afferent_types
    for name, value in (("afferent_types", afferent_types), ("regions", () if regions is None else regions)):
        if not hasattr(value, "__iter__"):  # a str is refused below, with the names allowed
            raise TypeError(f"{name} must be a sequence of names, got {type(value).__name__}")
    bad = [t for t in afferent_types if t not in shares]
    if bad or isinstance(afferent_types, str):
        raise ValueError(f"afferent_types={afferent_types!r}: allowed afferent_types are {', '.join(shares)}")
    names = region_names() if regions is None else tuple(get_region(r).name for r in regions)
    out = {}
    for name in names:
        region = REGIONS[name]
        total = int(np.floor(DENSITY_PER_CM2[region.kind] * region.area_mm2 / 100.0 + 0.5))
        counts = _largest_remainder(total, shares)
        out[name] = {t: counts[t] for t in shares if t in afferent_types}
    return out


def region_table() -> list:
    """One dict per region: name, kind, area_mm2, center_mm, frame_deg, density_per_cm2, counts.

    Examples
    --------
    >>> row = region_table()[2]
    >>> row["name"], row["kind"], round(row["area_mm2"]), row["frame_deg"]
    ('D2d', 'fingertip', 339, 0.0)
    """
    counts = region_counts()
    return [{"name": r.name, "kind": r.kind, "area_mm2": r.area_mm2, "center_mm": r.center_mm,
             "frame_deg": r.frame_deg, "density_per_cm2": DENSITY_PER_CM2[r.kind], "counts": counts[r.name]}
            for r in REGIONS.values()]


def outline(name: str, n: int = 73) -> np.ndarray:
    """Closed outline of region ``name``, shape (m, 2), hand frame (mm), for drawing.

    Examples
    --------
    >>> outline("D2d").shape
    (73, 2)
    """
    return get_region(name).shape.outline(check_count(n, "n", minimum=3))
