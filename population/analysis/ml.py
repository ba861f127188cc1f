"""The shear-direction decoders as scikit-learn estimators.

`features` turns a simulation Dataset into the ``X, y, groups`` scikit-learn
expects; `PopulationVectorDecoder`, `MaximumLikelihoodDecoder` and
`FirstSpikeLatencyDecoder` run the math of `decode`'s `PopulationVector`,
`MaximumLikelihood` and `FirstSpikeLatency` (the same functions, so the same
predictions) under the estimator contract: `sklearn.base.clone`,
``get_params``/``set_params``, pipelines, model selection.

Targets are directions in degrees; predictions lie in [0, 360).  A direction
is circular, so ``score`` is not R^2 but `circular_score`, the mean cosine of
the angular error: 1 perfect, 0 chance (a guess independent of the truth,
whatever the set of directions), -1 always opposite.  It keeps "higher is
better" and R^2's scale and stays bounded; the negative mean absolute error
would put chance at -90 deg for uniform directions only.

This module needs scikit-learn (``pip install 'ddmm[ml]'``); the rest of
`ddmm.population.analysis` does not import it.
"""

from __future__ import annotations

import numbers

import numpy as np
import xarray as xr

try:
    from sklearn.base import BaseEstimator, RegressorMixin
    from sklearn.utils.validation import (
        check_consistent_length,
        check_is_fitted,
        check_non_negative,
        column_or_1d,
        validate_data,
    )
except ImportError as err:  # pragma: no cover - exercised only without the extra
    raise ImportError("ddmm.population.analysis.ml needs scikit-learn >= 1.6: pip install 'ddmm[ml]'") from err

from ddmm.population.analysis.decode import (
    FirstSpikeLatency,
    MaximumLikelihood,
    PopulationVector,
    check_training,
    count_normalisation,
    latency_decode,
    latency_tuning,
    poisson_decode,
    poisson_tuning,
    population_vector,
    to_degrees,
    window_responses,
)
from ddmm.population.spec import NAP_CHOICES
from ddmm.utils.validation import as_float_array

__all__ = ["features", "example_features", "circular_score", "PopulationVectorDecoder", "MaximumLikelihoodDecoder",
           "FirstSpikeLatencyDecoder", "ESTIMATORS", "expected_failed_checks"]

KINDS = ("count", "latency")
GROUPINGS = ("condition", "direction", "trial")


def features(dataset: xr.Dataset, window_s: float = 0.125, *, start_s: float | None = None, kind: str = "count",
             group_by: str = "condition", drop_unlabelled: bool = False):
    """Samples for scikit-learn: one row per (condition, trial), one column per afferent.

    Parameters
    ----------
    dataset : xarray.Dataset
        A simulation (`ddmm.population.dataset` schema) with spike events and,
        unless ``start_s`` is given, the forces.
    window_s : float
        Length of the response window (s), as for `decode`'s decoders.
    start_s : float or None
        Window start: None for each condition's contact onset (as the Dataset
        decoders read it), else this many seconds after every scene's start.
    kind : {"count", "latency"}
        ``"count"``: spike counts in the window (int; not rates: the window is
        the same for every sample, and the Poisson likelihood needs counts).
        ``"latency"``: first-spike latency after the window start (s),
        ``window_s`` when silent (`FirstSpikeLatencyDecoder`'s input).
    group_by : {"condition", "direction", "trial"}
        What a cross-validation group is (see Notes).
    drop_unlabelled : bool
        Leave out conditions without a shear direction instead of raising.

    Returns
    -------
    X : ndarray, shape (n_conditions * n_trials, n_afferents)
        Rows in (condition, trial) order, as ``Decoder.predict(dataset).values.ravel()``.
    y : ndarray of float, shape (n_samples,)
        The condition's shear direction ``theta_r`` (deg).
    groups : ndarray of int, shape (n_samples,)
        The condition's position on ``condition`` (or the direction's rank).

    Notes
    -----
    Trials of one condition repeat the same stimulus, and afferents without
    noise answer every repeat identically (the simulator runs them once).
    Grouping by trial index would train on trials 1-2 of every condition and
    test on trial 0 of the same conditions: near-duplicate rows on both
    sides, an optimistic score.  So a group is a condition: every trial of a
    held-out scene is held out together, and a test direction is decoded
    from other scenes.  ``group_by="direction"`` also pools conditions that
    share a direction (e.g. one scene repeated under two names).
    ``group_by="trial"`` makes the trial index the group (every direction on
    both sides, repeats held out): it measures trial-to-trial generalisation,
    and is meaningful only for a population with noise.

    Examples
    --------
    >>> from ddmm.population import birznieks, make_population, simulate
    >>> pop = make_population(["SAI", "RAI", "SAII"] * 4, theta_t=np.arange(0, 360, 30), nap="selective", noise_cv=0.3)
    >>> ds = simulate(pop, [birznieks(d) for d in range(0, 360, 45)], engine="direct", trials=3, quiet=True)
    >>> X, y, groups = features(ds, 0.1)
    >>> X.shape, y[:4].tolist(), groups[:4].tolist()
    ((24, 12), [0.0, 0.0, 0.0, 45.0], [0, 0, 0, 1])
    """
    if not isinstance(dataset, xr.Dataset):
        raise TypeError(f"dataset must be an xarray.Dataset from simulate, got {type(dataset).__name__}")
    if kind not in KINDS:
        raise ValueError(f"kind must be one of {KINDS}, got {kind!r}")
    if group_by not in GROUPINGS:
        raise ValueError(f"group_by must be one of {GROUPINGS}, got {group_by!r}")
    has = _labelled_conditions(dataset, drop_unlabelled)
    counts, latency = window_responses(dataset, window_s, start_s=start_s)
    values = counts if kind == "count" else latency
    n_t = dataset.sizes["trial"]
    theta = dataset.theta_r.values[has].astype(float)
    rows = values[has].reshape(-1, values.shape[2])
    if group_by == "trial":
        return rows, np.repeat(theta, n_t), np.tile(np.arange(n_t, dtype=np.int64), int(has.sum()))
    key = np.flatnonzero(has) if group_by == "condition" else np.unique(np.round(theta, 6), return_inverse=True)[1]
    return rows, np.repeat(theta, n_t), np.repeat(key, n_t).astype(np.int64)


def example_features(kind: str = "count"):
    """A small labelled set to try the decoders on: ``(dataset, X, y, groups)``.

    Twelve selective afferents (SA-I, FA-I, SA-II, tuning angles every 30
    deg, receptor noise) under Birznieks' protocol in 8 directions, 3 trials
    each; `features` of the first 0.1 s (``kind`` as there).

    Examples
    --------
    >>> ds, X, y, groups = example_features()
    >>> X.shape, sorted(set(y.tolist()))[:3]
    ((24, 12), [0.0, 45.0, 90.0])
    """
    from ddmm.population import birznieks, make_population, simulate

    pop = make_population(["SAI", "RAI", "SAII"] * 4, theta_t=np.arange(0, 360, 30), nap="selective", noise_cv=0.3)
    ds = simulate(pop, [birznieks(d) for d in range(0, 360, 45)], engine="direct", trials=3, quiet=True)
    return (ds, *features(ds, 0.1, kind=kind))


def _labelled_conditions(dataset: xr.Dataset, drop: bool) -> np.ndarray:
    """Mask of the conditions with a shear direction; ValueError naming those without (unless ``drop``)."""
    if "theta_r" not in dataset or "has_theta_r" not in dataset:
        raise ValueError("dataset has no theta_r/has_theta_r on condition; features needs the shear directions")
    has = dataset.has_theta_r.values == 1
    names = [str(c) for c in dataset.condition.values[~has]]
    if names and (not drop or not has.any()):
        shown = ", ".join(repr(n) for n in names[:5]) + (f" and {len(names) - 5} more" if len(names) > 5 else "")
        hint = "" if has.any() else "; no condition has one"
        raise ValueError(f"dataset conditions without a shear direction (has_theta_r == 0): {shown}{hint}; "
                         "their theta_r is no target (drop_unlabelled=True leaves them out)")
    return has


def circular_score(y_true, y_pred, *, sample_weight=None) -> float:
    """Mean cosine of the angular error between directions in degrees, in [-1, 1]; higher is better.

    1: every prediction exact; 0: chance (predictions independent of the
    truth); -1: every prediction opposite.  ``cos(err)`` is 0.98 at 10 deg,
    0.87 at 30 deg, 0.5 at 60 deg.  As a scorer:
    ``sklearn.metrics.make_scorer(circular_score)``.

    Examples
    --------
    >>> circular_score([0.0, 90.0], [0.0, 270.0])  # errors 0 and 180 deg
    0.0
    >>> round(circular_score([0.0, 90.0], [10.0, 60.0], sample_weight=[3, 1]), 3)
    0.955
    """
    y_true = column_or_1d(as_float_array(y_true, "y_true"))
    y_pred = column_or_1d(as_float_array(y_pred, "y_pred"))
    check_consistent_length(y_true, y_pred, sample_weight)
    for name, v in (("y_true", y_true), ("y_pred", y_pred)):
        if v.size == 0 or not np.isfinite(v).all():
            raise ValueError(f"{name} must be finite directions in degrees, got {v.size} value(s), "
                             f"{int((~np.isfinite(v)).sum())} not finite")
    return float(np.average(np.cos(np.deg2rad(y_pred - y_true)), weights=sample_weight))


class _CircularDecoder(RegressorMixin, BaseEstimator):
    """Shared contract: validation, degrees in and out, the circular score."""

    _decoder = PopulationVector  # the Dataset decoder whose math this shares
    _min_samples, _min_directions = 1, 1  # its minimum training set
    _poor_generic_score = True

    def fit(self, X, y):
        """Learn from ``X`` (n_samples, n_afferents) and directions ``y`` (deg); returns self."""
        X, y = validate_data(self, X, y, y_numeric=True)
        self._check_params(X.shape[1])
        self._check_X(X)
        check_training(y, self._min_samples, self._min_directions, type(self).__name__, "samples")
        self._fit(X, np.deg2rad(np.mod(y, 360.0)))
        return self

    def predict(self, X) -> np.ndarray:
        """Decoded direction (deg, [0, 360)) of each row of ``X``."""
        check_is_fitted(self)
        X = validate_data(self, X, reset=False)
        self._check_X(X)
        return to_degrees(self._predict(X))

    def score(self, X, y, sample_weight=None) -> float:
        """`circular_score` of ``predict(X)`` against ``y`` (deg): mean cos(error), 1 perfect, 0 chance."""
        return circular_score(y, self.predict(X), sample_weight=sample_weight)

    def _check_params(self, n_features: int) -> None:
        pass

    def _check_X(self, X) -> None:
        pass

    def __sklearn_tags__(self):
        tags = super().__sklearn_tags__()
        # Fitted on scikit-learn's generic regression set (targets spanning 6 deg of the circle, features
        # not tuned to direction), a decoder built for tuning curves over the whole circle is at chance.
        tags.regressor_tags.poor_score = self._poor_generic_score
        return tags


class PopulationVectorDecoder(_CircularDecoder):
    """Population vector on spike counts (`decode.PopulationVector`'s math, `decode.population_vector`).

    Parameters
    ----------
    theta_t : array-like of float, shape (n_afferents,), or None
        Each afferent's tuning angle (deg), e.g. ``dataset.theta_t.values``.
        None: estimated from the training set as the direction of the
        afferent's normalised counts weighted by unit vectors at ``y``.
    nap : array-like of str, shape (n_afferents,), or None
        Each afferent's profile (``"selective"``, ``"broad"``, ``"bipolar"``
        (axial) or ``"none"`` (left out)), e.g. ``dataset.nap.values``.
        None: every afferent unipolar.

    Attributes
    ----------
    baseline_, scale_ : ndarray, shape (n_afferents,)
        Training mean count, and SD + 1 spike.
    theta_t_, nap_ : ndarray, shape (n_afferents,)
        The tuning angles (deg) and profiles used.

    Examples
    --------
    >>> ds, X, y, groups = example_features()
    >>> est = PopulationVectorDecoder(theta_t=ds.theta_t.values, nap=ds.nap.values).fit(X, y)
    >>> bool(est.score(X, y) > 0.9), est.predict(X).shape
    (True, (24,))
    """

    def __init__(self, *, theta_t=None, nap=None):
        self.theta_t = theta_t
        self.nap = nap

    def _check_params(self, n_features: int) -> None:
        for name, value in (("theta_t", self.theta_t), ("nap", self.nap)):
            if value is not None and np.shape(value) != (n_features,):
                raise ValueError(f"{name} must hold one value per afferent (column of X): shape ({n_features},), "
                                 f"got {np.shape(value)}")
        if self.theta_t is not None and not np.isfinite(np.asarray(self.theta_t, float)).all():
            raise ValueError("theta_t must be finite angles in degrees")
        bad = set() if self.nap is None else set(np.asarray(self.nap, dtype=object).tolist()) - set(NAP_CHOICES)
        if bad:
            raise ValueError(f"nap has unknown profile {sorted(bad, key=str)[0]!r}; allowed: {', '.join(NAP_CHOICES)}")

    def _fit(self, X, angles):
        self.baseline_, self.scale_ = count_normalisation(X)
        if self.theta_t is None:  # preferred direction of the normalised responses
            weights = (X - self.baseline_) / self.scale_
            self.theta_t_ = to_degrees(np.angle(weights.T @ np.exp(1j * angles)))
        else:
            self.theta_t_ = np.asarray(self.theta_t, float).copy()
        nap = np.full(X.shape[1], "selective", dtype=object) if self.nap is None else self.nap
        self.nap_ = np.asarray(nap, dtype=object).copy()

    def _predict(self, X):
        return population_vector(X, self.theta_t_, self.nap_, self.baseline_, self.scale_)


class MaximumLikelihoodDecoder(_CircularDecoder):
    """Poisson tuning curves decoded by maximum likelihood (`decode.MaximumLikelihood`'s math).

    ``X`` holds spike counts (``features(kind="count")``; >= 0).  Fitting needs
    at least 10 samples over 5 distinct directions.

    Parameters
    ----------
    ridge : float
        Penalty (>= 0) on the non-constant Fourier coefficients of the log-rate.

    Attributes
    ----------
    coef_ : ndarray, shape (5, n_afferents)
        Log-rate coefficients on (1, cos, sin, cos 2theta, sin 2theta).

    Examples
    --------
    >>> ds, X, y, groups = example_features()
    >>> est = MaximumLikelihoodDecoder(ridge=0.01).fit(X, y)
    >>> est.coef_.shape, bool(est.score(X, y) > 0.9)
    ((5, 12), True)
    """

    _decoder = MaximumLikelihood
    _min_samples, _min_directions = MaximumLikelihood.min_trials, MaximumLikelihood.min_directions

    def __init__(self, *, ridge=MaximumLikelihood.ridge):
        self.ridge = ridge

    def _check_params(self, n_features: int) -> None:
        _check_real("ridge", self.ridge, 0.0, np.inf)

    def _check_X(self, X) -> None:
        check_non_negative(X, f"{type(self).__name__} (X: spike counts)")

    def _fit(self, X, angles):
        self.coef_ = poisson_tuning(X, angles, self.ridge)

    def _predict(self, X):
        return poisson_decode(X, self.coef_)

    def __sklearn_tags__(self):
        tags = super().__sklearn_tags__()
        tags.input_tags.positive_only = True  # spike counts
        return tags


class FirstSpikeLatencyDecoder(_CircularDecoder):
    """First-spike latencies matched, as promptness, to fitted curves (`decode.FirstSpikeLatency`'s math).

    ``X`` holds latencies (``features(kind="latency")``, s, the window length
    for a silent afferent).  Fitting needs at least 10 samples over 5
    distinct directions.

    Parameters
    ----------
    alpha : float
        Significance (in (0, 1]) of an afferent's latency tuning (F-test) for it to be used.

    Attributes
    ----------
    coef_ : ndarray, shape (5, n_afferents)
        Promptness curves (1/s, `decode.promptness` of the latency) on (1, cos, sin, cos 2theta, sin 2theta).
    sigma_ : ndarray, shape (n_afferents,)
        Residual SD of the promptness (1/s).
    usable_ : ndarray of bool, shape (n_afferents,)
        Afferents used to decode.

    Examples
    --------
    >>> ds, X, y, groups = example_features(kind="latency")
    >>> est = FirstSpikeLatencyDecoder().fit(X, y)
    >>> est.usable_.shape, bool(est.score(X, y) > 0.9)
    ((12,), True)
    """

    _decoder = FirstSpikeLatency
    _min_samples, _min_directions = FirstSpikeLatency.min_trials, FirstSpikeLatency.min_directions
    _poor_generic_score = False  # latency curves are fitted by least squares: fine on any stretch of the circle

    def __init__(self, *, alpha=FirstSpikeLatency.alpha):
        self.alpha = alpha

    def _check_params(self, n_features: int) -> None:
        _check_real("alpha", self.alpha, 0.0, 1.0, low_open=True)

    def _fit(self, X, angles):
        self.coef_, self.sigma_, self.usable_ = latency_tuning(X, angles, self.alpha)

    def _predict(self, X):
        return latency_decode(X, self.coef_, self.sigma_, self.usable_)


def _check_real(name: str, value, low: float, high: float, low_open: bool = False) -> None:
    ok = isinstance(value, numbers.Real) and not isinstance(value, bool) and np.isfinite(value)
    if not ok or value < low or (low_open and value == low) or value > high:
        interval = f"in {'(' if low_open else '['}{low:g}, {high:g}]" if np.isfinite(high) else f">= {low:g}"
        raise ValueError(f"{name} must be a real number {interval}, got {value!r}")


#: Estimator classes by decoder name (the keys of `decode.DECODERS`).
ESTIMATORS = {c._decoder.name: c for c in (PopulationVectorDecoder, MaximumLikelihoodDecoder, FirstSpikeLatencyDecoder)}

# scikit-learn's generic checks (1.9) that fit on targets with only 2-4 distinct values.
_FEW_TARGETS_CHECKS = tuple(f"check_{name}" for name in (
    "dict_unchanged dont_overwrite_parameters dtype_object estimators_dtypes estimators_fit_returns_self "
    "estimators_nan_inf estimators_overwrite_params estimators_pickle f_contiguous_array_estimator fit2d_1feature "
    "fit2d_predict1d fit_score_takes_y methods_sample_order_invariance methods_subset_invariance "
    "pipeline_consistency readonly_memmap_input regressors_int supervised_y_2d").split())


def expected_failed_checks(estimator) -> dict:
    """The checks of `sklearn.utils.estimator_checks` that ``estimator`` fails, with why.

    `PopulationVectorDecoder` passes them all.  The Fourier-curve decoders fail
    those whose targets hold 2-4 distinct values: they need 5 directions, so
    ``fit`` raises ValueError as the Dataset decoders do (without that guard
    they pass).  For ``check_estimator(..., expected_failed_checks=...)``.

    Examples
    --------
    >>> expected_failed_checks(PopulationVectorDecoder())
    {}
    >>> len(expected_failed_checks(MaximumLikelihoodDecoder()))
    18
    """
    if estimator._min_directions < 5:
        return {}
    why = (f"the check's targets hold 2-4 distinct values; {type(estimator).__name__} fits a 2nd-order Fourier "
           f"series per afferent and needs {estimator._min_directions} distinct directions, so fit raises")
    names = _FEW_TARGETS_CHECKS
    if not estimator.__sklearn_tags__().input_tags.positive_only:  # X made non-negative, y still 2 values
        names += ("check_positive_only_tag_during_fit",)
    return dict.fromkeys(names, why)
