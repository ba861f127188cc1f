"""TouchSim's spiking responses on a named list of stimuli, recorded as a JSON fixture (issue 43).

TouchSim (Saal et al. 2017, ``touchsim`` 0.1.1) runs in its own environment: this script never imports ddmm
and imports touchsim only inside `main`.  The afferents are ``ts.affpop_single_models(loc=[0, 0],
noisy=False)``: one afferent per fitted TouchSim model, 4 SA1, 9 RA and 4 PC (17 in all), all at (0, 0) mm
(``Afferent`` reads ``location``, not ``loc``, so ``loc`` is ignored and the default (0, 0) applies), at
TouchSim's class depths, with the membrane noise off (``noisy=False`` skips the Gaussian current in
``lif_sub``) and no conduction delay (TouchSim's default).  The stimuli, all at fs = 5000 Hz:

* **ramp**: ``stim_ramp(amp=d, len=1.0, ramp_len=0.05, pin_radius=0.5, loc=[0, 0])``, d = 0.25, 0.5, 1.0 mm;
* **sine**: ``stim_sine(freq=f, amp=A, pre_indent=0.3, len=0.5, ramp_len=0.05, pin_radius=0.5)``,
  f = 5 ... 300 Hz (8 values), A = 0.01, 0.05, 0.2 mm;
* **grating**: a fixed skin grid of pins at pitch 0.2 mm over [-3, 3] x [-3, 3] mm (31 x 31 = 961 pins,
  pin_radius 0.1); pin at x gets, at t_k = k / fs (k = 0 ... 2499, 0.5 s), the depth
  ``0.8 - 0.5 * (mod(x + 40 t_k, 1.0) >= 0.5)`` mm, i.e. ridge (0.8 mm) where mod(x + v t, 1.0) < 0.5 and
  groove (0.3 mm) elsewhere: a 1 mm period square-wave grating scanned along +x at 40 mm/s (40 Hz);
* **sine_baseline**: the sine with amp 0, i.e. the 0.3 mm pre-indentation alone (SA1 fire on it);
* **sine_sweep**: the sine at each frequency on a log grid of amplitudes (0.0002-0.3 mm, 30 values) giving
  per class the lowest amplitude that drives it above baseline and that gives >= 1 spike per cycle.

For each stimulus and afferent: spike count, mean rate (count / duration), first-spike time (s, None without
spikes) and, for the sines and the grating, the vector strength |mean exp(2 pi i f t)| at the nominal stimulus
frequency over spikes at t > 0.1 s (None with fewer than 5 such spikes; the grating's also at 400 Hz, the
rate at which ridge edges cross the grid's pin centres); per class the mean rate, the median
first-spike time (over afferents that spiked) and the median vector strength (over afferents that have one).
It also records the stimulus parameters, warnings TouchSim gave, the commit, versions, the host and the wall
time of each stimulus (after a warm-up that compiles TouchSim's numba kernel).

Run, from the repository's root::

    /tmp/tsvenv/bin/python experiments/validation/touchsim_responses.py \\
        --out tests/population/data/touchsim_responses.json [--commit HASH]
"""

from __future__ import annotations

import argparse
import hashlib
import importlib.metadata
import json
import os
import platform
import subprocess
import sys
import time
import warnings
from pathlib import Path

import numpy as np

__all__ = ["GRATING", "RAMP_DEPTHS_MM", "SINE_AMPS_MM", "SINE_FREQS_HZ", "grating_trace", "main",
           "vector_strength"]

#: TouchSim commit the source at /tmp/touchsim_src was taken from (no git checkout there).
TOUCHSIM_COMMIT = "4ec9f5c382e7d48410566de743d7a4f05de75cec"
FS = 5000.0
RAMP_DEPTHS_MM = (0.25, 0.5, 1.0)
SINE_FREQS_HZ = (5.0, 10.0, 20.0, 40.0, 80.0, 150.0, 250.0, 300.0)
SINE_AMPS_MM = (0.01, 0.05, 0.2)
SWEEP_AMPS_MM = tuple(float(a) for a in np.round(np.geomspace(0.0002, 0.3, 30), 6))
GRATING = {"period_mm": 1.0, "ridge_width_mm": 0.5, "ridge_height_mm": 0.5, "speed_mm_per_s": 40.0,
           "duration_s": 0.5, "pitch_mm": 0.2, "half_width_mm": 3.0, "pin_radius_mm": 0.1,
           "ridge_depth_mm": 0.8, "groove_depth_mm": 0.3}
VS_T0_S = 0.1
VS_MIN_SPIKES = 5
CLASSES = ("SA1", "RA", "PC")


def vector_strength(spikes, freq, t0=VS_T0_S, min_spikes=VS_MIN_SPIKES):
    """Vector strength of spike times at a frequency.

    Parameters
    ----------
    spikes : array_like
        Spike times (s).
    freq : float
        Frequency (Hz).
    t0 : float
        Only spikes at t > t0 (s) count.
    min_spikes : int
        Fewer counted spikes than this give None.

    Returns
    -------
    float or None
        ``|mean(exp(2 pi i freq t))|`` over the counted spikes.
    """
    t = np.asarray(spikes, dtype=float)
    t = t[t > t0]
    if t.size < min_spikes:
        return None
    return float(np.abs(np.mean(np.exp(2j * np.pi * freq * t))))


def grating_trace(fs=FS, g=GRATING):
    """Pin positions and depths of the scanned square-wave grating on a fixed skin grid.

    Parameters
    ----------
    fs : float
        Sampling frequency (Hz).
    g : dict
        Grating parameters (see `GRATING`).

    Returns
    -------
    loc : ndarray, shape (n_pins, 2)
        Pin centres (mm).
    trace : ndarray, shape (n_pins, n_samples)
        Depth (mm): ridge depth where ``mod(x + v t, period) < ridge_width``, groove depth elsewhere.
    """
    n_side = round(2 * g["half_width_mm"] / g["pitch_mm"]) + 1
    axis = np.round(np.linspace(-g["half_width_mm"], g["half_width_mm"], n_side), 10)
    xx, yy = np.meshgrid(axis, axis, indexing="ij")
    loc = np.column_stack([xx.ravel(), yy.ravel()])
    t = np.arange(round(g["duration_s"] * fs)) / fs
    ridge = np.mod(loc[:, :1] + g["speed_mm_per_s"] * t[None, :], g["period_mm"]) < g["ridge_width_mm"]
    trace = np.where(ridge, g["ridge_depth_mm"], g["groove_depth_mm"])
    return loc, trace


def _respond(ts, aff, make_stim, freq=None, extra_freq=None):
    """Build a stimulus, run the population on it; per-afferent and per-class summaries plus timing."""
    t_start = time.perf_counter()
    with warnings.catch_warnings(record=True) as caught:
        warnings.simplefilter("always")
        stim = make_stim()
        resp = aff.response(stim)
    wall = time.perf_counter() - t_start
    dur = float(stim.duration)
    rows = []
    for a, sp in zip(aff.afferents, resp.spikes):
        sp = np.asarray(sp, dtype=float)
        row = {"class": a.affclass, "model_idx": int(a.idx), "n_spikes": int(sp.size),
               "rate_hz": sp.size / dur, "first_spike_s": float(sp[0]) if sp.size else None}
        if freq is not None:
            row["vector_strength"] = vector_strength(sp, freq)
        if extra_freq is not None:
            row["vector_strength_extra"] = vector_strength(sp, extra_freq)
        rows.append(row)
    per_class = {}
    for c in CLASSES:
        rs = [r for r in rows if r["class"] == c]
        fst = [r["first_spike_s"] for r in rs if r["first_spike_s"] is not None]
        entry = {"n_afferents": len(rs), "n_spiking": len(fst),
                 "mean_rate_hz": float(np.mean([r["rate_hz"] for r in rs])),
                 "median_first_spike_s": float(np.median(fst)) if fst else None}
        if freq is not None:
            vs = [r["vector_strength"] for r in rs if r["vector_strength"] is not None]
            entry["median_vector_strength"] = float(np.median(vs)) if vs else None
            entry["n_with_vs"] = len(vs)
        if extra_freq is not None:
            vs = [r["vector_strength_extra"] for r in rs if r["vector_strength_extra"] is not None]
            entry["median_vector_strength_extra"] = float(np.median(vs)) if vs else None
        per_class[c] = entry
    out = {"duration_s": dur, "n_pins": len(stim), "pin_radius_used_mm": float(stim.pin_radius),
           "warnings": sorted({str(w.message) for w in caught}), "wall_time_s": wall,
           "afferents": rows, "per_class": per_class}
    if extra_freq is not None:
        out["extra_freq_hz"] = extra_freq
    return out


def _thresholds(sweep, base):
    """Per class and frequency, the lowest sweep amplitude (mm) meeting each criterion (None if none).

    ``drive``: class-mean rate > the pre-indent-only baseline; ``one_per_cycle``: rate >= f;
    ``one_per_cycle_above_baseline``: rate - baseline >= f.
    """
    tests = {"drive": lambda r, f, b: r > b, "one_per_cycle": lambda r, f, b: r >= f,
             "one_per_cycle_above_baseline": lambda r, f, b: r - b >= f}
    out = {k: {c: {} for c in CLASSES} for k in tests}
    for k, test in tests.items():
        for c in CLASSES:
            for f in SINE_FREQS_HZ:
                ok = [a for a, r in zip(SWEEP_AMPS_MM, sweep[c][str(f)]) if test(r, f, base[c])]
                out[k][c][str(f)] = min(ok) if ok else None
    return out


def _best_freq(sines, base):
    """Per class: smallest named amplitude driving the class above baseline, and the frequency of its peak rate."""
    out = {}
    for c in CLASSES:
        out[c] = {"amp_mm": None, "best_freq_hz": None, "rate_hz": None}
        for amp in SINE_AMPS_MM:
            rates = [sines[f"f{f:g}_a{amp:g}"]["per_class"][c]["mean_rate_hz"] for f in SINE_FREQS_HZ]
            if max(rates) > base[c]:
                i = int(np.argmax(rates))
                out[c] = {"amp_mm": amp, "best_freq_hz": SINE_FREQS_HZ[i], "rate_hz": rates[i]}
                break
    return out


def _host():
    """CPU model (``lscpu | head -20``), machine and usable CPUs."""
    try:
        run = subprocess.run(["lscpu"], capture_output=True, text=True, timeout=10, check=False)
        lines = run.stdout.splitlines()[:20]
        model = next((ln.split(":", 1)[1].strip() for ln in lines if ln.startswith("Model name")), None)
    except (OSError, subprocess.SubprocessError):
        model = None
    return {"cpu_model": model, "machine": platform.machine(), "n_cpus": len(os.sched_getaffinity(0))}


def main(argv=None):
    """Run every stimulus of the named list through TouchSim and write the JSON fixture.

    Parameters
    ----------
    argv : list of str, optional
        Command-line arguments (``--out``, ``--commit``).
    """
    p = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    p.add_argument("--out", required=True, type=Path)
    p.add_argument("--commit", default=TOUCHSIM_COMMIT)
    args = p.parse_args(argv)

    import numba
    import scipy
    import touchsim as ts

    aff = ts.affpop_single_models(loc=[0, 0], noisy=False)
    assert all(not a.noisy for a in aff.afferents)
    t0 = time.perf_counter()
    aff.response(ts.stim_ramp(amp=0.1, len=0.05, ramp_len=0.01, fs=FS, pin_radius=0.5))  # numba JIT warm-up
    warmup = time.perf_counter() - t0
    timings = {"warmup_s": warmup}

    t0 = time.perf_counter()
    ramps = {f"d{d:g}": _respond(ts, aff, lambda d=d: ts.stim_ramp(amp=d, len=1.0, ramp_len=0.05, fs=FS,
                                                                  pin_radius=0.5, loc=[0, 0]))
             for d in RAMP_DEPTHS_MM}
    timings["ramp_s"] = time.perf_counter() - t0

    def sine(f, a):
        return ts.stim_sine(freq=f, amp=a, pre_indent=0.3, len=0.5, ramp_len=0.05, fs=FS, pin_radius=0.5,
                            loc=[0, 0])

    t0 = time.perf_counter()
    sines = {f"f{f:g}_a{a:g}": _respond(ts, aff, lambda f=f, a=a: sine(f, a), freq=f)
             for a in SINE_AMPS_MM for f in SINE_FREQS_HZ}
    baseline = _respond(ts, aff, lambda: sine(10.0, 0.0), freq=10.0)
    base = {c: baseline["per_class"][c]["mean_rate_hz"] for c in CLASSES}
    timings["sine_s"] = time.perf_counter() - t0

    t0 = time.perf_counter()
    loc, trace = grating_trace()
    grating = _respond(ts, aff, lambda: ts.Stimulus(trace=trace, location=loc, fs=FS,
                                                    pin_radius=GRATING["pin_radius_mm"]),
                       freq=GRATING["speed_mm_per_s"] / GRATING["period_mm"],
                       extra_freq=GRATING["speed_mm_per_s"] / (GRATING["pitch_mm"] / 2))
    timings["grating_s"] = time.perf_counter() - t0

    t0 = time.perf_counter()
    sweep = {c: {str(f): [] for f in SINE_FREQS_HZ} for c in CLASSES}
    for f in SINE_FREQS_HZ:
        for a in SWEEP_AMPS_MM:
            r = _respond(ts, aff, lambda f=f, a=a: sine(f, a), freq=f)
            for c in CLASSES:
                sweep[c][str(f)].append(r["per_class"][c]["mean_rate_hz"])
    timings["sine_sweep_s"] = time.perf_counter() - t0

    src = Path(ts.__file__).resolve().parent
    digest = hashlib.sha256(b"".join(q.read_bytes() for q in sorted(src.glob("*.py")))).hexdigest()
    out = {
        "what": "TouchSim responses of affpop_single_models (noisy=False) at (0, 0) on a named list of stimuli",
        "issue": 43,
        "touchsim": {"commit": args.commit, "version": importlib.metadata.version("touchsim"),
                     "source_sha256_of_py_files": digest},
        "versions": {"python": sys.version.split()[0], "numpy": np.__version__, "scipy": scipy.__version__,
                     "numba": numba.__version__},
        "host": _host(),
        "afferents": {"call": "ts.affpop_single_models(loc=[0, 0], noisy=False)",
                      "counts": {c: sum(a.affclass == c for a in aff.afferents) for c in CLASSES},
                      "depths_mm": {c: float(ts.Afferent.affdepths[c]) for c in CLASSES},
                      "location_mm": [0.0, 0.0], "noise": "off (noisy=False)", "delay": "off (default)"},
        "definitions": {
            "rate_hz": "n_spikes / stimulus duration (TouchSim Response.rate)",
            "first_spike_s": "first TouchSim spike time (sample index / 5000 + 1/5000 s)",
            "vector_strength": f"|mean(exp(2 pi i f t))| over spikes with t > {VS_T0_S} s at the nominal "
                               f"frequency; None with fewer than {VS_MIN_SPIKES} such spikes",
            "per_class": "mean of rates; median of first-spike times over spiking afferents; median VS over "
                         "afferents with a VS",
            "baseline": "sine with amp 0: the 0.3 mm pre-indentation alone (a step from sample 0)",
            "best_freq": "smallest named amplitude at which some frequency drives the class above the baseline "
                         "class-mean rate, and the frequency of the highest class-mean rate at that amplitude",
            "grating_extra_vs": "grating VS also at v / (pitch / 2) = 400 Hz: the rate at which ridge edges "
                                "cross pin centres of the fixed grid (a pin-grid artefact)",
            "thresholds": "lowest sine_sweep amplitude (mm): drive = rate > baseline; one_per_cycle = rate >= f; "
                          "one_per_cycle_above_baseline = rate - baseline >= f (rate = class mean over 0.5 s)",
            "sine_note": "stim_sine's phase is linspace(0, 2 pi f len, N): the sampled frequency is f N/(N-1)"},
        "params": {
            "fs_hz": FS,
            "ramp": {"depths_mm": RAMP_DEPTHS_MM, "len_s": 1.0, "ramp_len_s": 0.05, "pin_radius_mm": 0.5},
            "sine": {"freqs_hz": SINE_FREQS_HZ, "amps_mm": SINE_AMPS_MM, "pre_indent_mm": 0.3, "len_s": 0.5,
                     "ramp_len_s": 0.05, "pin_radius_mm": 0.5},
            "grating": dict(GRATING, n_pins=int(loc.shape[0]),
                            formula="depth(x, t) = 0.8 - 0.5 * (mod(x + 40 t, 1.0) >= 0.5) mm, t = k / fs"),
            "sine_sweep": {"amps_mm": SWEEP_AMPS_MM}},
        "timings_s": timings,
        "ramp": ramps,
        "sine": sines,
        "sine_baseline": baseline,
        "grating": grating,
        "sine_sweep": {"amps_mm": SWEEP_AMPS_MM, "class_mean_rate_hz": sweep},
        "summary": {"baseline_rate_hz": base, "best_freq": _best_freq(sines, base),
                    "thresholds_mm": _thresholds(sweep, base)},
    }
    args.out.parent.mkdir(parents=True, exist_ok=True)
    args.out.write_text(json.dumps(out, indent=1) + "\n")
    print(f"wrote {args.out} ({args.out.stat().st_size / 1e3:.0f} kB); timings {timings}")


if __name__ == "__main__":
    main()
