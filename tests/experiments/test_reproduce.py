"""The issue's reproduction targets (Tables II-III, Fig. 8), under both no-shear readings."""

import numpy as np
import pytest

from ddmm.experiments.paper.reproduce import FIG8_ANGLES, PROFILES, ReproConfig, reproduce_all, scene_sf
from ddmm.population.stimuli.scenes import birznieks, press_push_lift

TYPES = ("SAI", "RAI", "RAII")


@pytest.fixture(scope="module", params=["pass", "block"])
def result(request):
    return request.param, reproduce_all(ReproConfig(engine="direct", no_shear=request.param))


def test_json_shapes(result):
    _, res = result
    assert set(res) == {"table2", "table3", "fig8"}
    assert set(res["table2"]["prsi"]) == set(PROFILES)
    for p in PROFILES:
        assert set(res["table2"]["prsi"][p]) == set(TYPES)
        for t in TYPES:
            assert set(res["table3"]["sf"][p][t]) == {"75", "255"}
            assert list(res["fig8"]["sf"][p][t]) == [f"{a}" for a in FIG8_ANGLES]


def test_table2(result):
    _, res = result
    prsi = res["table2"]["prsi"]
    for t in TYPES:
        assert prsi["bipolar"][t] == 0.0 and prsi["cmm"][t] == 0.0
    for p in ("selective", "broad"):
        for t in ("SAI", "RAI"):
            assert 0.20 <= prsi[p][t] <= 0.70, (p, t, prsi[p][t])
    assert prsi["broad"]["SAI"] >= prsi["selective"]["SAI"]


def test_table3(result):
    reading, res = result
    sf = res["table3"]["sf"]
    for t in TYPES:
        assert sf["bipolar"][t]["75"] == sf["bipolar"][t]["255"]
        assert sf["cmm"][t]["75"] == sf["cmm"][t]["255"]
    ordered = TYPES if reading == "block" else ("SAI",)
    for p in ("selective", "broad"):
        for t in ordered:
            assert sf[p][t]["75"] > sf[p][t]["255"], (reading, p, t)
    assert 35 <= sf["cmm"]["SAI"]["75"] <= 60
    assert 5 <= sf["cmm"]["RAI"]["75"] <= 30 and 5 <= sf["cmm"]["RAII"]["75"] <= 30
    assert all(0 <= v <= 60 for p in sf for t in sf[p] for v in sf[p][t].values())
    contrast = {p: sf[p]["SAI"]["75"] - sf[p]["SAI"]["255"] for p in ("selective", "broad")}
    assert contrast["broad"] > contrast["selective"]


def test_fig8(result):
    _, res = result
    sf = res["fig8"]["sf"]
    for p in ("selective", "broad"):
        curve = {float(a): v for a, v in sf[p]["SAI"].items()}
        peak = max(curve, key=curve.get)
        assert abs(peak - 90.0) <= 15.0
    for t in TYPES:
        curve = {float(a): v for a, v in sf["bipolar"][t].items()}
        assert all(curve[a] == curve[(a + 180.0) % 360.0] for a in curve)


@pytest.mark.parametrize("scene,angles", [
    (birznieks(90.0), [0.0, 90.0, 180.0, 270.0]),
    (press_push_lift(90.0), [float(a) for a in FIG8_ANGLES]),
])
def test_engines_identical_on_reproduction_scenes(scene, angles):
    for reading in ("pass", "block"):
        _, a = scene_sf(scene, angles, ReproConfig(engine="direct", no_shear=reading))
        _, b = scene_sf(scene, angles, ReproConfig(engine="brian2", no_shear=reading))
        np.testing.assert_array_equal(a.afferent, b.afferent)
        np.testing.assert_array_equal(a.step, b.step)
