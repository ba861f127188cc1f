"""The tilted-load and SA-I peak command (`ddmm.experiments.validation.tilt`): a small run (the scenes and
fractions are tested with `ddmm.population.analysis.physiology_tilt`)."""

import numpy as np
import pytest

from ddmm.experiments.validation.tilt import peak_table, tilt_table
from ddmm.population import sample_population


@pytest.fixture(scope="module")
def few():
    pop = sample_population("fingertip", rng=7)
    kinds = np.asarray(pop.afferent_type)
    keep = np.concatenate([np.flatnonzero(kinds == k)[:n] for k, n in (("SAI", 30), ("RAI", 30), ("SAII", 12))])
    return pop.select(np.sort(keep))


def test_tangential_load_adds_to_sa_ii_and_the_table_is_fractions(few):
    table = tilt_table(few, 4.0, directions=6, seed=7)
    assert set(table) == {"SAI", "SAII", "RAI"}
    for row in table.values():
        assert all(0.0 <= row[k] <= 1.0 for k in ("above_10pct", "halved_worst", "silenced_worst"))
    assert table["SAII"]["median_best_over_normal"] > 1.2  # stretch drives SA-II: 1.43 on the whole fingertip


def test_sa_i_plateaus_code_force_not_loading_rate(few):
    table = peak_table(few, rates_n_s=(4.0, 32.0), seed=7)
    plateau = {key: row["median_plateau"] for key, row in table.items()}
    assert plateau["4 N at 4 N/s"] > plateau["2 N at 4 N/s"]
    assert plateau["2 N at 32 N/s"] == pytest.approx(plateau["2 N at 4 N/s"], rel=0.2)
    assert table["2 N at 32 N/s"]["median_peak"] > table["2 N at 4 N/s"]["median_peak"]
