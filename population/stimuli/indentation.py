"""Indentation stimuli: rigid pins pressed into the skin, as a multi-site scene the DDMM reads.

A TouchSim user thinks in skin displacement: a probe indented 0.5 mm, a
250 Hz vibration of 20 um, a bar or a pin array pressed into the fingertip.
`indent` turns such a stimulus into a `Scene` through the skin mechanics of
`ddmm.population.stimuli.contact`:

1. the pins (`Pins`: `probe`, `bar_pins`, `circle_pins`, `pin_array`) and a
   depth waveform per pin (`ddmm.population.stimuli.waveforms`: `ramp_hold`,
   `sinusoid`, `band_noise`, `impulse`, or any array) give each sample's
   indentation in mm;
2. the skin (``skin="default"`` or ``"touchsim"``, `SkinMechanics`) gives
   each pin's normal load (N; pins in contact only, none pulls), and a pin
   moved sideways (``lateral_mm``) its tangential load by Coulomb stick and
   slip;
3. the scene's sites are the pins, each with its load ``(Q_x, Q_y, P)``, and
   their spread to the afferents is the mechanics' (`ContactSpread`): the
   normal stress each pin's load causes at each afferent's receptor depth
   (its type's, `ddmm.models.afferent_types.AfferentType.receptor_depth_mm`, or the skin's
   table), times the reference area the model's forces refer to
   (`ddmm.population.stimuli.scenes.REFERENCE_AREA_MM2`).  An afferent under a
   uniform pressure p over a fingertip-sized contact thus feels p x A_ref,
   the force the force path would give it.

The spatial spread is counted once: the mechanics replace the receptive
fields for these scenes (docs/model.md, "Skin contact mechanics").  The
tangential loads spread with the same kernel, so the DDMM's NAPs read the
pins' traction direction at each afferent, and both engines apply unchanged.

Positions are in mm in the population's frame (+X radial, +Y distal), depths
in mm into the skin, times in s, loads in N.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from ddmm.population.stimuli.contact import (
    effective_radius,
    get_skin_mechanics,
    receptor_depths,
    solve_pin_loads,
    stress_kernel,
    tangential_loads,
)
from ddmm.population.stimuli.scenes import REFERENCE_AREA_MM2, Scene, Sites
from ddmm.population.stimuli.transduction import get_transduction
from ddmm.population.stimuli.waveforms import INDENT_FS, band_noise, impulse, ramp_hold, sinusoid
from ddmm.utils.resources import check_memory
from ddmm.utils.validation import as_finite_array, check_nonnegative, check_positive, check_real, shown

__all__ = ["ContactSpread", "Pins", "bar_pins", "band_noise", "circle_pins", "impulse", "indent", "pin_array",
           "probe", "ramp_hold", "sinusoid"]

#: Longest indentation in mm a pin may be given: deeper than the fingertip pad's soft tissue.
MAX_DEPTH_MM = 10.0
#: Most pins a stimulus may use (the contact solve is cubic in the touching pins).
MAX_PINS = 4000


@dataclass(frozen=True, eq=False)
class Pins:
    """Rigid flat-ended cylindrical pins over the skin.

    Attributes
    ----------
    x_mm, y_mm : ndarray, shape (n_pins,)
        Pin centres in mm (the population's frame).
    radius_mm : float
        Pin radius in mm (every pin's).
    offset_mm : ndarray, shape (n_pins,)
        Each pin's depth relative to the stimulus waveform in mm (0: flat;
        a curved shape's edge pins sit higher, negative).

    Examples
    --------
    >>> len(pin_array(3, 4, pitch_mm=1.0))
    12
    """

    x_mm: np.ndarray
    y_mm: np.ndarray
    radius_mm: float = 0.5
    offset_mm: np.ndarray | None = None

    def __post_init__(self):
        x = np.atleast_1d(as_finite_array(self.x_mm, "pins x_mm"))
        y = np.atleast_1d(as_finite_array(self.y_mm, "pins y_mm"))
        if x.ndim != 1 or x.shape != y.shape or x.size == 0:
            raise ValueError(f"pins x_mm and y_mm must be 1-D of one equal, non-zero length; got {x.shape} and "
                             f"{y.shape}")
        check_positive(self.radius_mm, "radius_mm", "mm")
        offset = np.zeros(x.size) if self.offset_mm is None else np.atleast_1d(
            as_finite_array(self.offset_mm, "pins offset_mm"))
        if offset.shape != x.shape:
            raise ValueError(f"pins offset_mm must hold one value per pin ({x.size}), got shape {offset.shape}")
        for name, arr in (("x_mm", x), ("y_mm", y), ("offset_mm", offset)):
            arr = np.array(arr, dtype=float)
            arr.setflags(write=False)
            object.__setattr__(self, name, arr)
        object.__setattr__(self, "radius_mm", float(self.radius_mm))

    def __len__(self) -> int:
        return self.x_mm.size


def probe(x_mm: float = 0.0, y_mm: float = 0.0, radius_mm: float = 0.5) -> Pins:
    """One cylindrical probe (TouchSim's default: 1 mm across) centred at (x, y) mm.

    Examples
    --------
    >>> probe(radius_mm=0.25).radius_mm
    0.25
    """
    check_real(x_mm, "x_mm", "mm")
    check_real(y_mm, "y_mm", "mm")
    return Pins([float(x_mm)], [float(y_mm)], radius_mm)


def pin_array(rows: int, cols: int, *, pitch_mm: float = 1.0, center_mm=(0.0, 0.0), radius_mm: float | None = None
              ) -> Pins:
    """A rows x cols grid of pins of pitch ``pitch_mm`` (a braille cell or an Optacon), centred at ``center_mm``.

    ``radius_mm`` defaults to a quarter of the pitch (pins half as wide as their spacing).

    Examples
    --------
    >>> p = pin_array(2, 2, pitch_mm=2.0)
    >>> p.x_mm.tolist(), p.radius_mm
    ([-1.0, 1.0, -1.0, 1.0], 0.5)
    """
    for name, n in (("rows", rows), ("cols", cols)):
        if isinstance(n, bool) or not isinstance(n, (int, np.integer)) or not 1 <= n <= 100:
            raise ValueError(f"{name} must be a whole number in [1, 100], got {shown(n)}")
    check_positive(pitch_mm, "pitch_mm", "mm")
    cx, cy = _centre(center_mm)
    gx, gy = np.meshgrid((np.arange(cols) - (cols - 1) / 2.0) * pitch_mm, (np.arange(rows) - (rows - 1) / 2.0) * pitch_mm)
    return Pins(gx.ravel() + cx, gy.ravel() + cy, pitch_mm / 4.0 if radius_mm is None else radius_mm)


def bar_pins(width_mm: float = 1.0, height_mm: float = 0.5, *, angle_deg: float = 0.0, pins_per_mm: float = 10.0,
             center_mm=(0.0, 0.0)) -> Pins:
    """A bar ``width_mm`` x ``height_mm`` tiled by pins (``pins_per_mm``), turned by ``angle_deg`` from +X.

    The pins' radius is half their spacing, so they tile the bar; at most `MAX_PINS` pins.

    Examples
    --------
    >>> len(bar_pins(1.0, 0.5, pins_per_mm=4.0))
    8
    """
    for name, v in (("width_mm", width_mm), ("height_mm", height_mm), ("pins_per_mm", pins_per_mm)):
        check_positive(v, name, "mm" if name != "pins_per_mm" else "per mm")
    check_real(angle_deg, "angle_deg", "deg")
    step = 1.0 / pins_per_mm
    nx, ny = (max(1.0, float(np.rint(side * pins_per_mm))) for side in (width_mm, height_mm))
    _check_pin_count(nx * ny, "bar", f"of {shown(width_mm)} x {shown(height_mm)} mm at "
                     f"pins_per_mm={shown(pins_per_mm)}")
    nx, ny = int(nx), int(ny)
    gx, gy = np.meshgrid((np.arange(nx) - (nx - 1) / 2.0) * step, (np.arange(ny) - (ny - 1) / 2.0) * step)
    a = np.deg2rad(angle_deg)
    x, y = gx.ravel() * np.cos(a) - gy.ravel() * np.sin(a), gx.ravel() * np.sin(a) + gy.ravel() * np.cos(a)
    cx, cy = _centre(center_mm)
    return Pins(x + cx, y + cy, step / 2.0)


def circle_pins(radius_mm: float = 2.0, *, pins_per_mm: float = 10.0, curvature_mm: float = 0.0,
                center_mm=(0.0, 0.0)) -> Pins:
    """A disc of radius ``radius_mm`` tiled by pins; with ``curvature_mm`` > 0 a dome whose edge sits that much
    higher than its centre (a sphere's cap, read as a parabola); at most `MAX_PINS` pins.

    Examples
    --------
    >>> p = circle_pins(1.0, pins_per_mm=2.0, curvature_mm=0.2)
    >>> len(p), float(p.offset_mm.min()) >= -0.2
    (12, True)
    """
    check_positive(radius_mm, "radius_mm", "mm")
    check_positive(pins_per_mm, "pins_per_mm", "per mm")
    check_nonnegative(curvature_mm, "curvature_mm", "mm")
    step = 1.0 / pins_per_mm
    n = max(1.0, float(np.rint(2.0 * radius_mm * pins_per_mm)))
    what = f"of radius {shown(radius_mm)} mm at pins_per_mm={shown(pins_per_mm)}"
    if n * n > 4 * MAX_PINS:  # too many to build: the disc holds about pi / 4 of its square's n^2 points
        _check_pin_count(np.pi / 4.0 * n * n, "disc", what)
    axis = (np.arange(int(n)) - (n - 1) / 2.0) * step
    gx, gy = (g.ravel() for g in np.meshgrid(axis, axis))
    inside = np.hypot(gx, gy) <= radius_mm
    _check_pin_count(np.count_nonzero(inside), "disc", what)
    offset = -curvature_mm * (np.hypot(gx, gy)[inside] / radius_mm) ** 2
    cx, cy = _centre(center_mm)
    return Pins(gx[inside] + cx, gy[inside] + cy, step / 2.0, offset)


def _check_pin_count(count: float, shape: str, what: str) -> None:
    """Refuse a ``shape`` (``"bar"``, ``"disc"``) of more than `MAX_PINS` pins, before building it."""
    if count > MAX_PINS:
        raise ValueError(f"a {shape} {what} would take about {count:.0f} pins, more than the {MAX_PINS} allowed; use a "
                         f"lower pins_per_mm or a smaller {shape}")


def _centre(center_mm) -> tuple:
    c = as_finite_array(center_mm, "center_mm", ndim=1)
    if c.size != 2:
        raise ValueError(f"center_mm must be two numbers (x, y) in mm, got {c.size}")
    return float(c[0]), float(c[1])


@dataclass(frozen=True)
class ContactSpread:
    """How a contact scene's pin loads reach the afferents: the skin's normal stress at their receptor depth.

    The coefficient of pin s at afferent i is ``A_ref K_si``, with ``K_si``
    the compressive stress (per newton on the pin, in 1/mm^2) at the
    afferent's depth (`ddmm.population.stimuli.contact.stress_kernel`) and A_ref
    `ddmm.population.stimuli.scenes.REFERENCE_AREA_MM2`.  Coefficients below
    ``floor`` times the pin's largest one at that depth (right under it) are
    dropped: the afferents no pin reaches are provably silent and skipped.

    Attributes
    ----------
    skin : SkinMechanics
    radius_mm : float
        The pins' radius in mm (as the skin uses it).
    floor : float
        Relative floor of the coefficients (dimensionless).
    transduction : tuple
        ``(type code, Transduction)`` pairs (`ddmm.population.stimuli.transduction.get_transduction`):
        each type's gain scales its coefficients, its lead-lag runs before its
        own filters (`input_sections`); a type left out: unit gain, no filter.
    """

    skin: object
    radius_mm: float
    floor: float = 1e-6
    transduction: tuple = ()

    def input_sections(self, fs: float) -> dict:
        """{type code: filter sections at ``fs`` Hz} of the types whose transduction filters (for
        `ddmm.models.fused.FusedPipeline`'s ``input_sections``); a corner at or above ``fs / 2`` is
        compressed towards it, not refused (`ddmm.population.stimuli.transduction.Transduction.sections`)."""
        out = {kind: t.sections(fs) for kind, t in self.transduction}
        return {kind: sos for kind, sos in out.items() if sos is not None}

    def describe(self) -> dict:
        """{name: value} of what shapes the spikes besides the loads, for a Dataset's per-condition record:
        the skin's name and each type's transduction (gain, and zero and pole in Hz, NaN without a filter)."""
        out = {"skin": self.skin.name}
        for kind, t in self.transduction:
            out.update({f"transduction_{kind}_gain": t.gain,
                        f"transduction_{kind}_zero_hz": np.nan if t.zero_hz is None else t.zero_hz,
                        f"transduction_{kind}_pole_hz": np.nan if t.pole_hz is None else t.pole_hz})
        return out

    def _gains(self, afferent_type) -> np.ndarray:
        gains = np.ones(np.shape(afferent_type))
        for kind, t in self.transduction:
            gains[np.asarray(afferent_type) == kind] = t.gain
        return gains

    def check_reach(self, population, sites) -> None:
        """Refuse a pin off the skin the population covers: farther from every afferent than
        `skin_gap_mm` (a ValueError naming the pin and its position)."""
        from scipy.spatial import cKDTree

        tree = cKDTree(np.column_stack([population.x_mm, population.y_mm]))
        gap = skin_gap_mm(population, tree)
        dist, _ = tree.query(np.column_stack([sites.x_mm, sites.y_mm]))
        off = np.flatnonzero(dist > gap)
        if off.size:
            s = int(off[0])
            raise ValueError(f"pin {sites.site_id[s]!r} at ({float(sites.x_mm[s]):g}, {float(sites.y_mm[s]):g}) mm is off "
                             f"the skin of population {population.name!r}: {float(dist[s]):.3g} mm from its nearest "
                             f"afferent (at most {gap:.3g} mm)")

    def local_mixing(self, x_mm, y_mm, afferent_type, sites):
        """The sparse coefficients of each afferent's local force and its coverage (1 if any pin reaches it),
        as `ddmm.population.anatomy.receptive_fields.local_mixing` returns them."""
        x_mm, y_mm = np.asarray(x_mm, dtype=float), np.asarray(y_mm, dtype=float)
        depth = receptor_depths(np.asarray(afferent_type), self.skin)
        k = stress_kernel(sites.x_mm, sites.y_mm, self.radius_mm, x_mm, y_mm, depth) * 1e-6  # Pa per N -> 1/mm^2
        peak = stress_kernel(np.zeros(1), np.zeros(1), self.radius_mm, np.zeros(depth.size), np.zeros(depth.size),
                             depth)[0] * 1e-6
        w = np.where(k >= self.floor * peak[None, :], k * REFERENCE_AREA_MM2, 0.0).T  # (n_afferents, n_pins)
        w *= self._gains(afferent_type)[:, None]
        rows, cols = np.nonzero(w)
        indptr = np.concatenate([[0], np.cumsum(np.bincount(rows, minlength=w.shape[0]))]).astype(np.int64)
        return indptr, cols.astype(np.int64), w[rows, cols], np.any(w > 0.0, axis=1).astype(float)


def skin_gap_mm(population, tree=None) -> float:
    """How far (mm) from its nearest afferent a point may lie and still be on the population's skin:
    twice the median spacing of neighbouring afferents, and at least 2 mm."""
    from scipy.spatial import cKDTree

    xy = np.column_stack([population.x_mm, population.y_mm])
    if xy.shape[0] < 2:
        return 2.0
    tree = cKDTree(xy) if tree is None else tree
    spacing, _ = tree.query(xy, k=2)
    return max(2.0, 2.0 * float(np.median(spacing[:, 1])))


def indent(pins: Pins, depth_mm, *, fs: float = INDENT_FS, lateral_mm=None, skin="default",
           transduction="fitted", name: str = "indentation") -> Scene:
    """A scene of ``pins`` pressed into the skin by ``depth_mm``, through the skin's mechanics.

    Parameters
    ----------
    pins : Pins
    depth_mm : array_like, shape (n_samples,) or (n_samples, n_pins)
        Indentation in mm (>= 0) of every pin, or of each; each pin's
        ``offset_mm`` is added (a pin above the skin touches nothing).
    fs : float
        Sample rate in Hz.
    lateral_mm : array_like, shape (n_samples, 2) or (n_samples, n_pins, 2), optional
        Sideways displacement of every pin (or each) in mm, (x, y): it loads
        the skin tangentially, with Coulomb stick and slip.
    skin : str or SkinMechanics
        ``"default"`` or ``"touchsim"`` (`ddmm.population.stimuli.contact.SKIN_MODELS`).
    transduction : str or mapping
        Each type's front end from stress to drive: ``"fitted"`` (default),
        ``"none"`` (the mechanics straight into the force path) or a mapping
        of type to `ddmm.population.stimuli.transduction.Transduction`.
    name : str

    Returns
    -------
    Scene
        A multi-site scene, one site per pin with its load (Q_x, Q_y, P) in N,
        spread to the afferents by the mechanics and the transduction
        (`ContactSpread`).

    Examples
    --------
    >>> s = indent(probe(), ramp_hold(0.5, fs=1000.0), fs=1000.0)
    >>> s.n_sites, bool(s.fz.max() > 0)
    (1, True)
    """
    if not isinstance(pins, Pins):
        raise TypeError(f"pins must be a Pins (probe, bar_pins, circle_pins, pin_array), got {type(pins).__name__}")
    skin = get_skin_mechanics(skin) if isinstance(skin, str) else skin
    depth = _pin_depths(depth_mm, pins, lateral_mm is not None)
    check_positive(fs, "fs", "Hz")
    radius = effective_radius(pins.x_mm, pins.y_mm, pins.radius_mm, skin)
    loads = solve_pin_loads(depth, pins.x_mm, pins.y_mm, radius, skin)
    forces = np.zeros(loads.shape + (3,))
    forces[:, :, 2] = loads
    if lateral_mm is not None:
        forces[:, :, :2] = tangential_loads(_lateral(lateral_mm, depth.shape), loads, radius, skin)
    sites = Sites(pins.x_mm, pins.y_mm, radius, site_id=[f"pin{i}" for i in range(len(pins))],
                  spread=ContactSpread(skin, radius, transduction=get_transduction(transduction)))
    return Scene.from_sites(forces, sites, fs=fs, name=name)


def _indent_bytes(n_samples: int, n_pins: int, lateral: bool, held: int = 1) -> float:
    """Peak resident bytes of `indent` on ``n_samples`` x ``n_pins`` (its caller holding ``held`` such float64
    arrays), checked against scans' measured peaks: its largest phase in (samples, pins) and (pins, pins) arrays,
    the compliance (1 and 4.25 square), the solve (5.75 and 3.25 square) or with ``lateral`` the friction (11:
    forces, motion, ...), and two freed square arrays the allocator keeps (glibc: those under 32 MiB)."""
    el, sq = float(n_samples) * n_pins, float(n_pins) ** 2
    phases = ((held + 1.0) * el + 4.25 * sq, (held + 5.75) * el + 3.25 * sq, (held + 11.0) * el * lateral)
    return 8.0 * max(phases) + 2.0 * min(8.0 * sq, 32 << 20)


def _pin_depths(depth_mm, pins: Pins, lateral: bool) -> np.ndarray:
    """(n_samples, n_pins) depths in mm: the waveform (validated >= 0) plus each pin's offset, floored at 0."""
    depth = as_finite_array(depth_mm, "depth_mm")
    if depth.ndim == 1:
        depth = depth[:, None]
    if depth.ndim != 2 or depth.shape[1] not in (1, len(pins)) or depth.shape[0] < 2:
        raise ValueError(f"depth_mm must be (n_samples,) or (n_samples, {len(pins)}) with 2 or more samples, got "
                         f"shape {np.shape(depth_mm)}")
    if np.any(depth < 0.0):
        k, j = np.argwhere(depth < 0.0)[0]
        raise ValueError(f"depth_mm must be >= 0 mm (into the skin); got {float(depth[k, j]):g} at sample {int(k)}, "
                         f"pin {int(j)}")
    if np.any(depth > MAX_DEPTH_MM):
        raise ValueError(f"depth_mm must be <= {MAX_DEPTH_MM:g} mm, got {float(depth.max()):g}")
    check_memory(_indent_bytes(depth.shape[0], len(pins), lateral), f"an indentation of {depth.shape[0]} samples x "
                 f"{len(pins)} pins", "use fewer pins or samples")
    return np.maximum(depth + pins.offset_mm[None, :], 0.0)


def _lateral(lateral_mm, shape) -> np.ndarray:
    lateral = as_finite_array(lateral_mm, "lateral_mm")
    if lateral.ndim == 2:
        lateral = np.repeat(lateral[:, None, :], shape[1], axis=1)
    if lateral.shape != shape + (2,):
        raise ValueError(f"lateral_mm must be (n_samples, 2) or (n_samples, n_pins, 2) = {shape + (2,)}, got shape "
                         f"{np.shape(lateral_mm)}")
    return lateral
