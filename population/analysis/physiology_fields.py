"""Scorecard protocol ``fields``: receptive fields that grow with force, as human fields do.

A point probe (a contact of 0.5 mm radius) presses at 0.4, 0.8 and 1.6 N
(a 50 ms ramp, a 0.65 s hold) on a line of untuned afferents of each type
at 0-30 mm from its centre, with the population's current stage and
receptive-field shape, free of noise and of trial-to-trial excitability
(a field is a geometric property: with noise, the farthest responding
afferent would move from trial to trial).  An afferent responds when it fires after the
ramp starts; the field's radius at a force is the farthest responding
afferent.  The statistic is the smallest ratio of radii from one force to
the next doubling: above 1 when every doubling widens the field, 1 when the
field stops at a cliff (docs/references.md row 17; human fields grow with
force, recalled: R).  SA-II are left out: they fire at rest, and their
response is the subject of the slowly adapting protocols.
"""

from __future__ import annotations

import numpy as np

from ddmm.population.analysis.physiology import Property, _run, load_extensions
from ddmm.population.stimuli.scenes import Contact, Scene, Stage

__all__ = ["FIELD_FORCES_N", "PROPERTIES", "PROTOCOLS", "RUNNERS", "field_radii", "probe_scene"]

#: Probe forces (N), each double the last.
FIELD_FORCES_N = (0.4, 0.8, 1.6)
#: Distances (mm) of the probed afferents from the probe's centre.
_DISTANCES_MM = np.arange(0.0, 30.01, 0.25)
_TYPES = ("SAI", "RAI", "RAII")
_FS = 1000.0

PROPERTIES = {f"field_growth_{kind}": Property(f"field_growth_{kind}", kind, "fields",
                                               "smallest radius ratio per force doubling, 0.4 -> 0.8 -> 1.6 N probe", "1")
              for kind in _TYPES}
PROTOCOLS = ("fields",)


def probe_scene(force_n: float) -> Scene:
    """A 0.5 mm point probe at the origin: 0.1 s at rest, a 50 ms ramp to ``force_n`` newtons, a 0.65 s hold."""
    t = np.arange(int(0.8 * _FS)) / _FS
    fz = np.interp(t, [0.0, 0.1, 0.15, 0.8], [0.0, 0.0, force_n, force_n])
    zero = np.zeros_like(t)
    return Scene(zero, zero, fz, _FS, f"probe_{force_n:g}N",
                 (Stage("loading", 0.1, 0.15), Stage("hold", 0.15, 0.8)), Contact(0.0, 0.0, 0.5))


def field_radii(population, afferent_type: str, context) -> np.ndarray:
    """Radius (mm) of the responding field of ``afferent_type`` at each of `FIELD_FORCES_N` (0 where none responds)."""
    from ddmm.population.sampling import make_population

    quiet = population.current.with_all_types(excite_cv=0.0)
    line = make_population([afferent_type] * _DISTANCES_MM.size, x_mm=_DISTANCES_MM, current=quiet,
                           name=f"{population.name}_probe_line", receptive_field=population.receptive_field)
    ds = _run(line, [probe_scene(f) for f in FIELD_FORCES_N], context, record=("spikes",))
    radii = np.zeros(len(FIELD_FORCES_N))
    for c in range(len(FIELD_FORCES_N)):
        keep = (ds.spike_condition.values == c) & (ds.spike_time.values >= 0.1)
        fired = np.bincount(ds.spike_afferent.values[keep], minlength=_DISTANCES_MM.size) > 0
        radii[c] = _DISTANCES_MM[fired].max() if fired.any() else 0.0
    return radii


def _fields(population, context):
    out, data = {}, {}
    present = set(np.unique(population.afferent_type).tolist())
    for kind in _TYPES:
        if kind not in present:
            continue
        radii = field_radii(population, kind, context)
        data[kind] = radii
        ratios = radii[1:] / np.maximum(radii[:-1], 1e-12)
        out[f"field_growth_{kind}"] = float(ratios.min()) if radii[0] > 0 else 0.0
    return out, {"radii_mm": data, "forces_n": FIELD_FORCES_N}


RUNNERS = {"fields": _fields}
load_extensions()  # a no-op unless this module was imported before the scorecard (see `load_extensions`)
