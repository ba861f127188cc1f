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

TouchSim beside it: its single models (noise off), one per unit at the positions of the units analysed, the
models of a class taken in turn, on the same pins and depths (`ddmm.population.stimuli.scanning.scan_depths`;
TouchSim's skin is normal-only), scored the same way.  Record them where TouchSim and ddmm are both installed
(the fixture holds TouchSim's commit)::

    python -m ddmm.experiments.validation.pattern_scans --record tests/population/data/touchsim_pattern_scans.json

Run::

    python -m ddmm.experiments.validation.pattern_scans [--seeds 1 2 3 4] [--out DIR] \
        [--touchsim tests/population/data/touchsim_pattern_scans.json]

``--out`` writes ``<pattern>_sep.png``, the first seed's spatial event plot of each pattern; ``--touchsim``
prints TouchSim's recorded r beside ddmm's for the seeds it holds.
"""

from __future__ import annotations

import argparse
import importlib.metadata
import json
from pathlib import Path

import numpy as np

from ddmm.experiments.io import ensure_out_dir, save_json, seed_arg

__all__ = ["PATTERNS", "SPEED_MM_S", "DURATION_S", "TOUCHSIM_COMMIT", "pattern_scene", "fingertip_run",
           "relief_correlations", "record_touchsim", "main"]

#: The scanned patterns by name: the `ddmm.population.stimuli.surfaces` function that makes each, and its arguments.
PATTERNS = {"letters": ("letters", ("AB",)), "dots": ("dot_pattern", (3.0,))}
SPEED_MM_S, DURATION_S = 40.0, 0.6
_CONTACT_MM, _PITCH_MM, _WINDOW_MM, _INNER_MM, _BIN_MM = 0.5, 0.25, 10.0, 3.5, 0.25
_TYPES = ("SAI", "RAI", "RAII")
_CLASSES = {"SAI": "SA1", "RAI": "RA", "RAII": "PC"}  # ddmm's type -> TouchSim's class
TOUCHSIM_COMMIT = "4ec9f5c382e7d48410566de743d7a4f05de75cec"
_SCAN = {"speed_mm_s": SPEED_MM_S, "duration_s": DURATION_S, "contact_mm": _CONTACT_MM,
         "window_mm": (_WINDOW_MM, _WINDOW_MM), "pitch_mm": _PITCH_MM}


def _surface(name: str):
    from ddmm.population.stimuli import surfaces

    maker, args = PATTERNS[name]
    return getattr(surfaces, maker)(*args)


def pattern_scene(name: str = "letters"):
    """(scene, surface, path): the pattern ``name`` of `PATTERNS` scanned as the module docstring says."""
    from ddmm.population.analysis.surface_maps import ScanPath
    from ddmm.population.stimuli.scanning import scan
    from ddmm.utils.validation import check_choice

    surface = _surface(check_choice(name, "name", sorted(PATTERNS)))
    return scan(surface, **_SCAN, name=f"scan_{name}"), surface, ScanPath(SPEED_MM_S, DURATION_S)


def fingertip_run(seed: int, scene) -> tuple:
    """(dataset, inner): the fingertip of ``seed``'s units under the window run on ``scene`` (noise seed ``seed``),
    and the positions of those whose centre lies in the inner 7 x 7 mm."""
    from ddmm.population import simulate

    sub, inner = _window_units(seed)
    return simulate(sub, scene, engine="direct", seed=seed, quiet=True), inner


def _window_units(seed: int) -> tuple:
    """(the fingertip of ``seed``'s units under the window, positions of those in the inner 7 x 7 mm)."""
    from ddmm.population import sample_population

    pop = sample_population("fingertip", rng=seed)
    half = _WINDOW_MM / 2.0
    sub = pop.select(np.flatnonzero((np.abs(pop.x_mm) <= half) & (np.abs(pop.y_mm) <= half)))
    return sub, np.flatnonzero((np.abs(sub.x_mm) <= _INNER_MM) & (np.abs(sub.y_mm) <= _INNER_MM))


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


def record_touchsim(seeds=(1, 2, 3, 4)) -> dict:
    """{pattern: {seed: {type: [r, mean rate]}}} of TouchSim's single models on each pattern (module docstring);
    needs TouchSim (``import touchsim``) beside ddmm."""
    import touchsim as ts

    from ddmm.population.analysis.surface_maps import ScanPath
    from ddmm.population.stimuli.scanning import scan_depths

    out = {}
    for name in PATTERNS:
        surface = _surface(name)
        pins, depth, fs = scan_depths(surface, **_SCAN)
        stim = ts.Stimulus(location=np.column_stack([pins.x_mm, pins.y_mm]), trace=depth.T, fs=fs,
                           pin_radius=float(np.min(pins.radius_mm)))
        out[name] = {}
        for seed in seeds:
            sub, inner = _window_units(seed)
            keep = [j for j in inner if str(sub.afferent_type[j]) in _CLASSES]
            turn = {cls: 0 for cls in _CLASSES.values()}
            models = []
            for j in keep:
                cls = _CLASSES[str(sub.afferent_type[j])]
                idx, turn[cls] = turn[cls] % len(ts.Afferent.affparams[cls]), turn[cls] + 1
                models.append(ts.Afferent(cls, location=[sub.x_mm[j], sub.y_mm[j]], idx=idx, noisy=False))
            spikes = ts.AfferentPopulation(*models).response(stim).spikes
            ds = _spike_dataset(sub.x_mm[keep], sub.y_mm[keep], sub.afferent_type[keep], spikes)
            res = relief_correlations(ds, np.arange(len(keep)), surface, ScanPath(SPEED_MM_S, DURATION_S))
            out[name][str(seed)] = {kind: [round(r, 4), round(rate, 3)] for kind, (r, rate, _) in res.items()}
    return out


def _spike_dataset(x_mm, y_mm, types, spikes):
    """A one-condition, one-trial run in the simulator's schema (the fields `surface_maps` reads) of units at
    (``x_mm``, ``y_mm``) of ``types`` with spike times ``spikes`` (s, one array per unit)."""
    import xarray as xr

    times = [np.asarray(s, dtype=float).ravel() for s in spikes]
    t = np.concatenate(times) if times else np.zeros(0)
    owner = np.concatenate([np.full(u.size, j) for j, u in enumerate(times)]).astype(np.int32) if times else \
        np.zeros(0, np.int32)
    zeros = np.zeros(t.size, np.int32)
    return xr.Dataset({"spike_time": ("spike", t), "spike_afferent": ("spike", owner), "spike_trial": ("spike", zeros),
                       "spike_condition": ("spike", zeros),
                       "spike_count": (("condition", "trial", "afferent"), np.array([[[u.size for u in times]]]))},
                      coords={"afferent_type": ("afferent", np.asarray(types).astype(object)),
                              "x_mm": ("afferent", np.asarray(x_mm, dtype=float)),
                              "y_mm": ("afferent", np.asarray(y_mm, dtype=float))})


def main(argv=None) -> int:
    """Print each pattern's and seed's correlations, labelled held out, with the target; ``--out`` writes the
    first seed's plots."""
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--seeds", type=seed_arg, nargs="+", default=[1, 2, 3, 4], help="fingertip and noise seeds")
    parser.add_argument("--patterns", nargs="+", choices=sorted(PATTERNS), default=list(PATTERNS))
    parser.add_argument("--out", type=Path, help="directory for <pattern>_sep.png")
    parser.add_argument("--touchsim", type=Path, help="TouchSim's recorded correlations (JSON) to print beside ddmm's")
    parser.add_argument("--record", type=Path, help="run TouchSim (and nothing else) and write its correlations here")
    args = parser.parse_args(argv)
    if args.record is not None:
        recording = {"what": __doc__.splitlines()[0], "touchsim": {
            "commit": TOUCHSIM_COMMIT, "version": importlib.metadata.version("touchsim")},
            "scan": {**_SCAN, "window_mm": list(_SCAN["window_mm"])}, "patterns": PATTERNS,
            "correlations": record_touchsim(args.seeds)}
        save_json(recording, args.record)
        return 0
    try:
        theirs = json.loads(args.touchsim.read_text())["correlations"] if args.touchsim is not None else {}
    except (OSError, ValueError, KeyError) as exc:
        parser.error(f"--touchsim {str(args.touchsim)!r} is not a recording of --record ({type(exc).__name__}: {exc})")
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
            if str(seed) in theirs.get(name, {}):
                ts_r = theirs[name][str(seed)]
                print("    TouchSim (recorded): " + "; ".join(f"{_CLASSES[k]} r {ts_r[k][0]:.2f} ({ts_r[k][1]:.1f} imp/s)"
                                                          for k in _TYPES))
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
