"""scikit-learn estimators for the decoders: estimator contract, grouped cross-validation, shared math, bad input."""

import subprocess
import sys
from dataclasses import replace

import numpy as np
import pytest

from ddmm.population import birznieks, make_population, simulate
from ddmm.population.analysis.decode import DECODERS, FirstSpikeLatency, MaximumLikelihood, PopulationVector

from .synthetic import cosine_dataset

pytest.importorskip("sklearn")
from sklearn.base import clone  # noqa: E402
from sklearn.exceptions import NotFittedError  # noqa: E402
from sklearn.model_selection import GroupKFold, cross_val_score  # noqa: E402
from sklearn.utils.estimator_checks import check_estimator  # noqa: E402

from ddmm.population.analysis.ml import (  # noqa: E402
    ESTIMATORS,
    FirstSpikeLatencyDecoder,
    MaximumLikelihoodDecoder,
    PopulationVectorDecoder,
    circular_score,
    expected_failed_checks,
    features,
)

CLASSES = (PopulationVectorDecoder, MaximumLikelihoodDecoder, FirstSpikeLatencyDecoder)
KIND = {PopulationVectorDecoder: "count", MaximumLikelihoodDecoder: "count", FirstSpikeLatencyDecoder: "latency"}
PAIRS = ((PopulationVectorDecoder, PopulationVector), (MaximumLikelihoodDecoder, MaximumLikelihood),
         (FirstSpikeLatencyDecoder, FirstSpikeLatency))


@pytest.fixture(scope="module")
def sim():
    """12 afferents (SA-I, RA-I with receptor noise, SA-II), 8 Birznieks directions, 3 trials."""
    pop = make_population(["SAI", "RAI", "SAII"] * 4, theta_t=np.arange(0, 360, 30), nap="selective", noise_cv=0.3)
    return simulate(pop, [birznieks(d) for d in range(0, 360, 45)], engine="direct", trials=3, seed=1, quiet=True)


@pytest.fixture(scope="module")
def tuned():
    """Noiseless cosine-tuned counts, and latencies, at 36 directions: what a decoder should get right."""
    theta_t, directions = np.arange(0.0, 360.0, 15.0), np.arange(0.0, 360.0, 10.0)
    return {"count": cosine_dataset(directions, theta_t, peak=60, base=20),
            "latency": cosine_dataset(directions, theta_t, latency_s=lambda d: 0.02 - 0.01 * np.cos(d))}


@pytest.mark.parametrize("cls", CLASSES)
def test_clone_get_params_set_params(cls, sim):
    params = {PopulationVectorDecoder: {"theta_t": sim.theta_t.values, "nap": sim.nap.values},
              MaximumLikelihoodDecoder: {"ridge": 0.5}, FirstSpikeLatencyDecoder: {"alpha": 0.05}}[cls]
    est = cls(**params)
    assert all(est.get_params()[k] is v for k, v in params.items())  # stored unchanged
    copy = clone(est)
    assert copy is not est and set(copy.get_params()) == set(params)
    for key, value in copy.get_params().items():
        np.testing.assert_array_equal(value, params[key])
    defaults = cls().get_params()
    assert cls().set_params(**params).get_params().keys() == defaults.keys()
    assert clone(est.set_params(**defaults)).get_params() == defaults  # round trip back to the defaults
    with pytest.raises(ValueError, match="Invalid parameter 'window_s'"):
        est.set_params(window_s=0.1)
    X, y, _ = features(sim, 0.1, kind=KIND[cls])
    fitted = est.fit(X, y)
    assert fitted is est and est.n_features_in_ == 12
    assert not [a for a in vars(clone(est)) if a.endswith("_")]  # a clone is unfitted


@pytest.mark.parametrize("cls", CLASSES)
def test_cross_val_score_with_group_kfold(cls, sim, tuned):
    X, y, groups = features(sim, 0.1, kind=KIND[cls])
    scores = cross_val_score(cls(), X, y, groups=groups, cv=GroupKFold(n_splits=4))
    assert scores.shape == (4,) and np.all((scores >= -1) & (scores <= 1))
    X, y, groups = features(tuned[KIND[cls]], 0.2, kind=KIND[cls])
    cv = GroupKFold(n_splits=6)
    assert cross_val_score(cls(), X, y, groups=groups, cv=cv).min() > 0.99  # held-out directions, noiseless
    shuffled = np.random.default_rng(0).permutation(y)  # no relation left: about chance (0)
    assert cross_val_score(cls(), X, shuffled, groups=groups, cv=cv).mean() < 0.5


def test_features_shapes_and_groups(sim):
    X, y, groups = features(sim, 0.1)
    assert X.shape == (24, 12) and X.dtype.kind == "i" and y.shape == groups.shape == (24,)
    np.testing.assert_array_equal(y, np.repeat(np.arange(0.0, 360.0, 45.0), 3))
    np.testing.assert_array_equal(groups, np.repeat(np.arange(8), 3))
    for train, test in GroupKFold(n_splits=4).split(X, y, groups):  # a condition never straddles the split
        assert not set(groups[train]) & set(groups[test])
    latency, _, _ = features(sim, 0.1, kind="latency")
    assert latency.shape == X.shape and np.all((latency >= 0) & (latency <= 0.1))
    assert np.all((X == 0) == (latency == 0.1))  # silent afferents read the window's end
    # start_s: a window at a fixed time after every scene's start, against the events themselves
    counts, _, _ = features(sim, 0.05, start_s=0.2)
    t, c, tr, a = (sim[v].values for v in ("spike_time", "spike_condition", "spike_trial", "spike_afferent"))
    inside = (t >= 0.2) & (t < 0.25)
    expect = np.zeros((8, 3, 12), int)
    np.add.at(expect, (c[inside], tr[inside], a[inside]), 1)
    np.testing.assert_array_equal(counts, expect.reshape(24, 12))


def test_groups_by_direction_and_unlabelled_conditions():
    pop = make_population(["SAI", "RAI"], theta_t=[0.0, 180.0], nap="selective")
    scenes = [birznieks(90.0), birznieks(None), birznieks(0.0), replace(birznieks(90.0, normal_n=3.0), name="light")]
    ds = simulate(pop, scenes, engine="direct", trials=2, quiet=True)
    with pytest.raises(ValueError, match=r"without a shear direction \(has_theta_r == 0\): 'normal';"):
        features(ds)
    X, y, groups = features(ds, drop_unlabelled=True)
    assert X.shape == (6, 2) and y.tolist() == [90.0] * 2 + [0.0] * 2 + [90.0] * 2
    assert groups.tolist() == [0, 0, 2, 2, 3, 3]  # positions on condition
    assert features(ds, drop_unlabelled=True, group_by="direction")[2].tolist() == [1, 1, 0, 0, 1, 1]
    with pytest.raises(ValueError, match="no condition has one"):
        features(ds.isel(condition=[1]), drop_unlabelled=True)


@pytest.mark.parametrize(("cls", "decoder"), PAIRS)
def test_predictions_equal_the_dataset_decoders(cls, decoder, sim):
    expected = decoder(0.1).fit(sim).predict(sim).values.ravel()
    X, y, _ = features(sim, 0.1, kind=KIND[cls])
    est = cls(theta_t=sim.theta_t.values, nap=sim.nap.values) if cls is PopulationVectorDecoder else cls()
    predicted = est.fit(X, y).predict(X)
    np.testing.assert_allclose(predicted, expected, rtol=0, atol=1e-9)
    assert np.all((predicted >= 0) & (predicted < 360))
    assert est.score(X, y) == pytest.approx(np.mean(np.cos(np.deg2rad(expected - y))))
    assert ESTIMATORS[decoder.name] is cls and set(ESTIMATORS) == set(DECODERS)


class _AnyTargetML(MaximumLikelihoodDecoder):
    _min_samples = _min_directions = 1  # the guard lifted: the generic checks' 2-4 target values are enough


class _AnyTargetLatency(FirstSpikeLatencyDecoder):
    _min_samples = _min_directions = 1


@pytest.mark.filterwarnings("ignore::sklearn.exceptions.SkipTestWarning")
@pytest.mark.parametrize("est", [c() for c in CLASSES] + [_AnyTargetML(), _AnyTargetLatency()],
                         ids=lambda e: type(e).__name__)
def test_sklearn_generic_checks(est):
    expected = expected_failed_checks(est)
    results = check_estimator(est, expected_failed_checks=expected, on_fail=None, on_skip=None)
    failed = {r["check_name"] for r in results if r["status"] == "failed"}
    assert not failed
    assert {r["check_name"] for r in results if r["status"] == "xfail"} == set(expected)  # and each does fail
    assert sum(r["status"] == "passed" for r in results) >= 30


def test_bad_input(sim):
    X, y, _ = features(sim, 0.1)
    MaximumLikelihoodDecoder(ridge=-1.0)  # the contract: __init__ stores, fit validates
    for est, match in ((MaximumLikelihoodDecoder(ridge=-1.0), "ridge must be"),
                       (MaximumLikelihoodDecoder(ridge="big"), "ridge must be"),
                       (FirstSpikeLatencyDecoder(alpha=0.0), r"alpha must be a real number in \(0, 1\]"),
                       (PopulationVectorDecoder(theta_t=[0.0, 90.0]), r"theta_t must hold one value per afferent"),
                       (PopulationVectorDecoder(nap=["sharp"] * 12), "nap has unknown profile 'sharp'")):
        with pytest.raises(ValueError, match=match):
            est.fit(X, y)
    with pytest.raises(ValueError, match="Negative values in data passed to MaximumLikelihoodDecoder"):
        MaximumLikelihoodDecoder().fit(-X, y)
    with pytest.raises(ValueError, match="Input y contains NaN"):
        PopulationVectorDecoder().fit(X, np.where(y > 100, np.nan, y))
    with pytest.raises(ValueError, match="needs at least 10 samples with a shear direction"):
        MaximumLikelihoodDecoder().fit(X[:9], y[:9])
    with pytest.raises(NotFittedError):  # a ValueError too
        PopulationVectorDecoder().predict(X)
    with pytest.raises(ValueError, match="X has 3 features, but PopulationVectorDecoder is expecting 12"):
        PopulationVectorDecoder().fit(X, y).predict(X[:, :3])
    for kwargs, match in (({"kind": "rate"}, "kind must be one of"), ({"group_by": "repeat"}, "group_by must be"),
                          ({"window_s": 0.0}, "window_s must be > 0"), ({"start_s": -1.0}, "start_s must be"),
                          ({"start_s": 0.48}, "after start_s .* is longer than condition")):
        with pytest.raises(ValueError, match=match):
            features(sim, **{"window_s": 0.1, **kwargs})
    with pytest.raises(TypeError, match="dataset must be an xarray.Dataset"):
        features(X)
    with pytest.raises(ValueError, match="no theta_r"):
        features(sim.drop_vars(["theta_r", "has_theta_r"]))
    with pytest.raises(ValueError, match="y_pred must be finite"):
        circular_score([0.0, 90.0], [0.0, np.inf])
    with pytest.raises(ValueError, match="inconsistent numbers of samples"):
        circular_score([0.0, 90.0], [0.0])


def test_analysis_package_imports_without_touching_sklearn():
    code = ("import sys, ddmm.population.analysis as a; print('sklearn' in sys.modules, 'features' in dir(a));"
            "a.PopulationVectorDecoder; print('sklearn' in sys.modules)")
    out = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, check=True).stdout.split()
    assert out == ["False", "True", "True"]
    # without scikit-learn: the package and the Dataset decoders work, the estimators say what to install
    code = ("import sys; sys.modules['sklearn'] = None; import ddmm.population.analysis as a; a.MaximumLikelihood\n"
            "try:\n    a.features\nexcept ImportError as e:\n    print(e)")
    out = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, check=True).stdout
    assert "needs scikit-learn" in out and "pip install 'ddmm[ml]'" in out


def test_trials_as_groups_hold_out_repeats_at_every_direction():
    from ddmm.population import birznieks, make_population, simulate

    pop = make_population(["SAI", "RAI", "SAII"] * 4, theta_t=np.arange(0, 360, 30), nap="selective", noise_cv=0.3)
    ds = simulate(pop, [birznieks(d) for d in range(0, 360, 45)], engine="direct", trials=3, seed=2, quiet=True)
    X, y, groups = features(ds, 0.1, group_by="trial")
    assert groups.tolist() == [0, 1, 2] * 8
    for train, test in GroupKFold(n_splits=3).split(X, y, groups):
        assert set(y[train]) == set(y[test]) and len(set(groups[test])) == 1
    scores = cross_val_score(MaximumLikelihoodDecoder(), X, y, groups=groups, cv=GroupKFold(n_splits=3))
    assert scores.mean() > 0.5
