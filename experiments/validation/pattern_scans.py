"""Embossed letters and a dot pattern scanned over the fingertip: spatial event plots, and how faithfully each
type draws them.

Protocol (all **held out**: no fit saw a scanned pattern): each pattern of `PATTERNS` pressed until its raised
parts are 0.5 mm into the skin (the base just touching) and scanned along +X at 40 mm/s for 0.6 s over a
10 x 10 mm window of 0.25 mm pins, on the fingertip preset's units under the window (default skin, the
shipped transduction).  The patterns: ``letters`` "AB" in `ddmm.population.stimuli.surfaces.letters`' 5 x 7
font (6 mm capitals raised 0.5 mm), and ``dots``, raised dots of 0.5 mm radius 3 mm apart (0.5 mm high),
Johnson & Lamb's braille-like dots.  Each spike of a unit whose centre lies in the inner 7 x 7 mm is placed on
the surface (`ddmm.population.analysis.surface_maps`: the surface point over the unit's centre when it
fired); per type, the rate map in 0.25 mm bins is correlated with the pattern's relief (`relief_correlation`).

Target (Johnson & Lamb 1981; Phillips, Johnson & Hsiao 1988; recalled, docs/references.md): in the monkey's
spatial event plots of scanned dot patterns and letters, SA-I draw the pattern most sharply, FA-I blurred,
FA-II not at all: r of SA-I > FA-I > FA-II.

Run::

    python -m ddmm.experiments.validation.pattern_scans [--seeds 1 2 3 4] [--out DIR]

``--out`` writes ``<pattern>_sep.png``, the first seed's spatial event plot of each pattern.
"""

from __future__ import annotations

import argparse
from pathlib import Path

import numpy as np

from ddmm.experiments.io import ensure_out_dir, seed_arg

__all__ = ["PATTERNS", "SPEED_MM_S", "DURATION_S", "pattern_scene", "fingertip_run", "relief_correlations", "main"]

#: The scanned patterns by name: the `ddmm.population.stimuli.surfaces` function that makes each, and its arguments.
PATTERNS = {"letters": ("letters", ("AB",)), "dots": ("dot_pattern", (3.0,))}
SPEED_MM_S, DURATION_S = 40.0, 0.6
_CONTACT_MM, _PITCH_MM, _WINDOW_MM, _INNER_MM, _BIN_MM = 0.5, 0.25, 10.0, 3.5, 0.25
_TYPES = ("SAI", "RAI", "RAII")


def _surface(name: str):
    from ddmm.population.stimuli import surfaces

    maker, args = PATTERNS[name]
    return getattr(surfaces, maker)(*args)


def pattern_scene(name: str = "letters"):
    """(scene, surface, path): the pattern ``name`` of `PATTERNS` scanned as the module docstring says."""
    from ddmm.population.analysis.surface_maps import ScanPath
    from ddmm.population.stimuli.surfaces import scan
    from ddmm.utils.validation import check_choice

    surface = _surface(check_choice(name, "name", sorted(PATTERNS)))
    scene = scan(surface, speed_mm_s=SPEED_MM_S, duration_s=DURATION_S, contact_mm=_CONTACT_MM,
                 window_mm=(_WINDOW_MM, _WINDOW_MM), pitch_mm=_PITCH_MM, name=f"scan_{name}")
    return scene, surface, ScanPath(SPEED_MM_S, DURATION_S)


def fingertip_run(seed: int, scene) -> tuple:
    """(dataset, inner): the fingertip of ``seed``'s units under the window run on ``scene`` (noise seed ``seed``),
    and the positions of those whose centre lies in the inner 7 x 7 mm."""
    from ddmm.population import sample_population, simulate

    pop = sample_population("fingertip", rng=seed)
    half = _WINDOW_MM / 2.0
    sub = pop.select(np.flatnonzero((np.abs(pop.x_mm) <= half) & (np.abs(pop.y_mm) <= half)))
    inner = np.flatnonzero((np.abs(sub.x_mm) <= _INNER_MM) & (np.abs(sub.y_mm) <= _INNER_MM))
    return simulate(sub, scene, engine="direct", seed=seed, quiet=True), inner


def _extent(surface) -> tuple:
    """The map's box: the pattern's length along the scan (at most the window plus its travel), the inner band."""
    half = min(surface.width_mm, _WINDOW_MM + SPEED_MM_S * DURATION_S - 2.0 * _INNER_MM) / 2.0
    return (-half, half, -_INNER_MM, _INNER_MM)


def relief_correlations(ds, inner, surface, path) -> dict:
    """{type: (r, mean rate in imp/s over the map, units)} of the inner units' rate maps (module docstring)."""
    from ddmm.population.analysis.surface_maps import event_rate_map, relief_correlation

    out = {}
    for kind in _TYPES:
        rate = event_rate_map(ds, path, kind, bin_mm=_BIN_MM, extent_mm=_extent(surface), afferents=inner)
        units = int(np.sum(ds.afferent_type.values[inner].astype(str) == kind))
        out[kind] = (relief_correlation(rate, surface), float(np.nanmean(rate.values)), units)
    return out


def main(argv=None) -> int:
    """Print each pattern's and seed's correlations, labelled held out, with the target; ``--out`` writes the
    first seed's plots."""
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--seeds", type=seed_arg, nargs="+", default=[1, 2, 3, 4], help="fingertip and noise seeds")
    parser.add_argument("--patterns", nargs="+", choices=sorted(PATTERNS), default=list(PATTERNS))
    parser.add_argument("--out", type=Path, help="directory for <pattern>_sep.png")
    args = parser.parse_args(argv)
    try:  # before the runs: a bad directory fails at once
        out = ensure_out_dir(args.out) if args.out is not None else None
    except ValueError as exc:
        parser.error(str(exc))
    print(f"patterns scanned at {SPEED_MM_S:g} mm/s, HELD OUT (no fit saw a scanned pattern): Pearson r of each "
          "type's rate map with the relief; target SA-I > FA-I > FA-II (Johnson & Lamb 1981; Phillips et al. 1988; "
          "recalled)")
    for name in args.patterns:
        scene, surface, path = pattern_scene(name)
        held = 0
        for k, seed in enumerate(args.seeds):
            ds, inner = fingertip_run(seed, scene)
            res = relief_correlations(ds, inner, surface, path)
            ordered = res["SAI"][0] > res["RAI"][0] > res["RAII"][0]
            held += ordered
            cells = "; ".join(f"{kind} r {r:.2f} ({rate:.1f} imp/s, {n} units)" for kind, (r, rate, n) in res.items())
            print(f"  {name}, seed {seed}: {cells}: {'ordered' if ordered else 'NOT ordered'}")
            if k == 0 and out is not None:
                _save_plot(ds, inner, surface, path, out / f"{name}_sep.png")
        print(f"  {name}: ordering held on {held} of {len(args.seeds)} fingertips")
    return 0


def _save_plot(ds, inner, surface, path, file: Path) -> None:
    from ddmm.experiments.io import save_figure
    from ddmm.experiments.plots.texture import plot_spatial_events
    from ddmm.population.analysis.surface_maps import spatial_events

    figure = plot_spatial_events(spatial_events(ds, path, afferents=inner), surface, extent_mm=_extent(surface))
    print(f"  wrote {save_figure(figure, file)}")


if __name__ == "__main__":
    raise SystemExit(main())
