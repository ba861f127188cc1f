"""Scenes that only force fields over the skin can express: torsion and incipient slip.

Each is a multi-site scene (`Scene.from_sites`): a contact disc of radius
``radius_mm`` is tiled by a square grid of pitch ``pitch_mm`` (`contact_grid`),
and every grid cell is a site with the cell's force.  Forces are in newtons,
positions in mm in the population's frame (+X radial, +Y distal, +Z into the
skin), torques in mNm (= N mm).

**Torsion** (`torsion`).  A normal force is applied and held; then a torque
about the contact's normal ramps on, holds and ramps off.  The normal
pressure is uniform.  The shear traction is tangential (perpendicular to the
radius) and grows linearly with the distance r from the centre,
``tau(r) = c r`` with ``c = 2 T / (pi R^4)``, so that it integrates to the
torque T over the disc (the stuck contact of a rigid twist with a linear
skin response; the elastic half-space's Reissner-Sagoci field, which is
singular at the edge, is not used).  On the grid, the cell forces are
rescaled so that their moment is exactly T.  ``direction = +1`` turns from
+X toward +Y (anticlockwise looking at the skin, +Z away from the viewer).

**Grasp** (`grasp`), after the grip-lift task of Johansson & Westling
(1984).  One site on each of two (thumb and index) or five digit tips, in
the hand frame of `ddmm.population.anatomy.hand_map` (each tip's pad centre, a footprint
of the reference contact area).  Phases: *preload* (the grip force, normal
at every tip, rises to ``preload_n`` with no load), *loading* (grip and
load rise in parallel until the load equals the object's weight: lift-off),
*hold* (static), *replacement* (both fall back to the preload), *release*.
The load (the weight ``load_n``) is shared equally by the tips and acts on
each tip's skin along ``load_direction_deg`` in that digit's own frame
(default 270 deg, proximal), turned into the hand frame by the digit's
``frame_deg``.  The hold grip per tip is ``safety`` times the slip limit
``(load_n / n_tips) / mu`` (grip-to-load ratios some 20-60% above the slip
ratio in that task; recalled, not read).

**Incipient slip** (`incipient_slip`), read after Cattaneo and Mindlin.  A
Hertzian contact of radius a carries the normal force N with pressure
``p(r) = p0 sqrt(1 - r^2/a^2)``, ``p0 = 3 N / (2 pi a^2)``.  A tangential load
Q ramps up in direction ``direction_deg``.  While ``Q < mu_s N`` an annulus
``c <= r <= a`` slips, with traction ``mu_s p(r)``, around a stuck disc of
radius ``c = a (1 - Q / (mu_s N))^(1/3)`` that shrinks from the edge inward,
where the traction is ``mu_s p0 (sqrt(1 - r^2/a^2) - (c/a) sqrt(1 - r^2/c^2))``.
At ``Q = mu_s N`` the stick region vanishes: gross slip (the start of the
scene's ``slip`` stage).  The contact then slides; its friction falls to
``mu_k N`` over ``drop_s``, with the sliding traction ``mu p(r)``
everywhere, and the sliding contact vibrates (stick-slip): both the
friction and the normal force carry a vibration of relative amplitude
``vibration`` at ``vibration_hz``.  The vibration is this scene's reading,
not Cattaneo-Mindlin's: in the DDMM a change of shear *magnitude* above
2 F_TH moves no AF, so without the normal-force part a slip would reach only
SA-II.  A control scene (``slip=False``) ramps to
``hold_fraction mu_s N`` and holds without slipping.
"""

from __future__ import annotations

import numbers

import numpy as np

from ddmm.population.stimuli.scenes import DEFAULT_FS, Scene, Sites, Stage, taxel_radius
from ddmm.utils.validation import as_finite_array, check_nonnegative, check_positive, check_real, shown

__all__ = ["contact_grid", "torsion", "incipient_slip", "grasp", "digit_tip_sites"]


def contact_grid(radius_mm: float, pitch_mm: float, *, center_mm=(0.0, 0.0), region: str = ""):
    """Sites tiling a contact disc: grid cells of pitch ``pitch_mm`` whose centres lie inside the disc.

    Returns `Sites` (footprint: the cell's equal-area radius) and each cell's
    offset (dx, dy) from the centre in mm.

    Examples
    --------
    >>> sites, dx, dy = contact_grid(2.0, 1.0)
    >>> len(sites), float(dx.min()), float(dx.max())
    (12, -1.5, 1.5)
    """
    radius, pitch = check_positive(radius_mm, "radius_mm", "mm"), check_positive(pitch_mm, "pitch_mm", "mm")
    n = int(np.ceil(radius / pitch))
    axis = (np.arange(-n, n) + 0.5) * pitch
    dx, dy = (a.ravel() for a in np.meshgrid(axis, axis))
    inside = np.hypot(dx, dy) <= radius
    if not inside.any():
        raise ValueError(f"pitch_mm={pitch_mm!r} is too coarse for radius_mm={radius_mm!r}: no cell centre inside")
    dx, dy = dx[inside], dy[inside]
    cx, cy = _center(center_mm)
    ids = [f"c{i:03d}" for i in range(dx.size)]
    return Sites(cx + dx, cy + dy, taxel_radius(pitch), region=[region] * dx.size, site_id=ids), dx, dy


def _center(center_mm) -> tuple:
    """``center_mm`` as an (x, y) pair of finite floats, mm."""
    center = as_finite_array(center_mm, "center_mm")
    if center.shape != (2,):
        raise ValueError(f"center_mm must be an (x, y) pair in mm, got shape {center.shape}")
    return float(center[0]), float(center[1])


def _envelope(t, knots, values):
    return np.interp(t, knots, values)


def torsion(torque_mnm: float = 5.0, normal_n: float = 3.0, radius_mm: float = 6.0, direction: int = 1, *,
            pitch_mm: float = 1.0, center_mm=(0.0, 0.0), preload_s: float = 0.3, ramp_s: float = 0.1,
            hold_s: float = 0.5, fs: float = DEFAULT_FS, region: str = "", name: str | None = None) -> Scene:
    """Torque about the contact normal on a pressed contact disc (module docstring).

    Timing: the normal force ramps on over ``ramp_s`` and is held; the torque
    ramps on at ``preload_s`` (the scene's ``torque_onset`` stage starts
    there) over ``ramp_s``, holds ``hold_s`` and ramps off; then the normal
    force is released.

    Parameters
    ----------
    torque_mnm : float
        Torque in mNm (N mm), >= 0; its sign is ``direction``.
    normal_n : float
        Normal force in N.
    radius_mm, pitch_mm : float
        Contact radius and grid pitch in mm.
    direction : {+1, -1}
        +1 turns from +X toward +Y (anticlockwise), -1 the other way.

    Examples
    --------
    >>> s = torsion(5.0, 3.0, direction=-1)
    >>> s.n_sites, round(float(s.fz.max()), 6), s.stages[2].label
    (112, 3.0, 'torque_ramp')
    """
    if direction not in (1, -1):
        raise ValueError(f"direction must be +1 or -1, got {shown(direction)}")
    real = isinstance(torque_mnm, numbers.Real) and not isinstance(torque_mnm, bool)
    if not real or not np.isfinite(torque_mnm) or torque_mnm < 0:
        raise ValueError(f"torque_mnm must be finite and >= 0 mNm, got {shown(torque_mnm)}")
    check_positive(normal_n, "normal_n", "N")
    sites, dx, dy = contact_grid(radius_mm, pitch_mm, center_mm=center_mm, region=region)
    knots = [0.0, ramp_s, preload_s, preload_s + ramp_s, preload_s + ramp_s + hold_s,
             preload_s + 2 * ramp_s + hold_s, preload_s + 3 * ramp_s + hold_s]
    t = np.arange(int(round(knots[-1] * fs))) / fs
    normal = _envelope(t, knots, [0, 1, 1, 1, 1, 1, 0]) * normal_n
    twist = _envelope(t, knots, [0, 0, 0, 1, 1, 0, 0]) * torque_mnm * direction
    r = np.hypot(dx, dy)
    tx, ty = -dy, dx  # tangential (anticlockwise) times r: the traction c r grows with r
    moment = np.sum(dx * ty - dy * tx)  # sum of r^2 over cells
    forces = np.empty((t.size, len(sites), 3))
    forces[:, :, 0] = twist[:, None] * (tx / moment)[None, :]
    forces[:, :, 1] = twist[:, None] * (ty / moment)[None, :]
    forces[:, :, 2] = normal[:, None] / r.size
    stages = (Stage("loading", 0.0, knots[1]), Stage("preload", knots[1], knots[2]),
              Stage("torque_ramp", knots[2], knots[3]), Stage("torque_hold", knots[3], knots[4]),
              Stage("torque_release", knots[4], knots[5]), Stage("unloading", knots[5], knots[6]))
    label = name or f"torsion_{'ccw' if direction > 0 else 'cw'}_{torque_mnm:g}mNm_{normal_n:g}N"
    return Scene.from_sites(forces, sites, fs, label, stages)


def _mindlin_traction(r, a, c, mu, p0):
    """Tangential traction (N/mm^2) of a partially slipping Hertzian contact at radius r (module docstring)."""
    outer = mu * p0 * np.sqrt(np.clip(1.0 - (r / a) ** 2, 0.0, None))
    if c <= 0.0:
        return outer
    inner = outer - mu * p0 * (c / a) * np.sqrt(np.clip(1.0 - (r / c) ** 2, 0.0, None))
    return np.where(r < c, inner, outer)


def incipient_slip(normal_n: float = 2.0, *, mu_s: float = 1.0, mu_k: float = 0.8, load_rate_n_s: float = 4.0,
                   direction_deg: float = 270.0, radius_mm: float = 6.0, pitch_mm: float = 1.0, slip: bool = True,
                   hold_fraction: float = 0.8, preload_s: float = 0.2, slide_s: float = 0.3, drop_s: float = 0.01,
                   vibration: float = 0.05, vibration_hz: float = 100.0, center_mm=(0.0, 0.0),
                   fs: float = DEFAULT_FS, region: str = "", name: str | None = None) -> Scene:
    """A tangential load ramp on a Hertzian contact up to gross slip, or a control that stops short (module docstring).

    The scene's ``slip_onset`` stage starts at gross slip (absent in the
    control); its start is the onset a slip detector must report.

    Examples
    --------
    >>> s = incipient_slip(2.0)
    >>> onset = [st for st in s.stages if st.label == "slip"][0].start
    >>> round(onset, 3)
    0.7
    """
    for value, label in ((normal_n, "normal_n"), (mu_s, "mu_s"), (mu_k, "mu_k"), (load_rate_n_s, "load_rate_n_s")):
        check_positive(value, label, "N, N/s or 1")
    if mu_k > mu_s or not 0 < hold_fraction < 1:
        raise ValueError(f"need mu_k <= mu_s and 0 < hold_fraction < 1; got mu_k={mu_k!r}, mu_s={mu_s!r}, "
                         f"hold_fraction={hold_fraction!r}")
    sites, dx, dy = contact_grid(radius_mm, pitch_mm, center_mm=center_mm, region=region)
    r, cell = np.hypot(dx, dy), pitch_mm ** 2
    p0 = 3.0 * normal_n / (2.0 * np.pi * radius_mm ** 2)
    pressure = p0 * np.sqrt(np.clip(1.0 - (r / radius_mm) ** 2, 0.0, None)) * cell
    pressure *= normal_n / pressure.sum()  # the grid carries exactly N
    q_max = mu_s * normal_n * (1.0 if slip else hold_fraction)
    t_onset = preload_s + q_max / load_rate_n_s
    t_end = t_onset + (slide_s if slip else 0.3)
    t = np.arange(int(round(t_end * fs))) / fs
    ramp_t = np.clip((t - preload_s) * load_rate_n_s, 0.0, q_max)
    normal = np.clip(t / 0.1, 0.0, 1.0)
    shear = np.empty((t.size, r.size))
    for k, q in enumerate(ramp_t):
        c = radius_mm * max(1.0 - q / (mu_s * normal_n), 0.0) ** (1.0 / 3.0) if q < mu_s * normal_n else 0.0
        traction = _mindlin_traction(r, radius_mm, c, mu_s, p0) * cell
        total = traction.sum()
        shear[k] = traction * (q / total if total > 0 else 0.0)
    if slip:
        after = t >= t_onset
        drop = np.clip((t[after] - t_onset) / drop_s, 0.0, 1.0)
        shake = 1.0 + vibration * np.sin(2 * np.pi * vibration_hz * (t[after] - t_onset))
        mu = (mu_s + (mu_k - mu_s) * drop) * shake
        shear[after] = (pressure / normal_n)[None, :] * (mu * normal_n)[:, None]
        normal[after] = normal[after] * shake
    rad = np.deg2rad(direction_deg)
    forces = np.empty((t.size, r.size, 3))
    forces[:, :, 0], forces[:, :, 1] = shear * np.cos(rad), shear * np.sin(rad)
    forces[:, :, 2] = normal[:, None] * pressure[None, :]
    stages = [Stage("loading", 0.0, preload_s), Stage("tangential_ramp", preload_s, t_onset)]
    stages.append(Stage("slip", t_onset, t_end) if slip else Stage("hold", t_onset, t_end))
    label = name or f"{'slip' if slip else 'noslip'}_{normal_n:g}N_{load_rate_n_s:g}Nps"
    return Scene.from_sites(forces, sites, fs, label, tuple(stages), direction_deg)


def digit_tip_sites(digits=("D1", "D2", "D3", "D4", "D5")) -> Sites:
    """One site on each digit tip's pad centre (region ``D<n>d``), a footprint of the reference contact area.

    The hand frame of `ddmm.population.anatomy.hand_map`; the sites `grasp`
    uses, and those of a five-sensor glove streamed live (``ddmm stream
    --sites fingertips``).  Site ids are the region names.

    Examples
    --------
    >>> digit_tip_sites(("D1", "D2")).site_id.tolist()
    ['D1d', 'D2d']
    """
    from ddmm.population.anatomy.hand_map import get_region
    from ddmm.population.anatomy.receptive_fields import REFERENCE_AREA_MM2

    tips = [get_region(f"{d}d") for d in _digits(digits)]
    radius = float(np.sqrt(REFERENCE_AREA_MM2 / np.pi))
    return Sites([tip.center_mm[0] for tip in tips], [tip.center_mm[1] for tip in tips], radius,
                 region=[tip.name for tip in tips], site_id=[tip.name for tip in tips])


def _digits(digits) -> list:
    """``digits`` as a list of distinct digit names (``"D1"`` .. ``"D5"``); errors name ``digits``."""
    allowed = ("D1", "D2", "D3", "D4", "D5")
    if isinstance(digits, str) or not hasattr(digits, "__iter__"):
        raise TypeError(f"digits must be a sequence of digit names ({', '.join(allowed)}), got {type(digits).__name__}")
    digits = list(digits)
    bad = [d for d in digits if not isinstance(d, str) or d not in allowed]
    if bad or not digits or len(set(digits)) != len(digits):
        got = f"{bad[0]!r}" if bad else ("none" if not digits else "a repeated digit")
        raise ValueError(f"digits must name one or more distinct digits of {', '.join(allowed)}, got {got}")
    return digits


def grasp(digits=("D1", "D2"), *, load_n: float = 2.0, mu: float = 1.0, safety: float = 1.4,
          preload_n: float = 0.3, load_direction_deg: float = 270.0, preload_s: float = 0.1,
          loading_s: float = 0.3, hold_s: float = 1.0, replace_s: float = 0.3, release_s: float = 0.1,
          fs: float = DEFAULT_FS, name: str | None = None) -> Scene:
    """Grip-lift-hold-replace with one site on each digit tip (module docstring); forces in N, times in s.

    Examples
    --------
    >>> s = grasp(("D1", "D2", "D3", "D4", "D5"))
    >>> s.n_sites, [st.label for st in s.stages][:3]
    (5, ['preload', 'loading', 'hold'])
    """
    from ddmm.population.anatomy.hand_map import get_region

    sites = digit_tip_sites(digits)
    tips = [get_region(f"{d}d") for d in _digits(digits)]
    for value, label in ((load_n, "load_n"), (mu, "mu"), (safety, "safety"), (preload_n, "preload_n")):
        check_positive(value, label, "N or 1")
    for label, value in (("preload_s", preload_s), ("loading_s", loading_s), ("hold_s", hold_s),
                         ("replace_s", replace_s), ("release_s", release_s)):
        check_nonnegative(value, label, "s")
    check_real(load_direction_deg, "load_direction_deg", "degrees")
    check_positive(fs, "fs", "Hz")
    n = len(tips)
    grip = max(safety * (load_n / n) / mu, preload_n)
    knots = np.cumsum([0.0, preload_s, loading_s, hold_s, replace_s, release_s])
    t = np.arange(int(round(knots[-1] * fs))) / fs
    normal = np.interp(t, knots, [0.0, preload_n, grip, grip, preload_n, 0.0])
    load = np.interp(t, knots, [0.0, 0.0, load_n, load_n, 0.0, 0.0]) / n
    forces = np.empty((t.size, n, 3))
    for j, tip in enumerate(tips):
        rad = np.deg2rad(load_direction_deg + tip.frame_deg)
        forces[:, j, 0], forces[:, j, 1], forces[:, j, 2] = load * np.cos(rad), load * np.sin(rad), normal
    labels = ("preload", "loading", "hold", "replacement", "release")
    stages = tuple(Stage(lab, float(a), float(b)) for lab, a, b in zip(labels, knots[:-1], knots[1:]))
    return Scene.from_sites(forces, sites, fs, name or f"grasp_{n}digits_{load_n:g}N", stages)
