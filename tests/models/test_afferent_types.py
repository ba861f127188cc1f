"""The afferent-type registry (`ddmm.models.afferent_types`), and the model path asking it instead of comparing codes."""

import ast
import sys
from pathlib import Path

import numpy as np
import pytest

from ddmm.models import afferent_types as registry
from ddmm.models.afferent_types import (
    AFFERENT_TYPES,
    PAPER_TYPES,
    TYPE_LABELS,
    AfferentType,
    afferent_type_codes,
    afferent_type_info,
    normalize_type,
    register_afferent_type,
    type_label,
    type_mask,
)

ROOT = Path(__file__).resolve().parents[2]
#: The model path: where a type's behaviour is decided.  Protocol selections (population/analysis/physiology_*)
#: and parameter tables keyed by code (NEURON_PARAMS, the anatomy's shares) are not in it.
MODEL_PATH = ("models", "population/runtime", "population/simulation.py", "population/dataset.py")
DEFINITIONS = ROOT / "models" / "afferent_types.py"


@pytest.fixture
def scratch_registry(monkeypatch):
    """A copy of the registry for one test: a toy type registered in it goes away after."""
    monkeypatch.setattr(registry, "_REGISTRY", dict(registry._REGISTRY))
    monkeypatch.setattr(registry, "_CODE_OF", dict(registry._CODE_OF))


def test_the_constants_are_the_registry_views():
    assert AFFERENT_TYPES == ("SAI", "RAI", "RAII", "SAII") == afferent_type_codes()
    assert PAPER_TYPES == ("SAI", "RAI", "RAII") == afferent_type_codes("in_paper")
    assert TYPE_LABELS == {"SAI": "SA-I", "RAI": "FA-I", "RAII": "FA-II", "SAII": "SA-II"}


def test_the_package_types_declare_their_mechanisms():
    assert {t: afferent_type_info(t).derivative_order for t in AFFERENT_TYPES} == \
        {"SAI": 0, "RAI": 1, "RAII": 2, "SAII": 0}
    assert afferent_type_codes("stretch_drive") == afferent_type_codes("phase_spread") == ("SAII",)
    assert afferent_type_codes(lambda t: not t.log_compression) == ("SAII",)
    assert afferent_type_codes("shared_cutoff") == ("RAI", "RAII")
    assert afferent_type_codes(lambda t: t.fs_per_cutoff is not None) == ("RAII",)
    assert afferent_type_codes("recorded_by_humans") == ("SAI", "RAI", "SAII")


@pytest.mark.parametrize("spelling,code", [("SA1", "SAI"), ("fa-i", "RAI"), ("RA 1", "RAI"), ("FA2", "RAII"),
                                           ("ra_ii", "RAII"), ("SA-II", "SAII"), ("sa2", "SAII")])
def test_every_old_spelling_still_normalizes(spelling, code):
    assert normalize_type(spelling) == code


def test_a_registered_type_appears_in_every_view(scratch_registry):
    toy = register_afferent_type(AfferentType("MERK", "Toy-M", ("TM1",), "tab:brown", recorded_by_humans=True,
                                              derivative_order=1, stretch_drive=True, fs_per_cutoff=3.0))
    assert afferent_type_codes()[-1] == "MERK" and afferent_type_info("toy-m") is toy
    assert normalize_type("tm1") == normalize_type("TOY_M") == "MERK" and type_label("MERK") == "Toy-M"
    assert "MERK" in afferent_type_codes("stretch_drive") and "MERK" in afferent_type_codes("recorded_by_humans")
    assert "MERK" not in afferent_type_codes("in_paper")
    assert type_mask(np.array(["SAI", "MERK", "SAII"]), "stretch_drive").tolist() == [False, True, True]
    with pytest.raises(ValueError, match="afferent_type='XYZ'.*MERK"):
        normalize_type("XYZ")


def test_register_refuses_a_duplicate_a_taken_spelling_and_a_non_type(scratch_registry):
    with pytest.raises(ValueError, match="kind: afferent type 'SAI' is already registered"):
        register_afferent_type(AfferentType("SAI", "Other"))
    with pytest.raises(ValueError, match="spelling 'FAI' of 'NEW' already names 'RAI'"):
        register_afferent_type(AfferentType("NEW", "FA-I"))
    with pytest.raises(TypeError, match="kind must be an AfferentType"):
        register_afferent_type("NEW")
    assert "NEW" not in afferent_type_codes()


@pytest.mark.parametrize("name,value", [("code", "sa3"), ("label", ""), ("spellings", "X"), ("derivative_order", 3),
                                        ("fs_per_cutoff", 1.5)])
def test_an_afferent_type_checks_its_fields(name, value):
    with pytest.raises((TypeError, ValueError), match=name):
        AfferentType(**{"code": "NEW", "label": "New", name: value})


def test_the_views_refuse_an_unknown_field():
    with pytest.raises(ValueError, match="where='stretch'"):
        afferent_type_codes("stretch")
    with pytest.raises(TypeError, match="where"):
        afferent_type_codes(5)


@pytest.mark.parametrize("kind", AFFERENT_TYPES)
def test_the_current_stage_follows_each_declaration(kind):
    from ddmm.models.current_filters import check_fs
    from ddmm.models.current_params import CurrentParams

    info, params = afferent_type_info(kind), CurrentParams(i_sat=3.0, cutoff_hz=30.0)
    st = params.for_type(kind)
    assert st.derivative == info.derivative_order and st.signed == info.stretch_drive
    assert (st.i_sat == 3.0) == info.log_compression and (st.i_sat is None) != info.log_compression
    own = params.type_params(kind).cutoff_hz
    assert st.cutoff_hz == (own or 30.0 if info.shared_cutoff else own)
    factor = info.fs_per_cutoff or 2.0
    check_fs(factor * 30.0 * 1.01, params, (kind,))  # just fast enough
    if st.cutoff_hz == 30.0:
        with pytest.raises(ValueError, match=f"too slow for {kind}"):
            check_fs(factor * 30.0 * 0.99, params, (kind,))


def test_the_plots_and_the_tuning_read_the_registry():
    from ddmm.experiments.plots.common import TYPE_COLOURS
    from ddmm.population.analysis.tuning import RECORDED_TYPES

    assert TYPE_COLOURS == {t: afferent_type_info(t).colour for t in AFFERENT_TYPES}
    assert len(set(TYPE_COLOURS.values())) == len(AFFERENT_TYPES)
    assert set(RECORDED_TYPES) == {"SAI", "RAI", "SAII"}


def _is_code(node) -> bool:
    if not (isinstance(node, ast.Constant) and isinstance(node.value, str)):
        return False
    try:
        normalize_type(node.value)
    except ValueError:
        return False
    return True


def _lists_code(node) -> bool:
    return _is_code(node) or (isinstance(node, (ast.Tuple, ast.List, ast.Set)) and any(map(_is_code, node.elts)))


def _type_code_offences(path: Path) -> list:
    """Where ``path`` decides by a type code: a comparison with one (``== "SAII"``, ``in ("RAI", "RAII")``), a
    loop over a literal list of them, a literal listing two or more, or a ``case "SAI":``."""
    found = set()
    for node in ast.walk(ast.parse(path.read_text())):
        if isinstance(node, ast.Compare):
            hit = any(map(_lists_code, (node.left, *node.comparators)))
        elif isinstance(node, (ast.For, ast.comprehension)):
            hit = _lists_code(node.iter)
        elif isinstance(node, (ast.Tuple, ast.List, ast.Set)):
            hit = sum(map(_is_code, node.elts)) >= 2
        else:
            hit = isinstance(node, ast.MatchValue) and _is_code(node.value)
        if hit:
            found.add(getattr(node, "lineno", None) or node.iter.lineno)
    return [f"{path.relative_to(ROOT)}:{line}" for line in sorted(found)]


def _model_path_files() -> list:
    files = []
    for part in MODEL_PATH:
        where = ROOT / part
        files += sorted(where.rglob("*.py")) if where.is_dir() else [where]
    return [f for f in files if f != DEFINITIONS]


def test_no_type_code_comparison_in_the_model_path():
    """A type's behaviour is declared on its `AfferentType`; the model path asks the registry
    (`afferent_type_info`, `afferent_type_codes`, `type_mask`) and never compares a code.

    Naming one type to use (``for_type("RAI")``) is allowed; models/afferent_types.py is exempt.
    """
    files = _model_path_files()
    assert len(files) > 30 and ROOT / "population" / "runtime" / "plan.py" in files
    offenders = [hit for path in files for hit in _type_code_offences(path)]
    assert not offenders, offenders


def test_the_type_code_check_catches_each_form(tmp_path, monkeypatch):
    monkeypatch.setattr(sys.modules[__name__], "ROOT", tmp_path)
    (tmp_path / "m.py").write_text(
        'if kind == "SAII":\n    pass\n'  # 1
        'ok = kind in ("RAI", "RAII")\n'  # 3
        'bad = t != "FA-I"\n'  # 4
        'for k in ("SAI",):\n    pass\n'  # 5
        'x = [k for k in ["RAI"]]\n'  # 7
        'PRESSURE = ("SAI", "RAI")\n'  # 8
        'match kind:\n    case "SAII":\n        pass\n'  # 10
        'fine = params.for_type("RAI")\nalso = {"SAI": 1}\nname = "pass" == mode\n')
    assert _type_code_offences(tmp_path / "m.py") == [f"m.py:{n}" for n in (1, 3, 4, 5, 7, 8, 10)]


def _code_equalities(path: Path) -> list:
    """Where ``path`` tests a value for equality with a type code (``== "SAI"``, ``!= "RAII"``)."""
    found = []
    for node in ast.walk(ast.parse(path.read_text())):
        if isinstance(node, ast.Compare) and any(isinstance(op, (ast.Eq, ast.NotEq)) for op in node.ops) \
                and any(map(_is_code, (node.left, *node.comparators))):
            found.append(f"{path.relative_to(ROOT)}:{node.lineno}")
    return found


def test_no_equality_with_a_type_code_anywhere_in_the_package():
    """Outside the type definitions no module tests ``== "<type>"``: behaviour asks the registry, and a protocol
    selects its units with `is_type` (which takes any spelling)."""
    files = [p for part in ("ddmm", "models", "population", "experiments") for p in sorted((ROOT / part).rglob("*.py"))
             if p != DEFINITIONS]
    assert len(files) > 100
    offenders = [hit for path in files for hit in _code_equalities(path)]
    assert not offenders, offenders
