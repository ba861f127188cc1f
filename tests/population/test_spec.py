"""Population specs: presets, TOML, and every bad-spec error named."""

import pytest

from ddmm.population.data.published import TOUCHSIM_COUNTS
from ddmm.population.anatomy import hand_map
from ddmm.population.spec import load_spec, spec_from_dict


def test_fingertip_has_touchsim_counts_plus_sa2_at_the_row_16_ratio():
    counts = load_spec("fingertip").n_afferents()
    assert {k: counts[k] for k in ("SAI", "RAI", "RAII")} == TOUCHSIM_COUNTS["fingertip"]
    assert counts["SAII"] == round(TOUCHSIM_COUNTS["fingertip"]["SAI"] * 9 / 70)  # SA-II 9 vs SA-I 70 per cm^2


def test_hand_preset_is_the_hand_map():
    spec = load_spec("hand")
    assert spec.map is not None and spec.map.region_names() == hand_map.region_names()
    by_region = hand_map.region_counts()
    assert spec.n_afferents() == {t: sum(c[t] for c in by_region.values()) for t in hand_map.TYPES}
    assert sum(spec.n_afferents().values()) == 12584


def test_density_gives_count_over_region():
    spec = spec_from_dict({"region": {"semi_axes_mm": [10.0, 10.0]},
                           "types": {"SAI": {"density_per_cm2": 70.0}}})
    assert spec.n_afferents() == {"SAI": round(70.0 * 3.14159265 * 100 / 100)}


def test_toml_file_roundtrip(tmp_path):
    path = tmp_path / "mine.toml"
    path.write_text('[types.RAI]\ncount = 5\nnap = { selective = 0.5, none = 0.5 }\n'
                    '[types.RAI.sharpness.selective]\ndistribution = "fixed"\nof = "theta_a"\nvalue = 30.0\n')
    spec = load_spec(path)
    assert spec.name == "mine" and spec.n_afferents() == {"RAI": 5}


BAD = [
    ({"types": {"SAI": {"count": 3, "colour": "red"}}}, "types.SAI.colour"),
    ({"typos": {}}, "typos"),
    ({"types": {"SAI": {"count": -1}}}, "count"),
    ({"types": {"SAI": {"count": 3, "nap": {"selective": 0.5, "none": 0.4}}}}, "sum to 1"),
    ({"types": {"SAI": {"count": 3, "theta_t": {"distribution": "cauchy"}}}}, "cauchy"),
    ({"types": {"SAI": {"count": 3, "sharpness": {"broad": {"distribution": "gamma"}}}}}, "gamma"),
    ({"types": {"SAIII": {"count": 3}}}, "SAIII"),
    ({"types": {"SAI": {"count": 3, "nap": {"round": 1.0}}}}, "round"),
    ({"types": {"SAI": {"count": 3, "density_per_cm2": 5.0}}}, "exactly one"),
    ({"types": {}}, "types"),
    ({"types": {"SAI": {"count": 3}}, "region": {"semi_axes_mm": [0.0, 3.0]}}, "semi_axes_mm"),
    ({"types": {"SAI": {}}}, "types.SAI.count"),
    ({"types": {"SAI": {"count": 3}}, "region": {"name": "D9d"}}, "region.name"),
    ({"types": {"SAI": {}}, "map": {"name": "foot"}}, "map.name"),
    ({"types": {"SAI": {}}, "map": {"regions": ["D2d", "elbow"]}}, "map.regions.*elbow"),
    ({"types": {"SAI": {}}, "map": {"regions": "D2d"}}, "map.regions"),
    ({"types": {"SAI": {}}, "map": {"shape": "ellipse"}}, "map.shape"),
    ({"types": {"SAI": {"count": 3}}, "map": {}}, "types.SAI.count.*map"),
    ({"types": {"SAI": {"density_per_cm2": 3.0}}, "map": {}}, "types.SAI.count.*map"),
    ({"types": {"SAI": {}}, "map": {}, "region": {}}, "region.*map"),
]


def test_map_subset_counts_and_fingertip_region_name():
    spec = spec_from_dict({"types": {"SAI": {}, "SAII": {}}, "map": {"regions": ["D3d", "D2d"]}})
    assert spec.map.region_names() == ("D2d", "D3d")  # map order
    counts = hand_map.region_counts(regions=["D2d", "D3d"])
    assert spec.n_afferents() == {t: counts["D2d"][t] + counts["D3d"][t] for t in ("SAI", "SAII")}
    assert load_spec("fingertip").region.name == "D2d" and load_spec("fingertip").region.frame_deg == 0.0


@pytest.mark.parametrize("data,match", BAD)
def test_bad_specs_name_the_problem(data, match):
    with pytest.raises(ValueError, match=match):
        spec_from_dict(data)


def test_bad_files(tmp_path):
    with pytest.raises(ValueError, match="preset"):
        load_spec("wrist")
    with pytest.raises(ValueError, match="cannot be read"):
        load_spec(tmp_path / "missing.toml")
    bad = tmp_path / "bad.toml"
    bad.write_text("[types.SAI\ncount = 3")
    with pytest.raises(ValueError, match="not valid TOML"):
        load_spec(bad)


def test_presets_are_parsed_once_but_handed_out_as_copies():
    """`load_spec` caches each preset; a caller that edits its spec's dicts must not change the next load."""
    first = load_spec("hand")
    first.types["SAI"].nap["broad"] = 0.99
    first.types.clear()
    again = load_spec("hand")
    assert len(again.types) == 4 and again.types["SAI"].nap["broad"] != 0.99
