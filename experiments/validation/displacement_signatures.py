"""The classic signatures of tactile afferents on displacement input, all held out from the transduction fit.

Each runs the fingertip preset (from seed 1 by default) through `indent` with the shipped ``"fitted"``
transduction and the default skin, on protocols the fit never saw; the fit's units were the few nearest of
each type of seeds 0-9, so some units here were among them (``--seed 11`` runs on fingertips it never saw).
In 1-3 the 10 units of each type nearest the fingertip's centre are moved under the probe (its hotspot on
each unit, as in microneurography).  1, 3 and 4 pool the units of four fingertips (`N_FINGERTIPS`), as a
study pools its subjects' units: with one fingertip's ten units per type the outcomes turned on which units
were sampled.

1. **Threshold against frequency** (docs/references.md row 8, read): sinusoids of 5-400 Hz on one 1 mm
   probe on a 0.5 mm pre-indentation (the fit used 0.3 mm), amplitudes 0.5 um-0.5 mm; a unit's threshold is
   the smallest amplitude at one spike per cycle in 0.1-0.5 s: a spike in at least 95% of the cycles
   (`ONE_PER_CYCLE`), and 0.95 spike per cycle more than the pre-indentation alone gives (above an SA-I's
   static discharge).  Cycle by cycle, not by count: a count lets two spikes in one cycle stand for a
   missed one, and above 200 Hz, where a unit cannot fire twice a cycle, it failed every unit that
   skipped one cycle in 120 (docs/validation.md gives both).  A type's best frequency is where the median
   threshold over its units is lowest.  Targets: FA-I 8-64 Hz, FA-II 200-300 Hz.
2. **Entrainment** (row 21, recalled): the vector strength of each unit's spikes at its one-spike-per-cycle
   amplitude, median over FA-I at 8-64 Hz and FA-II at 100-300 Hz; target above 0.8.
3. **Rate-intensity** (row 6, read for the shape): SA-I mean rate over ramps to 0.1-1.6 mm and a 1 s hold
   (0.1 s ramps: the fit used 50 ms), median over units, never falls with depth and does not saturate
   (1.6 mm at least 1.3x 0.8 mm); FA-I spikes during ramps to 0.5 mm grow with indentation velocity (1-40 mm/s).
4. **Spatial modulation** (Phillips & Johnson 1981, recalled): a grating pressed 0.8 mm into the skin;
   the same units placed at 13 offsets across one period, their rates over the first 0.3 s fitted by
   ``m + a cos + b sin`` of the offset; modulation ``sqrt(a^2 + b^2) / m``, median per type over the
   5 SA-I, 5 FA-I and 3 FA-II nearest the centre of each of four fingertips.  SA-I resolve
   the finest gratings, FA-I coarser ones, FA-II none: the finest period of the 0.5-4 mm set whose
   modulation reaches 0.3 is SA-I's <= FA-I's, and FA-II reach it at none.
5. **Grating locking** (issue's target): a 1 mm grating scanned at 40 mm/s (the named list's), units in
   the inner 4 x 4 mm of the window; median vector strength at 40 Hz, SA-I at least twice FA-II's.

Run::

    python -m ddmm.experiments.validation.displacement_signatures [--seed 1] [--population fingertip_vibration]
"""

from __future__ import annotations

import argparse
import dataclasses

import numpy as np

from ddmm.models.afferent_types import is_type
from ddmm.utils.validation import check_count

__all__ = ["FREQUENCIES_HZ", "AMPLITUDES_MM", "PERIODS_MM", "N_FINGERTIPS", "ONE_PER_CYCLE", "threshold_curves",
           "rate_intensity", "spatial_modulation", "grating_locking", "main"]

FREQUENCIES_HZ = (5.0, 8.0, 16.0, 32.0, 64.0, 100.0, 150.0, 200.0, 250.0, 300.0, 400.0)
AMPLITUDES_MM = tuple(np.geomspace(5e-4, 0.5, 25))
PERIODS_MM = (0.5, 1.0, 2.0, 4.0)
#: Fingertips whose units the threshold curves and the spatial modulation pool (seeds ``seed`` ... ``seed + 3``).
N_FINGERTIPS = 4
#: A unit is at one spike per cycle when a spike falls in this share of the window's cycles (one missed cycle
#: in twenty allowed: receptor noise skips a cycle now and then at any amplitude).
ONE_PER_CYCLE = 0.95
_FS = 5000.0
_WINDOW = (0.1, 0.5)
_TYPES = ("SAI", "RAI", "RAII")


def _units_near(seed: int, n_fingertips: int = 1, n_per_type: int = 10, population="fingertip"):
    """The ``n_per_type`` SA-I, FA-I and FA-II nearest the centre of each of ``n_fingertips`` fingertips (the
    preset sampled with seeds ``seed``, ``seed + 1``, ...), pooled and moved to the probe at (0, 0): the probe
    on each unit's hotspot, as a microneurographer places it, over units of several hands, as a study pools
    its subjects' (`touchsim_side_by_side.named_units`); ``population`` a preset name, path or spec."""
    from ddmm.experiments.validation.touchsim_side_by_side import named_units

    n_fingertips = check_count(n_fingertips, "n_fingertips")
    return named_units(range(seed, seed + n_fingertips), per_type={t: n_per_type for t in _TYPES},
                       population=population)


def _vibration(freq_hz: float, amplitude_mm: float, pre_mm: float = 0.5) -> np.ndarray:
    """0.6 s at 5 kHz: ``pre_mm`` held from the first sample, the sinusoid ramped in over 50 ms."""
    t = np.arange(int(0.6 * _FS)) / _FS
    envelope = np.minimum(t / 0.05, 1.0)
    return pre_mm + amplitude_mm * envelope * np.sin(2.0 * np.pi * freq_hz * t)


def threshold_curves(seed: int = 1, n_fingertips: int = N_FINGERTIPS, population="fingertip") -> dict:
    """{type: {"thresholds_mm": median threshold per frequency (nan: none reached), "best_hz", "vs": median
    VS at the 1:1 amplitude per frequency, "n": units}} over the 10 units of each type of ``n_fingertips``
    fingertips from seed ``seed`` (module docstring, 1-2)."""
    from ddmm.population import simulate
    from ddmm.population.analysis.physiology_vibration import locking_at_threshold
    from ddmm.population.stimuli.indentation import indent, probe

    pop = _units_near(seed, n_fingertips, population=population)
    scenes = [indent(probe(), _vibration(f, a), fs=_FS, name=f"vib_{f:g}_{i}") for f in FREQUENCIES_HZ
              for i, a in enumerate(AMPLITUDES_MM)]
    ds = simulate(pop, scenes, engine="direct", seed=seed, quiet=True)
    vs1, _, _ = locking_at_threshold(ds, FREQUENCIES_HZ, AMPLITUDES_MM, window=_WINDOW)
    static = simulate(pop, indent(probe(), _vibration(5.0, 0.0), fs=_FS, name="static"), engine="direct", seed=seed,
                      quiet=True)
    thresholds = _thresholds(ds, len(AMPLITUDES_MM), _window_counts(static, 1)[0])
    out = {}
    for kind in _TYPES:
        mine = pop.afferent_type == kind
        med = np.array([np.nanmedian(np.where(np.isnan(row[mine]), np.inf, row[mine])) for row in thresholds])
        med = np.where(np.isinf(med), np.nan, med)
        best = FREQUENCIES_HZ[int(np.nanargmin(med))] if np.any(np.isfinite(med)) else None
        vs = [float(np.nanmedian(row[mine])) if np.any(np.isfinite(row[mine])) else np.nan for row in vs1]
        out[kind] = {"thresholds_mm": med, "best_hz": best, "vs": np.array(vs), "n": int(mine.sum())}
    return out


def _window_counts(ds, n_conditions: int) -> np.ndarray:
    """(n_conditions, n_afferents) spike counts in the steady window 0.1-0.5 s."""
    t, cond, aff = ds.spike_time.values, ds.spike_condition.values, ds.spike_afferent.values
    keep = (t >= _WINDOW[0]) & (t < _WINDOW[1])
    counts = np.zeros((n_conditions, ds.sizes["afferent"]))
    np.add.at(counts, (cond[keep], aff[keep]), 1.0)
    return counts


def _cycles_hit(ds, n_amp: int) -> np.ndarray:
    """(n_frequencies, n_amp, n_afferents): the fraction of the window's stimulus cycles holding a spike."""
    t, cond, aff = ds.spike_time.values, ds.spike_condition.values, ds.spike_afferent.values
    keep = (t >= _WINDOW[0]) & (t < _WINDOW[1])
    t, cond, aff = t[keep], cond[keep], aff[keep]
    freq = np.asarray(FREQUENCIES_HZ)[cond // n_amp]
    cycle = np.floor((t - _WINDOW[0]) * freq + 1e-9).astype(np.int64)
    cond, aff, _ = np.unique(np.stack([cond, aff, cycle]), axis=1)  # one entry per (condition, unit, cycle hit)
    hits = np.zeros((len(FREQUENCIES_HZ) * n_amp, ds.sizes["afferent"]))
    np.add.at(hits, (cond, aff), 1.0)
    cycles = np.asarray(FREQUENCIES_HZ) * (_WINDOW[1] - _WINDOW[0])
    return hits.reshape(len(FREQUENCIES_HZ), n_amp, -1) / cycles[:, None, None]


def _thresholds(ds, n_amp: int, baseline) -> np.ndarray:
    """(n_frequencies, n_afferents): each unit's smallest amplitude (mm) at one spike per cycle (`ONE_PER_CYCLE`:
    a spike in that share of the cycles, and that share of a spike per cycle more than its ``baseline``, its
    count on the pre-indentation alone; nan: none)."""
    counts = _window_counts(ds, len(FREQUENCIES_HZ) * n_amp).reshape(len(FREQUENCIES_HZ), n_amp, -1)
    cycles = np.asarray(FREQUENCIES_HZ)[:, None, None] * (_WINDOW[1] - _WINDOW[0])
    driven = counts - np.asarray(baseline)[None, None, :] >= ONE_PER_CYCLE * cycles
    reached = driven & (_cycles_hit(ds, n_amp) >= ONE_PER_CYCLE)
    first = np.argmax(reached, axis=1)
    return np.where(reached.any(axis=1), np.asarray(AMPLITUDES_MM)[first], np.nan)


def rate_intensity(seed: int = 2, n_fingertips: int = N_FINGERTIPS, population="fingertip") -> dict:
    """{"depths_mm", "sai_hold_rate": median SA-I mean rate over the ramp and hold per depth, "velocities_mm_s",
    "rai_ramp_spikes": median FA-I spikes during the ramp per velocity} over the 10 units of each type of
    ``n_fingertips`` fingertips from seed ``seed`` (module docstring, 3)."""
    from ddmm.population import simulate
    from ddmm.population.stimuli.indentation import indent, probe, ramp_hold

    pop = _units_near(seed, n_fingertips, population=population)
    depths, velocities = (0.1, 0.2, 0.4, 0.8, 1.2, 1.6), (1.0, 2.0, 5.0, 10.0, 20.0, 40.0)
    holds = [indent(probe(), ramp_hold(d, ramp_s=0.1, hold_s=1.0, fs=_FS), fs=_FS, name=f"d{d:g}") for d in depths]
    ramps = [indent(probe(), ramp_hold(0.5, ramp_s=0.5 / v, hold_s=0.2, fs=_FS), fs=_FS, name=f"v{v:g}")
             for v in velocities]
    ds = simulate(pop, holds + ramps, engine="direct", seed=seed, quiet=True)
    t, cond, aff = ds.spike_time.values, ds.spike_condition.values, ds.spike_afferent.values
    sai, rai = is_type(pop.afferent_type, "SAI"), is_type(pop.afferent_type, "RAI")
    hold = [np.median(_counts(t, cond, aff, c, (0.0, 1.1), len(pop))[sai]) / 1.1 for c in range(len(depths))]
    ramp = [np.median(_counts(t, cond, aff, len(depths) + c, (0.0, 0.5 / v + 0.01), len(pop))[rai])
            for c, v in enumerate(velocities)]
    return {"depths_mm": depths, "sai_hold_rate": np.array(hold), "velocities_mm_s": velocities,
            "rai_ramp_spikes": np.array(ramp)}


def _counts(t, cond, aff, c, window, n) -> np.ndarray:
    keep = (cond == c) & (t >= window[0]) & (t < window[1])
    return np.bincount(aff[keep], minlength=n).astype(float)


def _placed(pop, offsets_mm, background) -> tuple:
    """Copies of every unit of ``pop`` at each x offset (y = 0), then the units of ``background`` (which
    cover the skin around them), with fresh ids; (population, number of copies)."""
    n, m = len(pop), len(offsets_mm)
    idx, x = np.repeat(np.arange(n), m), np.tile(np.asarray(offsets_mm, dtype=float), n)
    fields = {}
    for f in dataclasses.fields(pop):
        v, w = getattr(pop, f.name), getattr(background, f.name)
        if isinstance(v, np.ndarray) and v.shape[:1] == (n,):
            fields[f.name] = np.concatenate([v[idx], w])
        else:
            fields[f.name] = v
    fields["x_mm"] = np.concatenate([x, background.x_mm])
    fields["y_mm"] = np.concatenate([np.zeros(idx.size), background.y_mm])
    fields["afferent_id"] = np.arange(fields["x_mm"].size, dtype=np.int64)
    return type(pop)(**fields), idx.size


def _pressed_grating(period_mm: float, contact_mm: float = 0.8):
    """A grating of ``period_mm`` (ridges half the period, 0.5 mm high) pressed ``contact_mm`` in over 50 ms and
    held to 0.3 s, on a window of pins at least 6 mm and a period plus 4 mm wide (pitch a fifth of the period,
    at most 0.2 mm)."""
    from ddmm.population.stimuli.indentation import indent, pin_array
    from ddmm.population.stimuli.surfaces import grating

    pitch = min(0.2, period_mm / 5.0)
    side = int(np.ceil(max(6.0, period_mm + 4.0) / pitch))
    pins = pin_array(side, side, pitch_mm=pitch, radius_mm=0.5 * pitch * (1.0 - 1e-9))  # a hair under: no overlap
    surface = grating(period_mm, pixel_mm=min(0.05, period_mm / 10.0))
    h = surface.height_at(pins.x_mm, pins.y_mm)
    envelope = np.minimum(np.arange(int(0.3 * _FS)) / (0.05 * _FS), 1.0)
    depth = envelope[:, None] * np.maximum(contact_mm - (surface.max_height_mm - h), 0.0)[None, :]
    return indent(pins, depth, fs=_FS, name=f"grating_{period_mm:g}mm")


def spatial_modulation(seed: int = 3, n_fingertips: int = N_FINGERTIPS, n_offsets: int = 13,
                       population="fingertip") -> dict:
    """{type: modulation per period of `PERIODS_MM`} (module docstring, 4): the median over a type's units
    (the 5 SA-I, 5 FA-I and 3 FA-II nearest the centre of each of ``n_fingertips`` fingertips from seed
    ``seed``) of each unit's modulation across offsets."""
    seeds = range(seed, seed + check_count(n_fingertips, "n_fingertips"))
    parts = [_unit_modulation(s, n_offsets, population) for s in seeds]
    types = np.concatenate([kinds for kinds, _ in parts])
    index = np.concatenate([rows for _, rows in parts], axis=1)  # (period, unit)
    return {kind: np.median(index[:, types == kind], axis=1) for kind in _TYPES}


def _unit_modulation(seed: int, n_offsets: int, population) -> tuple:
    """(types, (period, unit) modulation) of one fingertip's nearest units.  The copies are simulated among the
    fingertip's own units under the window (not analysed), so that every pin lies on the population's skin."""
    from ddmm.experiments.validation.touchsim_side_by_side import nearest_units
    from ddmm.population import sample_population, simulate

    pop = sample_population(population, rng=seed)
    units = pop.select(nearest_units(pop, {"SAI": 5, "RAI": 5, "RAII": 3}))
    rows = []
    for period in PERIODS_MM:
        offsets = np.linspace(-period / 2.0, period / 2.0, n_offsets, endpoint=False)
        scene = _pressed_grating(period)
        half = float(np.max(np.abs(scene.sites.x_mm))) + 0.5
        background = pop.select(np.flatnonzero((np.abs(pop.x_mm) <= half) & (np.abs(pop.y_mm) <= half)))
        placed, n_copies = _placed(units, offsets, background)
        ds = simulate(placed, scene, engine="direct", seed=seed, quiet=True)
        counts = ds.spike_count.sum(("condition", "trial")).values[:n_copies]
        rates = counts.reshape(len(units), n_offsets) / 0.3
        design = np.column_stack([np.ones(n_offsets), np.cos(2 * np.pi * offsets / period),
                                  np.sin(2 * np.pi * offsets / period)])
        coef = np.linalg.lstsq(design, rates.T, rcond=None)[0]  # (3, n_units)
        rows.append(np.where(coef[0] > 0, np.hypot(coef[1], coef[2]) / np.maximum(coef[0], 1e-12), 0.0))
    return units.afferent_type, np.array(rows)


def grating_locking(seed: int = 1, population="fingertip") -> dict:
    """{type: (median VS at 40 Hz after 0.1 s, units with >= 5 spikes)} of the inner 4 x 4 mm's units under the
    named list's 1 mm grating at 40 mm/s (module docstring, 5)."""
    from ddmm.experiments.validation.touchsim_side_by_side import grating_scene
    from ddmm.population import sample_population, simulate
    from ddmm.population.analysis.physiology_vibration import vector_strength

    pop = sample_population(population, rng=seed)
    window = (np.abs(pop.x_mm) <= 4.5) & (np.abs(pop.y_mm) <= 4.5)
    sub = pop.select(np.flatnonzero(window))
    inner = np.flatnonzero((np.abs(sub.x_mm) <= 2.0) & (np.abs(sub.y_mm) <= 2.0))
    ds = simulate(sub, grating_scene(), engine="direct", seed=seed, quiet=True)
    t, aff = ds.spike_time.values, ds.spike_afferent.values
    out = {}
    for kind in _TYPES:
        strengths = []
        for j in inner[sub.afferent_type[inner] == kind]:
            spikes = t[(aff == j) & (t >= 0.1)]
            if spikes.size >= 5:
                strengths.append(vector_strength(spikes, 40.0))
        out[kind] = (float(np.median(strengths)) if strengths else float("nan"), len(strengths))
    return out


def _finest(modulation, criterion: float = 0.3):
    hits = [p for p, m in zip(PERIODS_MM, modulation) if m >= criterion]
    return min(hits) if hits else None


def main(argv=None) -> int:
    """Run the five signatures and print each, labelled held out, with its target (module docstring)."""
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--seed", type=int, default=1, help="population and noise seed (the fit's units: the "
                        "nearest of seeds 0-9; 10 and above: fingertips it never saw)")
    parser.add_argument("--population", default="fingertip", help="a fingertip-frame preset (fingertip, "
                        "fingertip_vibration) or a spec .toml file; the units are its nearest to the centre")
    args = parser.parse_args(argv)
    s, population = args.seed, args.population
    seen = "some of their units were in the fit" if s <= 9 else "fingertips the fit never saw"
    print(f"displacement signatures, HELD OUT protocols (no fit saw them); fingertip seeds {s}-{s + 5} "
          f"({seen}), units pooled over four: thresholds {s}-{s + 3}, rate-intensity {s + 1}-{s + 4}, spatial "
          f"modulation {s + 2}-{s + 5}; the scanned grating {s}; population {population}")
    curves = threshold_curves(s, population=population)
    for kind in _TYPES:
        c = curves[kind]
        th = " ".join("-" if np.isnan(v) else f"{v * 1e3:.3g}" for v in c["thresholds_mm"])
        print(f"threshold (um) at {'/'.join(f'{f:g}' for f in FREQUENCIES_HZ)} Hz, {kind} (n={c['n']}): {th}; "
              f"best {c['best_hz']} Hz")
    ok_fa1 = curves["RAI"]["best_hz"] is not None and 8 <= curves["RAI"]["best_hz"] <= 64
    ok_fa2 = curves["RAII"]["best_hz"] is not None and 200 <= curves["RAII"]["best_hz"] <= 300
    print(f"best frequency FA-I in 8-64 Hz: {ok_fa1}; FA-II in 200-300 Hz: {ok_fa2} (row 8, read)")
    f = np.asarray(FREQUENCIES_HZ)
    vs1 = np.nanmedian(curves["RAI"]["vs"][(f >= 8) & (f <= 64)])
    vs2 = np.nanmedian(curves["RAII"]["vs"][(f >= 100) & (f <= 300)])
    print(f"entrainment: median VS at 1:1, FA-I 8-64 Hz {vs1:.2f}, FA-II 100-300 Hz {vs2:.2f}; above 0.8: "
          f"{bool(vs1 > 0.8)}, {bool(vs2 > 0.8)} (row 21, recalled)")
    ri = rate_intensity(s + 1, population=population)
    hold, ramp = ri["sai_hold_rate"], ri["rai_ramp_spikes"]
    print(f"SA-I mean rate (imp/s) at {ri['depths_mm']} mm: {np.round(hold, 1).tolist()}; non-decreasing: "
          f"{bool(np.all(np.diff(hold) >= 0))}; 1.6 mm / 0.8 mm = {hold[-1] / max(hold[3], 1e-9):.2f} (>= 1.3)")
    print(f"FA-I ramp spikes at {ri['velocities_mm_s']} mm/s: {np.round(ramp, 1).tolist()}; non-decreasing: "
          f"{bool(np.all(np.diff(ramp) >= 0))} (row 6, read for the shape)")
    mod = spatial_modulation(s + 2, population=population)
    for kind in _TYPES:
        print(f"spatial modulation at {PERIODS_MM} mm, {kind}: {np.round(mod[kind], 2).tolist()}; finest period "
              f">= 0.3: {_finest(mod[kind])}")
    lock = grating_locking(s, population=population)
    print("grating 1 mm at 40 mm/s, median VS at 40 Hz (units): " + ", ".join(
        f"{k} {v[0]:.2f} ({v[1]})" for k, v in lock.items()) + f"; SA-I >= 2x FA-II: "
          f"{bool(lock['SAI'][0] >= 2 * lock['RAII'][0])}")
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
