"""Fuzzed files: every reader returns a valid object or raises ValueError / TypeError naming the file, never
anything else (a KeyError, an IndexError, a RecursionError, h5py's OSError)."""

import io
import warnings

import numpy as np
import pytest
from hypothesis import HealthCheck, given, settings
from hypothesis import strategies as st

from ddmm.population import from_array, from_long_csv, load_spec
from ddmm.population.stimuli.recordings import from_csv

_FUZZ = settings(max_examples=120, deadline=None, suppress_health_check=[HealthCheck.function_scoped_fixture])
_CELL = st.one_of(st.sampled_from(["0", "1", "-1", "0.001", "1e3", "nan", "inf", "1_0", "", " ", "x", "1e400",
                                   "time", "fz", "Fz", "3.5", "-0.2"]), st.text(max_size=6))


def _csv_text(rows):
    return "\n".join(",".join(r) for r in rows) + "\n"


@_FUZZ
@given(header=st.lists(st.sampled_from(["time", "fx", "fy", "fz", "Time", "FZ", "t", ""]), min_size=0, max_size=5),
       rows=st.lists(st.lists(_CELL, min_size=0, max_size=5), max_size=8))
def test_scene_csv_reader(tmp_path_factory, header, rows):
    path = tmp_path_factory.mktemp("csv") / "f.csv"
    path.write_text(_csv_text([header] + rows))
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        try:
            scene = from_csv(path)
        except (ValueError, TypeError) as exc:
            assert "f.csv" in str(exc) or "column" in str(exc) or "fs" in str(exc), exc
            return
    assert np.all(np.isfinite(scene.fz)) and np.all(scene.fz >= 0)


@_FUZZ
@given(rows=st.lists(st.lists(_CELL, min_size=0, max_size=5), max_size=8), sites=st.lists(
    st.lists(_CELL, min_size=0, max_size=4), max_size=4))
def test_long_csv_reader(tmp_path_factory, rows, sites):
    d = tmp_path_factory.mktemp("long")
    (d / "f.csv").write_text(_csv_text([["time", "site", "fx", "fy", "fz"]] + rows))
    (d / "s.csv").write_text(_csv_text([["site", "x_mm", "y_mm"]] + sites))
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        try:
            from_long_csv(d / "f.csv", d / "s.csv")
        except (ValueError, TypeError):
            pass


_TOML = st.recursive(st.one_of(st.integers(-10, 10**8), st.floats(allow_nan=True), st.text(max_size=5),
                               st.booleans()),
                     lambda inner: st.one_of(st.lists(inner, max_size=3), st.dictionaries(
                         st.sampled_from(["count", "nap", "SAI", "RAI", "types", "region", "gain", "x", "name"]),
                         inner, max_size=3)), max_leaves=12)


def _toml_value(value):
    if isinstance(value, bool):
        return "true" if value else "false"
    if isinstance(value, (int, float)):
        return repr(float(value)) if isinstance(value, float) and not np.isfinite(value) is False else repr(value)
    if isinstance(value, str):
        return '"' + value.encode("unicode_escape").decode().replace('"', '\\"') + '"'
    if isinstance(value, list):
        return "[" + ", ".join(_toml_value(v) for v in value) + "]"
    return "{" + ", ".join(f"{k} = {_toml_value(v)}" for k, v in value.items()) + "}"


@_FUZZ
@given(doc=st.dictionaries(st.sampled_from(["name", "types", "region", "current", "neuron", "map", "extra"]), _TOML,
                           max_size=4), raw=st.text(max_size=40))
def test_spec_reader(tmp_path_factory, doc, raw):
    d = tmp_path_factory.mktemp("toml")
    for i, text in enumerate(("\n".join(f"{k} = {_toml_value(v)}" for k, v in doc.items()), raw)):
        path = d / f"p{i}.toml"
        path.write_text(text)
        try:
            load_spec(path)
        except (ValueError, TypeError):
            pass


@_FUZZ
@given(data=st.binary(max_size=300), ext=st.sampled_from([".npz", ".nc", ".h5"]))
def test_array_reader_on_garbage(tmp_path_factory, data, ext):
    path = tmp_path_factory.mktemp("arr") / f"a{ext}"
    path.write_bytes(data)
    with pytest.raises((ValueError, TypeError)):
        from_array(path)


@_FUZZ
@given(fields=st.dictionaries(st.sampled_from(["fs", "forces", "x_mm", "y_mm", "radius_mm", "region", "site", "z"]),
                              st.one_of(st.floats(allow_nan=True, width=32), st.lists(st.floats(-5, 5, width=32),
                                                                                     max_size=6)),
                              max_size=6))
def test_npz_fields(tmp_path_factory, fields):
    path = tmp_path_factory.mktemp("npz") / "a.npz"
    buffer = io.BytesIO()
    np.savez(buffer, **{k: np.asarray(v) for k, v in fields.items()})
    path.write_bytes(buffer.getvalue())
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        try:
            from_array(path)
        except (ValueError, TypeError):
            pass


_ELECTRODE_FIELDS = ["id", "x_mm", "y_mm", "radius_mm", "region", "amplitude_min_ua", "amplitude_max_ua",
                     "phase_width_us", "max_rate_hz", "charge_limit_nc", "interphase_us", "ID", "foo", ""]


@_FUZZ
@given(header=st.lists(st.sampled_from(_ELECTRODE_FIELDS), min_size=0, max_size=11),
       rows=st.lists(st.lists(_CELL, min_size=0, max_size=11), max_size=5))
def test_electrode_table_csv_reader(tmp_path_factory, header, rows):
    from ddmm.population.neurostim import ElectrodeTable, read_electrodes

    path = tmp_path_factory.mktemp("electrodes") / "e.csv"
    path.write_text(_csv_text([header] + rows))
    try:
        table = read_electrodes(path)
    except (ValueError, TypeError) as exc:
        assert "e.csv" in str(exc), exc
        return
    assert isinstance(table, ElectrodeTable)
    for e in table:  # whatever was accepted holds its own limits
        assert 0 < e.amplitude_min_ua <= e.amplitude_max_ua and e.max_charge_nc <= e.charge_limit_nc * (1 + 1e-12)
        assert e.pulse_s < e.min_interval_s


@_FUZZ
@given(text=st.text(max_size=300), nested=st.integers(0, 3000))
def test_electrode_table_toml_reader(tmp_path_factory, text, nested):
    from ddmm.population.neurostim import read_electrodes

    path = tmp_path_factory.mktemp("electrodes") / "e.toml"
    path.write_text(("x = " + "[" * nested + "]" * nested + "\n") if nested > 2 else text)
    try:
        read_electrodes(path)
    except (ValueError, TypeError) as exc:
        assert "e.toml" in str(exc), exc
