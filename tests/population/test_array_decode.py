"""Torque and slip decoding from population spikes: the classifier, the detector, their scoring."""

import numpy as np
import pytest

from ddmm.population import sample_population, simulate
from ddmm.population.analysis.array_decode import (
    CentroidClassifier,
    SlipDetector,
    evaluate_slip,
    onset_counts,
    stage_onset,
)
from ddmm.population.stimuli.site_scenes import incipient_slip, torsion


def test_centroid_classifier_weights_features_by_their_spread():
    rng = np.random.default_rng(0)
    # feature 0 separates the classes by 1 with spread 0.1; feature 1 by 3 with spread 10: 0 must win
    X = np.column_stack([np.r_[rng.normal(0, 0.1, 50), rng.normal(1, 0.1, 50)],
                         np.r_[rng.normal(3, 10, 50), rng.normal(0, 10, 50)]])
    y = np.r_[["a"] * 50, ["b"] * 50]
    clf = CentroidClassifier(shrinkage=0.0).fit(X, y)
    assert np.mean(clf.predict(X) == y) > 0.97
    with pytest.raises(ValueError, match="at least two classes"):
        CentroidClassifier().fit(X, ["a"] * 100)
    with pytest.raises(ValueError, match="shrinkage"):
        CentroidClassifier(shrinkage=2.0)


@pytest.fixture(scope="module")
def small_pop():
    return sample_population("fingertip", rng=0).select(np.arange(0, 991, 4))


def test_torsion_direction_is_decoded_within_100_ms(small_pop):
    scenes = [torsion(5.0, 3.0, direction=d, hold_s=0.2, name=f"t{d}") for d in (1, -1)]
    ds = simulate(small_pop, scenes, engine="direct", trials=8, seed=0, quiet=True)
    counts = onset_counts(ds, stage_onset(ds, "torque_ramp"), 0.1)
    X = lambda trials: counts[:, trials].reshape(-1, counts.shape[2])  # noqa: E731
    y = np.repeat(["ccw", "cw"], 4)
    clf = CentroidClassifier().fit(X(np.arange(4)), y)
    assert np.mean(clf.predict(X(np.arange(4, 8))) == y) >= 0.95


def test_slip_detector_finds_slips_before_the_human_grip_response(small_pop):
    scenes = [incipient_slip(2.0, load_rate_n_s=4.0, slip=s) for s in (True, False)]
    ds = simulate(small_pop, scenes, engine="direct", trials=6, seed=1, quiet=True)
    onset = np.array([scenes[0].stages[2].start, scenes[1].stages[2].start])
    slip = np.array([True, False])
    keep = np.flatnonzero(ds.spike_trial.values < 3)
    train = ds.isel(spike=keep, trial=[0, 1, 2])
    detector = SlipDetector(0.01).fit(train, slip, np.arange(ds.sizes["afferent"]), onset)
    times = detector.detect(ds)
    score = evaluate_slip(times, slip, onset, ds.duration.values)
    assert score["accuracy"] == 1.0 and score["false_alarms_per_s"] == 0.0
    assert 0 < score["latency_ms"] < 74.0 / 2


@pytest.mark.parametrize(("settle_s", "caught"), [(0.0, False), (0.05, True)])
def test_the_slip_detector_waits_out_the_loading_onset_burst(small_pop, settle_s, caught):
    """Every FA-I fires when tangential loading starts: watched from that moment, the burst sets the
    threshold above the slips of a slow (2 N/s) load; watched from 50 ms on, every slip is caught."""
    scenes = [incipient_slip(2.0, load_rate_n_s=rate, slip=s) for rate in (2.0, 8.0) for s in (True, False)]
    ds = simulate(small_pop, scenes, engine="direct", trials=6, seed=2, quiet=True)
    onset = np.array([sc.stages[2].start for sc in scenes])
    slip = np.array([True, False, True, False])
    train = ds.isel(spike=np.flatnonzero(ds.spike_trial.values < 3), trial=[0, 1, 2])
    detector = SlipDetector(0.01, settle_s=settle_s).fit(train, slip, np.arange(ds.sizes["afferent"]), onset)
    score = evaluate_slip(detector.detect(ds), slip, onset, ds.duration.values)
    assert (score["accuracy"] == 1.0) is caught, score
    with pytest.raises(ValueError, match="settle_s must be >= 0"):
        SlipDetector(settle_s=-0.01)


def test_evaluate_slip_counts_early_and_false_detections():
    times = np.array([[0.55, 0.4, np.inf], [np.inf, 0.2, np.inf]])
    score = evaluate_slip(times, [True, False], [0.5, 0.5], [1.0, 1.0])
    assert score["accuracy"] == pytest.approx(3 / 6)  # slip: 1 right, 1 early, 1 missed; no-slip: 2 of 3 right
    assert score["latency_ms"] == pytest.approx(50.0)
    assert score["false_alarms_per_s"] == pytest.approx(2 / (3 * 0.5 + 3 * 1.0))


def test_stage_onset_needs_the_stage(small_pop):
    ds = simulate(small_pop, torsion(5.0, 3.0, hold_s=0.1), engine="direct", quiet=True)
    with pytest.raises(ValueError, match="no stage 'slip'"):
        stage_onset(ds, "slip")
    with pytest.raises(ValueError, match="window_s must be > 0"):
        onset_counts(ds, [0.1], 0.0)
