"""What the NWB and Neo exporters share: the checked Dataset, afferent metadata, trials, spikes, forces.

A *trial* here is one (condition, trial) pair of the Dataset; they are
numbered ``k = condition * n_trials + trial`` (condition-major), the order
both exporters lay them out in.
"""

from __future__ import annotations

import json

import numpy as np

__all__ = ["AFFERENT_FIELDS", "OPTIONAL_FIELDS", "afferent_values", "attrs_json", "check_dataset", "condition_forces",
           "n_samples", "plain", "site_labels", "spike_order", "stages_of", "trial_grid"]

# (coordinate on ``afferent``, unit, description); the afferent id is the unit / spike train's own id.
AFFERENT_FIELDS = (
    ("afferent_type", "1", "afferent type: SAI, RAI, RAII or SAII (unitless label)"),
    ("theta_t", "deg", "preferred shear direction theta_T in degrees, in the afferent's local digit frame "
                       "(0 radial, 90 distal, 180 ulnar, 270 proximal)"),
    ("nap", "1", "direction profile (NAP): selective, broad, bipolar or none (unitless label)"),
    ("k", "1", "tuning sharpness k (dimensionless; 0 for untuned afferents)"),
    ("gain", "1", "per-afferent current gain (dimensionless, mean 1)"),
    ("sensitivity", "1", "per-afferent sensitivity (dimensionless, median 1): multiplies the gain and divides the "
                         "type's dead zone, so the unit's stimulus thresholds are its type's over it"),
    ("x_mm", "mm", "receptor position x in millimetres (+X radial)"),
    ("y_mm", "mm", "receptor position y in millimetres (+Y distal)"),
    ("region", "1", "hand-map region (ddmm.population.anatomy.hand_map), empty when unknown (unitless label)"),
    ("frame_deg", "deg", "rotation in degrees (counterclockwise) from the local digit frame to the hand frame"),
    ("noise_sigma", "mV/sqrt(ms)", "additive current-noise intensity in mV/sqrt(ms)"),
    ("noise_cv", "sqrt(ms)", "receptor (drive-proportional) noise intensity in sqrt(ms)"),
)
_LABELS = {"afferent_type", "nap", "region"}
#: Fields a Dataset of an older version may lack, with the value its run used.
OPTIONAL_FIELDS = {"sensitivity": 1.0}
_REQUIRED = ("afferent", *(name for name, _, _ in AFFERENT_FIELDS if name not in OPTIONAL_FIELDS), "condition",
             "duration", "theta_r",
             "has_theta_r", "trial", "spike_count")
_EVENTS = ("spike_time", "spike_afferent", "spike_trial", "spike_condition")


def check_dataset(dataset, caller: str) -> None:
    """Raise TypeError / ValueError unless ``dataset`` is a simulation Dataset with spike events."""
    import xarray as xr

    if not isinstance(dataset, xr.Dataset):
        raise TypeError(f"{caller}: dataset must be an xarray.Dataset from ddmm.population.simulate or "
                        f"load_dataset, got {type(dataset).__name__}")
    missing = [name for name in _REQUIRED if name not in dataset.variables]
    if missing:
        raise ValueError(f"{caller}: dataset lacks {', '.join(missing)}; allowed: a Dataset of the schema in "
                         "population/dataset.py (ddmm.population.simulate or load_dataset)")
    if "fs" not in dataset.attrs:
        raise ValueError(f"{caller}: dataset attrs lack 'fs' (force sampling rate); allowed: a Dataset from "
                         "ddmm.population.simulate or load_dataset")
    if any(name not in dataset.variables for name in _EVENTS):
        raise ValueError(f"{caller}: dataset has no spike events (spike_time etc.); simulate with record "
                         "including 'spikes'")
    times = np.asarray(dataset["spike_time"].values, dtype=float)
    if times.size and not (np.all(np.isfinite(times)) and times.min() >= 0):
        bad = int(np.flatnonzero(~np.isfinite(times) | (times < 0))[0])
        raise ValueError(f"{caller}: dataset spike_time must be finite and >= 0 s, got {float(times[bad])} at event "
                         f"{bad}; was the Dataset edited after simulation?")
    for name, dim in (("spike_afferent", "afferent"), ("spike_trial", "trial"), ("spike_condition", "condition")):
        pos = dataset[name].values
        if pos.size and not (0 <= pos.min() and pos.max() < dataset.sizes[dim]):
            raise ValueError(f"{caller}: dataset {name} holds positions outside 0..{dataset.sizes[dim] - 1}; "
                             "was the Dataset subset after simulation? Export the full Dataset")


def afferent_values(dataset) -> dict:
    """Every field of `AFFERENT_FIELDS` as a list of plain Python str / float, plus ``afferent_id`` (int)."""
    out = {"afferent_id": [int(v) for v in dataset["afferent"].values]}
    for name, _, _ in AFFERENT_FIELDS:
        if name not in dataset.variables:  # an older Dataset: the value its run used
            out[name] = [OPTIONAL_FIELDS[name]] * len(out["afferent_id"])
            continue
        values = dataset[name].values
        out[name] = [str(v) for v in values] if name in _LABELS else [float(v) for v in values]
    return out


def trial_grid(dataset):
    """``(condition, trial)`` positions of every trial k, in the exporters' order."""
    n_c, n_t = dataset.sizes["condition"], dataset.sizes["trial"]
    return np.repeat(np.arange(n_c), n_t), np.tile(np.arange(n_t), n_c)


def spike_order(dataset, major: str):
    """Spike times (s, from their trial's start), trial number k and afferent position of every event.

    Sorted by (k, afferent, time) when ``major`` is ``"trial"`` and by
    (afferent, k, time) when it is ``"afferent"``.
    """
    time = dataset["spike_time"].values.astype(np.float64)
    k = dataset["spike_condition"].values.astype(np.int64) * dataset.sizes["trial"] + dataset["spike_trial"].values
    aff = dataset["spike_afferent"].values.astype(np.int64)
    order = np.lexsort((time, aff, k) if major == "trial" else (time, k, aff))
    return time[order], k[order], aff[order]


def stages_of(dataset, c: int) -> list:
    """``(label, start_s, end_s)`` of condition ``c``'s stages (a stage its scene lacks is left out)."""
    if "stage" not in dataset.coords:
        return []
    start, end = dataset["stage_start"].values[c], dataset["stage_end"].values[c]
    return [(str(label), float(a), float(b)) for label, a, b in zip(dataset["stage"].values, start, end) if b > a]


def n_samples(dataset, c: int) -> int:
    """Force samples of condition ``c`` (its duration times fs)."""
    return int(round(float(dataset["duration"].values[c]) * float(dataset.attrs["fs"])))


def condition_forces(dataset, c: int):
    """``(force (n, 3), site_force (n, n_sites, 3) or None)`` of condition ``c`` in N, or ``(None, None)``."""
    if "fx" not in dataset:
        return None, None
    n = n_samples(dataset, c)
    force = np.stack([dataset[name].values[c, :n] for name in ("fx", "fy", "fz")], axis=1)
    if "site_fx" not in dataset:
        return force, None
    return force, np.stack([dataset[name].values[c, :n] for name in ("site_fx", "site_fy", "site_fz")], axis=2)


def site_labels(dataset) -> list:
    """``"<site id> f<axis>"`` for the flattened (site, axis) channels of the per-site forces."""
    return [f"{site} {axis}" for site in dataset["site"].values for axis in ("fx", "fy", "fz")]


def plain(value):
    """A numpy scalar or array as plain Python (JSON- and annotation-safe)."""
    return value.tolist() if isinstance(value, (np.generic, np.ndarray)) else value


def attrs_json(dataset) -> str:
    """The Dataset's attrs (engine, dt, method, seed, model constants, version) as sorted JSON."""
    return json.dumps({key: plain(value) for key, value in dataset.attrs.items()}, sort_keys=True)
