"""Tuning statistics: the ANOVA criterion, DSI and preferred direction, on known populations."""

import numpy as np
import pytest

from ddmm.population import make_population, sample_population, simulate
from ddmm.population.analysis.tuning import _anova_p, direction_tuning, tuning_scenes, tuning_summary


@pytest.fixture(scope="module")
def known():
    # selective distal, selective radial, bipolar along Y, untuned; one with noise
    pop = make_population(["SAI", "SAI", "SAI", "SAI", "RAI"], [90.0, 0.0, 90.0, 0.0, 90.0],
                          ["selective", "selective", "bipolar", "none", "selective"], noise_sigma=[0, 0, 0, 0, 1.0])
    ds = simulate(pop, tuning_scenes(), engine="direct", trials=5, seed=4, quiet=True)
    return direction_tuning(ds)


def test_known_afferents(known):
    np.testing.assert_array_equal(known.tuned.values, [1, 1, 1, 0, 1])
    assert known.preferred_deg.values[0] == pytest.approx(90.0, abs=1.0)
    assert known.preferred_deg.values[1] == pytest.approx(0.0, abs=1.0) or known.preferred_deg.values[1] > 359.0
    np.testing.assert_array_equal(known.has_preferred.values[:4], [1, 1, 0, 0])
    assert known.dsi.values[0] > 0.3 and known.dsi.values[2] == pytest.approx(0.0, abs=1e-9)
    assert known.dsi.values[3] == 0.0 and known.p_loading.values[3] == 1.0


def test_anova_degenerate_and_regular_cases():
    same = np.full((5, 4, 1), 3.0)
    assert _anova_p(same)[0] == 1.0
    exact = np.repeat(np.arange(5.0)[:, None, None], 4, axis=1)
    assert _anova_p(exact)[0] == 0.0
    rng = np.random.default_rng(0)
    null = rng.poisson(10, size=(5, 5, 4000)).astype(float)
    assert np.mean(_anova_p(null) < 0.05) == pytest.approx(0.05, abs=0.015)  # calibrated per phase


def test_false_positive_rate_of_the_criterion_in_use():
    # The criterion is "tuned if either phase is significant": on null data it flags
    # 1 - 0.95^2 = 9.75% of afferents, not 5%; Bonferroni brings it to <= 5%.
    from ddmm.population.analysis.tuning import tuned_criterion
    rng = np.random.default_rng(1)
    p = np.stack([_anova_p(rng.poisson(10, size=(5, 5, 20000)).astype(float)) for _ in range(2)])
    assert np.mean(tuned_criterion(p)) == pytest.approx(0.0975, abs=0.006)
    assert np.mean(tuned_criterion(p, correction="bonferroni")) == pytest.approx(0.049, abs=0.005)


def test_summary_reports_absent_types(known):
    summary = tuning_summary(known)
    assert summary["tuned_fraction"]["RAII"] == "absent" and summary["dsi"]["RAII"] == "absent"
    assert summary["tuned_fraction"]["SAI"] == 0.75 and summary["n_responsive"]["RAI"] == 1


def test_fingertip_preset_meets_the_calibration_targets_over_five_seeds():
    from ddmm.experiments.calibration.presets import validate
    from ddmm.population import load_spec

    stats = validate(load_spec("fingertip"), scorecard=False)["mean_sd"]
    assert abs(stats["tuned_fraction.recorded"][0] - 0.86) <= 0.03  # held out: SA-I + SA-II + FA-I
    assert abs(stats["tuned_fraction.SAI"][0] - 0.93) <= 0.04
    assert abs(stats["tuned_fraction.RAI"][0] - 0.83) <= 0.04
    assert abs(stats["dsi.SAI.mean"][0] - 0.23) <= 0.03 and abs(stats["dsi.RAI.mean"][0] - 0.24) <= 0.03
    assert abs(stats["dsi.SAI.sd"][0] - 0.18) <= 0.05 and abs(stats["dsi.RAI.sd"][0] - 0.18) <= 0.05


def test_bad_input():
    pop = sample_population("fingertip", rng=0).select([0, 400])
    ds = simulate(pop, tuning_scenes(), engine="direct", trials=1, quiet=True)
    with pytest.raises(ValueError, match="2 trials"):
        direction_tuning(ds)
    ds2 = simulate(pop, tuning_scenes(), engine="direct", trials=2, quiet=True)
    with pytest.raises(ValueError, match="correction"):
        direction_tuning(ds2, correction="holm")
    with pytest.raises(ValueError, match="alpha"):
        direction_tuning(ds2, alpha=1.5)
