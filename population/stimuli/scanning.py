"""Scanning: a textured surface slid across the fingertip, as an indentation scene (issue 43, part 1).

`scan` presses a `ddmm.population.stimuli.surfaces.Surface` into a window of
skin and slides it across at a constant velocity:

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
   loads and the scene; ``lattice_average`` then averages them over the pin
   lattice's positions.

`scan_depths` gives the pins and depths alone, for another model;
`min_scan_fs` the slowest sample rate a scan accepts.

Frame: positions in mm in the population's frame (+X radial, +Y distal); a
direction of 0 deg is +X, 90 deg +Y.
"""

from __future__ import annotations

import dataclasses
import math

import numpy as np

from ddmm.population.stimuli._contact_kernels import box_average
from ddmm.population.stimuli.contact import SkinMechanics, get_skin_mechanics
from ddmm.population.stimuli.indentation import MAX_DEPTH_MM, MAX_PINS, Pins, _indent_bytes, indent
from ddmm.population.stimuli.scenes import Scene
from ddmm.population.stimuli.surfaces import Surface
from ddmm.utils.resources import check_memory
from ddmm.utils.validation import (
    as_finite_array,
    check_flag,
    check_instance,
    check_nonnegative,
    check_positive,
    check_real,
    shown,
)

__all__ = ["MAX_SPEED_MM_S", "MAX_WINDOW_MM", "MIN_DEFAULT_FS", "MIN_PITCH_MM", "min_scan_fs", "scan", "scan_depths"]

#: Widest scan window side in mm (a fingertip's contact patch is about 10 x 15 mm).
MAX_WINDOW_MM = 20.0
#: Finest pin pitch in mm (below it the elastic pins crowd each other for little gain).
MIN_PITCH_MM = 0.05
#: Fastest scan in mm/s (free exploration of textures runs at 10-300 mm/s).
MAX_SPEED_MM_S = 500.0
#: The lowest sample rate in Hz `scan` picks when given none: the fitted transduction's 1000 Hz corner below Nyquist.
MIN_DEFAULT_FS = 2500.0


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
    check_flag(friction, "friction")
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
        The scene's name (default from the speed and direction, and
        ``_lattice_averaged`` when averaged).

    Returns
    -------
    Scene
        `ddmm.population.stimuli.indentation.indent` of the window's pins.

    Examples
    --------
    >>> from ddmm.population.stimuli.surfaces import grating
    >>> s = scan(grating(1.0), duration_s=0.05, window_mm=(2.0, 2.0), pitch_mm=0.5)
    >>> s.n_sites, s.n_samples, s.fs, bool(s.fz.max() > 0), bool(s.fx.max() > 0)
    (16, 125, 2500.0, True, True)
    """
    skin = _scan_skin(skin, friction)
    check_flag(lattice_average, "lattice_average")
    pins, depth, travel, unit, fs = _scan_track(surface, speed_mm_s, direction_deg, duration_s, contact_mm, window_mm,
                                                pitch_mm, fs, center_mm, ramp_s, friction)
    lateral = travel[:, None] * unit[None, :] if friction else None
    if name is None:
        name = (f"scan_{float(speed_mm_s):g}mm_s_{np.rad2deg(np.deg2rad(float(direction_deg))):g}deg"
                + ("_lattice_averaged" if lattice_average else ""))
    scene = indent(pins, depth, fs=fs, lateral_mm=lateral, skin=skin, transduction=transduction, name=name)
    if not lattice_average:
        return scene
    del depth, lateral  # what `indent`'s memory estimate counted the scan as holding
    forces = scene.site_forces.copy()
    for axis in np.abs(unit):  # one crossing time per lattice axis the motion has a part along
        if axis > 1e-9:
            box_average(forces, fs, float(pitch_mm) / (float(speed_mm_s) * axis), out=forces)
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
    >>> from ddmm.population.stimuli.surfaces import grating
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
