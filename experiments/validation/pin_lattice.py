"""Scans and the pin lattice: each type's response to a scanned grating by pin pitch, with the fixed lattice
(`scan`'s default, TouchSim's form) and averaged over the lattice's positions (``lattice_average=True``).

A surface scanned over fixed pins reaches the skin through pins that enter and leave contact one column at
a time, so the loads carry the lattice's own frequency, speed / pitch along each lattice axis; FA-II answer
it.  Protocol (**held out**: no fit saw a scan at these pitches or an averaged lattice): the fingertip of
``--seed`` (default 1), its units under a 6 x 6 mm window at the centre, those in the inner 4 x 4 mm
analysed; each surface of `SURFACES` pressed until its highest point is 0.8 mm in and scanned at 40 mm/s
for 0.5 s at 5 kHz along each direction of ``--directions``, over pins of each pitch of ``--pitches``,
friction on, the default skin and the fitted transduction.  Per type: the mean rate after 0.1 s and the
median vector strength at the grating's temporal frequency (speed x |cos(direction)| / period) of the units
with at least 5 spikes.

    python -m ddmm.experiments.validation.pin_lattice [--seed 1] [--pitches 0.25 0.2 0.1] [--directions 0 45]
"""

from __future__ import annotations

import argparse

import numpy as np

__all__ = ["SURFACES", "lattice_responses", "lattice_scene", "main"]

#: The scanned surfaces by name, each with its period in mm: a 1 mm square grating (ridges 0.5 mm wide and
#: high) and a shallow 1 mm cosine (0.1 mm from crest to trough: every pin touches, pressed by its base).
SURFACES = {"grating": 1.0, "cosine": 1.0}
SPEED_MM_S, DURATION_S, FS, CONTACT_MM, WINDOW_MM, INNER_MM = 40.0, 0.5, 5000.0, 0.8, 6.0, 2.0
_TYPES = ("SAI", "RAI", "RAII")


def _surface(name: str):
    from ddmm.population.stimuli.surfaces import Surface, grating

    if name == "grating":
        return grating(1.0, 0.5, 0.5)
    x = (np.arange(200) + 0.5) * 0.05
    return Surface(np.tile(0.05 * (1.0 + np.cos(2.0 * np.pi * x)), (200, 1)), pixel_mm=0.05, periodic=True)


def lattice_scene(name: str, pitch_mm: float, direction_deg: float, lattice_average: bool,
                  duration_s: float = DURATION_S):
    """The surface ``name`` of `SURFACES` scanned as the module docstring says.

    Examples
    --------
    >>> s = lattice_scene("cosine", 0.5, 0.0, True, duration_s=0.01)
    >>> s.n_sites, s.n_samples
    (144, 50)
    """
    from ddmm.population.stimuli.scanning import scan
    from ddmm.utils.validation import check_choice

    return scan(_surface(check_choice(name, "name", sorted(SURFACES))), speed_mm_s=SPEED_MM_S,
                direction_deg=direction_deg, duration_s=duration_s, contact_mm=CONTACT_MM,
                window_mm=(WINDOW_MM, WINDOW_MM), pitch_mm=pitch_mm, fs=FS, lattice_average=lattice_average)


def _type_rows(ds, sub, inner, freq_hz, duration_s) -> dict:
    """{type: (mean rate imp/s after 0.1 s, median VS at ``freq_hz`` of units with >= 5 spikes, units)}."""
    from ddmm.population.analysis.physiology_vibration import vector_strength

    t, aff = ds.spike_time.values, ds.spike_afferent.values
    out = {}
    for kind in _TYPES:
        units = inner[np.asarray(sub.afferent_type)[inner] == kind]
        trains = [t[(aff == j) & (t >= 0.1)] for j in units]
        rates = [train.size / (duration_s - 0.1) for train in trains]
        strengths = [vector_strength(train, freq_hz) for train in trains if train.size >= 5]
        out[kind] = (float(np.mean(rates)) if rates else float("nan"),
                     float(np.median(strengths)) if strengths else float("nan"), len(units))
    return out


def lattice_responses(seed: int = 1, surfaces=("grating",), pitches=(0.25, 0.2, 0.1), directions=(0.0, 45.0),
                      duration_s: float = DURATION_S) -> list:
    """Rows (surface, direction, pitch, lattice_average, {type: (rate, VS, units)}) over every combination.

    Examples
    --------
    >>> rows = lattice_responses(1, ("cosine",), (0.5,), (0.0,), duration_s=0.15)
    >>> [(r[0], r[3], sorted(r[4])) for r in rows]
    [('cosine', False, ['RAI', 'RAII', 'SAI']), ('cosine', True, ['RAI', 'RAII', 'SAI'])]
    """
    from ddmm.population import sample_population, simulate

    pop = sample_population("fingertip", rng=seed)
    half = WINDOW_MM / 2.0 + 1.0
    sub = pop.select(np.flatnonzero((np.abs(pop.x_mm) <= half) & (np.abs(pop.y_mm) <= half)))
    inner = np.flatnonzero((np.abs(sub.x_mm) <= INNER_MM) & (np.abs(sub.y_mm) <= INNER_MM))
    rows = []
    for name in surfaces:
        for direction in directions:
            freq = SPEED_MM_S * abs(np.cos(np.deg2rad(direction))) / SURFACES[name]
            for pitch in pitches:
                for average in (False, True):
                    scene = lattice_scene(name, pitch, direction, average, duration_s)
                    ds = simulate(sub, scene, engine="direct", seed=seed, quiet=True)
                    rows.append((name, float(direction), float(pitch), average,
                                 _type_rows(ds, sub, inner, freq, duration_s)))
    return rows


def _print(rows) -> None:
    print("Scans and the pin lattice (held out): mean rate after 0.1 s (imp/s) / median vector strength at the "
          "grating's temporal frequency, per type (units)")
    for name, direction, pitch, average, by_type in rows:
        cells = "  ".join(f"{kind} {r:6.1f} / {vs:4.2f} ({n})" for kind, (r, vs, n) in by_type.items())
        print(f"{name:8s} {direction:5.0f} deg  pitch {pitch:4.2f} mm  {'averaged' if average else 'fixed   '}  "
              f"{cells}")


def main(argv=None) -> int:
    """Run the module docstring's protocol and print its table; returns 0."""
    parser = argparse.ArgumentParser(prog="python -m ddmm.experiments.validation.pin_lattice",
                                     description=__doc__.split("\n\n")[0])
    parser.add_argument("--seed", type=int, default=1, help="fingertip seed (also the noise seed)")
    parser.add_argument("--surfaces", nargs="+", default=["grating", "cosine"], choices=sorted(SURFACES))
    parser.add_argument("--pitches", nargs="+", type=float, default=[0.25, 0.2, 0.1], help="pin pitches, mm")
    parser.add_argument("--directions", nargs="+", type=float, default=[0.0, 45.0], help="scan directions, deg")
    args = parser.parse_args(argv)
    try:
        rows = lattice_responses(args.seed, args.surfaces, args.pitches, args.directions)
    except (ValueError, TypeError) as error:
        parser.exit(2, f"error: {error}\n")
    _print(rows)
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
