"""Sampling: reproducible, distributions honoured, ids stable."""

import numpy as np
import pytest

from ddmm.models.nap import selectivity_from_k
from ddmm.population.sampling import make_population, sample_population
from ddmm.population.spec import load_spec, spec_from_dict


def test_same_seed_same_population_and_different_seed_differs():
    a, b, c = (sample_population("fingertip", rng=s) for s in (3, 3, 4))
    for name in ("theta_t", "k", "gain", "x_mm", "nap"):
        np.testing.assert_array_equal(getattr(a, name), getattr(b, name))
    assert not np.array_equal(a.theta_t, c.theta_t)


def test_nap_fractions_are_exact_and_k_valid():
    pop = sample_population("fingertip", rng=0)
    fractions = load_spec("fingertip").types["SAI"].nap
    sai = pop.nap[pop.afferent_type == "SAI"]
    counts = {n: int(np.sum(sai == n)) for n in fractions}
    assert sum(counts.values()) == 282
    assert all(abs(counts[n] - 282 * f) < 1 for n, f in fractions.items())  # largest-remainder apportionment
    assert np.all(pop.k[pop.nap == "none"] == 0.0)
    sel = selectivity_from_k(pop.k[pop.nap == "selective"], "selective")
    assert sel.min() >= 20.0 - 1e-9 and sel.max() <= 50.0 + 1e-9


def test_preferred_direction_biases():
    spec = load_spec("hand")
    pop = sample_population(spec, rng=1)
    for kind, expected in (("SAI", 90.0),):
        th = np.deg2rad(pop.theta_t[pop.afferent_type == kind])
        mean = np.rad2deg(np.arctan2(np.sin(th).mean(), np.cos(th).mean())) % 360
        assert abs(mean - expected) < 10.0
    rai = np.deg2rad(pop.theta_t[pop.afferent_type == "RAI"])
    assert np.mean(np.cos(rai)) > 0.1 and np.mean(np.sin(rai)) < -0.1  # toward radial (+X) and proximal (-Y)


def test_positions_inside_region_and_gain_spread():
    pop = sample_population("fingertip", rng=2)
    (a, b) = load_spec("fingertip").region.semi_axes_mm
    assert np.all((pop.x_mm / a) ** 2 + (pop.y_mm / b) ** 2 <= 1.0 + 1e-12)
    assert pop.gain.mean() == pytest.approx(1.0, abs=0.05)
    assert pop.gain.std() / pop.gain.mean() == pytest.approx(0.3, abs=0.05)


def test_angle_distributions():
    def spec(theta):
        return spec_from_dict({"types": {"SAI": {"count": 8, "theta_t": theta}}})
    assert np.all(sample_population(spec({"distribution": "fixed", "value_deg": 370.0}), 0).theta_t == 10.0)
    listed = sample_population(spec({"distribution": "list", "values_deg": [0.0, 90.0]}), 0).theta_t
    np.testing.assert_array_equal(listed, [0, 90] * 4)


def test_select_keeps_ids_and_make_population_validates():
    pop = sample_population("fingertip", rng=0)
    sub = pop.select(np.array([5, 700]))
    np.testing.assert_array_equal(sub.afferent_id, [5, 700])
    assert not sub.k.flags.writeable and len(pop.select(slice(10, 20))) == 10
    assert len(pop.select(pop.afferent_type == "SAII")) == 36
    for repeated in ([3, 3], [0, -len(pop)]):  # select skips the element checks, not this one
        with pytest.raises(ValueError, match="repeats an afferent"):
            pop.select(repeated)
    with pytest.raises(ValueError, match="k="):
        make_population(["SAI"], nap="broad", k=1.0)
    with pytest.raises(ValueError, match="afferent_type"):
        make_population(["SAIII"])


def test_sampling_does_not_depend_on_the_hash_seed():
    import subprocess
    import sys
    code = "from ddmm.population import sample_population; print(sample_population('fingertip', rng=0).k.sum().hex())"
    outs = {subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, check=True,
                           env={**__import__("os").environ, "PYTHONHASHSEED": str(h)}).stdout for h in (1, 2, 3)}
    assert len(outs) == 1
