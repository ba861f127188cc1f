"""Scenes: three-axis fingertip force on a uniform time base.

Frame: +X radial, +Y distal, +Z into the skin (normal force >= 0), so a shear
direction theta = 0 deg is radial, 90 deg distal, 180 deg ulnar and 270 deg
proximal.  Forces are in newtons, times in seconds, positions in mm.
"""

from __future__ import annotations

from dataclasses import dataclass, field

import numpy as np

from ddmm.utils.resources import check_memory
from ddmm.utils.validation import as_finite_array, check_nonnegative, check_positive, check_real, shown

__all__ = [
    "DEFAULT_FS",
    "MAX_FS",
    "MAX_RADIUS_MM",
    "MAX_INCLINATION_DEG",
    "REFERENCE_AREA_MM2",
    "Contact",
    "Sites",
    "taxel_radius",
    "Stage",
    "Scene",
    "birznieks",
    "press_push_lift",
    "rotating_shear",
]

#: Default force sample rate in Hz: 50x the 20 Hz derivative cut-off.
DEFAULT_FS = 1000.0
#: Bounds of physical sense, checked by the constructors: sample rate (Hz), footprint radius (mm: larger than a
#: hand), and the inclination of Birznieks' force from the normal (deg: tan 80 = 5.7 times the normal force).
MAX_FS = 1.0e6
MAX_RADIUS_MM = 200.0
MAX_INCLINATION_DEG = 80.0
#: The contact area the model's forces refer to, mm^2: a fingertip pad under a flat surface at 2-4 N,
#: a disc of 6 mm radius (recalled, not read in a stored source: R).  A site's or a pin's traction
#: counts times this area (`ddmm.population.anatomy.receptive_fields`, `ddmm.population.stimuli.indentation`).
REFERENCE_AREA_MM2 = float(np.pi * 6.0 ** 2)


@dataclass(frozen=True)
class Contact:
    """Contact geometry on the fingertip: centre (mm, fingertip frame) and radius (mm)."""

    x_mm: float
    y_mm: float
    radius_mm: float

    def __post_init__(self):
        for name in ("x_mm", "y_mm"):
            check_real(getattr(self, name), f"contact {name}", "mm")
        check_positive(self.radius_mm, "contact radius_mm", "mm")
        if self.radius_mm > MAX_RADIUS_MM:
            raise ValueError(f"contact radius_mm must be <= {MAX_RADIUS_MM:g} mm (a contact larger than a hand), "
                             f"got {float(self.radius_mm):g}")


@dataclass(frozen=True, eq=False)
class Sites:
    """Where a scene's forces act: one footprint per site, in the population's frame.

    Attributes
    ----------
    x_mm, y_mm : ndarray, shape (n_sites,)
        Centre of each site in mm.
    radius_mm : ndarray, shape (n_sites,)
        Footprint radius in mm: the contact radius, or for a taxel of pitch
        p the equal-area radius ``p / sqrt(pi)`` (`taxel_radius`).
    region : ndarray of str, shape (n_sites,)
        Region label (e.g. ``"D2d"``), ``""`` when unknown.
    site_id : ndarray of str, shape (n_sites,)
        Unique site names.
    spread : object, optional
        How the sites' forces reach the afferents: None for the receptive
        fields (`ddmm.population.anatomy.receptive_fields.local_mixing`), or an object
        with that function's ``local_mixing(x_mm, y_mm, afferent_type,
        sites)`` and ``check_reach(population, sites)``, and optionally
        ``input_sections(fs)`` (filter sections by type run before each
        type's own): an indentation's skin mechanics and transduction
        (`ddmm.population.stimuli.indentation.ContactSpread`).
    """

    x_mm: np.ndarray
    y_mm: np.ndarray
    radius_mm: np.ndarray
    region: np.ndarray = None
    site_id: np.ndarray = None
    spread: object = None

    def __post_init__(self):
        x = as_finite_array(self.x_mm, "sites x_mm", ndim=1)
        n = x.size
        if n == 0:
            raise ValueError("sites x_mm must hold at least one site, got 0")
        y = as_finite_array(self.y_mm, "sites y_mm", ndim=1)
        r = np.broadcast_to(as_finite_array(self.radius_mm, "sites radius_mm"), (n,)).copy()
        if y.size != n:
            raise ValueError(f"sites: x_mm and y_mm must have equal length; got {n} and {y.size}")
        if np.any((r <= 0) | (r > MAX_RADIUS_MM)):
            i = int(np.flatnonzero((r <= 0) | (r > MAX_RADIUS_MM))[0])
            raise ValueError(f"sites radius_mm must be in (0, {MAX_RADIUS_MM:g}] mm; got {float(r[i]):g} at site {i}")
        region = np.full(n, "", dtype=object) if self.region is None else np.asarray(self.region, dtype=object)
        ids = np.array([str(i) for i in range(n)], dtype=object) if self.site_id is None else np.asarray(
            [str(s) for s in self.site_id], dtype=object)
        for name, arr in (("region", region), ("site_id", ids)):
            if arr.shape != (n,):
                raise ValueError(f"sites {name} must have one entry per site ({n}), got shape {arr.shape}")
        if self.spread is not None and not (callable(getattr(self.spread, "local_mixing", None))
                                            and callable(getattr(self.spread, "check_reach", None))):
            raise TypeError(f"sites spread must be None or have local_mixing and check_reach, got "
                            f"{type(self.spread).__name__}")
        if len(set(ids.tolist())) != n:
            dup = next(s for s in ids if (ids == s).sum() > 1)
            raise ValueError(f"sites: duplicate site id {dup!r}")
        for name, arr in (("x_mm", x), ("y_mm", y), ("radius_mm", r), ("region", region), ("site_id", ids)):
            arr.setflags(write=False)
            object.__setattr__(self, name, arr)

    def __len__(self) -> int:
        return self.x_mm.size

    @property
    def area_mm2(self) -> np.ndarray:
        """Footprint area of each site in mm^2."""
        return np.pi * self.radius_mm ** 2


def taxel_radius(pitch_mm: float) -> float:
    """Equal-area footprint radius (mm) of a square taxel of pitch ``pitch_mm``: ``pitch / sqrt(pi)``.

    Examples
    --------
    >>> round(taxel_radius(2.5), 4)
    1.4105
    """
    return float(check_positive(pitch_mm, "pitch_mm", "mm") / np.sqrt(np.pi))


@dataclass(frozen=True)
class Stage:
    """A labelled interval [start, end) of a scene, in seconds (0 <= start <= end)."""

    label: str
    start: float
    end: float

    def __post_init__(self):
        if not isinstance(self.label, str):
            raise TypeError(f"stage label must be a str, got {type(self.label).__name__}")
        for name in ("start", "end"):
            value = getattr(self, name)
            if isinstance(value, bool) or not isinstance(value, (int, float, np.floating, np.integer)) \
                    or not np.isfinite(value):
                raise ValueError(f"stage {self.label!r}: {name} must be a finite number of seconds, got {shown(value)}")
        if not 0.0 <= self.start <= self.end:  # an empty stage (a zero-length ramp) is allowed
            raise ValueError(f"stage {self.label!r} must start at or after 0 s and end no earlier, got "
                             f"{float(self.start):g}-{float(self.end):g} s")


@dataclass(frozen=True, eq=False)
class Scene:
    """Three-axis force sampled uniformly at ``fs``.

    Attributes
    ----------
    fx, fy, fz : ndarray, shape (n_samples,)
        Force in newtons: shear (+X radial, +Y distal) and normal (>= 0).
    fs : float
        Sample rate in Hz; sample i is at ``i / fs`` seconds.
    name : str
        Condition name (used as the dataset's ``condition`` label).
    stages : tuple of Stage
        Labelled phases, e.g. loading, plateau, unloading.
    contact : Contact or None
        Where the force is applied; None means no spatial information.
    theta_r : float or None
        Nominal shear direction in degrees, when the scene has one.
    sites : Sites or None
        For a multi-site scene (`Scene.from_sites`): where each force acts.
        None: the one-site scene, whose force ``(fx, fy, fz)`` is the whole
        contact's.
    site_forces : ndarray, shape (n_samples, n_sites, 3), or None
        Force at each site in newtons (F_X, F_Y, F_Z), with ``sites``; then
        ``fx``, ``fy``, ``fz`` are their sums over sites.
    """

    fx: np.ndarray
    fy: np.ndarray
    fz: np.ndarray
    fs: float = DEFAULT_FS
    name: str = "scene"
    stages: tuple = field(default_factory=tuple)
    contact: Contact | None = None
    theta_r: float | None = None
    sites: Sites | None = None
    site_forces: np.ndarray | None = None

    def __post_init__(self):
        arrays = [as_finite_array(getattr(self, n), n, ndim=1) for n in ("fx", "fy", "fz")]
        if not (arrays[0].size == arrays[1].size == arrays[2].size):
            raise ValueError(
                "fx, fy and fz must have equal length; got "
                f"{arrays[0].size}, {arrays[1].size} and {arrays[2].size}"
            )
        if arrays[0].size == 0:
            raise ValueError("a scene needs at least one force sample, got 0")
        if np.any(arrays[2] < 0):
            i = int(np.flatnonzero(arrays[2] < 0)[0])
            raise ValueError(f"fz must be >= 0 N (compressive); got {arrays[2][i]!r} at t = {i / self.fs} s")
        check_positive(self.fs, "fs", "Hz")
        if self.fs > MAX_FS:
            raise ValueError(f"fs must be <= {MAX_FS:g} Hz (no force sensor samples faster), got {float(self.fs):g}")
        if self.contact is not None and not isinstance(self.contact, Contact):
            raise TypeError(f"contact must be a Contact or None, got {type(self.contact).__name__}")
        if not isinstance(self.name, str):
            raise TypeError(f"name must be a str (the condition label), got {type(self.name).__name__}")
        if isinstance(self.stages, str) or not hasattr(self.stages, "__iter__"):
            raise TypeError(f"stages must be a tuple of Stage, got {type(self.stages).__name__}")
        for n, a in zip(("fx", "fy", "fz"), arrays):
            a.setflags(write=False)
            object.__setattr__(self, n, a)
        object.__setattr__(self, "stages", tuple(self.stages))
        self._check_stages(arrays[0].size / float(self.fs))
        self._check_sites(arrays[0].size)

    def _check_stages(self, duration: float) -> None:
        for stage in self.stages:
            if not isinstance(stage, Stage):
                raise TypeError(f"stages must be Stage objects, got {type(stage).__name__} ({stage!r})")
            if stage.start >= duration:
                raise ValueError(f"stage {stage.label!r} starts at {float(stage.start):g} s, after the scene's "
                                 f"end at {duration:g} s")
        if self.theta_r is not None and not (isinstance(self.theta_r, (int, float, np.floating, np.integer))
                                             and np.isfinite(self.theta_r)):
            raise ValueError(f"theta_r must be a finite angle in degrees or None, got {shown(self.theta_r)}")

    def _check_sites(self, n_samples: int) -> None:
        if (self.sites is None) != (self.site_forces is None):
            raise ValueError("sites and site_forces go together: give both (a multi-site scene) or neither")
        if self.sites is None:
            return
        if not isinstance(self.sites, Sites):
            raise TypeError(f"sites must be a Sites, got {type(self.sites).__name__}")
        if self.contact is not None:
            raise ValueError("a multi-site scene has no contact: each site carries its own footprint")
        forces = as_finite_array(self.site_forces, "site_forces", ndim=3)
        if forces.shape != (n_samples, len(self.sites), 3):
            raise ValueError(f"site_forces must have shape (n_samples, n_sites, 3) = ({n_samples}, "
                             f"{len(self.sites)}, 3), got {forces.shape}")
        _check_site_fz(forces, self.sites, self.fs)
        forces.setflags(write=False)
        object.__setattr__(self, "site_forces", forces)

    @classmethod
    def from_sites(cls, forces, sites: Sites, fs: float = DEFAULT_FS, name: str = "scene", stages=(),
                   theta_r: float | None = None) -> "Scene":
        """A multi-site scene: ``forces`` (n_samples, n_sites, 3) in newtons at ``sites``.

        ``fx``, ``fy``, ``fz`` become the total force (the sum over sites).

        Examples
        --------
        >>> sites = Sites([-3.0, 3.0], [0.0, 0.0], 1.5)
        >>> s = Scene.from_sites(np.ones((10, 2, 3)), sites, name="two")
        >>> s.n_sites, float(s.fz[0])
        (2, 2.0)
        """
        forces = as_finite_array(forces, "forces", ndim=3)
        if forces.shape[2] != 3 or not isinstance(sites, Sites) or forces.shape[1] != len(sites):
            raise ValueError(f"forces must have shape (n_samples, n_sites, 3) for its Sites, got {forces.shape}")
        _check_site_fz(forces, sites, fs)
        total = forces.sum(axis=1)
        return cls(total[:, 0], total[:, 1], total[:, 2], fs, name, stages, None, theta_r, sites, forces)

    @property
    def n_sites(self) -> int:
        """Number of force sites (1 for a one-site scene)."""
        return 1 if self.sites is None else len(self.sites)

    @property
    def n_samples(self) -> int:
        """Number of force samples."""
        return self.fz.size

    @property
    def duration(self) -> float:
        """Length in seconds (``n_samples / fs``)."""
        return self.n_samples / self.fs

    @property
    def time(self) -> np.ndarray:
        """Sample times in seconds."""
        return np.arange(self.n_samples) / self.fs

    def max_shear(self) -> float:
        """Largest shear magnitude in newtons (at any one site of a multi-site scene)."""
        if self.sites is not None:
            return float(np.max(np.hypot(self.site_forces[:, :, 0], self.site_forces[:, :, 1])))
        return float(np.max(np.hypot(self.fx, self.fy)))


def as_scenes(scenes, name: str = "scenes") -> list:
    """``scenes`` (a Scene or a non-empty sequence of Scenes) as a list; TypeError naming ``name`` otherwise."""
    listed = [scenes] if isinstance(scenes, Scene) else (
        list(scenes) if hasattr(scenes, "__iter__") and not isinstance(scenes, str) else None)
    if not listed or not all(isinstance(s, Scene) for s in listed):
        if listed is None:
            got = type(scenes).__name__
        else:
            got = f"a sequence of {', '.join(sorted({type(s).__name__ for s in listed}))}" if listed else "an empty sequence"
        raise TypeError(f"{name} must be a Scene or a non-empty sequence of Scenes, got {got}")
    return listed


def _check_site_fz(forces, sites, fs) -> None:
    if np.any(forces[:, :, 2] < 0):
        k, j = np.argwhere(forces[:, :, 2] < 0)[0]
        raise ValueError(f"site_forces: fz must be >= 0 N; got {float(forces[k, j, 2])!r} at site "
                         f"{sites.site_id[j]!r}, t = {k / fs} s")


def _check_delay(shear_delay_s, ramp_s) -> None:
    if not (isinstance(shear_delay_s, (int, float)) and 0.0 <= shear_delay_s < ramp_s):
        raise ValueError(f"shear_delay_s must be in [0, ramp_s = {ramp_s:g}) s, got {shown(shear_delay_s)}")


def _samples(duration: float, fs: float) -> np.ndarray:
    check_positive(fs, "fs", "Hz")
    if not (np.isfinite(duration) and duration > 0):
        raise ValueError(f"a scene's duration must be a finite number of seconds > 0, got {shown(duration)}")
    n = int(round(duration * fs))
    # the times, three forces and the builders' temporaries: about eight float64 arrays of n samples
    check_memory(64.0 * n, f"a scene of {duration:g} s at {fs:g} Hz ({n:,} samples)", "shorten it or lower fs")
    return np.arange(n) / fs


def birznieks(direction_deg: float | None = 90.0, *, normal_n: float = 4.0, angle_deg: float = 20.0,
              ramp_s: float = 0.125, hold_s: float = 0.25, shear_delay_s: float = 0.0, fs: float = DEFAULT_FS,
              contact: Contact | None = None) -> Scene:
    """Ramp-hold-release of Birznieks et al. 2001 (paper Fig. 6a, docs/model.md §1.9).

    0-0.125 s loading ramp, 0.125-0.375 s plateau, 0.375-0.5 s unloading.
    The normal force rises to ``normal_n`` (4 N); the tangential force to
    ``normal_n * tan(angle_deg)`` (about 1.456 N) in direction
    ``direction_deg``, so the force is inclined 20 deg from the normal.

    Parameters
    ----------
    direction_deg : float or None
        Shear direction theta_R in degrees (0 radial, 90 distal, 180 ulnar,
        270 proximal); None gives the normal-only condition.
    normal_n, angle_deg, ramp_s, hold_s, fs, contact
        Normal force (N), inclination (deg), ramp and plateau lengths (s),
        sample rate (Hz) and optional contact geometry.
    shear_delay_s : float
        The tangential force starts this long after the normal force and
        reaches its plateau with it (s, in [0, ``ramp_s``); default 0: both
        together, as drawn in paper Fig. 6a).  A parameter of the paper
        calibration (`ddmm.experiments.paper.calibrations`).

    Examples
    --------
    >>> s = birznieks(90.0)
    >>> round(float(s.fy.max()), 3), s.duration
    (1.456, 0.5)
    """
    if direction_deg is not None:
        check_real(direction_deg, "direction_deg", "degrees")
    check_nonnegative(normal_n, "normal_n", "N")
    check_positive(ramp_s, "ramp_s", "s")
    check_nonnegative(hold_s, "hold_s", "s")
    _check_delay(shear_delay_s, ramp_s)
    if not (isinstance(angle_deg, (int, float)) and 0.0 <= angle_deg <= MAX_INCLINATION_DEG):
        raise ValueError(f"angle_deg must be in [0, {MAX_INCLINATION_DEG:g}] degrees from the normal, got {shown(angle_deg)}")
    t = _samples(2 * ramp_s + hold_s, fs)
    knots = [0.0, ramp_s, ramp_s + hold_s, 2 * ramp_s + hold_s]
    profile = np.interp(t, knots, [0.0, 1.0, 1.0, 0.0])
    fz = normal_n * profile
    if direction_deg is None:
        fx = fy = np.zeros_like(fz)
        name = "normal"
    else:
        shear_profile = np.interp(t, [0.0, shear_delay_s, *knots[1:]], [0.0, 0.0, 1.0, 1.0, 0.0])
        shear = normal_n * np.tan(np.deg2rad(angle_deg)) * shear_profile
        rad = np.deg2rad(direction_deg)
        fx, fy = shear * np.cos(rad), shear * np.sin(rad)
        name = f"birznieks_{direction_deg:g}"
    stages = (Stage("loading", 0.0, knots[1]), Stage("plateau", knots[1], knots[2]),
              Stage("unloading", knots[2], knots[3]))
    return Scene(fx, fy, fz, fs, name, stages, contact, direction_deg)


def press_push_lift(theta_r: float = 90.0, *, press_n: float = 3.0, push_n: float = 6.0,
                    shear_n: float | None = None, ramp_s: float = 2.0, lift_ramp_s: float | None = None,
                    shear_delay_s: float = 0.0, fs: float = DEFAULT_FS, contact: Contact | None = None) -> Scene:
    """Press-push-lift of paper §IV.B (Fig. 7a), with documented choices.

    * 0-5 s: no contact.
    * Stage 1 (5-15 s): ramp F_Z to ``press_n`` (3 N) over ``ramp_s``, hold.
    * Stage 2 (15-25 s): ramp F_Z to ``push_n`` (6 N) over ``ramp_s`` and the
      shear to ``shear_n`` in direction ``theta_r`` from ``shear_delay_s``
      into that ramp to its end, hold.  The default shear is
      ``push_n * tan 20 deg`` (about 2.18 N), Birznieks' inclination.
    * Stage 3 (25-30 s): ramp everything to 0 over ``lift_ramp_s`` (default
      ``ramp_s``; at most 5 s, which leaves no static period), rest.

    Each stage is a dynamic period (D, the ramp) then a static one (S).  The
    paper gives neither ramp length nor the shear's onset: they are
    parameters of the paper calibration (`ddmm.experiments.paper.calibrations`).

    Examples
    --------
    >>> s = press_push_lift()
    >>> s.duration, round(float(s.fz.max()), 1)
    (30.0, 6.0)
    """
    check_real(theta_r, "theta_r", "degrees")
    for name, value in (("press_n", press_n), ("push_n", push_n), ("shear_n", shear_n)):
        if value is not None:
            check_nonnegative(value, name, "N")
    shear_n = push_n * np.tan(np.deg2rad(20.0)) if shear_n is None else shear_n
    lift_s = ramp_s if lift_ramp_s is None else lift_ramp_s
    for name, value, top in (("ramp_s", ramp_s, 10.0), ("lift_ramp_s", lift_s, 5.0)):
        if not (isinstance(value, (int, float)) and 0.0 < value <= top):
            raise ValueError(f"{name} must be in (0, {top:g}] s, got {shown(value)}")
    _check_delay(shear_delay_s, ramp_s)
    t = _samples(30.0, fs)
    knots = [0.0, 5.0, 5.0 + ramp_s, 15.0, 15.0 + ramp_s, 25.0, 25.0 + lift_s, 30.0]
    fz = np.interp(t, knots, [0, 0, press_n, press_n, push_n, push_n, 0, 0])
    shear = np.interp(t, [*knots[:4], 15.0 + shear_delay_s, *knots[4:]], [0, 0, 0, 0, 0, shear_n, shear_n, 0, 0])
    rad = np.deg2rad(theta_r)
    stages = tuple(
        Stage(label, a, b) for label, a, b in (
            ("stage1_dynamic", 5.0, 5.0 + ramp_s), ("stage1_static", 5.0 + ramp_s, 15.0),
            ("stage2_dynamic", 15.0, 15.0 + ramp_s), ("stage2_static", 15.0 + ramp_s, 25.0),
            ("stage3_dynamic", 25.0, 25.0 + lift_s), ("stage3_static", 25.0 + lift_s, 30.0),
        ) if a < b  # a 5 s lift leaves no static period
    )
    return Scene(shear * np.cos(rad), shear * np.sin(rad), fz, fs, f"press_push_lift_{theta_r:g}",
                 stages, contact, theta_r)


def rotating_shear(*, normal_n: float = 4.0, shear_n: float = 1.456, period_s: float = 2.0,
                   start_deg: float = 0.0, turns: float = 1.0, ramp_s: float = 0.125,
                   fs: float = DEFAULT_FS, contact: Contact | None = None) -> Scene:
    """Constant normal force with a shear direction rotating counter-clockwise.

    The normal force and shear ramp up over ``ramp_s`` with the direction
    fixed at ``start_deg``, then the direction turns at ``360 / period_s``
    deg/s for ``turns`` turns, then everything ramps down: a stimulus for
    continuous direction decoding.

    Examples
    --------
    >>> s = rotating_shear(period_s=1.0)
    >>> round(s.duration, 3)
    1.25
    """
    check_nonnegative(normal_n, "normal_n", "N")
    check_real(shear_n, "shear_n", "N")
    check_real(start_deg, "start_deg", "degrees")
    for name, value in (("period_s", period_s), ("turns", turns), ("ramp_s", ramp_s)):
        check_positive(value, name)
    rotate_s = period_s * turns
    t = _samples(2 * ramp_s + rotate_s, fs)
    knots = [0.0, ramp_s, ramp_s + rotate_s, 2 * ramp_s + rotate_s]
    envelope = np.interp(t, knots, [0.0, 1.0, 1.0, 0.0])
    angle = np.deg2rad(start_deg) + 2 * np.pi * np.clip(t - ramp_s, 0.0, rotate_s) / period_s
    shear = shear_n * envelope
    stages = (Stage("loading", 0.0, ramp_s), Stage("rotation", ramp_s, ramp_s + rotate_s),
              Stage("unloading", ramp_s + rotate_s, knots[-1]))
    return Scene(shear * np.cos(angle), shear * np.sin(angle), normal_n * envelope, fs,
                 "rotating_shear", stages, contact, None)
