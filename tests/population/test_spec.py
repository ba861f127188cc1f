"""Population specs: presets, TOML, and every bad-spec error named."""

import pytest

from experiments.reference import TOUCHSIM_COUNTS
from population.spec import load_spec, spec_from_dict


@pytest.mark.parametrize("name", ["fingertip", "hand"])
def test_presets_have_touchsim_counts_plus_sa2_at_the_row_16_ratio(name):
    counts = load_spec(name).n_afferents()
    assert {k: counts[k] for k in ("SAI", "RAI", "RAII")} == TOUCHSIM_COUNTS[name]
    assert counts["SAII"] == round(TOUCHSIM_COUNTS[name]["SAI"] * 9 / 70)  # SA-II 9 vs SA-I 70 per cm^2


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
]


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
