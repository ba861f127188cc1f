"""ddmm beside TouchSim on one named list of indentation stimuli: per-type rates and first-spike times.

The named list (issue 43): a ramp-and-hold on one 1 mm probe at 0.25, 0.5 and 1.0 mm; sinusoids on the
probe at 5-300 Hz and 0.01, 0.05 and 0.2 mm on a 0.3 mm pre-indentation; a 1 mm grating scanned at 40 mm/s
(`grating_scene`).  ddmm's units are the nearest units of each type of ten fingertips (the preset sampled
with ten seeds: by default `HELD_OUT_SEEDS`, which the transduction fit never saw), moved to the probe's
centre (their own gains, sensitivities and noise), on the default skin; TouchSim's are its single models at
the same place; ddmm reads the stress through its shipped transduction (``"fitted"``: fitted on part of
these cells with the units of `FIT_SEEDS`, `ddmm.experiments.calibration.displacement`).  TouchSim's
figures come from its own run
(`experiments/validation/touchsim_responses.py`, in TouchSim's environment), recorded in a JSON file.

Run::

    python -m ddmm.experiments.validation.touchsim_side_by_side --touchsim tests/population/data/touchsim_responses.json

It prints, per stimulus and type, both mean rates (spikes/s), their ratio and both median first-spike times,
then per type the cells within 2x of TouchSim.  ``--population FILE`` runs the same units drawn from another
spec, such as the ``fingertip_vibration`` preset (the fingertip with faster FA-I and SA-I currents, whose
three constants were chosen on these cells: constrained; docs/validation.md).
Cells of the transduction fit are FITTED, the rest (and the grating) HELD OUT
(`ddmm.experiments.calibration.displacement.is_fitted_cell`); on the held-out fingertips every cell is a
prediction for units the fit never saw.
"""

from __future__ import annotations

import argparse
import dataclasses
import json

import numpy as np

__all__ = ["FIT_SEEDS", "HELD_OUT_SEEDS", "PAIRS", "ddmm_responses", "grating_scene", "main", "named_list",
           "named_units", "nearest_units", "touchsim_summary"]

#: ddmm's type for each TouchSim class (TouchSim fits SA1, RA and PC only).
PAIRS = {"SA1": "SAI", "RA": "RAI", "PC": "RAII"}
_UNITS = {"SAI": 4, "RAI": 9, "RAII": 4}  # as many as TouchSim has single models of each class
#: Fingertip seeds whose units the transduction fit saw (`ddmm.experiments.calibration.displacement`), and the
#: seeds held out from it, on which this script compares by default.
FIT_SEEDS = tuple(range(10))
HELD_OUT_SEEDS = tuple(range(10, 20))


def named_list() -> dict:
    """{name: (depth waveform in mm at 5 kHz, the key of TouchSim's recording)} of the probe stimuli.

    The waveforms are TouchSim's stimuli as its recording describes them: a ramp-and-hold of 1 s with
    linear 50 ms ramps (`ramp_hold`, the same samples); a sinusoid whose phase runs over
    ``linspace(0, 2 pi f T, n)`` with linear 50 ms ramps, on a 0.3 mm pre-indentation present from the
    first sample (a step: the filters start at rest on it, so it makes no onset transient).
    """
    from ddmm.population.stimuli.indentation import ramp_hold

    stimuli = {f"ramp_{d:g}mm": (ramp_hold(d, ramp_s=0.05, hold_s=0.9, fs=5000.0), ("ramp", f"d{d:g}"))
               for d in (0.25, 0.5, 1.0)}
    n, k = 2500, 250
    envelope = np.ones(n)
    envelope[:k], envelope[n - k:] = np.linspace(0.0, 1.0, k), np.linspace(1.0, 0.0, k)
    for f in (5.0, 10.0, 20.0, 40.0, 80.0, 150.0, 250.0, 300.0):
        for a in (0.01, 0.05, 0.2):
            wave = 0.3 + a * np.sin(np.linspace(0.0, 2.0 * np.pi * f * 0.5, n)) * envelope
            stimuli[f"sine_{f:g}hz_{a:g}mm"] = (wave, ("sine", f"f{f:g}_a{a:g}"))
    return stimuli


def nearest_units(pop, per_type=_UNITS) -> np.ndarray:
    """Indices of the ``per_type[t]`` units of each type t nearest the centre of ``pop``'s frame, type by type.

    Examples
    --------
    >>> from ddmm.population import sample_population
    >>> nearest_units(sample_population("fingertip", rng=0), {"SAI": 2, "RAII": 1}).size
    3
    """
    r = np.hypot(pop.x_mm, pop.y_mm)
    return np.concatenate([np.flatnonzero(pop.afferent_type == t)[np.argsort(r[pop.afferent_type == t])[:n]]
                           for t, n in per_type.items()])


def named_units(seeds=(0,), per_type=_UNITS, population="fingertip"):
    """The nearest ``per_type`` units of each type (default ``_UNITS``: 4 SA-I, 9 FA-I, 4 FA-II) of the
    ``population`` spec (a preset name, a `PopulationSpec` or a TOML path; the fingertip preset by default)
    sampled with each of ``seeds`` (its ``rng``), all moved to (0, 0), pooled: each with its own sensitivity,
    gain and noise.  A unit of seed s keeps its id plus s x 10**6, so units of different seeds never share an
    id (nor the noise and excitability drawn from it)."""
    from ddmm.population import load_spec, sample_population

    spec, parts = load_spec(population), []
    for seed in seeds:
        pop = sample_population(spec, rng=seed)
        sub = pop.select(nearest_units(pop, per_type))
        parts.append(dataclasses.replace(sub, afferent_id=sub.afferent_id + int(seed) * 10**6))
    arrays = {f.name: np.concatenate([getattr(part, f.name) for part in parts])
              for f in dataclasses.fields(parts[0]) if isinstance(getattr(parts[0], f.name), np.ndarray)}
    arrays["x_mm"], arrays["y_mm"] = np.zeros(arrays["x_mm"].size), np.zeros(arrays["y_mm"].size)
    return dataclasses.replace(parts[0], **arrays)


def grating_scene():
    """The named list's grating: 1 mm period, ridges 0.5 mm wide and high, scanned along +X at 40 mm/s for 0.5 s
    over a 6 x 6 mm window of 0.2 mm pins, ridges 0.8 mm into the skin, at 5 kHz (TouchSim's recording
    builds the same grating on the same pin grid)."""
    from ddmm.population.stimuli.scanning import scan
    from ddmm.population.stimuli.surfaces import grating

    return scan(grating(1.0, 0.5, 0.5), speed_mm_s=40.0, direction_deg=0.0, duration_s=0.5, contact_mm=0.8,
                window_mm=(6.0, 6.0), pitch_mm=0.2, fs=5000.0, name="grating_40mm_s")


def ddmm_responses(seed: int = 0, seeds=HELD_OUT_SEEDS, population="fingertip") -> dict:
    """{stimulus: {type: {"rate": mean spikes/s, "first_spike_s": median first-spike time or None, "vs": median
    vector strength at 40 Hz after 0.1 s (the grating)}}} of the `named_units` of the ``population`` spec's
    fingertip ``seeds`` (noise seed ``seed``).  The grating's per type: the mean over the seeds' rates, the
    median of their medians."""
    from ddmm.population import load_spec, sample_population, simulate
    from ddmm.population.stimuli.indentation import indent, probe

    spec = load_spec(population)
    units, out = named_units(seeds, population=spec), {}
    for name, (depth, _) in named_list().items():
        ds = simulate(units, indent(probe(), depth, fs=5000.0, name=name), engine="direct", seed=seed, quiet=True)
        out[name] = _summary(ds, depth.size / 5000.0)
    # The grating's window needs skin under every pin, so its units stay where they are in the fingertip.
    by_seed = [_grating_summary(sample_population(spec, rng=s), seed) for s in seeds]
    out["grating_40mm_s"] = {kind: _pooled([g[kind] for g in by_seed]) for kind in _UNITS}
    return out


def _pooled(summaries: list) -> dict:
    """One type's grating summary over seeds: mean rate, median of the medians (None when none has one)."""
    def median(key):
        values = [v[key] for v in summaries if v.get(key) is not None]
        return float(np.median(values)) if values else None
    return {"rate": float(np.mean([v["rate"] for v in summaries])), "first_spike_s": median("first_spike_s"),
            "vs": median("vs")}


def _grating_summary(pop, seed: int) -> dict:
    """The nearest units' responses to the grating, simulated within the population that covers its window."""
    from ddmm.population import simulate

    window = np.flatnonzero((np.abs(pop.x_mm) <= 4.5) & (np.abs(pop.y_mm) <= 4.5))
    sub = pop.select(window)
    ds = simulate(sub, grating_scene(), engine="direct", seed=seed, quiet=True)
    return _summary(ds, 0.5, vs_hz=40.0, units=nearest_units(sub))


def _summary(ds, duration_s: float, vs_hz: float | None = None, units=None) -> dict:
    """Per type: mean rate, median first spike (and median VS at ``vs_hz``) over ``units`` (afferent positions
    in ``ds``; None: all)."""
    counts = ds.spike_count.sum(("condition", "trial")).values
    units = np.arange(counts.size) if units is None else np.asarray(units)
    summary = {}
    for kind in _UNITS:
        mine = units[ds.afferent_type.values[units] == kind]
        trains = [ds.spike_time.values[ds.spike_afferent.values == j] for j in mine]
        firsts = [float(t.min()) for t in trains if t.size]
        summary[kind] = {"rate": float(counts[mine].mean() / duration_s),
                         "first_spike_s": float(np.median(firsts)) if firsts else None}
        if vs_hz is not None:
            strengths = [abs(np.mean(np.exp(2j * np.pi * vs_hz * t[t >= 0.1]))) for t in trains
                         if np.sum(t >= 0.1) >= 5]
            summary[kind]["vs"] = float(np.median(strengths)) if strengths else None
    return summary


def touchsim_summary(recording: dict, key: tuple) -> dict:
    """{class: {"rate": mean spikes/s, "first_spike_s": median first-spike time or None}} of one recorded
    TouchSim stimulus (``key``: its group and name in the recording)."""
    units = (recording[key[0]] if key[1] is None else recording[key[0]][key[1]])["afferents"]
    out = {}
    for cls in PAIRS:
        mine = [u for u in units if u["class"] == cls]
        firsts = [u["first_spike_s"] for u in mine if u["first_spike_s"] is not None]
        out[cls] = {"rate": float(np.mean([u["rate_hz"] for u in mine])),
                    "first_spike_s": float(np.median(firsts)) if firsts else None}
    return out


def main(argv=None) -> int:
    """Print the side-by-side table (module docstring)."""
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--touchsim", required=True, help="TouchSim's recorded responses (JSON)")
    parser.add_argument("--seed", type=int, default=0, help="the noise seed")
    parser.add_argument("--fingertips", default=",".join(map(str, HELD_OUT_SEEDS)),
                        help="comma-separated fingertip seeds whose nearest units to compare (default: the seeds the "
                             "transduction fit held out)")
    parser.add_argument("--population", default="fingertip",
                        help="the fingertip preset (default) or a spec .toml file: a variant of its force path")
    args = parser.parse_args(argv)
    with open(args.touchsim) as f:
        recording = json.load(f)
    seeds = tuple(int(v) for v in args.fingertips.split(","))
    ours = ddmm_responses(args.seed, seeds, args.population)
    from ddmm.experiments.calibration.displacement import is_fitted_cell

    held = "held out" if not set(seeds) & set(FIT_SEEDS) else "seen by the fit"
    print(f"ddmm: the nearest units of fingertip seeds {', '.join(map(str, seeds))} ({held}), population "
          f"{args.population}")
    print("role: the cell's role in the transduction fit; what a population's own constants were chosen on, "
          "its spec and docs/model.md say")
    print("stimulus | role | type | ddmm imp/s | TouchSim imp/s | ratio | ddmm first spike s | TouchSim first spike s")
    for name, (_, key) in {**named_list(), "grating_40mm_s": (None, ("grating", None))}.items():
        theirs, role = touchsim_summary(recording, key), "fitted" if is_fitted_cell(name) else "held out"
        for cls, kind in PAIRS.items():
            mine, ts = ours[name][kind], theirs[cls]
            ratio = f"{mine['rate'] / ts['rate']:.2f}" if ts["rate"] else "-"
            print(f"{name} | {role} | {kind} | {mine['rate']:.1f} | {ts['rate']:.1f} | {ratio} | "
                  f"{_s(mine['first_spike_s'])} | {_s(ts['first_spike_s'])}"
                  + (f" | ddmm VS at 40 Hz {_s(mine['vs'])}" if "vs" in mine else ""))
    print(_agreement_lines(ours, recording))
    return 0


def _agreement_lines(ours: dict, recording: dict) -> str:
    """Per type, the probe cells within 2x of TouchSim where it fires and quiet where it is silent, fitted and
    held-out cells apart (`ddmm.experiments.calibration.displacement.agreement`)."""
    from ddmm.experiments.calibration.displacement import agreement, is_fitted_cell, touchsim_rates

    lines = []
    for cls, kind in PAIRS.items():
        mine, theirs = {name: ours[name][kind]["rate"] for name in named_list()}, touchsim_rates(recording, kind)
        parts = []
        for role, cells in (("fitted", [n for n in mine if is_fitted_cell(n)]),
                            ("held out", [n for n in mine if not is_fitted_cell(n)])):
            a = agreement(mine, theirs, cells)
            parts.append(f"{role} cells {a['within_2x']}/{a['firing']} within 2x, {a['quiet']}/{a['silent']} quiet")
        lines.append(f"{kind} / {cls}: " + "; ".join(parts))
    return "\n".join(lines)


def _s(t) -> str:
    return "-" if t is None else f"{t:.4f}"


if __name__ == "__main__":
    raise SystemExit(main())
