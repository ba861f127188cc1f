"""A spec that starts from a preset (``extends``), and the ``fingertip_vibration`` preset built that way."""

import dataclasses

import numpy as np
import pytest

from ddmm.models.afferent_types import normalize_type
from ddmm.population import sample_population
from ddmm.population.spec import PRESETS, load_spec, spec_from_dict
from ddmm.population.spec_parts import merge_tables


def _fields(spec):
    """Every leaf of a spec, by dotted path (dataclasses and dicts opened)."""
    out, todo = {}, [("", spec)]
    while todo:
        path, value = todo.pop()
        if dataclasses.is_dataclass(value):
            todo += [(f"{path}.{f.name}", getattr(value, f.name)) for f in dataclasses.fields(value)]
        elif isinstance(value, dict):
            todo += [(f"{path}.{k}", v) for k, v in value.items()]
        elif isinstance(value, tuple) and value and all(isinstance(v, tuple) and len(v) == 2 for v in value):
            todo += [(f"{path}.{k}", v) for k, v in value]
        else:
            out[path] = value
    return out


def _changed(a, b):
    fa, fb = _fields(a), _fields(b)
    return {k for k in set(fa) | set(fb) if fa.get(k, "<absent>") != fb.get(k, "<absent>")}


def test_vibration_preset_changes_three_constants_and_no_unit():
    base, vib = load_spec("fingertip"), load_spec("fingertip_vibration")
    assert "fingertip_vibration" in PRESETS
    moved = _changed(base, vib) - {".name", ".description"}
    # the neuron table is new in the variant: its RAI neuron is the type's own (paper) neuron but t_ref
    neuron = {k for k in moved if k.startswith(".neuron.RAI.")}
    assert moved - neuron == {".current.types.SAI.tau_s", ".current.types.RAI.tau_s"}
    assert vib.current.type_params("SAI").tau_s == 0.005 and vib.current.type_params("RAI").tau_s == 0.002
    assert vib.neuron["RAI"].t_ref == 0.002
    paper = dataclasses.replace(vib.neuron["RAI"], t_ref=0.0)
    assert paper == load_spec(spec_from_dict({"extends": "fingertip", "neuron": {"RAI": {}}})).neuron["RAI"]
    a, b = sample_population(base, rng=3), sample_population(vib, rng=3)
    for name in ("afferent_id", "theta_t", "x_mm", "gain", "k"):
        np.testing.assert_array_equal(getattr(a, name), getattr(b, name))


def test_extends_lays_keys_on_the_preset_in_either_type_spelling():
    spec = spec_from_dict({"extends": "fingertip", "current": {"SA-I": {"tau_s": 0.01}},
                           "types": {"FA-I": {"count": 10}}})
    base = load_spec("fingertip")
    assert spec.name == "custom" and "extends fingertip" in spec.description
    assert spec.current.type_params("SAI").tau_s == 0.01
    assert spec.current.type_params("SAI").gain == base.current.type_params("SAI").gain
    assert spec.n_afferents() == {**base.n_afferents(), "RAI": 10}
    assert spec.types["RAI"].theta_t == base.types["RAI"].theta_t


def test_extends_from_a_file_and_a_chain(tmp_path):
    path = tmp_path / "mine.toml"
    path.write_text('extends = "fingertip_vibration"\n[current.RAI]\ntau_s = 0.004\n', encoding="utf-8")
    spec = load_spec(path)
    assert spec.name == "mine"
    assert spec.current.type_params("RAI").tau_s == 0.004
    assert spec.current.type_params("SAI").tau_s == 0.005 and spec.neuron["RAI"].t_ref == 0.002


@pytest.mark.parametrize("value, match", [("fingertips", "extends: 'fingertips' is not a preset"),
                                          (3, "extends: 3 is not a preset")])
def test_extends_refuses_what_is_not_a_preset(value, match):
    with pytest.raises(ValueError, match=match):
        spec_from_dict({"extends": value})


def test_merge_tables_replaces_region_by_map_and_merges_tables():
    base = {"region": {"center_mm": [0, 0]}, "current": {"cutoff_hz": 20.0, "SAI": {"gain": 1.0, "tau_s": 0.1}}}
    over = {"map": {"name": "hand"}, "current": {"SA-I": {"gain": 2.0}}}
    out = merge_tables(base, over, normalize_type)
    assert "region" not in out and out["map"] == {"name": "hand"}
    assert out["current"] == {"cutoff_hz": 20.0, "SAI": {"gain": 2.0, "tau_s": 0.1}}
    assert base["current"]["SAI"]["gain"] == 1.0  # the base is not changed in place
