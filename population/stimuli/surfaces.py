"""Textured surfaces: heightmaps to press and scan across the fingertip (issue 43, part 1).

A `Surface` is a heightmap (mm above its base plane, raised features
positive) on a square grid; `grating`, `dot_pattern`, `letters` and
`from_bitmap` make them.  `ddmm.population.stimuli.scanning.scan` presses a
surface into a window of skin and slides it across at a constant velocity.

Frame: a surface's own frame has its origin at its centre, rows along +Y
(row 0 the lowest y) and columns along +X.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from ddmm.population.stimuli._contact_kernels import bilinear
from ddmm.population.stimuli._font import FONT_5X7
from ddmm.utils.validation import as_finite_array, check_instance, check_positive, shown

__all__ = ["FONT_5X7", "Surface", "dot_pattern", "from_bitmap", "grating", "letters"]


@dataclass(frozen=True, eq=False)
class Surface:
    """A rigid textured surface: a heightmap over its base plane.

    Attributes
    ----------
    height_mm : ndarray, shape (n_rows, n_cols)
        Height in mm (>= 0) of each pixel's centre above the base plane,
        raised features positive; rows run along +Y (row 0 the lowest y),
        columns along +X.  Read-only.
    pixel_mm : float
        Grid spacing in mm (> 0), the same along X and Y.
    periodic : bool
        True: the heightmap is one tile of a surface that repeats in X and Y
        (every ``width_mm`` and ``length_mm``); False: the surface ends at its
        edges and is flat (height 0) beyond them.

    Examples
    --------
    >>> s = Surface(np.array([[0.0, 1.0], [0.0, 1.0]]), pixel_mm=0.5)
    >>> s.shape, s.width_mm, s.max_height_mm
    ((2, 2), 1.0, 1.0)
    """

    height_mm: np.ndarray
    pixel_mm: float
    periodic: bool = False

    def __post_init__(self):
        h = np.array(as_finite_array(self.height_mm, "height_mm", ndim=2), dtype=float)
        if h.size == 0:
            raise ValueError(f"height_mm must hold at least one pixel, got shape {h.shape}")
        if np.any(h < 0.0):
            i, j = np.argwhere(h < 0.0)[0]
            raise ValueError(f"height_mm must be >= 0 mm (above the base plane); got {shown(h[i, j])} at row {int(i)}, "
                             f"column {int(j)}")
        check_positive(self.pixel_mm, "pixel_mm", "mm")
        if not isinstance(self.periodic, (bool, np.bool_)):
            raise TypeError(f"periodic must be True or False, got {type(self.periodic).__name__}")
        h.setflags(write=False)
        object.__setattr__(self, "height_mm", h)
        object.__setattr__(self, "pixel_mm", float(self.pixel_mm))
        object.__setattr__(self, "periodic", bool(self.periodic))

    @property
    def shape(self) -> tuple:
        """(n_rows, n_cols) of the heightmap."""
        return self.height_mm.shape

    @property
    def width_mm(self) -> float:
        """Extent along X in mm (``n_cols * pixel_mm``; a periodic surface's period in X)."""
        return self.shape[1] * self.pixel_mm

    @property
    def length_mm(self) -> float:
        """Extent along Y in mm (``n_rows * pixel_mm``; a periodic surface's period in Y)."""
        return self.shape[0] * self.pixel_mm

    @property
    def max_height_mm(self) -> float:
        """The highest point in mm above the base plane."""
        return float(self.height_mm.max())

    def height_at(self, x_mm, y_mm) -> np.ndarray:
        """Height (mm) at points (``x_mm``, ``y_mm``) of the surface's frame (origin at its centre), bilinear
        between pixel centres; a periodic surface wraps, a finite one is 0 beyond its edge pixels.

        Examples
        --------
        >>> s = Surface(np.array([[0.0, 1.0]]), pixel_mm=1.0)  # pixel centres at x = -0.5, 0.5
        >>> s.height_at([-0.5, 0.0, 0.5, 1.0, 5.0], 0.0).tolist()
        [0.0, 0.5, 1.0, 0.5, 0.0]
        >>> Surface(np.array([[0.0, 1.0]]), pixel_mm=1.0, periodic=True).height_at([1.0, 1.5], 0.0).tolist()
        [0.5, 0.0]
        """
        x, y = np.broadcast_arrays(as_finite_array(x_mm, "x_mm"), as_finite_array(y_mm, "y_mm"))
        n_rows, n_cols = self.shape
        u = x / self.pixel_mm + (n_cols - 1) / 2.0  # fractional column
        v = y / self.pixel_mm + (n_rows - 1) / 2.0  # fractional row
        shape = u.shape
        u2, v2 = np.ascontiguousarray(u, dtype=float).reshape(1, -1), np.ascontiguousarray(v, dtype=float).reshape(1, -1)
        return bilinear(np.ascontiguousarray(self.height_mm, dtype=float), u2, v2, bool(self.periodic)).reshape(shape)


def _whole_pixels(value_mm: float, name: str, pixel_mm: float) -> int:
    """``value_mm / pixel_mm`` as an int, refusing a value that is not a whole number (>= 2) of pixels."""
    n = value_mm / pixel_mm
    if abs(n - round(n)) > 1e-6 * max(1.0, n) or round(n) < 2:
        raise ValueError(f"{name}={shown(value_mm)} mm must be a whole number (>= 2) of pixels of "
                         f"pixel_mm={shown(pixel_mm)} mm; choose a pixel_mm that divides it")
    return round(n)


def _tile(length_mm: float, width_mm: float, period_x: float, period_y: float, pixel_mm: float, periodic: bool):
    """Pixel-centre coordinates (mm, from the tile's corner), shape (n_rows, n_cols) each.

    A periodic tile holds whole periods (the extents rounded to them, at least one); a finite one the extents
    rounded to whole pixels.
    """
    check_positive(length_mm, "length_mm", "mm")
    check_positive(width_mm, "width_mm", "mm")
    if periodic:
        width_mm = max(1, round(width_mm / period_x)) * period_x
        length_mm = max(1, round(length_mm / period_y)) * period_y
    n_cols, n_rows = max(1, round(width_mm / pixel_mm)), max(1, round(length_mm / pixel_mm))
    y, x = np.meshgrid((np.arange(n_rows) + 0.5) * pixel_mm, (np.arange(n_cols) + 0.5) * pixel_mm, indexing="ij")
    return x, y


def grating(period_mm: float, ridge_mm: float | None = None, height_mm: float = 0.5, *, length_mm: float = 20.0,
            width_mm: float = 20.0, pixel_mm: float = 0.05, periodic: bool = True) -> Surface:
    """A square-wave grating: ridges ``ridge_mm`` wide every ``period_mm`` along X, running along Y.

    Parameters
    ----------
    period_mm : float
        Ridge spacing in mm: a whole number (>= 2) of pixels.
    ridge_mm : float, optional
        Ridge width in mm, in (0, period_mm); default half the period.
    height_mm : float
        Ridge height in mm above the grooves (> 0).
    length_mm, width_mm : float
        Extent along Y (the ridges' long axis) and X in mm; a periodic
        grating's width is rounded to whole periods (one tile).
    pixel_mm : float
        Grid spacing in mm.
    periodic : bool
        Whether the grating tiles in X and Y (default) or ends at its edges.

    Returns
    -------
    Surface

    Examples
    --------
    >>> g = grating(1.0, ridge_mm=0.3, width_mm=2.0, length_mm=0.5, pixel_mm=0.1)
    >>> g.shape, g.height_mm[0].tolist()[:10]
    ((5, 20), [0.5, 0.5, 0.5, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0])
    """
    pixel_mm = check_positive(pixel_mm, "pixel_mm", "mm")
    period_mm = check_positive(period_mm, "period_mm", "mm")
    _whole_pixels(period_mm, "period_mm", pixel_mm)
    ridge_mm = period_mm / 2.0 if ridge_mm is None else check_positive(ridge_mm, "ridge_mm", "mm")
    if ridge_mm >= period_mm:
        raise ValueError(f"ridge_mm={shown(ridge_mm)} mm must be less than period_mm={shown(period_mm)} mm")
    height_mm = check_positive(height_mm, "height_mm", "mm")
    x, _ = _tile(length_mm, width_mm, period_mm, pixel_mm, pixel_mm, periodic)
    return Surface(np.where(np.mod(x, period_mm) < ridge_mm, height_mm, 0.0), pixel_mm, periodic)


def dot_pattern(spacing_mm: float, dot_radius_mm: float = 0.5, height_mm: float = 0.5, *, length_mm: float = 20.0,
                width_mm: float = 20.0, pixel_mm: float = 0.05, periodic: bool = True) -> Surface:
    """A square lattice of raised flat-topped round dots, ``spacing_mm`` apart along X and Y.

    Each dot is centred in its ``spacing_mm`` cell; ``spacing_mm`` is a whole
    number (>= 2) of pixels and the dots may not touch (``2 * dot_radius_mm <
    spacing_mm``).  The other arguments are `grating`'s.

    Examples
    --------
    >>> d = dot_pattern(2.0, 0.5, 0.3, width_mm=4.0, length_mm=4.0, pixel_mm=0.1)
    >>> d.shape, d.max_height_mm, round(float((d.height_mm > 0).mean()), 2)  # pi r^2 / s^2 of the area
    ((40, 40), 0.3, 0.2)
    """
    pixel_mm = check_positive(pixel_mm, "pixel_mm", "mm")
    spacing_mm = check_positive(spacing_mm, "spacing_mm", "mm")
    _whole_pixels(spacing_mm, "spacing_mm", pixel_mm)
    dot_radius_mm = check_positive(dot_radius_mm, "dot_radius_mm", "mm")
    if 2.0 * dot_radius_mm >= spacing_mm:
        raise ValueError(f"dot_radius_mm={shown(dot_radius_mm)} mm is too large for spacing_mm={shown(spacing_mm)} mm: "
                         "the dots would touch (need 2 * dot_radius_mm < spacing_mm)")
    height_mm = check_positive(height_mm, "height_mm", "mm")
    x, y = _tile(length_mm, width_mm, spacing_mm, spacing_mm, pixel_mm, periodic)
    r = np.hypot(np.mod(x, spacing_mm) - spacing_mm / 2.0, np.mod(y, spacing_mm) - spacing_mm / 2.0)
    return Surface(np.where(r <= dot_radius_mm, height_mm, 0.0), pixel_mm, periodic)


def from_bitmap(array, pixel_mm: float, relief_mm: float) -> Surface:
    """A finite surface from an image: each entry (in [0, 1], or bool) times ``relief_mm`` is a pixel's height.

    The array reads as printed, seen from above: its first row is the top
    (the largest y), its first column the left (the smallest x).

    Examples
    --------
    >>> s = from_bitmap([[1, 0], [0, 0]], pixel_mm=0.5, relief_mm=0.4)
    >>> s.height_mm.tolist()  # row 0 is now the lowest y
    [[0.0, 0.0], [0.4, 0.0]]
    """
    arr = as_finite_array(array, "array", ndim=2)
    if arr.size and (arr.min() < 0.0 or arr.max() > 1.0):
        raise ValueError(f"array must hold values in [0, 1] (or bool), got a range of {shown(float(arr.min()))} to "
                         f"{shown(float(arr.max()))}")
    relief_mm = check_positive(relief_mm, "relief_mm", "mm")
    return Surface(relief_mm * arr[::-1], check_positive(pixel_mm, "pixel_mm", "mm"))


def _text_cells(text: str) -> np.ndarray:
    """The text's glyphs as a 0/1 cell bitmap, top row first: one blank cell between glyphs and around them."""
    check_instance(text, "text", str, "a str")
    glyphs = text.upper()
    unknown = sorted({c for c in glyphs if c not in FONT_5X7})
    if not glyphs.strip() or unknown:
        raise ValueError(f"text={text!r} must hold letters A-Z, digits 0-9 and spaces (at least one that is not a "
                         f"space); {'unknown: ' + repr(''.join(unknown)) if unknown else 'got none'}")
    cols = [np.zeros((7, 1))]
    for c in glyphs:
        cols += [np.array([[ch == "#" for ch in row] for row in FONT_5X7[c]], dtype=float), np.zeros((7, 1))]
    body = np.hstack(cols)
    return np.pad(body, ((1, 1), (0, 0)))


def letters(text: str, *, height_mm: float = 6.0, relief_mm: float = 0.5, pixel_mm: float = 0.1) -> Surface:
    """Embossed capitals and digits (a 5 x 7 bitmap font, `FONT_5X7`), reading along +X, upright along +Y.

    Each glyph is 5 x 7 square cells of ``height_mm / 7``; one blank cell
    separates the glyphs and borders the text.  Lower case is read as upper
    case; a space is a blank glyph.

    Parameters
    ----------
    text : str
    height_mm : float
        Letter (cap) height in mm.
    relief_mm : float
        How far the strokes stand above the base plane, mm.
    pixel_mm : float
        Grid spacing in mm (at most a cell, ``height_mm / 7``).

    Examples
    --------
    >>> s = letters("I", height_mm=7.0, pixel_mm=1.0)  # one pixel per cell
    >>> s.shape, s.height_mm[::-1][1].tolist()  # the top stroke of the I
    ((9, 7), [0.0, 0.0, 0.5, 0.5, 0.5, 0.0, 0.0])
    """
    cells = _text_cells(text)
    cell = check_positive(height_mm, "height_mm", "mm") / 7.0
    pixel_mm = check_positive(pixel_mm, "pixel_mm", "mm")
    if pixel_mm > cell * (1.0 + 1e-9):
        raise ValueError(f"pixel_mm={shown(pixel_mm)} mm is coarser than a glyph cell (height_mm / 7 = {cell:g} mm); "
                         "use a smaller pixel_mm or taller letters")
    n_rows, n_cols = (round(k * cell / pixel_mm) for k in cells.shape)
    rows = np.minimum(((np.arange(n_rows) + 0.5) * pixel_mm / cell).astype(int), cells.shape[0] - 1)
    cols = np.minimum(((np.arange(n_cols) + 0.5) * pixel_mm / cell).astype(int), cells.shape[1] - 1)
    return from_bitmap(cells[np.ix_(rows, cols)], pixel_mm, relief_mm)
