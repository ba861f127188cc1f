"""The tilted-load protocols (`ddmm.population.analysis.physiology_tilt`): registered, analytic, and measuring."""

from dataclasses import replace

import numpy as np
import pytest

from ddmm.population import sample_population
from ddmm.population.analysis import physiology, physiology_tilt
from ddmm.population.analysis.physiology_tilt import tilt_fractions, tilt_scene
from ddmm.population.data.published import PHYSIOLOGY_REFERENCE

NAMES = list(physiology_tilt.PROPERTIES)


def test_rows_are_registered_with_references_half_held_out():
    assert set(NAMES) <= set(physiology.PROPERTIES)
    assert set(physiology_tilt.PROTOCOLS) <= set(physiology.PROTOCOLS)
    roles = [PHYSIOLOGY_REFERENCE[n].role for n in NAMES]
    assert roles.count("held out") * 2 >= len(roles)


def test_a_tilt_scene_tilts_the_resultant_toward_its_direction():
    scene = tilt_scene(4.0, 20.0, 135.0)
    hold = slice(500, None)
    tangential = np.hypot(scene.fx[hold], scene.fy[hold])
    np.testing.assert_allclose(np.degrees(np.arctan2(tangential, scene.fz[hold])), 20.0)
    np.testing.assert_allclose(np.degrees(np.arctan2(scene.fy[hold], scene.fx[hold])), 135.0)
    assert scene.fz[100] == 0.0 and scene.fz[150] == pytest.approx(1.0)  # 20 N/s from 0.1 s


def test_fractions_count_only_units_that_respond_to_the_normal_load():
    out = tilt_fractions([4.0, 0.0, 10.0, 10.0], [[4.5, 9.0, 11.5, 10.0], [3.0, 1.0, 0.0, 10.5]])
    assert out["units"] == 3
    assert out["above_10pct"] == pytest.approx(2 / 3)  # 4.5 > 4.4, 11.5 > 11; 10.5 is not 10% above 10
    assert out["silenced_worst"] == pytest.approx(1 / 3) and out["halved_worst"] == pytest.approx(1 / 3)
    assert out["median_best_over_normal"] == pytest.approx(1.125)
    assert tilt_fractions([0.0, 0.0], [[1.0, 2.0]])["above_10pct"] is None


@pytest.fixture(scope="module")
def few():
    pop = sample_population("fingertip", rng=3)
    kinds = np.asarray(pop.afferent_type)
    keep = np.concatenate([np.flatnonzero(kinds == k)[::n] for k, n in (("SAI", 4), ("RAI", 10), ("SAII", 2))])
    return pop.select(np.sort(keep))


def _values(pop):
    rows, _ = physiology.score_physiology(pop, PHYSIOLOGY_REFERENCE, properties=NAMES, seed=3)
    return {r["name"]: (r["value"], r["pass"]) for r in rows}


def test_preset_passes_and_the_papers_attenuation_alone_fails(few):
    values = _values(few)
    assert all(ok for _, ok in values.values()), values
    paper = few.current.with_type("SAI", depth=1.0, shear=0.0, opponent_shear=0.0)
    values = _values(replace(few, current=paper))
    assert not values["tilt_above_SAI"][1] and not values["tilt_variant_above_SAI"][1], values
