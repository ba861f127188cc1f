"""Everyday probing beside TouchSim: how far from a probe units respond, and whether a slow press excites FA-I.

Two presses of one 1 mm probe (radius 0.5 mm) to 0.5 mm, as TouchSim's ``stim_ramp`` makes them (linear
ramps on and off inside the stated length):

* **fast**: 50 ms ramps (10 mm/s), 1.2 s in all;
* **slow**: 250 ms ramps (2 mm/s, an everyday press), 1.5 s in all;

with every unit placed at (d, 0) mm, d in `DISTANCES_MM`, the probe at the origin.  TouchSim's units are its
single models (``affpop_single_models``, noise off, 4 SA1, 9 RA, 4 PC), moved to (d, 0) by their
``location``; ddmm's are the fingertip preset's nearest units of each type
(`touchsim_side_by_side.named_units`), moved to (d, 0), on the default skin with the shipped transduction.
Per unit the spikes are counted in three windows: the loading ramp and 50 ms after it (``on``), the hold
from 0.2 s after the ramp to the release (``hold``), and the release and after (``off``).

Both sides are **held out**: no fit saw a unit off the probe's centre or a ramp slower than 10 mm/s.

Record TouchSim's side in its own environment (this file imports ddmm only for ddmm's side)::

    /tmp/tsvenv/bin/python experiments/validation/touchsim_probe_spread.py \\
        --record tests/population/data/touchsim_probe_spread.json

Print both side by side::

    python -m ddmm.experiments.validation.touchsim_probe_spread --touchsim tests/population/data/touchsim_probe_spread.json
"""

from __future__ import annotations

import argparse
import importlib.metadata
import json
from pathlib import Path

import numpy as np

__all__ = ["DISTANCES_MM", "PRESSES", "count_windows", "ddmm_spread", "main", "record_touchsim", "summarise"]

#: Distances (mm) of the units from the probe's axis.  Beyond 2 mm ddmm refuses a pin with no unit within
#: 2 mm of it (the skin's edge), so the units cannot all stand further off.
DISTANCES_MM = (0.0, 0.5, 1.0, 1.5, 2.0)
#: The presses: (depth mm, each ramp's length s, total length s), TouchSim's ``stim_ramp(amp, len, ramp_len)``.
PRESSES = {"fast": (0.5, 0.05, 1.2), "slow": (0.5, 0.25, 1.5)}
FS = 5000.0
_CLASSES = {"SA1": "SAI", "RA": "RAI", "PC": "RAII"}  # TouchSim's class -> ddmm's type
TOUCHSIM_COMMIT = "4ec9f5c382e7d48410566de743d7a4f05de75cec"


def count_windows(spike_times, press: str) -> dict:
    """Spike counts of one unit in the ``on``, ``hold`` and ``off`` windows of ``press`` (module docstring).

    Examples
    --------
    >>> count_windows([0.01, 0.5, 1.19], "fast")
    {'on': 1, 'hold': 1, 'off': 1}
    """
    _, ramp, total = PRESSES[press]
    t = np.asarray(spike_times, dtype=float)
    release = total - ramp
    return {"on": int(np.sum(t < ramp + 0.05)), "hold": int(np.sum((t >= ramp + 0.2) & (t < release))),
            "off": int(np.sum(t >= release))}


def _ramp(depth_mm: float, ramp_s: float, total_s: float) -> np.ndarray:
    """TouchSim's linear ``stim_ramp`` trace (mm at `FS`): up over ``ramp_s``, held, down over ``ramp_s``."""
    n, k = round(total_s * FS), round(ramp_s * FS)
    trace = np.full(n, depth_mm)
    trace[:k], trace[n - k:] = np.linspace(0.0, depth_mm, k), np.linspace(depth_mm, 0.0, k)
    return trace


def ddmm_spread(seed: int = 0) -> dict:
    """{press: {distance: [(type, counts by window), ...]}} of ddmm's named units (module docstring)."""
    import dataclasses

    from ddmm.experiments.validation.touchsim_side_by_side import named_units
    from ddmm.population import simulate
    from ddmm.population.stimuli.indentation import indent, probe

    units, out = named_units(), {}
    for press, (depth, ramp, total) in PRESSES.items():
        scene = indent(probe(), _ramp(depth, ramp, total), fs=FS, name=press)
        out[press] = {}
        for d in DISTANCES_MM:
            placed = dataclasses.replace(units, x_mm=np.full(len(units), d))
            ds = simulate(placed, scene, engine="direct", seed=seed, quiet=True)
            times, owner = ds.spike_time.values, ds.spike_afferent.values
            out[press][str(d)] = [(str(kind), count_windows(times[owner == j], press))
                                  for j, kind in enumerate(placed.afferent_type)]
    return out


def record_touchsim() -> dict:
    """{press: {distance: [(class, counts by window), ...]}} of TouchSim's single models (module docstring)."""
    import touchsim as ts

    out = {}
    for press, (depth, ramp, total) in PRESSES.items():
        out[press] = {}
        for d in DISTANCES_MM:
            aff = ts.affpop_single_models(noisy=False)
            for a in aff.afferents:
                a.location = np.array([[d, 0.0]])
            stim = ts.stim_ramp(amp=depth, len=total, ramp_len=ramp, fs=FS, pin_radius=0.5, loc=[0, 0])
            if not np.allclose(stim.trace[0], _ramp(depth, ramp, total)):
                raise RuntimeError("TouchSim's stim_ramp is not the linear ramp this file assumes")
            response = aff.response(stim)
            out[press][str(d)] = [(a.affclass, count_windows(np.asarray(s, float), press))
                                  for a, s in zip(aff.afferents, response.spikes)]
    return out


def summarise(responses: dict, kind: str, press: str, window: str) -> list:
    """Per distance: (units of ``kind`` with a spike in ``window``, units of ``kind``, their mean count).
    ``kind`` is a ddmm type or a TouchSim class; ``responses`` is `ddmm_spread`'s or the recording's."""
    rows = []
    for d in DISTANCES_MM:
        counts = [c[window] for k, c in responses[press][str(d)] if k == kind]
        rows.append((sum(c > 0 for c in counts), len(counts), float(np.mean(counts))))
    return rows


def main(argv=None) -> int:
    """Record TouchSim's side (``--record``) or print both sides (``--touchsim``); module docstring."""
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    group = parser.add_mutually_exclusive_group(required=True)
    group.add_argument("--record", type=Path, help="run TouchSim and write its responses (JSON) here")
    group.add_argument("--touchsim", type=Path, help="TouchSim's recorded responses (JSON) to compare with")
    parser.add_argument("--seed", type=int, default=0, help="ddmm's noise seed")
    args = parser.parse_args(argv)
    if args.record:
        recording = {"what": __doc__.splitlines()[0], "touchsim": {
            "commit": TOUCHSIM_COMMIT, "version": importlib.metadata.version("touchsim")},
            "presses": {k: {"depth_mm": v[0], "ramp_s": v[1], "len_s": v[2]} for k, v in PRESSES.items()},
            "distances_mm": DISTANCES_MM, "fs_hz": FS, "responses": record_touchsim()}
        args.record.write_text(json.dumps(recording, indent=1) + "\n")
        return 0
    theirs = json.loads(args.touchsim.read_text())["responses"]
    ours = ddmm_spread(args.seed)
    print("HELD OUT (no fit saw these): units with a spike / units, mean spikes, by distance from a 1 mm probe")
    print("press | window | type | " + " | ".join(f"{d:g} mm ddmm / TouchSim" for d in DISTANCES_MM))
    for press in PRESSES:
        for window in ("on", "hold", "off"):
            for cls, kind in _CLASSES.items():
                pairs = zip(summarise(ours, kind, press, window), summarise(theirs, cls, press, window))
                print(f"{press} | {window} | {kind} | " + " | ".join(
                    f"{a}/{n} {m:.1f} / {b}/{k} {q:.1f}" for (a, n, m), (b, k, q) in pairs))
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
