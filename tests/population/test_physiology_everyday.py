"""The scorecard's everyday-touch protocols (`ddmm.population.analysis.physiology_everyday`)."""

import dataclasses

import numpy as np
import pytest

from ddmm.population import sample_population
from ddmm.population.analysis import physiology_everyday as every
from ddmm.population.analysis.physiology import score_physiology
from ddmm.population.data.published import PHYSIOLOGY_REFERENCE

CONTEXT = {"seed": 3, "engine": "direct", "no_shear": "smooth"}


def test_press_scene_ramps_holds_and_releases_at_its_rates():
    scene, windows = every.press_scene(4.0, 8.0, force_n=3.0, hold_s=0.5)
    slope = np.diff(scene.fz) * scene.fs
    assert scene.fz.max() == pytest.approx(3.0) and slope.max() == pytest.approx(4.0)
    assert slope.min() == pytest.approx(-8.0)
    assert windows["on"] == pytest.approx((0.2, 0.95 + 0.1)) and windows["off"] == pytest.approx((1.45, 1.825 + 0.1))


def test_crossing_rate_and_fires():
    assert every.crossing_rate([0.0, 0.2, 1.0], 0.6, rates=(1.0, 2.0, 8.0)) == pytest.approx(4.0)
    assert every.crossing_rate([0.5, 1.0], 0.1, rates=(1.0, 2.0)) == 1.0  # already above at the first rate
    assert every.fires(np.array([[1, 0], [0, 0], [2, 0], [0, 1]])).tolist() == [True, False]


def test_threshold_spread_counts_units_without_a_threshold():
    spread = every.threshold_spread(np.array([1.0, 2.0, 4.0, np.inf]))
    assert spread["responding"] == 0.75 and spread["q90_over_q10"] == pytest.approx(3.6 / 1.2)


@pytest.fixture(scope="module")
def small():
    """12 FA-I and 6 FA-II of the fingertip (seed 3, never fitted on), with and without their spread."""
    full = sample_population("fingertip", rng=3)
    pick = np.r_[np.flatnonzero(full.afferent_type == "RAI")[::48], np.flatnonzero(full.afferent_type == "RAII")[::17]]
    pop = full.select(pick)
    return pop, dataclasses.replace(pop, sensitivity=np.ones(len(pop)))


def test_units_that_differ_spread_their_vibration_thresholds_and_equal_ones_do_not(small):
    spread, same = small
    fa1 = lambda p: p.select(p.afferent_type == "RAI")  # noqa: E731
    wide = every.threshold_spread(every.vibration_thresholds(fa1(spread), CONTEXT, 40.0))
    narrow = every.threshold_spread(every.vibration_thresholds(fa1(same), CONTEXT, 40.0))
    assert wide["q90_over_q10"] >= 3.0 and narrow["q90_over_q10"] <= 2.0  # 12 units: a small sample


def test_the_everyday_rows_are_measured_and_labelled(small):
    spread, _ = small
    names = [n for n, p in every.PROPERTIES.items()]
    rows, _ = score_physiology(spread, PHYSIOLOGY_REFERENCE, properties=names, seed=3)
    assert [r["name"] for r in rows] == names and all(np.isfinite(r["value"]) for r in rows)
    roles = [r["role"] for r in rows]
    assert roles.count("held out") >= roles.count("constrained")  # at least half of the new rows held out
    release = {r["name"]: r["value"] for r in rows}
    assert release["release_4Ns_RAI"] >= release["release_2Ns_RAI"]
