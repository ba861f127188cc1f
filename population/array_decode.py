"""Decoding what only force fields carry: torque and slip, from population spikes.

* `stage_onset`: when a named stage of each condition starts (e.g. the
  torsion scenes' ``torque_ramp``, the slip scenes' ``slip``).
* `onset_counts`: spike counts per (condition, trial, afferent) in a window
  after that onset.
* `CentroidClassifier`: a Gaussian classifier with one shared, shrunk
  variance per afferent (the linear discriminant of independent Poisson-like
  counts); it decodes rotation direction or torque magnitude from counts.
* `SlipDetector`: sums the population's spikes in a sliding window and
  reports slip when the sum exceeds a threshold learned on no-slip trials
  (the largest sum any of them reached, times a margin); its latency and
  false alarms are measured by `evaluate_slip`.
"""

from __future__ import annotations

import numpy as np
import xarray as xr

__all__ = ["stage_onset", "onset_counts", "CentroidClassifier", "SlipDetector", "evaluate_slip"]


def stage_onset(ds: xr.Dataset, label: str) -> np.ndarray:
    """Start (s) of stage ``label`` per condition; NaN-free: raises if a condition lacks it."""
    if "stage" not in ds.coords or label not in ds.stage.values:
        raise ValueError(f"the dataset has no stage {label!r}; stages: {list(ds.coords.get('stage', []).values)}")
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
    >>> from population import make_population, birznieks, simulate
    >>> ds = simulate(make_population(["SAI"]), birznieks(90.0), engine="direct", quiet=True)
    >>> onset_counts(ds, [0.1], 0.05).shape
    (1, 1, 1)
    """
    if not window_s > 0:
        raise ValueError(f"window_s must be > 0 s, got {window_s!r}")
    if "spike_time" not in ds:
        raise ValueError("decoding needs spike events; simulate with record including 'spikes'")
    onset = np.broadcast_to(np.asarray(onset_s, dtype=float), (ds.sizes["condition"],))
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
        if not 0.0 <= shrinkage <= 1.0:
            raise ValueError(f"shrinkage must be in [0, 1], got {shrinkage!r}")
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
    """Slip reported when the population's spike count in a sliding window exceeds a learned threshold.

    Parameters
    ----------
    window_s : float
        Sliding window in s.
    margin : float
        Threshold = ``margin`` times the largest windowed count seen in the
        training no-slip trials (after ``start_stage`` begins).
    start_stage : str
        Stage from which the detector watches (the tangential load ramp).
    """

    def __init__(self, window_s: float = 0.01, margin: float = 1.2, start_stage: str = "tangential_ramp"):
        if not window_s > 0 or not margin > 0:
            raise ValueError(f"window_s and margin must be > 0; got {window_s!r} and {margin!r}")
        self.window_s, self.margin, self.start_stage = float(window_s), float(margin), start_stage

    def _sums(self, ds, afferents):
        """Windowed population counts, shape (condition, trial, step of window_s / 4)."""
        step = self.window_s / 4
        n_bins = int(np.ceil(float(ds.duration.max()) / step))
        keep = np.isin(ds.spike_afferent.values, afferents)
        b = np.minimum((ds.spike_time.values[keep] / step).astype(np.int64), n_bins - 1)
        binned = np.zeros((ds.sizes["condition"], ds.sizes["trial"], n_bins))
        np.add.at(binned, (ds.spike_condition.values[keep], ds.spike_trial.values[keep], b), 1)
        kernel = np.ones(4)
        sums = np.apply_along_axis(lambda v: np.convolve(v, kernel)[: v.size], 2, binned)
        return sums, (np.arange(n_bins) + 1) * step  # each sum ends at that time

    def fit(self, ds, slip, afferents) -> "SlipDetector":
        """Learn the threshold on the no-slip conditions (``slip`` is a boolean per condition)."""
        slip = np.asarray(slip, bool)
        if slip.all():
            raise ValueError("the detector needs no-slip conditions to learn its threshold")
        sums, ends = self._sums(ds, afferents)
        start = stage_onset(ds, self.start_stage)
        watched = ends[None, None, :] >= start[:, None, None] + self.window_s
        self.threshold_ = self.margin * max(1.0, float(np.max(np.where(watched, sums, 0.0)[~slip])))
        self.afferents_ = np.asarray(afferents)
        return self

    def detect(self, ds) -> np.ndarray:
        """Detection time (s) per (condition, trial), ``inf`` where slip is never reported."""
        sums, ends = self._sums(ds, self.afferents_)
        start = stage_onset(ds, self.start_stage)
        hit = (sums > self.threshold_) & (ends[None, None, :] >= start[:, None, None] + self.window_s)
        first = np.where(hit.any(axis=2), ends[np.argmax(hit, axis=2)], np.inf)
        return first


def evaluate_slip(times, slip, onset, duration) -> dict:
    """Latency and false alarms of detection ``times`` (condition, trial) against the true slip ``onset``.

    A detection before a slip's onset, or in a no-slip condition, is a false
    alarm; ``false_alarms_per_s`` divides them by the watched no-slip and
    pre-onset time.  ``accuracy`` is the fraction of trials judged right
    (slip detected after its onset; no-slip never detected).
    """
    slip, onset, duration = np.asarray(slip, bool), np.asarray(onset, float), np.asarray(duration, float)
    times = np.asarray(times, float)
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
