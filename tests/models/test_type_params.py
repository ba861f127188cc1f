"""Per-type parameter objects (`TypeParams`) in `CurrentParams`, and the one-release shim of the old flat fields."""

import dataclasses
import warnings

import pytest

from ddmm.models.afferent_types import AFFERENT_TYPES, afferent_type_info
from ddmm.models.current_params import LEGACY_FIELDS, CurrentParams
from ddmm.models.type_params import FIELDS, TypeParams
from ddmm.population.spec import load_spec, spec_from_dict


def test_defaults_are_each_types_declaration():
    params = CurrentParams()
    assert params.types == ()  # only departures are stored
    for kind in AFFERENT_TYPES:
        assert params.type_params(kind) == afferent_type_info(kind).current
    assert [params.gain(k) for k in ("SAI", "RAI", "RAII")] == [5.367, 11.036, 6.162]  # eqs 1-3, fitted


def test_with_type_changes_one_type_and_compares_by_value():
    params = CurrentParams().with_type("FA-I", gain=6.0, adapt=0.5)
    assert params.type_params("RAI").gain == 6.0 and params.type_params("RAI").tau_adapt_s == 0.1  # the rest kept
    assert params.type_params("SAI") == CurrentParams().type_params("SAI")
    assert params.with_type("RAI", gain=11.036, adapt=0.0) == CurrentParams()  # back to the defaults: equal
    assert hash(params) == hash(CurrentParams().with_type("RAI", gain=6.0, adapt=0.5))
    assert CurrentParams().with_all_types(excite_cv=0.3).excite_cv("SAII") == 0.3


@pytest.mark.parametrize("legacy", sorted(LEGACY_FIELDS))
def test_every_old_flat_field_still_works_with_a_warning(legacy):
    code, field = LEGACY_FIELDS[legacy]
    value = 0.5 if field not in ("order",) else 3
    with pytest.warns(DeprecationWarning, match=rf"CurrentParams\({legacy}=\).*TypeParams\({field}="):
        old = CurrentParams(**{legacy: value})
    assert old == CurrentParams().with_type(code, **{field: value})
    with pytest.warns(DeprecationWarning, match=rf"CurrentParams\.{legacy} is deprecated"):
        assert getattr(old, legacy) == value
    with pytest.warns(DeprecationWarning):  # dataclasses.replace goes through the same constructor
        assert dataclasses.replace(CurrentParams(), **{legacy: value}) == old


def test_the_old_flat_fields_map_onto_every_type_params_field_once():
    assert len(LEGACY_FIELDS) == 51 and len(set(LEGACY_FIELDS.values())) == 51  # the 54 old fields but 3 shared
    assert {field for _, field in LEGACY_FIELDS.values()} <= set(FIELDS)


def test_bad_values_name_the_field_as_written():
    with pytest.raises(ValueError, match=r"^gain must be a finite number > 0, got -1"):
        CurrentParams().with_type("SAI", gain=-1.0)
    with pytest.raises(ValueError, match=r"^g_sai must be a finite number > 0"), pytest.warns(DeprecationWarning):
        CurrentParams(g_sai=-1.0)
    with pytest.raises(TypeError, match="unexpected keyword argument 'g_toy'"):
        CurrentParams(g_toy=1.0)
    with pytest.raises(TypeError, match="'gian' is not a field of TypeParams"):
        CurrentParams().with_type("SAI", gian=1.0)
    with pytest.raises(ValueError, match="types='TOY' is not an afferent type"):
        CurrentParams(types={"TOY": TypeParams()})
    with pytest.raises(TypeError, match=r"types\['SAI'\] must be a TypeParams, got dict"):
        CurrentParams(types={"SAI": {"gain": 1.0}})


def test_a_spec_sets_a_type_in_its_own_table_from_the_types_defaults():
    spec = spec_from_dict({"name": "x", "region": {"center_mm": [0, 0], "semi_axes_mm": [5, 5]},
                           "types": {"RAI": {"count": 3}}, "current": {"cutoff_hz": 25.0, "FA-I": {"gain": 6.0}}})
    assert spec.current == CurrentParams(cutoff_hz=25.0).with_type("RAI", gain=6.0)
    with pytest.raises(ValueError, match=r"current\.FA-I\.gian: unknown key; allowed: gain, cutoff_hz"):
        spec_from_dict({"name": "x", "region": {"center_mm": [0, 0], "semi_axes_mm": [5, 5]},
                        "types": {"RAI": {"count": 3}}, "current": {"FA-I": {"gian": 6.0}}})


def test_the_old_flat_toml_keys_still_read_with_a_warning_in_the_files_terms():
    new = load_spec("fingertip")
    with warnings.catch_warnings(record=True) as caught:
        warnings.simplefilter("always")
        old = load_spec(str(__import__("pathlib").Path(__file__).parents[1] / "population" / "data"
                            / "fingertip_before.toml"))
    messages = {str(w.message) for w in caught if w.category is DeprecationWarning}
    assert "[current] g_sai is deprecated and will be removed in the next release; use [current.SAI] gain" in messages
    assert old.current.type_params("SAII") == new.current.type_params("SAII")  # unchanged since that preset


def test_the_calibration_writes_the_new_form_and_reads_it_back():
    from ddmm.experiments.calibration.presets import spec_to_toml

    spec = load_spec("fingertip")
    text = spec_to_toml(spec)
    assert "[current.SAI]" in text and "g_sai" not in text
    import tomllib

    with warnings.catch_warnings():
        warnings.simplefilter("error", DeprecationWarning)
        assert spec_from_dict(tomllib.loads(text)).current == spec.current
