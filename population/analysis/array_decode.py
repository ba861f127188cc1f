"""Decoding what only force fields carry: torque and slip, from population spikes.

* `stage_onset`: when a named stage of each condition starts (e.g. the
  torsion scenes' ``torque_ramp``, the slip scenes' ``slip``).
* `onset_counts`: spike counts per (condition, trial, afferent) in a window
  after that onset.
* `CentroidClassifier`: a Gaussian classifier with one shared, shrunk
  variance per afferent (the linear discriminant of independent Poisson-like
  counts); it decodes rotation direction or torque magnitude from counts.
* `SlipDetector`: in a sliding window, sums each afferent's excess count
  over what it did in no-slip trials (in units of its own spread) and
  reports slip when the sum exceeds a threshold learned on no-slip trials;
  its latency and false alarms are measured by `evaluate_slip`.
"""

from __future__ import annotations

import numpy as np
import xarray as xr

from ddmm.utils.validation import (
    as_finite_array,
    as_float_array,
    check_dataset,
    check_instance,
    check_positive,
    check_real,
)

__all__ = ["stage_onset", "onset_counts", "CentroidClassifier", "SlipDetector", "evaluate_slip"]


def stage_onset(ds: xr.Dataset, label: str) -> np.ndarray:
    """Start (s) of stage ``label`` per condition; NaN-free: raises if a condition lacks it."""
    check_dataset(ds)
    check_instance(label, "label", str, "a stage label (str)")
    if "stage" not in ds.coords or label not in ds.stage.values:
        raise ValueError(f"label: the dataset has no stage {label!r}; "
                         f"stages: {list(ds.coords.get('stage', []).values)}")
    k = int(np.flatnonzero(ds.stage.values == label)[0])
    start = ds.stage_start.values[:, k]
    if not np.all(np.isfinite(start)):
        bad = str(ds.condition.values[np.flatnonzero(~np.isfinite(start))[0]])
        raise ValueError(f"condition {bad!r} has no stage {label!r}")
    return start


def onset_counts(ds: xr.Dataset, onset_s, window_s: float) -> np.ndarray:
    """Spike counts in ``[onset, onset + window)`` per (condition, trial, afferent).

    ``onset_s`` is one time per condition (s), ``window_s`` in s.

    Examples
    --------
    >>> from ddmm.population import make_population, birznieks, simulate
    >>> ds = simulate(make_population(["SAI"]), birznieks(90.0), engine="direct", quiet=True)
    >>> onset_counts(ds, [0.1], 0.05).shape
    (1, 1, 1)
    """
    check_dataset(ds)
    if not check_real(window_s, "window_s") > 0:
        raise ValueError(f"window_s must be > 0 s, got {float(window_s)!r}")
    if "spike_time" not in ds:
        raise ValueError("decoding needs spike events; simulate with record including 'spikes'")
    onset = as_finite_array(onset_s, "onset_s")
    if onset.size not in (1, ds.sizes["condition"]):
        raise ValueError(f"onset_s must be one time or one per condition ({ds.sizes['condition']}), got {onset.size}")
    onset = np.broadcast_to(onset.ravel(), (ds.sizes["condition"],))
    cond, trial, aff = (ds[v].values for v in ("spike_condition", "spike_trial", "spike_afferent"))
    rel = ds.spike_time.values - onset[cond]
    keep = (rel >= 0) & (rel < window_s)
    counts = np.zeros((ds.sizes["condition"], ds.sizes["trial"], ds.sizes["afferent"]), np.int64)
    np.add.at(counts, (cond[keep], trial[keep], aff[keep]), 1)
    return counts


class CentroidClassifier:
    """Nearest class mean under one shared variance per feature (shrunk towards the mean variance).

    Parameters
    ----------
    shrinkage : float
        Weight in [0, 1] of the average variance in each feature's variance
        (keeps silent or constant afferents from dominating).

    Examples
    --------
    >>> X = np.array([[0.0, 5.0], [1.0, 6.0], [9.0, 1.0], [8.0, 0.0]])
    >>> CentroidClassifier().fit(X, ["a", "a", "b", "b"]).predict([[7.0, 1.0]]).tolist()
    ['b']
    """

    def __init__(self, shrinkage: float = 0.2):
        if not 0.0 <= check_real(shrinkage, "shrinkage") <= 1.0:
            raise ValueError(f"shrinkage must be in [0, 1], got {float(shrinkage)!r}")
        self.shrinkage = float(shrinkage)

    def fit(self, X, y) -> "CentroidClassifier":
        """Class means and pooled within-class variances of features ``X`` (obs, features)."""
        X, y = np.asarray(X, dtype=float), np.asarray(y)
        if X.ndim != 2 or X.shape[0] != y.size:
            raise ValueError(f"X must be (observations, features) with one label each; got {X.shape} and {y.size}")
        self.classes_ = np.unique(y)
        if self.classes_.size < 2:
            raise ValueError(f"need at least two classes to fit, got {self.classes_.tolist()}")
        self.means_ = np.stack([X[y == c].mean(axis=0) for c in self.classes_])
        resid = X - self.means_[np.searchsorted(self.classes_, y)]
        var = resid.var(axis=0) + 1e-3  # a feature with no within-class spread still has a finite weight
        self.var_ = (1.0 - self.shrinkage) * var + self.shrinkage * var.mean()
        return self

    def predict(self, X) -> np.ndarray:
        """The class whose mean is nearest in the variance-weighted metric."""
        X = np.asarray(X, dtype=float)
        d = (((X[:, None, :] - self.means_[None]) ** 2) / self.var_).sum(axis=2)
        return self.classes_[np.argmin(d, axis=1)]


class SlipDetector:
    """Slip reported when the population's surprise in a sliding window exceeds a learned threshold.

    Each afferent's spike count in a sliding window is standardised by what
    it did in the training no-slip trials, ``z = (count - mean) / max(sd, 0.5)``,
    and weighted by how much it rose in the training slips' first
    ``learn_s`` after onset, ``w = max(0, z_slip)`` (a matched filter: FA-II,
    silent in the controls, weigh most; afferents slips do not move weigh
    nothing).  The statistic is ``sum w z``; the threshold is ``margin``
    times its largest value in the training no-slip trials.  The detector
    watches from ``settle_s`` after the start of ``start_stage``: the
    onset of tangential loading itself fires every FA-I in a burst (measured,
    fingertip seed 0: it set the no-slip maximum 20-25 ms after the onset,
    above most slips, and the whole fingertip then caught 72-83% of them).

    Parameters
    ----------
    window_s : float
        Sliding window in s (advanced in quarter steps).
    margin : float
        Threshold factor over the no-slip maximum.
    start_stage : str
        Stage from which the detector watches (the tangential load ramp).
    learn_s : float
        Span after a training slip's onset that sets the weights, in s.
    settle_s : float
        Time after the start of ``start_stage`` before the detector watches,
        in s (>= 0).
    """

    def __init__(self, window_s: float = 0.01, margin: float = 1.2, start_stage: str = "tangential_ramp",
                 learn_s: float = 0.03, settle_s: float = 0.05):
        for name, value in (("window_s", window_s), ("margin", margin), ("learn_s", learn_s)):
            check_positive(value, name)
        if not check_real(settle_s, "settle_s") >= 0:
            raise ValueError(f"settle_s must be >= 0 (s); got {float(settle_s)!r}")
        check_instance(start_stage, "start_stage", str, "a stage label (str)")
        self.window_s, self.margin, self.start_stage = float(window_s), float(margin), start_stage
        self.learn_s, self.settle_s = float(learn_s), float(settle_s)

    def _windowed(self, ds, afferents, c):
        """Sliding-window counts of condition ``c``, shape (trial, afferent, step), and each window's end (s)."""
        step = self.window_s / 4
        n_bins = int(np.ceil(float(ds.duration.max()) / step))
        pos = np.full(ds.sizes["afferent"], -1, np.int64)
        pos[afferents] = np.arange(afferents.size)
        keep = (ds.spike_condition.values == c) & (pos[ds.spike_afferent.values] >= 0)
        b = np.minimum((ds.spike_time.values[keep] / step).astype(np.int64), n_bins - 1)
        binned = np.zeros((ds.sizes["trial"], afferents.size, n_bins + 3), np.float32)
        np.add.at(binned, (ds.spike_trial.values[keep], pos[ds.spike_afferent.values[keep]], b + 3), 1)
        cs = np.cumsum(binned, axis=2)
        sums = cs[:, :, 3:] - np.concatenate([np.zeros_like(cs[:, :, :1]), cs[:, :, :-4]], axis=2)
        return sums, (np.arange(n_bins) + 1) * step

    def _statistic(self, sums):
        z = (sums - self.mean_[None, :, None]) / self.sd_[None, :, None]
        return np.einsum("i,tij->tj", self.weight_, z)

    def fit(self, ds, slip, afferents, onset) -> "SlipDetector":
        """Learn the no-slip statistics, the weights and the threshold.

        ``slip`` is a boolean per condition, ``onset`` the slip onset (s) per
        condition (ignored where ``slip`` is False).
        """
        slip, self.afferents_ = np.asarray(slip, bool), np.asarray(afferents, np.int64)
        if slip.all() or not slip.any():
            raise ValueError("the detector needs slip and no-slip training conditions")
        start = stage_onset(ds, self.start_stage) + self.settle_s
        windows = {c: self._windowed(ds, self.afferents_, c) for c in range(slip.size)}
        watched = [windows[c][0][:, :, windows[c][1] >= start[c] + self.window_s] for c in np.flatnonzero(~slip)]
        pooled = np.concatenate([w.transpose(1, 0, 2).reshape(self.afferents_.size, -1) for w in watched], axis=1)
        self.mean_, self.sd_ = pooled.mean(axis=1), np.maximum(pooled.std(axis=1), 0.5)
        rises = [windows[c][0][:, :, (windows[c][1] >= onset[c]) & (windows[c][1] < onset[c] + self.learn_s)]
                 for c in np.flatnonzero(slip)]
        rise = np.concatenate([r.transpose(1, 0, 2).reshape(self.afferents_.size, -1) for r in rises], axis=1)
        self.weight_ = np.maximum((rise.mean(axis=1) - self.mean_) / self.sd_, 0.0)
        self.threshold_ = self.margin * max(1e-9, max(float(self._statistic(w).max()) for w in watched))
        return self

    def detect(self, ds) -> np.ndarray:
        """Detection time (s) per (condition, trial), ``inf`` where slip is never reported."""
        start = stage_onset(ds, self.start_stage) + self.settle_s
        out = np.full((ds.sizes["condition"], ds.sizes["trial"]), np.inf)
        for c in range(ds.sizes["condition"]):
            sums, ends = self._windowed(ds, self.afferents_, c)
            hit = (self._statistic(sums) > self.threshold_) & (ends >= start[c] + self.window_s)[None, :]
            out[c] = np.where(hit.any(axis=1), ends[np.argmax(hit, axis=1)], np.inf)
        return out


def evaluate_slip(times, slip, onset, duration) -> dict:
    """Latency and false alarms of detection ``times`` (condition, trial) against the true slip ``onset``.

    A detection before a slip's onset, or in a no-slip condition, is a false
    alarm; ``false_alarms_per_s`` divides them by the watched no-slip and
    pre-onset time.  ``accuracy`` is the fraction of trials judged right
    (slip detected after its onset; no-slip never detected).
    """
    times, slip, onset, duration = _slip_inputs(times, slip, onset, duration)
    after = slip[:, None] & (times >= onset[:, None]) & np.isfinite(times)
    early = slip[:, None] & (times < onset[:, None])
    false = ~slip[:, None] & np.isfinite(times)
    correct = np.where(slip[:, None], after, ~np.isfinite(times))
    exposure = np.sum(np.where(slip, onset, duration)) * times.shape[1]
    latency = (times - onset[:, None])[after]
    return {"accuracy": float(correct.mean()),
            "latency_ms": float(np.median(latency) * 1e3) if latency.size else None,
            "latency_p90_ms": float(np.percentile(latency, 90) * 1e3) if latency.size else None,
            "false_alarms_per_s": float((early.sum() + false.sum()) / exposure)}


def _slip_inputs(times, slip, onset, duration) -> tuple:
    """`evaluate_slip`'s arguments as arrays, one row (or value) per condition; errors name the argument."""
    times = as_float_array(times, "times", ndim=2)  # inf: never detected
    n = times.shape[0]
    slip = np.asarray(slip)
    if slip.dtype.kind not in "biu" or slip.shape != (n,):
        raise ValueError(f"slip must hold one bool per condition ({n}), got dtype {slip.dtype}, shape {slip.shape}")
    slip = slip.astype(bool)
    onset, duration = as_float_array(onset, "onset"), as_finite_array(duration, "duration")
    if onset.size not in (1, n) or not np.all(np.isfinite(np.broadcast_to(onset.ravel(), (n,))[slip])):
        raise ValueError(f"onset must be one finite time (s), or one per condition ({n}), where slip is True")
    if duration.size not in (1, n) or np.any(duration <= 0):
        raise ValueError(f"duration must be one time > 0 s, or one per condition ({n})")
    return times, slip, np.broadcast_to(onset.ravel(), (n,)), np.broadcast_to(duration.ravel(), (n,))
