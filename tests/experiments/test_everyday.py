"""The everyday-touch protocols (`ddmm.experiments.validation.everyday`): scenes, criteria and a small run."""

import numpy as np
import pytest

from ddmm.experiments.validation import everyday
from ddmm.population import sample_population


def test_press_scene_ramps_holds_and_releases_at_its_rates():
    scene, windows = everyday.press_scene(4.0, 8.0)
    assert scene.fz.max() == pytest.approx(2.0)
    on, off = windows["on"], windows["off"]
    assert on == pytest.approx((0.2, 0.2 + 0.5 + 0.1)) and off[1] - off[0] == pytest.approx(0.25 + 0.1)
    slope = np.diff(scene.fz) * scene.fs
    assert slope.max() == pytest.approx(4.0) and slope.min() == pytest.approx(-8.0)


def test_the_crossing_is_log_interpolated_between_rates():
    fractions = [0.0, 0.0, 0.0, 0.5, 1.0, 1.0, 1.0]  # 0.5 reached at 4 N/s, 1.0 at 8 N/s
    assert everyday.crossing_rate(fractions, 0.5) == pytest.approx(4.0)
    assert everyday.crossing_rate(fractions, 0.75) == pytest.approx(np.sqrt(4.0 * 8.0))
    assert np.isnan(everyday.crossing_rate([0.0] * 7, 0.1))


def test_fires_means_a_spike_in_half_the_trials():
    counts = np.array([[1, 0, 0], [0, 0, 2], [1, 0, 0], [0, 0, 1]])  # 4 trials x 3 afferents
    assert everyday.fires(counts).tolist() == [True, False, True]


def test_a_small_population_gives_fractions_and_thresholds():
    full = sample_population("fingertip", rng=7)
    of = {t: np.flatnonzero(full.afferent_type == t) for t in ("RAI", "RAII")}
    pop = full.select(np.r_[of["RAI"][:3], of["RAII"][:1]])
    table = everyday.release_table(pop, seed=7, afferent_types=("RAI",))
    assert set(table) == {"RAI"} and set(table["RAI"]) == {f"{r:g}" for r in everyday.RELEASE_RATES}
    assert all(0.0 <= row["fires_off"] <= 1.0 for row in table["RAI"].values())
    assert table["RAI"]["40"]["fires_off"] == 1.0  # a fast release always excites FA-I
    thresholds = everyday.vibration_thresholds(pop, 7, "RAII", 250.0)
    assert thresholds.shape == (1,) and 0.0 < thresholds[0] < 0.3
