"""TouchSim's skin mechanics on its standard stimuli, recorded as a JSON fixture (issue 42).

TouchSim (Saal et al. 2017, ``touchsim`` 0.1.1) is not on the package registry: this script runs in TouchSim's
own environment and imports neither ddmm nor, until `main` runs, touchsim.  It records, for four stimuli built
with TouchSim's own generators (``ts.stim_ramp``, ``ts.stim_sine``, ``ts.Stimulus``):

* **ramp**: ``stim_ramp(amp=0.5, len=0.5, ramp_len=0.1, fs=5000, pin_radius=0.5, loc=[0, 0])``, one pin;
* **sine**: ``stim_sine(freq=50, amp=0.1, pre_indent=0.3, len=0.2, ramp_len=0.05, fs=5000, pin_radius=0.5)``,
  one pin;
* **two_pins**: ``Stimulus`` with pins at (0, 0) and (1.5, 0) mm, radius 0.5 mm, ramped in 0.1 s to 0.5 and
  0.3 mm and held, 0.3 s in all;
* **four_pins**: a 2x2 array at 0.8 mm spacing asked for radius 0.5 mm (TouchSim caps it to half the smallest
  pin spacing, 0.4 mm), ramped in 0.1 s to 0.4, 0.4, 0.1 and 0.0 mm and held, 0.3 s in all;

the stimulus parameters, ``fs``, the pin radius TouchSim used (and any warning it gave), the indentation,
the pin loads ``stim._profile`` (N) and the dynamic loads ``stim._profiledyn`` (N/s) at 10 named sample
indices, and, via ``stim.propagate(afferents)`` on SA1, RA and PC afferents at x = 0, 0.25, 0.5, 1, 2 and
5 mm (y = 0) at TouchSim's class depths (0.3, 1.6, 2.0 mm), the static component (``stat_comp``, N/mm^2) and
the dynamic component (``dyn_comp``, N/(s mm^3)) at the same indices, with each trace's extrema over the whole
stimulus.  It also records TouchSim's ``E`` and ``nu`` as read from its source, the commit, the library
versions, checks against the closed forms of a flat cylindrical punch (Sneddon 1946) and, with ``--timings``,
TouchSim's wall time and peak memory on this host for the whole hand under a 250 Hz sinusoid (1 s) and a
fingertip population under a 1 s ramp, each in a child process under ``/usr/bin/time -v``.

Run, from the repository's root, in an environment that has touchsim and not necessarily ddmm::

    /tmp/tsvenv/bin/python experiments/validation/touchsim_reference.py \\
        --out tests/population/data/touchsim_mechanics.json [--commit HASH] [--timings]

``--commit`` names TouchSim's commit (``git -C <touchsim clone> rev-parse HEAD``); without it the script asks
git in the folder above the imported ``touchsim`` package and records ``null`` when that is no checkout.
"""

from __future__ import annotations

import argparse
import hashlib
import json
import math
import os
import platform
import re
import subprocess
import sys
import time
import warnings
from pathlib import Path

import numpy as np

__all__ = ["AFFERENT_X_MM", "SAMPLE_NAMES", "main"]

#: Afferent positions along x (mm), all at y = 0.
AFFERENT_X_MM = (0.0, 0.25, 0.5, 1.0, 2.0, 5.0)
_CLASSES = ("SA1", "RA", "PC")
_FS = 5000.0
#: The 10 named sample indices of each stimulus (the sine's peak and trough are found on its trace: the
#: sampled maximum and minimum over samples 250-749, where the sine has its full amplitude).
SAMPLE_NAMES = {
    "ramp": {"first": 0, "second": 1, "mid_on_ramp": 250, "end_of_on_ramp": 499, "first_hold": 500,
             "mid_hold": 1250, "last_hold": 1999, "start_of_off_ramp": 2000, "mid_off_ramp": 2250, "last": 2499},
    "sine": {"first": 0, "second": 1, "mid_on_ramp": 125, "end_of_on_ramp": 249, "highest_peak_in_hold": None,
             "lowest_trough_in_hold": None, "middle": 500, "mid_off_ramp": 875, "second_last": 998, "last": 999},
    "pins": {"first": 0, "second": 1, "quarter_ramp": 125, "mid_ramp": 250, "end_of_ramp": 499, "first_hold": 500,
             "early_hold": 600, "mid_hold": 1000, "second_last": 1498, "last": 1499},
}


#: What TouchSim does that a comparison must allow for (read off its code at the recorded commit and seen in
#: the figures of this fixture).
_BEHAVIOUR = [
    ("Pin radius: with two or more pins TouchSim caps the radius to half the smallest pin spacing "
    "(check_pin_radius), warns 'Pin radius too big and has been adjusted to %.1f' (the message rounds: 0.4 here) "
    "and overwrites stim.pin_radius; four_pins asked 0.5 mm and used 0.4 mm, so its pins touch (spacing = 2a)."),
    ("Contact: loads are solved on |trace| with the Sneddon compliance matrix D; a pin whose load comes out "
    "negative has its indentation set to 0 and the system is solved again, so it carries no load. In four_pins "
    "the 0.1 mm pin is lifted off from sample 1 on: the two 0.4 mm pins push the skin under it to 0.169 mm. "
    "Pins whose trace is negative get their load's sign flipped back (a negative trace gives a negative load)."),
    ("Orientation: stim._profile is (n_samples, n_pins) but stim._profiledyn is (n_pins, n_samples); "
    "propagate returns stat_comp and dyn_comp as (n_samples, n_afferents)."),
    ("profiledyn is dP/dt by central differences of the surface profile (solve(D, dS/dt)); the first and last "
    "samples copy their neighbours, so sample 0 of a ramp already has the full slope and a ramp's corner "
    "samples (end of the on-ramp, start of the off-ramp) have half of it. Pins out of contact get round-off "
    "(below 1e-14 N/s), not exactly 0."),
    ("dyn_comp = sum over pins of profiledyn * decay(r) / z^2, decay = arcsin(a/r)/(pi a) (1/(2a) for r <= a), "
    "delayed by rint((r - a)/8000 mm/s * fs) samples with zeros before (dyn_delay_samples); it has no E, nu or "
    "radius in its depth decay and is not a stress rate (units N/(s mm^3))."),
    ("stat_comp is Sneddon's flat-punch vertical stress sigma_z (N/mm^2, compression positive) summed over pins; "
    "it is never negative here, and at SA1 depth it peaks off the axis near the punch edge (x = 0.25 > x = 0)."),
    ("stim_sine adds pre_indent to every sample after ramping only the sine: the 0.3 mm pre-indentation is a step "
    "present from sample 0 and makes no dynamic transient. Its phase is linspace(0, 2 pi f len, N), endpoint "
    "included, so the sampled frequency is f N/(N - 1) (50.05 Hz for 50 Hz over 1000 samples)."),
    ("apply_ramp multiplies the first and last ramp_len*fs samples by linspace(0, 1, n) and linspace(1, 0, n): "
    "the trace reaches its amplitude at sample n - 1 and starts down at sample N - n, so a 0.1 s ramp at 5 kHz "
    "rises over 499 intervals (0.0998 s)."),
    ("Stimulus.time is linspace(0, duration, N): spacing duration/(N - 1), not 1/fs; the 'time_s' here is "
    "index / fs."),
]


def _floats(a) -> list:
    """Nested lists of plain floats, NaN and inf as None (JSON has neither)."""
    a = np.asarray(a, dtype=float)
    if a.ndim == 0:
        v = float(a)
        return v if math.isfinite(v) else None
    return [_floats(x) for x in a]


def _extrema(a) -> dict:
    a = np.asarray(a, dtype=float)
    finite = np.isfinite(a)
    if not finite.any():
        return {"max": None, "argmax": None, "min": None, "argmin": None, "n_nonfinite": int(a.size)}
    b = np.where(finite, a, np.nan)
    return {"max": float(np.nanmax(b)), "argmax": int(np.nanargmax(b)), "min": float(np.nanmin(b)),
            "argmin": int(np.nanargmin(b)), "n_nonfinite": int((~finite).sum())}


def _source_constants(ts) -> dict:
    """E, nu and the wave speed as written in TouchSim's transduction module."""
    import inspect

    src = inspect.getsource(ts.transduction.skin_touch_profile)
    e = float(re.search(r"^\s*E\s*=\s*([0-9.eE+-]+)", src, re.MULTILINE).group(1))
    nu = float(re.search(r"^\s*nu\s*=\s*([0-9.eE+-]+)", src, re.MULTILINE).group(1))
    wave = inspect.getsource(ts.transduction.circ_load_dyn_wave)
    speed = float(re.search(r"rdel\s*/\s*([0-9.eE+-]+)", wave).group(1))
    return {"E": e, "nu": nu, "E_units": "N/mm^2 (MPa): 0.05 N/mm^2 = 50 kPa, with loads in N and lengths in mm",
            "where": "touchsim/transduction.py, skin_touch_profile (local constants E and nu)",
            "wave_speed_mm_per_s": speed,
            "wave_speed_where": "touchsim/transduction.py, circ_load_dyn_wave (delay = (r - a) / speed)"}


def _commit(ts, given):
    if given:
        return given, "given on the command line (--commit)"
    root = Path(ts.__file__).resolve().parent.parent
    try:
        out = subprocess.run(["git", "-C", str(root), "rev-parse", "HEAD"], capture_output=True, text=True,
                             timeout=10, check=False)
    except (OSError, subprocess.SubprocessError):
        return None, "unknown"
    if out.returncode == 0 and re.fullmatch(r"[0-9a-f]{40}", out.stdout.strip()):
        return out.stdout.strip(), f"git rev-parse HEAD in {root.name}/"
    return None, "unknown: the touchsim source is no git checkout and no --commit was given"


def _source_digest(ts) -> dict:
    folder = Path(ts.__file__).resolve().parent
    return {p.name: hashlib.sha256(p.read_bytes()).hexdigest() for p in sorted(folder.glob("*.py"))}


def _afferents(ts):
    """SA1, RA and PC at every x of AFFERENT_X_MM, class-major, model 0, noise off (propagate uses neither)."""
    affs = [ts.Afferent(c, location=np.array([x, 0.0]), idx=0, noisy=False) for c in _CLASSES
            for x in AFFERENT_X_MM]
    return ts.AfferentPopulation(*affs)


def _pin_trace(depths, n=1500, ramp=500) -> np.ndarray:
    """One row per pin: ``depth * i / (ramp - 1)`` for i < ramp (TouchSim's own linear ramp), then ``depth``."""
    shape = np.ones(n)
    shape[:ramp] = np.linspace(0.0, 1.0, ramp)
    return np.outer(np.asarray(depths, dtype=float), shape)


def _stimuli(ts):
    """name -> (stimulus, what was asked, a description of the trace, the pins' locations, warnings)."""
    made = {}

    def build(name, fn, asked, described, locations):
        with warnings.catch_warnings(record=True) as caught:
            warnings.simplefilter("always")
            stim = fn()
        made[name] = (stim, asked, described, locations, [str(w.message) for w in caught])

    ramp = {"amp": 0.5, "len": 0.5, "ramp_len": 0.1, "fs": _FS, "pin_radius": 0.5, "loc": [0.0, 0.0]}
    build("ramp", lambda: ts.stim_ramp(**ramp), {"generator": "touchsim.stim_ramp", "kwargs": ramp},
          "ts.stim_ramp: 0.5 mm * ones(2500); apply_ramp multiplies the first 500 samples by linspace(0, 1, 500) "
          "and the last 500 by linspace(1, 0, 500) (so samples 499..2000 are at 0.5 mm); ramp_type 'lin', "
          "no pre-indentation, no padding", [[0.0, 0.0]])
    sine = {"freq": 50.0, "amp": 0.1, "pre_indent": 0.3, "len": 0.2, "ramp_len": 0.05, "fs": _FS, "pin_radius": 0.5}
    build("sine", lambda: ts.stim_sine(**sine), {"generator": "touchsim.stim_sine", "kwargs": sine},
          "ts.stim_sine: 0.1 mm * sin(linspace(0, 2 pi 50 0.2, 1000)) (endpoint included: 10 cycles over 999 "
          "intervals), its first and last 250 samples multiplied by linspace(0, 1, 250) and linspace(1, 0, 250), "
          "then 0.3 mm added to every sample (the pre-indentation is a step present from sample 0, not ramped)",
          [[0.0, 0.0]])
    two = {"location": [[0.0, 0.0], [1.5, 0.0]], "fs": _FS, "pin_radius": 0.5}
    build("two_pins", lambda: ts.Stimulus(trace=_pin_trace([0.5, 0.3]), **two),
          {"generator": "touchsim.Stimulus", "kwargs": two, "depths_mm": [0.5, 0.3]},
          "trace[k, i] = depth_k * i / 499 for i < 500, depth_k for 500 <= i < 1500 (0.1 s linear ramp, then held "
          "to 0.3 s), depth = (0.5, 0.3) mm", two["location"])
    loc4 = [[0.0, 0.0], [0.8, 0.0], [0.0, 0.8], [0.8, 0.8]]
    four = {"location": loc4, "fs": _FS, "pin_radius": 0.5}
    build("four_pins", lambda: ts.Stimulus(trace=_pin_trace([0.4, 0.4, 0.1, 0.0]), **four),
          {"generator": "touchsim.Stimulus", "kwargs": four, "depths_mm": [0.4, 0.4, 0.1, 0.0]},
          "2x2 array at 0.8 mm spacing, pins (0,0), (0.8,0), (0,0.8), (0.8,0.8); trace[k, i] = depth_k * i / 499 "
          "for i < 500, depth_k for 500 <= i < 1500, depth = (0.4, 0.4, 0.1, 0.0) mm", loc4)
    return made


def _indices(name, stim) -> dict:
    key = name if name in ("ramp", "sine") else "pins"
    idx = dict(SAMPLE_NAMES[key])
    if name == "sine":
        tr = stim.trace[0]
        idx["highest_peak_in_hold"] = 250 + int(np.argmax(tr[250:750]))  # samples 250-749: full amplitude
        idx["lowest_trough_in_hold"] = 250 + int(np.argmin(tr[250:750]))
    return dict(sorted(idx.items(), key=lambda kv: kv[1]))


def _record(name, stim, asked, described, locations, caught, pop, consts) -> dict:
    idx = _indices(name, stim)
    at = np.array(list(idx.values()))
    with warnings.catch_warnings(record=True) as prop_warn:
        warnings.simplefilter("always")
        stat, dyn, fs = stim.propagate(pop)
    stat, dyn = np.asarray(stat), np.asarray(dyn)
    prof, profdyn = np.asarray(stim._profile), np.asarray(stim._profiledyn)
    # the skin's deflection under each pin implied by the loads (TouchSim's D, rebuilt from E and nu)
    xy = np.asarray(stim.location, dtype=float)
    a, e, nu = float(stim.pin_radius), consts["E"], consts["nu"]
    r = np.hypot(*(xy[:, None, :] - xy[None, :, :]).transpose(2, 0, 1))
    with np.errstate(all="ignore"):
        d = (1 - nu ** 2) / np.pi / a * np.arcsin(a / r) / e
    d[r <= a] = (1 - nu ** 2) / 2 / a / e
    surface = prof @ d
    n_aff = len(AFFERENT_X_MM)
    aff_xy = np.array([[x, 0.0] for x in AFFERENT_X_MM])
    dist = np.hypot(*(xy[:, None, :] - aff_xy[None, :, :]).transpose(2, 0, 1))
    delay = np.rint(np.maximum(dist - a, 0.0) / consts["wave_speed_mm_per_s"] * fs).astype(int)
    out = {
        "stimulus": asked, "trace_description": described, "fs": float(fs), "n_samples": int(stim.trace.shape[1]),
        "duration_s": float(stim.duration), "pin_locations_mm": _floats(locations),
        "pin_radius_requested_mm": float(asked["kwargs"]["pin_radius"]), "pin_radius_used_mm": a,
        "warnings": caught, "propagate_warnings": [str(w.message) for w in prop_warn],
        "samples": {"names": list(idx), "indices": [int(i) for i in at], "time_s": _floats(at / fs)},
        "trace_mm": _floats(stim.trace[:, at]),
        "profile_N": _floats(prof[at, :].T),
        "profiledyn_N_per_s": _floats(profdyn[:, at]),
        "surface_deflection_under_pins_mm": _floats(surface[at, :].T),
        "pins_out_of_contact_at_samples": [[bool(prof[i, k] == 0 and stim.trace[k, i] != 0) for i in at]
                                           for k in range(prof.shape[1])],
        "profile_extrema": [_extrema(prof[:, k]) for k in range(prof.shape[1])],
        "profiledyn_extrema": [_extrema(profdyn[k]) for k in range(profdyn.shape[0])],
        "dyn_delay_samples": [[int(v) for v in row] for row in delay],
        "stat_comp": {}, "dyn_comp": {}, "stat_comp_extrema": {}, "dyn_comp_extrema": {},
        "nonfinite": {"profile": int((~np.isfinite(prof)).sum()), "profiledyn": int((~np.isfinite(profdyn)).sum()),
                      "stat_comp": int((~np.isfinite(stat)).sum()), "dyn_comp": int((~np.isfinite(dyn)).sum())},
        "shapes": {"_profile": list(prof.shape), "_profiledyn": list(profdyn.shape), "stat_comp": list(stat.shape),
                   "dyn_comp": list(dyn.shape)},
    }
    for j, c in enumerate(_CLASSES):
        cols = range(j * n_aff, (j + 1) * n_aff)
        out["stat_comp"][c] = [_floats(stat[at, k]) for k in cols]
        out["dyn_comp"][c] = [_floats(dyn[at, k]) for k in cols]
        out["stat_comp_extrema"][c] = [_extrema(stat[:, k]) for k in cols]
        out["dyn_comp_extrema"][c] = [_extrema(dyn[:, k]) for k in cols]
    return out


def _checks(stimuli: dict, consts: dict, depths: dict) -> dict:
    """TouchSim's figures over the flat-punch closed forms (Sneddon 1946), at named samples."""
    e, nu = consts["E"], consts["nu"]
    checks = {"formulas": {
        "load": "P = 2 a E delta / (1 - nu^2)  (N, with a and delta in mm, E in N/mm^2)",
        "axial_stress": "sigma_z(0, z) = P (a^2 + 3 z^2) / (2 pi (a^2 + z^2)^2)  (N/mm^2), P TouchSim's own load",
        "dyn_on_axis": "dyn_comp(r <= a, z) = profiledyn / (2 a) / z^2 (TouchSim's decay under the pin, 1/z^2)",
        "profiledyn": "profiledyn = dP/dt by central differences (edge samples copy their neighbour)",
    }}
    rows = []
    for name, sample in (("ramp", "mid_on_ramp"), ("ramp", "mid_hold"), ("sine", "highest_peak_in_hold"),
                         ("sine", "lowest_trough_in_hold")):
        rec = stimuli[name]
        i = rec["samples"]["names"].index(sample)
        a, delta, p = rec["pin_radius_used_mm"], rec["trace_mm"][0][i], rec["profile_N"][0][i]
        p_closed = 2 * a * e * delta / (1 - nu ** 2)
        row = {"stimulus": name, "sample": sample, "index": rec["samples"]["indices"][i], "delta_mm": delta,
               "P_touchsim_N": p, "P_closed_N": p_closed, "P_ratio": p / p_closed, "axial_stress": {}}
        for c, z in depths.items():
            s = rec["stat_comp"][c][0][i]  # x = 0 (on the axis)
            closed = p * (a ** 2 + 3 * z ** 2) / (2 * math.pi * (a ** 2 + z ** 2) ** 2)
            row["axial_stress"][c] = {"depth_mm": z, "stat_comp": s, "closed_N_per_mm2": closed, "ratio": s / closed}
        rows.append(row)
    checks["single_pin"] = rows
    dyn_rows = []
    for name, sample in (("ramp", "mid_on_ramp"), ("ramp", "mid_off_ramp"), ("sine", "middle")):
        rec = stimuli[name]
        i = rec["samples"]["names"].index(sample)
        a, pd = rec["pin_radius_used_mm"], rec["profiledyn_N_per_s"][0][i]
        row = {"stimulus": name, "sample": sample, "profiledyn_N_per_s": pd, "dyn_on_axis": {}}
        if name == "ramp":
            slope = 0.5 / (499 / _FS) * (1 if sample == "mid_on_ramp" else -1)  # mm/s
            row["dP_dt_closed_N_per_s"] = 2 * a * e * slope / (1 - nu ** 2)
            row["profiledyn_ratio"] = pd / row["dP_dt_closed_N_per_s"]
        for c, z in depths.items():
            v = rec["dyn_comp"][c][0][i]
            closed = pd / (2 * a) / z ** 2
            row["dyn_on_axis"][c] = {"dyn_comp": v, "closed": closed, "ratio": v / closed if closed else None}
        dyn_rows.append(row)
    checks["dynamic_single_pin"] = dyn_rows
    return checks


def _host() -> dict:
    try:
        lines = subprocess.run(["lscpu"], capture_output=True, text=True, timeout=10, check=False).stdout.splitlines()
    except (OSError, subprocess.SubprocessError):
        lines = []
    keep = ("Architecture", "Model name", "CPU(s)", "Thread(s) per core", "Core(s) per socket", "Socket(s)",
            "Hypervisor vendor", "BogoMIPS")
    cpu = {k.strip(): v.strip() for k, v in (ln.split(":", 1) for ln in lines if ":" in ln) if k.strip() in keep}
    mem = None
    try:
        for ln in Path("/proc/meminfo").read_text().splitlines():
            if ln.startswith("MemTotal:"):
                mem = round(int(ln.split()[1]) / 1024 ** 2, 1)
    except OSError:
        pass
    return {"lscpu": cpu, "mem_total_GiB": mem, "platform": f"{platform.system()} {platform.machine()}"}


def _time_case(case: str, out: str) -> None:
    """Child of --timings: one case, in-process stage times, written to ``out``."""
    import resource

    t0 = time.perf_counter()
    import touchsim as ts

    rec = {"case": case, "import_touchsim_s": time.perf_counter() - t0}
    t = time.perf_counter()
    if case == "hand_sine":
        pop = ts.affpop_hand(seed=0)
        rec["population"] = "ts.affpop_hand(seed=0): the whole hand"
    else:
        pop = ts.affpop_hand(region="D2d", seed=0)
        rec["population"] = "ts.affpop_hand(region='D2d', seed=0): the index fingertip"
    rec["build_population_s"] = time.perf_counter() - t
    rec["n_afferents"] = {c: int(sum(pop.find(c))) for c in _CLASSES}
    t = time.perf_counter()
    if case == "hand_sine":
        kw = {"freq": 250.0, "amp": 0.05, "pre_indent": 0.3, "len": 1.0, "fs": _FS, "pin_radius": 0.5,
              "loc": [0.0, 0.0]}
        stim = ts.stim_sine(**kw)
        rec["stimulus"] = {"generator": "touchsim.stim_sine", "kwargs": kw}
    else:
        kw = {"amp": 0.5, "len": 1.0, "ramp_len": 0.1, "fs": _FS, "pin_radius": 0.5, "loc": [0.0, 0.0]}
        stim = ts.stim_ramp(**kw)
        rec["stimulus"] = {"generator": "touchsim.stim_ramp", "kwargs": kw}
    rec["build_stimulus_s"] = time.perf_counter() - t
    rec["stimulus_location_region"] = ts.hand_surface.locate(np.array([[0.0, 0.0]]))[0][0]
    t = time.perf_counter()
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        resp = pop.response(stim)
    rec["response_s"] = time.perf_counter() - t
    rec["total_spikes"] = int(sum(s.size for s in resp.spikes))
    rec["spiking_afferents"] = int(sum(s.size > 0 for s in resp.spikes))
    rec["maxrss_after_response_MiB"] = resource.getrusage(resource.RUSAGE_SELF).ru_maxrss / 1024
    del resp
    t = time.perf_counter()
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        stat, dyn, _ = stim.propagate(pop)
    rec["propagate_only_s"] = time.perf_counter() - t
    rec["stat_comp_shape"] = list(np.shape(stat))
    del stat, dyn
    t = time.perf_counter()
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        pop.response(stim)
    rec["response_again_s"] = time.perf_counter() - t
    Path(out).write_text(json.dumps(rec))


def _parse_time_v(text: str) -> dict:
    got = {}
    for ln in text.splitlines():
        ln = ln.strip()
        if ln.startswith("Maximum resident set size (kbytes):"):
            got["peak_rss_MiB"] = int(ln.rsplit(":", 1)[1]) / 1024
        elif ln.startswith("Elapsed (wall clock) time"):
            clock = ln.rsplit(": ", 1)[1].split(":")
            got["wall_s"] = sum(float(v) * 60 ** k for k, v in enumerate(reversed(clock)))
        elif ln.startswith("User time (seconds):"):
            got["user_s"] = float(ln.rsplit(":", 1)[1])
        elif ln.startswith("System time (seconds):"):
            got["system_s"] = float(ln.rsplit(":", 1)[1])
        elif ln.startswith("Percent of CPU this job got:"):
            got["cpu_percent"] = ln.rsplit(":", 1)[1].strip()
    return got


def _timings() -> dict:
    import tempfile

    timer = "/usr/bin/time"
    out = {"note": "measured on this host only (see 'host'); each case in its own child process under "
                   "`/usr/bin/time -v` (wall and peak RSS of the whole child, Python start and imports included); "
                   "the stage times are perf_counter inside it. 'response' is TouchSim's AfferentPopulation."
                   "response (mechanics + LIF), 'response_again' a second identical call (numba already "
                   "compiled, surface distances not cached).",
           "host": _host(), "python": sys.version.split()[0], "cases": {}}
    for case in ("hand_sine", "fingertip_ramp"):
        with tempfile.TemporaryDirectory() as tmp:
            rec_path = os.path.join(tmp, "rec.json")
            cmd = [sys.executable, os.path.abspath(__file__), "--time-case", case, "--time-out", rec_path]
            if os.path.exists(timer):
                cmd = [timer, "-v", *cmd]
            t = time.perf_counter()
            proc = subprocess.run(cmd, capture_output=True, text=True, check=False)
            wall = time.perf_counter() - t
            rec = json.loads(Path(rec_path).read_text()) if proc.returncode == 0 else {"stderr": proc.stderr[-2000:]}
            rec["child_wall_s_parent_clock"] = wall
            rec["time_v"] = _parse_time_v(proc.stderr) if os.path.exists(timer) else None
            out["cases"][case] = rec
            print(f"timing {case}: {rec.get('time_v')}", file=sys.stderr)
    return out


def main(argv=None) -> int:
    parser = argparse.ArgumentParser(prog="touchsim_reference.py", description=__doc__.split("\n\n")[0])
    parser.add_argument("--out", default="tests/population/data/touchsim_mechanics.json")
    parser.add_argument("--commit", default=None, help="TouchSim's commit hash")
    parser.add_argument("--timings", action="store_true", help="also time TouchSim on this host (minutes)")
    parser.add_argument("--time-case", choices=("hand_sine", "fingertip_ramp"), help=argparse.SUPPRESS)
    parser.add_argument("--time-out", help=argparse.SUPPRESS)
    args = parser.parse_args(argv)
    if args.time_case:
        _time_case(args.time_case, args.time_out)
        return 0

    import numba
    import scipy
    import touchsim as ts

    try:
        from importlib.metadata import version

        ts_version = version("touchsim")
    except Exception:  # noqa: BLE001 - not installed as a distribution (on PYTHONPATH)
        ts_version = None
    consts = _source_constants(ts)
    commit, commit_source = _commit(ts, args.commit)
    depths = {c: float(ts.Afferent.affdepths[c]) for c in _CLASSES}
    pop = _afferents(ts)
    stimuli = {name: _record(name, *made, pop, consts) for name, made in _stimuli(ts).items()}
    doc = {
        "about": {
            "what": "TouchSim's skin mechanics (pin loads, and the static and dynamic components at afferents) "
                    "on four standard stimuli, for comparison with ddmm's contact mechanics (issue 42)",
            "made_by": "experiments/validation/touchsim_reference.py (run in TouchSim's own environment)",
            "units": {"lengths": "mm", "time": "s", "profile_N": "N (pin load, TouchSim's stim._profile)",
                      "profiledyn_N_per_s": "N/s (dP/dt, TouchSim's stim._profiledyn)",
                      "stat_comp": "N/mm^2 (= MPa): vertical stress sigma_z of Sneddon's flat punch, compression "
                                   "positive",
                      "dyn_comp": "N/(s mm^3): profiledyn * decay(r) / z^2, decay = arcsin(a/r)/(pi a) "
                                  "(1/(2a) under the pin), delayed by (r - a)/8000 mm/s; not a stress rate"},
            "layout": {
                "trace_mm, profile_N, profiledyn_N_per_s, surface_deflection_under_pins_mm": "[pin][sample]",
                "stat_comp, dyn_comp": "{class: [afferent at afferents.x_mm[k]][sample]}",
                "*_extrema": "over every sample of the stimulus; argmax/argmin are sample indices",
                "samples": "names, indices (0-based, at fs) and times (index / fs) shared by every array",
                "surface_deflection_under_pins_mm": "derived here: profile @ D, TouchSim's compliance matrix "
                                                    "rebuilt from its E and nu; equals the trace where a pin "
                                                    "touches, and shows how far a lifted pin's skin is pushed",
                "pins_out_of_contact_at_samples": "[pin][sample]: TouchSim's contact detection set the load to 0 "
                                                  "although the pin's trace is not 0",
                "dyn_delay_samples": "[pin][afferent x]: rint(max(r - a, 0) / wave speed * fs), the samples by "
                                     "which that pin's dynamic load reaches each afferent x late (same for every "
                                     "class)"},
            "touchsim_behaviour": _BEHAVIOUR,
        },
        "touchsim": {"commit": commit, "commit_source": commit_source, "version": ts_version,
                     "source_sha256": _source_digest(ts), **consts,
                     "libraries": {"python": sys.version.split()[0], "numpy": np.__version__,
                                   "scipy": scipy.__version__, "numba": numba.__version__}},
        "afferents": {"x_mm": list(AFFERENT_X_MM), "y_mm": 0.0, "classes": list(_CLASSES), "depth_mm": depths,
                      "order": "class-major: SA1 at every x, then RA, then PC",
                      "model": "ts.Afferent(cls, location=[x, 0], idx=0, noisy=False) on the null (infinite) "
                               "surface; propagate uses only location, depth and surface"},
        "stimuli": stimuli,
        "checks": _checks(stimuli, consts, depths),
    }
    if args.timings:
        doc["timings"] = _timings()
    text = json.dumps(doc, indent=1, allow_nan=False)
    out = Path(args.out)
    out.parent.mkdir(parents=True, exist_ok=True)
    out.write_text(text + "\n")
    print(f"wrote {out} ({len(text) / 1024:.0f} KiB)")
    return 0


if __name__ == "__main__":  # pragma: no cover
    sys.exit(main())
