"""Scanned surfaces: a textured surface slid across the fingertip, as an indentation scene (issue 43, part 1).

A `Surface` is a heightmap (mm above its base plane, raised features
positive) on a square grid; `grating`, `dot_pattern`, `letters` and
`from_bitmap` make them.  `scan` presses a surface into a window of skin and
slides it across at a constant velocity:

1. the skin under the window is a grid of fixed pins (`indentation.Pins`,
   pitch ``pitch_mm``, radius half the pitch): the scene's sites stay put
   while the surface moves over them;
2. the surface's highest point sits ``contact_mm`` into the skin, so its base
   plane sits ``contact_mm - max height``; each pin's depth is
   ``contact_mm - (max height - h)`` with ``h`` the surface's height over the
   pin (bilinear in the heightmap), floored at 0 (no contact);
3. with friction the moving surface drags the skin: every pin is given the
   surface's displacement as its lateral motion, so each touching pin sticks,
   then slips at ``friction * P`` along the motion
   (`ddmm.population.stimuli.contact.tangential_loads`);
4. `ddmm.population.stimuli.indentation.indent` turns the depths into the pins'
   loads and the scene.

Frame: positions in mm in the population's frame (+X radial, +Y distal); a
direction of 0 deg is +X, 90 deg +Y.  A surface's own frame has its origin at
its centre, rows along +Y (row 0 the lowest y) and columns along +X.
"""

from __future__ import annotations

import dataclasses
import math
from dataclasses import dataclass

import numpy as np

from ddmm.population.stimuli._contact_kernels import bilinear, box_average
from ddmm.population.stimuli._font import FONT_5X7
from ddmm.population.stimuli.contact import SkinMechanics, get_skin_mechanics
from ddmm.population.stimuli.indentation import MAX_DEPTH_MM, MAX_PINS, Pins, _indent_bytes, indent
from ddmm.population.stimuli.scenes import Scene
from ddmm.utils.resources import check_memory
from ddmm.utils.validation import (
    as_finite_array,
    check_instance,
    check_nonnegative,
    check_positive,
    check_real,
    shown,
)

__all__ = ["FONT_5X7", "Surface", "dot_pattern", "from_bitmap", "grating", "letters", "min_scan_fs", "scan",
           "scan_depths"]

#: Widest scan window side in mm (a fingertip's contact patch is about 10 x 15 mm).
MAX_WINDOW_MM = 20.0
#: Finest pin pitch in mm (below it the elastic pins crowd each other for little gain).
MIN_PITCH_MM = 0.05
#: Fastest scan in mm/s (free exploration of textures runs at 10-300 mm/s).
MAX_SPEED_MM_S = 500.0
#: The lowest sample rate in Hz `scan` picks when given none: the fitted transduction's 1000 Hz corner below Nyquist.
MIN_DEFAULT_FS = 2500.0


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


def min_scan_fs(speed_mm_s: float, pixel_mm: float) -> float:
    """The lowest sample rate (Hz) of a scan `simulate` runs at its default step: the smallest rate at or above
    ``2 * speed_mm_s / pixel_mm`` whose sample interval is a whole number of 0.1 ms steps (``10000 / k`` Hz).

    `scan` refuses a rate below ``2 * speed_mm_s / pixel_mm``: the surface
    then moves at most half a pixel between samples, so its finest detail (a
    period of two pixels, at ``speed / (2 pixel)`` Hz) gets at least 4
    samples a cycle, and the bilinear height between pixel centres at least
    2 samples per pixel.  Above 10 kHz no rate is a whole number of 0.1 ms
    steps: that bound itself is returned, and `simulate` needs a ``dt`` that
    divides its interval.

    Examples
    --------
    >>> min_scan_fs(40.0, 0.05)  # 1600 Hz is 0.625 ms: 10000 / 6 Hz is the next whole number of steps
    1666.6666666666667
    >>> min_scan_fs(50.0, 0.05)
    2000.0
    """
    speed = check_positive(speed_mm_s, "speed_mm_s", "mm/s")
    return _stepped_rate(2.0 * speed / check_positive(pixel_mm, "pixel_mm", "mm"))


def _stepped_rate(need_hz: float) -> float:
    """The smallest rate >= ``need_hz`` (up to rounding) whose interval is a whole number of `simulate`'s default
    steps (`ddmm.population.simulation.DEFAULT_DT`); ``need_hz`` itself above one step's rate."""
    from ddmm.population.simulation import DEFAULT_DT

    top = 1.0 / DEFAULT_DT
    return need_hz if need_hz > top else top / math.floor(min(top / need_hz, 1e15) * (1.0 + 1e-9))


def _window_pins(window_mm, pitch_mm: float, center_mm) -> Pins:
    """The window's skin as a grid of pins of pitch ``pitch_mm`` (radius half the pitch), centred at ``center_mm``."""
    window = as_finite_array(window_mm, "window_mm", ndim=1)
    centre = as_finite_array(center_mm, "center_mm", ndim=1)
    if window.size != 2 or np.any(window <= 0.0) or np.any(window > MAX_WINDOW_MM):
        raise ValueError(f"window_mm must be two sides (x, y) in (0, {MAX_WINDOW_MM:g}] mm, got {window.tolist()}")
    if centre.size != 2:
        raise ValueError(f"center_mm must be two numbers (x, y) in mm, got {centre.tolist()}")
    if pitch_mm < MIN_PITCH_MM:
        raise ValueError(f"pitch_mm={shown(pitch_mm)} mm is finer than the {MIN_PITCH_MM:g} mm allowed")
    n_x, n_y = (max(1, round(side / pitch_mm)) for side in window)
    if n_x * n_y > MAX_PINS:
        raise ValueError(f"window_mm={window.tolist()} at pitch_mm={shown(pitch_mm)} mm needs {n_x * n_y} pins, more "
                         f"than the {MAX_PINS} allowed; use a coarser pitch_mm or a smaller window_mm")
    gx, gy = np.meshgrid((np.arange(n_x) - (n_x - 1) / 2.0) * pitch_mm, (np.arange(n_y) - (n_y - 1) / 2.0) * pitch_mm)
    # a hair under half the pitch, so that rounding in the centres never reads as overlapping pins
    return Pins(gx.ravel() + centre[0], gy.ravel() + centre[1], 0.5 * pitch_mm * (1.0 - 1e-9))


def _scan_skin(skin, friction) -> SkinMechanics:
    if not isinstance(friction, (bool, np.bool_)):
        raise TypeError(f"friction must be True or False, got {type(friction).__name__} {shown(friction)}")
    skin = get_skin_mechanics(skin) if isinstance(skin, str) else check_instance(
        skin, "skin", SkinMechanics, "a skin name or a SkinMechanics")
    return skin if friction else dataclasses.replace(skin, friction=0.0)


def _check_scan(surface, speed_mm_s, contact_mm, fs) -> tuple:
    """Validated (speed, contact, fs) of a scan; refuses a sample rate that would alias the surface."""
    check_instance(surface, "surface", Surface, "a Surface (grating, dot_pattern, letters, from_bitmap)")
    speed = check_positive(speed_mm_s, "speed_mm_s", "mm/s")
    if speed > MAX_SPEED_MM_S:
        raise ValueError(f"speed_mm_s={shown(speed)} mm/s is faster than the {MAX_SPEED_MM_S:g} mm/s allowed")
    contact = check_positive(contact_mm, "contact_mm", "mm")
    if contact > MAX_DEPTH_MM:
        raise ValueError(f"contact_mm={shown(contact)} mm must be <= {MAX_DEPTH_MM:g} mm")
    need = 2.0 * speed / surface.pixel_mm
    if fs is None:  # the default: a rate simulate's default step divides
        return speed, contact, _stepped_rate(max(need, MIN_DEFAULT_FS))
    fs = check_positive(fs, "fs", "Hz")
    if fs < need * (1.0 - 1e-9):
        raise ValueError(f"fs={shown(fs)} Hz is too slow for a surface of pixel_mm={shown(surface.pixel_mm)} mm at "
                         f"speed_mm_s={shown(speed)} mm/s: need fs >= 2 * speed / pixel = {need:g} Hz (min_scan_fs "
                         f"gives {_stepped_rate(need):g} Hz, a whole number of simulate's 0.1 ms steps)")
    return speed, contact, fs


def scan(surface: Surface, *, speed_mm_s: float = 40.0, direction_deg: float = 0.0, duration_s: float = 1.0,
         contact_mm: float = 0.8, window_mm=(8.0, 8.0), pitch_mm: float = 0.2, friction: bool = True,
         fs: float | None = None, skin="default", transduction="fitted", center_mm=(0.0, 0.0), ramp_s: float = 0.0,
         lattice_average: bool = False, name: str | None = None):
    """A scene of ``surface`` pressed into the skin and slid across it at constant velocity.

    The surface's centre passes under ``center_mm`` half-way through the
    scan; it moves ``speed_mm_s * t`` along ``direction_deg``, so the pin at
    p sees the surface point ``p - center - v (t - duration_s / 2)`` (its
    frame).  Its highest point sits ``contact_mm`` into the skin: a pin's
    depth is ``contact_mm - (max height - h)``, floored at 0.

    Parameters
    ----------
    surface : Surface
    speed_mm_s : float
        Scan speed in mm/s, in (0, 500].
    direction_deg : float
        Direction of the surface's motion (0 = +X radial, 90 = +Y distal).
    duration_s : float
        Scan length in s.
    contact_mm : float
        Depth in mm of the surface's highest point into the skin, in (0, 10].
    window_mm : (float, float)
        Sides (x, y) in mm of the skin window under contact, each <= 20.
    pitch_mm : float
        Spacing of the skin's pins in mm, >= 0.05 (at most 4000 pins).
    friction : bool
        True: the surface drags each touching pin (stick, then slip at
        ``skin.friction * P`` along the motion); False: the same skin with
        no friction (no tangential loads).
    fs : float, optional
        Sample rate in Hz, at least ``2 * speed_mm_s / surface.pixel_mm``
        (the surface moves at most half a pixel a sample).  Default: the
        smallest rate at or above that and `MIN_DEFAULT_FS` (2500 Hz) whose
        interval is a whole number of `simulate`'s 0.1 ms steps
        (`min_scan_fs`): 2500 Hz up to 62.5 mm/s on a 0.05 mm pixel.
    skin : str or SkinMechanics
    transduction : str or mapping
        Each type's front end from stress to drive (`indent`'s).
    center_mm : (float, float)
        Centre of the window in mm.
    ramp_s : float
        Time in s over which the surface is lowered into the skin, its depths
        scaled by ``t / ramp_s`` while it already slides; 0 (default, as
        TouchSim's traces): at full depth from the first sample.
    lattice_average : bool
        False (default): the fixed lattice's loads, TouchSim's form.  True:
        each pin's loads averaged over the time the surface takes to cross
        one pitch along each lattice axis it moves along (``pitch / (speed
        |cos|)``, ``pitch / (speed |sin|)``, centred), the average over the
        lattice's positions; it removes the lattice's own frequencies (speed /
        pitch along an axis), which pins entering and leaving contact one
        column at a time give the loads, and FA-II answer.
    name : str, optional
        The scene's name (default from the speed and direction).

    Returns
    -------
    Scene
        `ddmm.population.stimuli.indentation.indent` of the window's pins.

    Examples
    --------
    >>> s = scan(grating(1.0), duration_s=0.05, window_mm=(2.0, 2.0), pitch_mm=0.5)
    >>> s.n_sites, s.n_samples, s.fs, bool(s.fz.max() > 0), bool(s.fx.max() > 0)
    (16, 125, 2500.0, True, True)
    """
    skin = _scan_skin(skin, friction)
    if not isinstance(lattice_average, (bool, np.bool_)):
        raise TypeError(f"lattice_average must be True or False, got {type(lattice_average).__name__} "
                        f"{shown(lattice_average)}")
    pins, depth, travel, unit, fs = _scan_track(surface, speed_mm_s, direction_deg, duration_s, contact_mm, window_mm,
                                                pitch_mm, fs, center_mm, ramp_s, friction)
    lateral = travel[:, None] * unit[None, :] if friction else None
    if name is None:
        name = f"scan_{float(speed_mm_s):g}mm_s_{np.rad2deg(np.deg2rad(float(direction_deg))):g}deg"
    scene = indent(pins, depth, fs=fs, lateral_mm=lateral, skin=skin, transduction=transduction, name=name)
    if not lattice_average:
        return scene
    forces = scene.site_forces
    for axis in np.abs(unit):  # one crossing time per lattice axis the motion has a part along
        if axis > 1e-9:
            forces = box_average(forces, fs, float(pitch_mm) / (float(speed_mm_s) * axis))
    return Scene.from_sites(forces, scene.sites, fs=fs, name=name)


def scan_depths(surface: Surface, *, speed_mm_s: float = 40.0, direction_deg: float = 0.0, duration_s: float = 1.0,
                contact_mm: float = 0.8, window_mm=(8.0, 8.0), pitch_mm: float = 0.2, fs: float | None = None,
                center_mm=(0.0, 0.0), ramp_s: float = 0.0) -> tuple:
    """The pins `scan` presses and their depths: the same stimulus as normal traces, for a model that takes pin
    depths (TouchSim's ``Stimulus(location=..., trace=depth.T, fs=fs, pin_radius=...)``).

    Arguments as `scan`'s of the same names (friction and the skin act after the depths).

    Returns
    -------
    pins : Pins
        The window's pins (positions and radius in mm).
    depth : ndarray, shape (n_samples, n_pins)
        Each pin's depth into the skin in mm (>= 0).
    fs : float
        Sample rate in Hz (`scan`'s default when ``fs`` is None).

    Examples
    --------
    >>> pins, depth, fs = scan_depths(grating(1.0), duration_s=0.05, window_mm=(2.0, 2.0), pitch_mm=0.5)
    >>> len(pins), depth.shape, fs, float(depth.max())
    (16, (125, 16), 2500.0, 0.8)
    """
    pins, depth, _, _, fs = _scan_track(surface, speed_mm_s, direction_deg, duration_s, contact_mm, window_mm, pitch_mm,
                                        fs, center_mm, ramp_s, False)
    return pins, depth, fs


def _scan_track(surface, speed_mm_s, direction_deg, duration_s, contact_mm, window_mm, pitch_mm, fs, center_mm, ramp_s,
                friction) -> tuple:
    """`scan`'s pins, their depths (n_samples, n_pins) mm, the travel (n_samples,) mm along the unit direction
    (2,), and the sample rate in Hz; the arguments validated."""
    speed, contact, fs = _check_scan(surface, speed_mm_s, contact_mm, fs)
    angle = np.deg2rad(check_real(direction_deg, "direction_deg", "deg"))
    duration = check_positive(duration_s, "duration_s", "s")
    ramp = check_nonnegative(ramp_s, "ramp_s", "s")
    if ramp > duration:
        raise ValueError(f"ramp_s={shown(ramp)} s must be at most duration_s={shown(duration)} s")
    pins = _window_pins(window_mm, check_positive(pitch_mm, "pitch_mm", "mm"), center_mm)
    # `indent`'s peak while the scan holds the heights and the depths (two more (samples, pins) arrays)
    check_memory(_indent_bytes(duration * fs, len(pins), friction, held=2), f"a scan of {duration * fs:.0f} samples "
                 f"x {len(pins)} pins", "use fewer pins or samples")
    n = round(duration * fs)
    if n < 2:
        raise ValueError(f"duration_s={shown(duration)} s at fs={shown(fs)} Hz gives {n} sample(s); need 2 or more")
    travel = speed * (np.arange(n) / fs)  # mm along the direction
    unit = np.array([np.cos(angle), np.sin(angle)])
    shift = (travel - speed * duration / 2.0)[:, None] * unit[None, :]
    centre = np.array([pins.x_mm.mean(), pins.y_mm.mean()])
    h = surface.height_at(pins.x_mm[None, :] - centre[0] - shift[:, :1], pins.y_mm[None, :] - centre[1] - shift[:, 1:])
    depth = np.maximum(contact - (surface.max_height_mm - h), 0.0)
    if ramp > 0.0:  # lowered in while it slides: the onset no longer steps every pin at once
        depth *= np.minimum(np.arange(n) / (ramp * fs), 1.0)[:, None]
    return pins, depth, travel, unit, fs
