"""The event cases of ``ddmm bench --cases events``: latency measured from the event, not from the push.

A prosthetics engineer times an encoder from the moment the finger touches.  Each case
(``events_100hz``, ``events_1khz``, ``events_5khz``) runs clean (noise-free) force profiles sampled at
that rate through the fingertip preset (``sample_population("fingertip", rng=0)``) in the streaming
`Encoder` (model at 1 kHz, dt 0.1 ms, seed 0), with the default stimulation rule on one electrode over
the whole fingertip (`StimulationEncoder`), on two paths over the same samples:

- **default**: the default conditioning (`Conditioning()`), fed the samples at their own rate;
- **off**: ``conditioning=None`` on the samples as a recording reads with no conditioning
  (`resample_unconditioned`: monotone cubic onto 1 kHz, offline; every 5th sample at 5 kHz, the samples
  themselves at 1 kHz).  A stream with no conditioning runs the model at the input's rate, which FA-II
  refuse below 750 Hz, and a zero-order hold onto 1 kHz makes FA-II fire on every 100 Hz step.

Profiles (`PRESSES`, `SHEAR`): presses and releases at 2 N/s to 1 N, 10 N/s to 3 N and 20 N/s to 6 N, and
a shear step (a 2 N hold, then F_X rising to 0.5 N in 5 ms).  Events, on the raw input samples (event
time = sample index / fs): **contact**, the first sample with F_Z >= 30 mN (`EVENT_N`, the default
``contact_on_n``); **release**, the first sample after it with F_Z < 30 mN; **shear**, the first sample
whose tangential magnitude leaves its hold value by >= 30 mN.

Per event and path, in model time after the event (ms: algorithmic latency, deterministic): when the
path detects it (default: the conditioned contact state, from `condition_forces` on the same samples; off:
the first model sample at >= 30 mN or, for release, below it; shear: the tangential force the model
consumed leaving its hold value by 30 mN); per type, the median over afferents of each one's first spike after the event
(afferents firing within `WINDOW_S`, n given); at contact the first pulse after the event, at release the
last pulse after the first raw sample where F_Z has fallen to 0.05 N (`CONTACT_THRESHOLD`) for good.
Default minus off is what the issue's bound (`bound_ms`) applies to, at contact and release; the last
pulse is held to the bound on its own.  ``events_lsl`` times the 1 kHz press over Lab Streaming Layer.
"""

from __future__ import annotations

import math

import numpy as np

from ddmm.models.afferent_types import afferent_type_codes, type_label
from ddmm.models.metrics import CONTACT_THRESHOLD
from ddmm.utils.validation import as_finite_array, check_positive

__all__ = ["EVENT_N", "LABEL", "PRESSES", "SHEAR", "WINDOW_S", "bound_ms", "contact_events", "event_case",
           "fall_sample", "first_spikes", "format_event_case", "lsl_event_case", "measure_events",
           "press_release", "run_event_case", "shear_event", "shear_step"]

#: The events' force threshold, N: the default conditioning's ``contact_on_n`` (contact, release, shear).
EVENT_N = 0.03
#: The presses: (rate N/s, peak N), up and down at the same rate.
PRESSES = ((2.0, 1.0), (10.0, 3.0), (20.0, 6.0))
#: The shear step: normal hold N, tangential step N, its rise time s.
SHEAR = (2.0, 0.5, 0.005)
#: An afferent's first spike counts if it comes within this long after the event, s.
WINDOW_S = 0.15
#: The model's sample rate on both paths, Hz.
MODEL_FS = 1000.0
#: Every printed figure is a measurement.
LABEL = "measured, held out: no setting was chosen on it"
#: Case name -> input sample rate, Hz.
RATES = {"events_100hz": 100.0, "events_1khz": 1000.0, "events_5khz": 5000.0}
_PRE_S, _HOLD_S, _POST_S = 0.3, 0.5, 0.3


def bound_ms(fs_hz: float) -> float:
    """The issue's bound on default minus off, ms: max(5 ms, one input sample period + 2 ms)."""
    return max(5.0, 1e3 / check_positive(fs_hz, "fs_hz", "Hz") + 2.0)


def press_release(fs_hz: float, rate_n_per_s: float, peak_n: float, *, pre_s: float = _PRE_S,
                  hold_s: float = _HOLD_S, post_s: float = _POST_S) -> np.ndarray:
    """A clean press and release, (n, 3) in N at ``fs_hz``: ``pre_s`` at 0 N, a ramp at ``rate_n_per_s``
    (N/s) to ``peak_n`` (N), ``hold_s`` there, the ramp back down at the same rate, ``post_s`` at 0 N.

    Examples
    --------
    >>> f = press_release(1000.0, 10.0, 3.0)
    >>> f.shape, float(f[:, 2].max())
    ((1700, 3), 3.0)
    """
    fs_hz = check_positive(fs_hz, "fs_hz", "Hz")
    rate, peak = check_positive(rate_n_per_s, "rate_n_per_s", "N/s"), check_positive(peak_n, "peak_n", "N")
    for value, name in ((pre_s, "pre_s"), (hold_s, "hold_s"), (post_s, "post_s")):
        check_positive(value, name, "s")
    rise = peak / rate
    t = np.arange(round((pre_s + 2.0 * rise + hold_s + post_s) * fs_hz)) / fs_hz
    fz = np.clip(np.minimum((t - pre_s) * rate, peak - (t - pre_s - rise - hold_s) * rate), 0.0, peak)
    return np.column_stack([np.zeros_like(t), np.zeros_like(t), fz])


def shear_step(fs_hz: float, normal_n: float = SHEAR[0], shear_n: float = SHEAR[1],
               rise_s: float = SHEAR[2]) -> tuple[np.ndarray, int]:
    """A clean shear step, (n, 3) in N at ``fs_hz``, and the sample where its tangential ramp starts.

    0 N for 0.3 s, F_Z up at 10 N/s to ``normal_n`` (N), held; 0.5 s into the hold F_X rises linearly
    to ``shear_n`` (N) in ``rise_s`` (s) and is held for 0.3 s more.
    """
    fs_hz = check_positive(fs_hz, "fs_hz", "Hz")
    normal, shear = check_positive(normal_n, "normal_n", "N"), check_positive(shear_n, "shear_n", "N")
    rise = check_positive(rise_s, "rise_s", "s")
    start_s = _PRE_S + normal / 10.0 + _HOLD_S
    t = np.arange(round((start_s + rise + _POST_S) * fs_hz)) / fs_hz
    fz = np.clip((t - _PRE_S) * 10.0, 0.0, normal)
    fx = np.clip((t - start_s) / rise, 0.0, 1.0) * shear
    return np.column_stack([fx, np.zeros_like(t), fz]), math.ceil(start_s * fs_hz - 1e-9)


def _first(mask, start: int = 0):
    """The first index >= ``start`` where ``mask`` holds, or None."""
    hits = np.flatnonzero(np.asarray(mask)[start:])
    return None if hits.size == 0 else start + int(hits[0])


def contact_events(fz_n, threshold_n: float = EVENT_N) -> tuple:
    """(contact, release) sample indices: the first sample with F_Z >= ``threshold_n`` (N), then the first
    after it with F_Z < ``threshold_n``; None where there is none.

    Examples
    --------
    >>> contact_events([0.0, 0.02, 0.04, 0.5, 0.01, 0.0])
    (2, 4)
    """
    fz = as_finite_array(fz_n, "fz_n", ndim=1)
    on = _first(fz >= check_positive(threshold_n, "threshold_n", "N"))
    return on, None if on is None else _first(fz < threshold_n, on)


def shear_event(forces_n, start: int, threshold_n: float = EVENT_N):
    """The first sample from ``start`` whose tangential magnitude |(F_X, F_Y)| leaves its value at sample
    ``start - 1`` (the hold's) by >= ``threshold_n`` (N), or None."""
    forces = as_finite_array(forces_n, "forces_n", ndim=2)
    if not 1 <= start < forces.shape[0]:
        raise ValueError(f"start must be a sample index in [1, {forces.shape[0] - 1}], got {start}")
    tangential = np.hypot(forces[:, 0], forces[:, 1])
    return _first(np.abs(tangential - tangential[start - 1]) >= check_positive(threshold_n, "threshold_n", "N"),
                  start)


def fall_sample(fz_n, level_n: float = CONTACT_THRESHOLD):
    """The first sample after the last one with F_Z > ``level_n`` (N): where the force falls to it for good."""
    above = np.flatnonzero(as_finite_array(fz_n, "fz_n", ndim=1) > check_positive(level_n, "level_n", "N"))
    return None if above.size == 0 else int(above[-1]) + 1


def first_spikes(afferent, time_s, afferent_type, event_s: float, window_s: float = WINDOW_S) -> dict:
    """Per type, the median over afferents of each one's first spike in [event, event + ``window_s``) minus
    the event (ms), and how many afferents fired there: ``{"SA-I": {"median_ms": ..., "n": ...}, ...}``.

    ``afferent`` are positions into ``afferent_type``; ``time_s`` and ``event_s`` are model time, s.
    """
    check_positive(window_s, "window_s", "s")
    afferent, time_s = np.asarray(afferent, np.int64), as_finite_array(time_s, "time_s", ndim=1)
    keep = (time_s >= event_s - 1e-9) & (time_s < event_s + window_s)
    order = np.lexsort((afferent[keep], time_s[keep]))
    who, when = afferent[keep][order], time_s[keep][order]
    firsts, index = np.unique(who, return_index=True)
    latency_ms = np.maximum((when[index] - event_s) * 1e3, 0.0)  # a spike at the event's own time: 0, not -0
    kinds = np.asarray(afferent_type).astype(str)[firsts]
    out = {}
    for kind in afferent_type_codes():
        mine = latency_ms[kinds == kind]
        out[type_label(kind)] = {"median_ms": round(float(np.median(mine)), 2) if mine.size else None,
                                 "n": int(mine.size)}
    return out


def _run_path(pop, raw, fs_hz: float, conditioning) -> dict:
    """One path's spikes, pulses and consumed forces (model rate) for the raw samples ``raw`` at ``fs_hz``."""
    from ddmm.population.neurostim import Electrode, StimulationEncoder
    from ddmm.population.runtime.stream import Encoder
    from ddmm.population.stimuli.conditioning import condition_forces
    from ddmm.population.stimuli.recordings import resample_unconditioned

    if conditioning is None:
        fed, fs_in, kwargs = resample_unconditioned(raw, fs_hz, MODEL_FS), MODEL_FS, {"conditioning": None}
        contact = fed[:, 2] >= EVENT_N
    else:
        fed, fs_in, kwargs = raw, fs_hz, {"conditioning": conditioning, "model_fs": MODEL_FS}
        contact = condition_forces(raw, fs_hz, MODEL_FS, conditioning)[1]
    encoder = Encoder(pop, fs_in, seed=0, engine="direct", **kwargs)
    electrode = Electrode("D2d", 20.0, 80.0, 200.0, 300.0, 20.0, region="D2d")  # the whole fingertip
    out = StimulationEncoder(encoder, [electrode]).push(fed)
    return {"afferent": out.spikes.afferent, "time_s": out.spikes.time, "pulse_s": np.sort(out.time),
            "forces": out.spikes.forces, "contact": contact}


def _ms(value):
    return None if value is None else round(float(value) * 1e3, 2)


def _path_figures(run, pop, kind: str, event_s: float, fall_s) -> dict:
    """One path's figures at one event (module docstring); ``fall_s``: F_Z at 0.05 N for good (release)."""
    m0 = math.floor(event_s * MODEL_FS + 1e-9)  # the model sample holding the event
    if kind == "shear":
        tangential = np.hypot(run["forces"][:, 0], run["forces"][:, 1])
        m = _first(np.abs(tangential - tangential[m0 - 1]) >= EVENT_N, m0)
    else:
        on = _first(run["contact"])
        m = on if kind == "contact" else (None if on is None else _first(~run["contact"], on))
    pulses, pulse = run["pulse_s"], None
    if kind == "contact" and np.any(pulses >= event_s):
        pulse = pulses[pulses >= event_s][0] - event_s
    elif kind == "release" and pulses.size:
        pulse = pulses[-1] - fall_s
    return {"detected_ms": None if m is None else _ms(m / MODEL_FS - event_s),
            "first_spike": first_spikes(run["afferent"], run["time_s"], pop.afferent_type, event_s),
            "pulse_ms": _ms(pulse)}


def _compare(paths: dict, kind: str, fs_hz: float) -> dict:
    """Default minus off per figure, and whether each is within the bound (contact and release only)."""
    a, b = paths["default"], paths["off"]

    def minus(x, y):
        return None if x is None or y is None else round(x - y, 2)
    diff = {"detected_ms": minus(a["detected_ms"], b["detected_ms"]),
            "pulse_ms": minus(a["pulse_ms"], b["pulse_ms"])}
    diff.update({t: minus(a["first_spike"][t]["median_ms"], b["first_spike"][t]["median_ms"])
                 for t in a["first_spike"]})
    if kind == "shear":
        return {"difference_ms": diff, "within_bound": None}
    bound = bound_ms(fs_hz)
    within = {k: (None if v is None else bool(v <= bound)) for k, v in diff.items() if k != "pulse_ms"}
    if kind == "release":  # no pulse later than the bound after F_Z falls to 0.05 N: the default path's own figure
        within["last_pulse"] = None if a["pulse_ms"] is None else bool(a["pulse_ms"] <= bound)
    return {"difference_ms": diff, "within_bound": within}


def _events_of(pop, raw, fs_hz: float, profile: str, events: dict, fall) -> list:
    """Both paths on ``raw`` and the figures of each of ``events`` (kind -> raw sample index)."""
    from ddmm.population.stimuli.conditioning import Conditioning

    runs = {"default": _run_path(pop, raw, fs_hz, Conditioning()), "off": _run_path(pop, raw, fs_hz, None)}
    out = []
    for kind, k in events.items():
        if k is None:
            raise ValueError(f"profile {profile!r} has no {kind} event at {EVENT_N} N")
        event_s, fall_s = k / fs_hz, None if fall is None else fall / fs_hz
        paths = {p: _path_figures(r, pop, kind, event_s, fall_s) for p, r in runs.items()}
        out.append({"profile": profile, "event": kind, "event_sample": int(k), "event_s": round(event_s, 6),
                    "paths": paths, **_compare(paths, kind, fs_hz)})
    return out


def measure_events(pop, fs_hz: float, presses=PRESSES, shear: bool = True) -> list:
    """The figures of every event of ``presses`` ((N/s, N) pairs) and of the shear step at ``fs_hz`` (Hz)."""
    fs_hz = check_positive(fs_hz, "fs_hz", "Hz")
    out = []
    for rate, peak in presses:
        raw = press_release(fs_hz, rate, peak)
        on, off = contact_events(raw[:, 2])
        out += _events_of(pop, raw, fs_hz, f"press {rate:g} N/s to {peak:g} N", {"contact": on, "release": off},
                          fall_sample(raw[:, 2]))
    if shear:
        raw, start = shear_step(fs_hz)
        out += _events_of(pop, raw, fs_hz, f"shear {SHEAR[1]:g} N in {SHEAR[2] * 1e3:g} ms at {SHEAR[0]:g} N",
                          {"shear": shear_event(raw, start)}, None)
    return out


def event_case(name: str, pop=None, presses=PRESSES, shear: bool = True) -> dict:
    """One of the rate cases (`RATES`) as a bench result; ``pop`` defaults to the fingertip preset."""
    import resource
    import time

    if name not in RATES:
        raise ValueError(f"name must be one of {', '.join(RATES)}, got {name!r}")
    from ddmm.population import sample_population

    pop = sample_population("fingertip", rng=0) if pop is None else pop
    start = time.perf_counter()
    events = measure_events(pop, RATES[name], presses, shear)
    wall = time.perf_counter() - start
    sim_s = sum(press_release(MODEL_FS, r, p).shape[0] for r, p in presses) + (shear_step(MODEL_FS)[0].shape[0]
                                                                               if shear else 0)
    return {"name": name, "engine": "direct", "n_afferents": len(pop), "fs_hz": RATES[name], "model_fs_hz": MODEL_FS,
            "dt_ms": 0.1, "bound_ms": bound_ms(RATES[name]), "window_ms": WINDOW_S * 1e3, "label": LABEL,
            "sim_s_per_path": round(sim_s / MODEL_FS, 3), "wall_s": round(wall, 3),
            "peak_rss_mb": round(resource.getrusage(resource.RUSAGE_SELF).ru_maxrss / 1024.0, 1), "events": events}


def run_event_case(name: str) -> dict:
    """One of ``GROUPS["events"]`` in this process: a rate case (`RATES`) or ``events_lsl``."""
    return lsl_event_case(name) if name == "events_lsl" else event_case(name)


#: The press timed over LSL at 1 kHz: (rate N/s, peak N), how many times it is pressed in a row, and the rest
#: at 0 N after each, s (a press 0.3 s after a release finds the afferents' history: SA-I then fire later).
LSL_PRESS, LSL_REPEATS, LSL_REST_S = (10.0, 3.0), 3, 1.0


def lsl_event_case(name: str = "events_lsl", repeats: int = LSL_REPEATS) -> dict:
    """The 1 kHz press `LSL_PRESS`, ``repeats`` times in a row, over loopback LSL: ``ddmm stream --lsl-in
    --lsl-out`` in its own process (the default conditioning), the samples published one per ms; per event
    and type, the wall-clock time from publishing the event's sample to receiving the type's first spike
    after the event (and that spike's model time after it).  Without pylsl / liblsl: ``skipped``, the reason."""
    import os
    import tempfile

    from ddmm.experiments.bench.lsl import _LOOPBACK

    if not isinstance(repeats, int) or repeats < 1:
        raise ValueError(f"repeats must be an integer >= 1, got {repeats!r}")
    base = {"name": name, "engine": "direct", "fs_hz": 1000.0, "label": LABEL, "repeats": repeats,
            "profile": f"press {LSL_PRESS[0]:g} N/s to {LSL_PRESS[1]:g} N ({LSL_REST_S:g} s at 0 N after)",
            "window_ms": WINDOW_S * 1e3}
    one = press_release(1000.0, *LSL_PRESS, post_s=LSL_REST_S)
    with tempfile.TemporaryDirectory() as tmp:
        config, previous = os.path.join(tmp, "lsl_api.cfg"), os.environ.get("LSLAPICFG")
        with open(config, "w", encoding="utf-8") as f:
            f.write(_LOOPBACK)
        os.environ["LSLAPICFG"] = config  # before pylsl's first use; the bridge process inherits it
        try:
            missing = _lsl_missing()
            if missing:
                return {**base, "skipped": missing}
            pushed, anchor, arrivals, types = _typed_over_lsl(np.tile(one, (repeats, 1)))
        finally:
            if previous is None:
                os.environ.pop("LSLAPICFG", None)
            else:
                os.environ["LSLAPICFG"] = previous
    return {**base, **_lsl_figures(one, repeats, pushed, anchor, arrivals, types)}


def _lsl_missing():
    """Why pylsl / liblsl cannot be used here, or None."""
    try:
        import pylsl

        pylsl.local_clock()
    except (ImportError, OSError, RuntimeError) as exc:
        return f"pylsl / liblsl not importable ({type(exc).__name__}: {' '.join(str(exc).split())})"
    return None


def _spike_inlet(pylsl, name: str, proc):
    """The bridge's spike stream: its inlet, the input's clock offset (s) and afferent id -> type."""
    from ddmm.population.runtime.lsl_outlets import read_spike_metadata

    found = pylsl.resolve_byprop("name", name, 1, 180.0)
    if not found:
        raise RuntimeError(f"the bridge's spike stream did not appear: {proc.stderr.read() if proc.poll() else ''}")
    inlet = pylsl.StreamInlet(found[0], max_buflen=100_000)
    meta = read_spike_metadata(inlet.info(timeout=10.0))
    inlet.open_stream(timeout=10.0)
    types = dict(zip(meta["afferents"]["id"].tolist(), meta["afferents"]["type"].tolist()))
    return inlet, float(meta["input"]["clock_offset_s"]), types


def _typed_reader(inlet, arrivals, stop) -> None:
    """Note each chunk of spikes with its arrival (LSL clock), the afferent ids and the stamps."""
    import pylsl

    from ddmm.population.runtime.lsl import ChunkReader

    reader = ChunkReader(inlet, 4096)
    while not stop.is_set():
        ids, stamps = reader.pull(0.05)
        if len(stamps):
            arrivals.append((pylsl.local_clock(), ids[:, 0].astype(np.int64), stamps.copy()))


def _typed_over_lsl(forces):
    """Publish ``forces`` at 1 kHz to a ``ddmm stream`` bridge; (push times, anchor, arrivals, id -> type)."""
    import subprocess
    import sys
    import uuid

    import pylsl

    from ddmm.experiments.bench.lsl import publish
    from ddmm.population.runtime.lsl import open_force_outlet

    names = f"bench-events-force-{uuid.uuid4().hex[:8]}", f"bench-events-spikes-{uuid.uuid4().hex[:8]}"
    outlet = open_force_outlet(names[0], fs=MODEL_FS)  # the 1 kHz press, one sample per ms
    proc = subprocess.Popen([sys.executable, "-m", "ddmm.experiments.cli", "stream", "--lsl-in", names[0],
                             "--lsl-out", names[1], "--population", "fingertip", "--seed", "0",
                             "--resolve-timeout", "120"], stdout=subprocess.DEVNULL, stderr=subprocess.PIPE, text=True)
    try:
        inlet, offset, types = _spike_inlet(pylsl, names[1], proc)
        pushed, t0, arrivals = publish(pylsl, outlet, inlet, forces, _typed_reader)
    finally:
        proc.terminate()
        proc.communicate(timeout=60)
    return pushed, t0 + offset, arrivals, types


def _lsl_figures(one, repeats: int, pushed, anchor: float, arrivals, types) -> dict:
    """Per press and event, per type: the first spike after the event to arrive, wall and model time (ms)."""
    arrived = np.concatenate([np.full(a[1].size, a[0]) for a in arrivals]) if arrivals else np.empty(0)
    ids = np.concatenate([a[1] for a in arrivals]) if arrivals else np.empty(0, np.int64)
    model_s = (np.concatenate([a[2] for a in arrivals]) if arrivals else np.empty(0)) - anchor
    kind = np.array([type_label(types[i]) for i in ids.tolist()], dtype=object)
    on, off = contact_events(one[:, 2])
    per = {}
    for j in range(repeats):
        for event, k in (("contact", on + j * one.shape[0]), ("release", off + j * one.shape[0])):
            event_s = k / 1000.0
            near = (model_s >= event_s - 1e-6) & (model_s < event_s + WINDOW_S)  # stamps: ~1e-12 s off
            for label in (type_label(t) for t in afferent_type_codes()):
                mine = np.flatnonzero(near & (kind == label))
                if mine.size:
                    i = mine[np.argmin(arrived[mine])]
                    per.setdefault((event, label), []).append(((arrived[i] - pushed[k]) * 1e3,
                                                               (model_s[i] - event_s) * 1e3))
    summary = {}
    for (event, label), pairs in per.items():
        wall, model = np.array(pairs).T
        model = np.maximum(model, 0.0)  # a spike stamped at the event, ~1e-12 s early: 0
        summary.setdefault(event, {})[label] = {
            "wall_median_ms": round(float(np.median(wall)), 3), "wall_max_ms": round(float(wall.max()), 3),
            "model_median_ms": round(float(np.median(model)), 2), "wall_minus_model_median_ms":
                round(float(np.median(wall - model)), 3), "n": len(pairs)}
    return {"lsl": summary, "spikes_over_lsl": int(ids.size)}


def _cell(value, n=None, mark=None) -> str:
    text = "-" if value is None else f"{value:.1f}"
    if n is not None:
        text += f" ({n})"
    return text if mark is None or value is None else f"{text} {'within' if mark else 'OVER'}"


def _event_rows(e) -> list:
    """Three rows of one event: the default path, the off path, default minus off (marked against the bound)."""
    labels = list(e["paths"]["default"]["first_spike"])
    rows = []
    for path in ("default", "off"):
        p = e["paths"][path]
        mark = e["within_bound"].get("last_pulse") if path == "default" and e["event"] == "release" else None
        cells = [_cell(p["detected_ms"])] + [_cell(p["first_spike"][t]["median_ms"], p["first_spike"][t]["n"])
                                          for t in labels] + [_cell(p["pulse_ms"], mark=mark)]
        rows.append([e["profile"] if path == "default" else "", e["event"] if path == "default" else "", path, *cells])
    d, w = e["difference_ms"], e["within_bound"] or {}
    rows.append(["", "", "default - off", _cell(d["detected_ms"], mark=w.get("detected_ms")),
                 *[_cell(d[t], mark=w.get(t)) for t in labels], _cell(d["pulse_ms"])])
    return rows


def format_event_case(case: dict) -> list:
    """The printed lines of one event case (a rate case's table, the LSL case's table, or its skip)."""
    if "skipped" in case:
        return [f"{case['name']}: skipped: {case['skipped']}"]
    if "lsl" in case:
        return _format_lsl(case)
    labels = [type_label(t) for t in afferent_type_codes()]
    lines = [(f"{case['name']}: input {case['fs_hz']:g} Hz, model {case['model_fs_hz']:g} Hz, "
              f"{case['n_afferents']} afferents, {case['wall_s']:.1f} s; {case['label']}"),
             (f"ms after the raw event, model time; detected: the path's contact state (shear: its consumed "
              f"force) shows the event; first spike: median over the afferents (n) firing within "
              f"{case['window_ms']:g} ms; pulse: first after contact / last after F_Z falls to 0.05 N; "
              f"bound {case['bound_ms']:g} ms (within/OVER; shear: no bound)"),
             f"| profile | event | path | detected | {' | '.join(labels)} | pulse |",
             "|" + "---|" * (5 + len(labels))]
    for e in case["events"]:
        lines += ["| " + " | ".join(row) + " |" for row in _event_rows(e)]
    return lines


def _format_lsl(case: dict) -> list:
    lines = [(f"{case['name']}: the {case['fs_hz']:g} Hz {case['profile']} x {case['repeats']} over LSL (ddmm "
              f"stream --lsl-in/--lsl-out in its own process, default conditioning), {case['spikes_over_lsl']:,} "
              f"spikes; {case['label']}"),
             ("wall: publishing the event's sample -> receiving the type's first spike after it; model: that "
              "spike's model time after the event (ms; median over the presses, n of them with a spike)"),
             "| event | type | wall median | wall max | model median | wall - model median | n |",
             "|---|---|---|---|---|---|---|"]
    for event, per in case["lsl"].items():
        for label, f in per.items():
            lines.append(f"| {event} | {label} | {f['wall_median_ms']:.2f} | {f['wall_max_ms']:.2f} | "
                         f"{f['model_median_ms']:.1f} | {f['wall_minus_model_median_ms']:.2f} | {f['n']} |")
    return lines
