"""Decoding shear direction from population spikes.

Three decoders share a scikit-learn-like API on simulation datasets:
``fit(dataset)`` learns from every (condition, trial) whose scene has a
nominal shear direction (``has_theta_r == 1``), ``predict(dataset)``
returns the decoded direction (deg) per (condition, trial).  Responses are
read in a decision window of ``window_s`` seconds after contact onset (the
first sample with F_Z above `ddmm.models.metrics.CONTACT_THRESHOLD`).

* `PopulationVector`: baseline-subtracted spike counts weight unit vectors
  at each afferent's tuning angle theta_T; bipolar afferents are axial (their
  votes live on the doubled-angle circle and are folded onto the unipolar
  estimate); untuned afferents carry no direction and are left out.
* `MaximumLikelihood`: each afferent's count is Poisson with a log-rate
  that is a second-order Fourier series of direction, fitted on training
  trials (penalised maximum likelihood, L-BFGS); a test trial is decoded as
  the direction maximising the population log-likelihood.
* `FirstSpikeLatency`: each afferent's first-spike latency, clipped at the
  window's end (a silent afferent reads "no earlier than the window"), is read
  as its promptness 1 / (latency + `LATENCY_OFFSET_S`), a second-order Fourier
  series of direction fitted by least squares; only
  afferents whose latency is significantly tuned (F-test, p < 0.01) are
  used, and a test trial is decoded by weighted least-squares matching of
  the latencies (Johansson & Birznieks 2004: ensembles signal direction by
  their first spikes).

Their math is also exposed on plain arrays (rows are observations, columns
afferents, angles in radians): `count_normalisation` with `population_vector`,
`poisson_tuning` with `poisson_decode`, `latency_tuning` with
`latency_decode` (on `promptness`); `ddmm.population.analysis.ml` builds scikit-learn
estimators on them.
"""

from __future__ import annotations

import numpy as np
import xarray as xr
from scipy import stats
from scipy.optimize import minimize

from ddmm.models.metrics import CONTACT_THRESHOLD
from ddmm.utils.validation import as_finite_array, as_float_array, check_dataset

__all__ = ["angular_error", "to_degrees", "contact_onset", "window_responses", "select_afferents",
           "check_training", "population_vector", "count_normalisation", "poisson_tuning", "poisson_decode",
           "promptness", "latency_tuning", "latency_decode", "PopulationVector", "MaximumLikelihood",
           "FirstSpikeLatency", "DECODERS"]

_GRID = np.deg2rad(np.arange(0.0, 360.0, 0.5))


def angular_error(a_deg, b_deg) -> np.ndarray:
    """Absolute angular difference in degrees, wrapped to [0, 180].

    Examples
    --------
    >>> angular_error([350.0, 10.0], [10.0, 200.0]).tolist()
    [20.0, 170.0]
    """
    a, b = as_finite_array(a_deg, "a_deg"), as_finite_array(b_deg, "b_deg")
    try:
        d = np.mod(a - b, 360.0)
    except ValueError:
        raise ValueError(f"b_deg must match a_deg's shape {a.shape} (or broadcast to it), got {b.shape}") from None
    return np.minimum(d, 360.0 - d)


def to_degrees(theta_rad) -> np.ndarray:
    """Angles in radians as degrees in [0, 360) (``np.mod`` alone can round -1e-15 up to 360.0).

    Examples
    --------
    >>> to_degrees([-np.pi / 2, 2 * np.pi, -1e-17]).tolist()
    [270.0, 0.0, 0.0]
    """
    deg = np.mod(np.rad2deg(np.asarray(theta_rad, float)), 360.0)
    return np.where(deg >= 360.0, 0.0, deg)


def contact_onset(ds: xr.Dataset) -> np.ndarray:
    """Contact onset per condition in seconds (first F_Z sample above the contact threshold)."""
    if "fz" not in ds:
        raise ValueError("decoding needs the scene forces; simulate with record including 'forces'")
    above = ds.fz.values > CONTACT_THRESHOLD
    if not above.any(axis=1).all():
        bad = str(ds.condition.values[np.flatnonzero(~above.any(axis=1))[0]])
        raise ValueError(f"condition {bad!r} never makes contact (F_Z never exceeds {CONTACT_THRESHOLD} N)")
    return ds.time.values[above.argmax(axis=1)]


def window_responses(ds: xr.Dataset, window_s: float, *, start_s: float | None = None):
    """Counts and first-spike latencies in [onset, onset + window) per (condition, trial, afferent).

    The window opens at contact onset (`contact_onset`), or at ``start_s``
    seconds after every scene's start when given.

    Returns
    -------
    counts : ndarray of int, shape (condition, trial, afferent)
    latency : ndarray of float, same shape; ``window_s`` where no spike came (censored), in s
    """
    check_dataset(ds)
    if not (isinstance(window_s, (int, float)) and window_s > 0):
        raise ValueError(f"window_s must be > 0 s, got {window_s!r}")
    if start_s is not None and not (isinstance(start_s, (int, float)) and 0 <= start_s < np.inf):
        raise ValueError(f"start_s must be None (contact onset) or a time >= 0 s, got {start_s!r}")
    if "spike_time" not in ds:
        raise ValueError("decoding needs spike events; simulate with record including 'spikes'")
    onset = contact_onset(ds) if start_s is None else np.full(ds.sizes["condition"], float(start_s))
    too_long = onset + window_s > ds.duration.values + 1e-12
    if too_long.any():
        c = int(np.flatnonzero(too_long)[0])
        where = "contact onset" if start_s is None else "start_s"
        raise ValueError(f"window of {window_s * 1e3:g} ms after {where} ({onset[c] * 1e3:g} ms) is longer "
                         f"than condition {str(ds.condition.values[c])!r} ({ds.duration.values[c] * 1e3:g} ms)")
    cond, trial, aff = (ds[v].values for v in ("spike_condition", "spike_trial", "spike_afferent"))
    rel = ds.spike_time.values - onset[cond]
    keep = (rel >= 0) & (rel < window_s)
    shape = (ds.sizes["condition"], ds.sizes["trial"], ds.sizes["afferent"])
    counts = np.zeros(shape, np.int64)
    np.add.at(counts, (cond[keep], trial[keep], aff[keep]), 1)
    latency = np.full(shape, float(window_s))
    np.minimum.at(latency, (cond[keep], trial[keep], aff[keep]), rel[keep])
    return counts, latency


def select_afferents(ds: xr.Dataset, positions) -> xr.Dataset:
    """The dataset restricted to afferents at ``positions``, spike events remapped."""
    check_dataset(ds)
    index = as_float_array(positions, "positions")
    bad = (index < 0) | (index >= ds.sizes["afferent"]) | (index != np.floor(index))
    if index.ndim != 1 or np.any(bad):
        shown = f"shape {index.shape}" if index.ndim != 1 else f"{float(index[bad][0])!r}"
        raise ValueError(f"positions must be a 1-D list of afferent positions in [0, {ds.sizes['afferent']}), "
                         f"got {shown}")
    positions = index.astype(np.int64)
    out = ds.isel(afferent=positions)
    if "spike_afferent" in ds:
        remap = np.full(ds.sizes["afferent"], -1, np.int64)
        remap[positions] = np.arange(positions.size)
        new = remap[ds.spike_afferent.values]
        keep = np.flatnonzero(new >= 0)
        out = out.isel(spike=keep)
        out["spike_afferent"] = ("spike", new[keep].astype(np.int32), ds.spike_afferent.attrs)
    return out


def check_training(angles_deg, need: int, distinct: int, who: str, unit: str = "trials") -> None:
    """Raise ValueError unless ``angles_deg`` holds ``need`` observations over ``distinct`` directions."""
    n_obs = int(np.size(angles_deg))
    n_dir = np.unique(np.round(np.mod(angles_deg, 360.0), 6)).size
    if n_obs < need or n_dir < distinct:
        raise ValueError(f"{who} needs at least {need} {unit} with a shear direction, spanning at least "
                         f"{distinct} distinct directions; got {n_obs} {unit} over {n_dir} directions")


def _labelled(ds: xr.Dataset, features, need: int, distinct: int, who: str):
    """Observations with a known direction: (features of shape (obs, afferent, ...), angles deg)."""
    has = ds.has_theta_r.values == 1
    n_obs = int(has.sum()) * ds.sizes["trial"]
    angles = np.repeat(ds.theta_r.values[has], ds.sizes["trial"])
    check_training(angles, need, distinct, who)
    return [f[has].reshape(n_obs, *f.shape[2:]) for f in features], angles


def _harmonics(theta_rad) -> np.ndarray:
    t = np.atleast_1d(theta_rad)
    return np.stack([np.ones_like(t), np.cos(t), np.sin(t), np.cos(2 * t), np.sin(2 * t)], axis=-1)


class _Decoder:
    """Shared plumbing: windows, population checks, output shape."""

    name = "decoder"
    min_trials, min_directions = 1, 1

    def __init__(self, window_s: float = 0.125):
        if not (isinstance(window_s, (int, float)) and window_s > 0):
            raise ValueError(f"window_s must be > 0 s, got {window_s!r}")
        self.window_s = float(window_s)
        self.afferent_ids_ = None

    def _features(self, ds):
        return window_responses(ds, self.window_s)

    def fit(self, ds: xr.Dataset) -> "_Decoder":
        """Learn from the trials of ``ds`` that have a nominal shear direction."""
        features, angles = _labelled(ds, self._features(ds), self.min_trials, self.min_directions, self.name)
        self.afferent_ids_ = ds.afferent.values.copy()
        self._fit(ds, *features, np.deg2rad(angles))
        return self

    def predict(self, ds: xr.Dataset) -> xr.DataArray:
        """Decoded direction (deg, [0, 360)) per (condition, trial)."""
        if self.afferent_ids_ is None:
            raise ValueError(f"{self.name} is not fitted; call fit(dataset) first")
        ids = ds.afferent.values
        if ids.shape != self.afferent_ids_.shape or not np.array_equal(ids, self.afferent_ids_):
            raise ValueError(f"{self.name} was fitted on {self.afferent_ids_.size} afferents but predict got "
                             f"{ids.size} with different ids; fit and predict need the same population")
        features = self._features(ds)
        n_c, n_t = ds.sizes["condition"], ds.sizes["trial"]
        flat = [f.reshape(n_c * n_t, *f.shape[2:]) for f in features]
        theta = to_degrees(self._predict(*flat)).reshape(n_c, n_t)
        return xr.DataArray(theta, dims=("condition", "trial"), coords={"condition": ds.condition, "trial": ds.trial},
                            attrs={"units": "degree", "decoder": self.name, "window_s": self.window_s})


def population_vector(responses, theta_t_deg, nap, baseline, scale) -> np.ndarray:
    """Population-vector direction (radians) of each row of ``responses`` (obs, afferent).

    Weights ``(r - baseline) / scale`` multiply unit vectors at theta_T for
    unipolar afferents; bipolar afferents vote on the doubled-angle circle and
    that axis is folded onto the unipolar estimate; untuned ones are ignored.
    """
    theta = np.deg2rad(np.asarray(theta_t_deg, float))
    nap = np.asarray(nap, dtype=object)
    w = (np.asarray(responses, float) - baseline) / scale
    uni = w @ (np.exp(1j * theta) * np.isin(nap, ("selective", "broad")))
    axial = w @ (np.exp(2j * theta) * (nap == "bipolar"))
    half = np.angle(axial) / 2.0  # axis, 180-deg ambiguous
    pick = np.where(np.cos(half - np.angle(uni)) >= 0, half, half + np.pi)
    return np.angle(uni + np.abs(axial) * np.exp(1j * pick))


def count_normalisation(counts):
    """The population vector's ``(baseline, scale)`` per afferent: training mean, and SD + 1 spike."""
    counts = np.asarray(counts, float)
    return counts.mean(axis=0), counts.std(axis=0) + 1.0  # the scale equalises afferents with different rates


class PopulationVector(_Decoder):
    """Rate-weighted unit vectors at theta_T; bipolar afferents axial (see `population_vector`)."""

    name = "population_vector"

    def _fit(self, ds, counts, latency, angles):
        self.baseline_, self.scale_ = count_normalisation(counts)
        self.theta_t_, self.nap_ = ds.theta_t.values, ds.nap.values

    def _predict(self, counts, latency):
        return population_vector(counts, self.theta_t_, self.nap_, self.baseline_, self.scale_)


class MaximumLikelihood(_Decoder):
    """Poisson tuning curves (log-rate: 2nd-order Fourier series), decoded by maximum likelihood."""

    name = "maximum_likelihood"
    min_trials, min_directions = 10, 5
    ridge = 1e-2  # penalty on the non-constant coefficients, keeps silent afferents finite

    def _fit(self, ds, counts, latency, angles):
        self.coef_ = poisson_tuning(counts, angles, self.ridge)

    def _predict(self, counts, latency):
        return poisson_decode(counts, self.coef_)


def poisson_tuning(counts, angles_rad, ridge: float = MaximumLikelihood.ridge) -> np.ndarray:
    """Coefficients (5, afferent) of each afferent's Poisson log-rate, a 2nd-order Fourier series of direction.

    Penalised maximum likelihood (L-BFGS): ``ridge`` weighs the squared
    non-constant coefficients per observation (keeps silent afferents finite).
    """
    x = _harmonics(np.asarray(angles_rad, float))  # (obs, 5)
    y = np.asarray(counts, float)  # (obs, afferent)
    n_aff = y.shape[1]
    b0 = np.zeros((5, n_aff))
    b0[0] = np.log(y.mean(axis=0) + 0.1)
    penalty = np.r_[0.0, np.full(4, ridge)][:, None]

    def loss(flat):
        b = flat.reshape(5, n_aff)
        eta = np.clip(x @ b, -30.0, 30.0)
        mu = np.exp(eta)
        value = np.sum(mu - y * eta) + 0.5 * np.sum(penalty * b * b) * len(y)
        grad = x.T @ (mu - y) + penalty * b * len(y)
        return value, grad.ravel()

    res = minimize(loss, b0.ravel(), jac=True, method="L-BFGS-B", options={"maxiter": 500})
    return res.x.reshape(5, n_aff)


def poisson_decode(counts, coef) -> np.ndarray:
    """Maximum-likelihood direction (radians) of each row of ``counts`` under `poisson_tuning`'s ``coef``."""
    log_rate = np.clip(_harmonics(_GRID) @ coef, -30.0, 30.0)  # (grid, afferent)
    ll = np.asarray(counts, float) @ log_rate.T - np.exp(log_rate).sum(axis=1)  # (obs, grid)
    return _refine_on_grid(ll)


class FirstSpikeLatency(_Decoder):
    """First-spike latencies (clipped at the window's end) matched, as `promptness`, to fitted curves."""

    name = "first_spike_latency"
    min_trials, min_directions = 10, 5
    alpha = 0.01  # significance of latency tuning for an afferent to be used

    def _fit(self, ds, counts, latency, angles):
        self.coef_, self.sigma_, self.usable_ = latency_tuning(latency, angles, self.alpha)

    def _predict(self, counts, latency):
        return latency_decode(latency, self.coef_, self.sigma_, self.usable_)


#: Added to a first-spike latency before its reciprocal is taken (s): a spike at contact onset
#: reads 500/s rather than infinity. Between 1 and 10 ms the decoding errors differ by under 5%.
LATENCY_OFFSET_S = 0.002


def promptness(latency) -> np.ndarray:
    """First-spike promptness ``1 / (latency + LATENCY_OFFSET_S)`` in 1/s, the latency decoder's feature.

    A first spike comes when a driven membrane reaches threshold, after a time
    roughly inverse to the drive; a trial's excitability multiplies the drive.
    So the reciprocal of the latency, not the latency, is about linear in both,
    and its trial-to-trial scatter is about the same in every direction, as the
    least-squares fit of `latency_tuning` assumes.

    Examples
    --------
    >>> promptness([0.008, 0.048]).tolist()
    [100.0, 20.0]
    """
    return 1.0 / (np.asarray(latency, float) + LATENCY_OFFSET_S)


def latency_tuning(latency, angles_rad, alpha: float = FirstSpikeLatency.alpha):
    """Least-squares promptness curves: ``(coef (5, afferent), sigma (afferent,), usable (afferent,) bool)``.

    ``latency`` is in s; ``coef`` and ``sigma`` are in 1/s, on `promptness`.
    ``usable`` marks afferents whose latency is tuned (F-test of the Fourier
    fit against a constant, p < ``alpha``); when none is, the best one.
    """
    # A silent afferent reads as "latency >= window": the clipped latency
    # is a complete, bounded feature, so every trial enters the fit.
    y = promptness(latency)  # (obs, afferent), 1/s
    x = _harmonics(np.asarray(angles_rad, float))  # (obs, 5)
    coef, *_ = np.linalg.lstsq(x, y, rcond=None)  # (5, afferent)
    ss_full = ((y - x @ coef) ** 2).sum(axis=0)
    ss_flat = ((y - y.mean(axis=0)) ** 2).sum(axis=0)
    dof = max(y.shape[0] - 5, 1)
    sigma = np.sqrt(ss_full / dof) + 0.1  # 1/s; floor for perfectly regular units
    # Keep afferents whose latency depends on direction: flat, noisy curves of hundreds
    # of untuned afferents would otherwise swamp the score with overfit wiggles.
    with np.errstate(divide="ignore", invalid="ignore"):
        f_stat = ((ss_flat - ss_full) / 4.0) / (ss_full / dof)
    p = np.where(ss_full > 0, stats.f.sf(f_stat, 4, dof), np.where(ss_flat > 0, 0.0, 1.0))
    usable = p < alpha
    if not usable.any():  # no information: decode from the best there is (about chance level)
        usable = p <= p.min()
    return coef, sigma, usable


def latency_decode(latency, coef, sigma, usable) -> np.ndarray:
    """Direction (radians) of each row of ``latency`` (s) by weighted least squares against `latency_tuning`'s curves."""
    pred = (_harmonics(_GRID) @ coef)[None, :, usable]  # (1, grid, used)
    miss = (promptness(latency)[:, None, usable] - pred) / sigma[usable]
    return _refine_on_grid(-0.5 * np.sum(miss**2, axis=2))


def _refine_on_grid(score: np.ndarray) -> np.ndarray:
    """Argmax on the circular grid, refined by a parabola through the neighbours (radians)."""
    i = score.argmax(axis=1)
    n = _GRID.size
    rows = np.arange(score.shape[0])
    left, mid, right = score[rows, (i - 1) % n], score[rows, i], score[rows, (i + 1) % n]
    denom = left - 2 * mid + right
    shift = np.where(denom < 0, 0.5 * (left - right) / np.where(denom < 0, denom, -1.0), 0.0)
    return _GRID[i] + np.clip(shift, -0.5, 0.5) * (_GRID[1] - _GRID[0])


#: Decoder classes by name (the JSON keys of ``ddmm decode``).
DECODERS = {cls.name: cls for cls in (PopulationVector, MaximumLikelihood, FirstSpikeLatency)}
