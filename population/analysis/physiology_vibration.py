"""Scorecard protocols of phase locking to vibration (docs/references.md rows 8 and 21).

Registered in `ddmm.population.analysis.physiology` through `load_extensions`.

Protocols (forces in N, +Z into the skin):

* ``phase_locking``: sinusoidal normal force on a 1 N preload (the
  ``frequency`` protocol's scene, `physiology.vibration_scene`) at 10, 20, 40
  and 60 Hz for 20 FA-I afferents; per afferent and frequency the smallest
  grid amplitude giving at least one spike per cycle in the steady window
  (0.1-0.5 s), and the vector strength (VS) of its spike phases there, at the
  stimulus frequency f and at 2f.  The same on a 2 N preload at 15 and 45 Hz
  (a variant never used to set the model).  The same for 20 FA-II at 100,
  150, 200 and 250 Hz on 1 N, and on 2 N at 125 and 175 Hz (the variant).

`vibration_rate_sai` (not a row: the presets fail it, see docs/model.md):
SA-I on a 1.5 N preload, static or with a 0.3 N sinusoid at 5 and 10 Hz,
mean rate over 0.5-1.5 s, vibrated / static.

VS of spike phases ``phi_k = 2 pi f t_k`` is ``|mean(exp(i phi_k))|`` (1:
every spike at one phase, ~0: no preferred phase).
"""

from __future__ import annotations

import numpy as np

from ddmm.models.afferent_types import is_type
from ddmm.population.analysis import physiology as _ph
from ddmm.population.stimuli.scenes import Scene, Stage

__all__ = [
    "PROPERTIES",
    "PROTOCOLS",
    "RUNNERS",
    "locking_at_threshold",
    "vector_strength",
    "vibration_rate_sai",
    "vibration_scene",
]


def _rows(kind: str, band: str, variant: str) -> list:
    """The six rows of one type: VS, locked fraction and VS(2f)/VS(f) on 1 N (``band``) and on 2 N (``variant``)."""
    return [
        _ph._p(f"vs_{kind}", kind, "phase_locking", f"median VS at f, 1:1 amplitude, {band} on 1 N"),
        _ph._p(f"locked_{kind}", kind, "phase_locking", f"fraction 1:1 and locked (VS > 0.8), {band} on 1 N"),
        _ph._p(f"vs_2f_ratio_{kind}", kind, "phase_locking", f"median VS at 2f / VS at f, 1:1 amplitude, {band}"),
        _ph._p(f"vs_{kind}_2N", kind, "phase_locking", f"median VS at f, 1:1 amplitude, {variant} on 2 N"),
        _ph._p(f"locked_{kind}_2N", kind, "phase_locking", f"fraction 1:1 and locked (VS > 0.8), {variant} on 2 N"),
        _ph._p(f"vs_2f_ratio_{kind}_2N", kind, "phase_locking", f"median VS at 2f / VS at f, {variant} on 2 N"),
    ]


PROPERTIES = dict(_rows("RAI", "10-60 Hz", "15 and 45 Hz") + _rows("RAII", "100-250 Hz", "125 and 175 Hz"))
PROTOCOLS = ("phase_locking",)

FREQUENCIES_RAI_HZ = (10.0, 20.0, 40.0, 60.0)
VARIANT_HZ = (15.0, 45.0)
FREQUENCIES_RAII_HZ = (100.0, 150.0, 200.0, 250.0)
VARIANT_RAII_HZ = (125.0, 175.0)
AMPLITUDES_N = tuple(np.geomspace(1e-3, 1.0, 25))
LOCKED_VS = 0.8
_N_AFFERENTS = 20
#: The frequency (Hz) of each type's cycle histogram in the figure data.
CYCLE_HISTOGRAM_HZ = {"RAI": 20.0, "RAII": 150.0, "SAI": 10.0}
_FS = 5000.0


def vector_strength(times, frequency_hz: float, harmonic: int = 1) -> float:
    """VS of spike ``times`` (s) at ``harmonic`` times ``frequency_hz`` (nan without spikes).

    Examples
    --------
    >>> round(vector_strength(np.arange(10) / 20.0, 20.0), 6)
    1.0
    >>> round(vector_strength(np.arange(20) / 40.0, 20.0), 6)   # two per cycle, half a cycle apart
    0.0
    """
    times = np.asarray(times, dtype=float)
    if times.size == 0:
        return float("nan")
    return float(abs(np.exp(2j * np.pi * harmonic * frequency_hz * times).mean()))


def vibration_scene(frequency_hz: float, amplitude_n: float, name: str, preload_n: float = 1.0,
                    duration_s: float = 0.5, fs: float = _FS) -> Scene:
    """A sinusoid on ``preload_n`` (its amplitude rising over 50 ms); ``preload_n`` = 1 is the frequency protocol's."""
    t = np.arange(int(round(duration_s * fs))) / fs
    envelope = np.where(t < 0.05, 0.5 - 0.5 * np.cos(np.pi * t / 0.05), 1.0)
    fz = preload_n + amplitude_n * envelope * np.sin(2 * np.pi * frequency_hz * t)
    zero = np.zeros_like(t)
    return Scene(zero, zero, fz, fs, name, (Stage("steady", _ph._VIBRATION_WINDOW[0], duration_s),))


def locking_at_threshold(ds, frequencies, amplitudes, window=_ph._VIBRATION_WINDOW):
    """Per frequency and afferent: (VS at f, VS at 2f) at the smallest amplitude with >= 1 spike per cycle.

    Conditions are ordered frequency-major, amplitude-minor.  Afferents that
    never reach one spike per cycle get nan.  Returns two arrays of shape
    (n_frequencies, n_afferents).
    """
    n_aff, n_amp = ds.sizes["afferent"], len(amplitudes)
    t, cond, aff = ds.spike_time.values, ds.spike_condition.values, ds.spike_afferent.values
    keep = (t >= window[0]) & (t < window[1]) & (ds.spike_trial.values == 0)
    t, cond, aff = t[keep], cond[keep], aff[keep]
    vs1 = np.full((len(frequencies), n_aff), np.nan)
    vs2, phases = np.full_like(vs1, np.nan), [[] for _ in frequencies]
    order = np.lexsort((t, aff, cond))
    t, key = t[order], cond[order] * n_aff + aff[order]
    starts = np.searchsorted(key, np.arange(len(frequencies) * n_amp * n_aff + 1))
    for f, freq in enumerate(frequencies):
        cycles = freq * (window[1] - window[0])
        for j in range(n_aff):
            for i in range(n_amp):
                k = (f * n_amp + i) * n_aff + j
                spikes = t[starts[k]:starts[k + 1]]
                if spikes.size >= cycles:
                    vs1[f, j], vs2[f, j] = vector_strength(spikes, freq), vector_strength(spikes, freq, 2)
                    phases[f].append(np.mod(spikes * freq, 1.0))
                    break
    return vs1, vs2, [np.concatenate(p) if p else np.zeros(0) for p in phases]


def _locking(population, context, frequencies, preload_n, kind="RAI"):
    """(VS at f, VS at 2f) of up to 20 afferents of ``kind`` (chosen by the seed) at their 1:1 amplitudes."""
    idx = np.flatnonzero(population.afferent_type == kind)
    pick = np.random.default_rng(context["seed"]).choice(idx, min(idx.size, _N_AFFERENTS), replace=False)
    sub = population.select(np.sort(pick))
    scenes = [vibration_scene(f, a, f"lock_{f:g}_{i}", preload_n) for f in frequencies
              for i, a in enumerate(AMPLITUDES_N)]
    ds = _ph._run(sub, scenes, context, record=("spikes",))
    return locking_at_threshold(ds, frequencies, AMPLITUDES_N)


def _summary(vs1, vs2):
    """Median VS at f over afferent-frequencies that reach 1:1, fraction 1:1 and locked, median VS(2f)/VS(f)."""
    reached = ~np.isnan(vs1)
    if not reached.any():
        return float("nan"), 0.0, float("nan")
    locked = float(np.mean(np.where(reached, vs1, 0.0) > LOCKED_VS))
    return float(np.median(vs1[reached])), locked, float(np.median(vs2[reached] / vs1[reached]))


def _phase_locking(population, context):
    values, data = {}, {}
    for kind, frequencies, variant in (("RAI", FREQUENCIES_RAI_HZ, VARIANT_HZ),
                                       ("RAII", FREQUENCIES_RAII_HZ, VARIANT_RAII_HZ)):
        if not np.any(population.afferent_type == kind):
            continue
        vs1, vs2, phases = _locking(population, context, frequencies, 1.0, kind)
        w1, w2, _ = _locking(population, context, variant, 2.0, kind)
        for suffix, stats in (("", _summary(vs1, vs2)), ("_2N", _summary(w1, w2))):
            for name, value in zip(("vs_{}", "locked_{}", "vs_2f_ratio_{}"), stats):
                values[name.format(kind) + suffix] = value
        shown = frequencies.index(CYCLE_HISTOGRAM_HZ[kind])
        data[kind] = {"frequencies": frequencies, "vs": vs1, "vs_2f": vs2, "frequency_hz": CYCLE_HISTOGRAM_HZ[kind],
                      "phases": phases[shown]}
    return values, data


def _vibration_sai(population, context):
    """SA-I mean rate over 0.5-1.5 s on a 1.5 N preload, with 0.3 N at 5 and 10 Hz over without."""
    idx = np.flatnonzero(is_type(population.afferent_type, "SAI"))
    pick = np.random.default_rng(context["seed"]).choice(idx, min(idx.size, 40), replace=False)
    sub = population.select(np.sort(pick))
    fs, t1 = 1000.0, 1.5
    t = np.arange(int(t1 * fs)) / fs
    ramp = np.minimum(t / 0.3, 1.0) * 1.5  # 5 N/s to the preload, then a hold
    scenes = []
    for f, a in ((0.0, 0.0), (5.0, 0.3), (10.0, 0.3)):
        fz = ramp + a * np.where(t >= 0.4, np.sin(2 * np.pi * f * (t - 0.4)), 0.0)
        scenes.append(Scene(np.zeros_like(t), np.zeros_like(t), fz, fs, f"sai_vib_{f:g}", ()))
    ds = _ph._run(sub, scenes, context, record=("spikes",))
    rates = [_ph._rates(ds, 0.5, t1, condition=c).mean() for c in range(3)]
    ratio = float(np.mean(rates[1:]) / rates[0]) if rates[0] > 0 else float("inf")
    t_s = ds.spike_time.values[(ds.spike_condition.values == 2) & (ds.spike_time.values >= 0.5)]
    phases = np.mod((t_s - 0.4) * CYCLE_HISTOGRAM_HZ["SAI"], 1.0)
    return {"vibration_rate_SAI": ratio}, {"SAI": {"rates": rates, "frequency_hz": CYCLE_HISTOGRAM_HZ["SAI"],
                                                   "phases": phases}}


def vibration_rate_sai(population, context):
    """Not a scorecard row (the presets fail it, docs/model.md): SA-I rate with low-frequency vibration."""
    return _vibration_sai(population, context)


RUNNERS = {"phase_locking": _phase_locking}
_ph.load_extensions()  # a no-op unless this module was imported before the scorecard (see `load_extensions`)
