"""Public constructors and readers refuse absurd input with a named, one-line error (issue: hardening)."""

import numpy as np
import pytest

from ddmm.utils.validation import parse_number
from ddmm.population import Contact, Scene, Sites, birznieks, load_dataset, load_spec, save_array
from ddmm.population.stimuli.recordings import from_csv
from ddmm.population.stimuli.scenes import Stage

ONES = np.ones(5)


@pytest.mark.parametrize("make,error,match", [
    (lambda: birznieks(90.0, angle_deg=90.0), ValueError, r"angle_deg must be in \[0, 80\] degrees"),
    (lambda: birznieks(90.0, angle_deg=95.0), ValueError, "angle_deg must be in"),
    (lambda: Stage("hold", 2.0, 1.0), ValueError, "stage 'hold' must start at or after 0 s and end no earlier"),
    (lambda: Stage("hold", -1.0, 1.0), ValueError, "stage 'hold' must start at or after 0 s"),
    (lambda: Stage("hold", 0.0, float("nan")), ValueError, "end must be a finite number of seconds"),
    (lambda: Scene(0 * ONES, 0 * ONES, ONES, stages=[5]), TypeError, r"stages must be Stage objects, got int \(5\)"),
    (lambda: Scene(0 * ONES, 0 * ONES, ONES, stages=[Stage("late", 1.0, 2.0)]), ValueError, "after the scene's end"),
    (lambda: Scene(0 * ONES, 0 * ONES, ONES, fs=1e300), ValueError, r"fs must be <= 1e\+06 Hz"),
    (lambda: Scene(0 * ONES, 0 * ONES, ONES, theta_r=float("inf")), ValueError, "theta_r must be a finite angle"),
    (lambda: Contact(0.0, 0.0, 1e9), ValueError, "contact radius_mm must be <= 200 mm"),
    (lambda: Sites([0.0], [0.0], 1e9), ValueError, r"sites radius_mm must be in \(0, 200\] mm; got 1e\+09 at site 0"),
    (lambda: Scene(0 * ONES, np.r_[np.nan, ONES[1:]], ONES), ValueError, "fy must be finite; got nan at flat index 0"),
])
def test_absurd_input_is_refused_by_name(make, error, match):
    with pytest.raises(error, match=match):
        make()


@pytest.mark.parametrize("text", ["1_0", "0x10", "1e", "--1", "1,0", ""])
def test_numbers_in_files_are_decimal(text):
    with pytest.raises(ValueError, match="is not a number"):
        parse_number(text)


def test_csv_rejects_python_only_numbers_and_non_utf8(tmp_path):
    path = tmp_path / "s.csv"
    path.write_text("time,fx,fy,fz\n0,0,0,1_0\n0.001,0,0,1\n")
    with pytest.raises(ValueError, match=r"s.csv': column 'fz', line 2: '1_0' is not a number"):
        from_csv(path)
    path.write_bytes(b"time,fx,fy,fz\n0,0,0,\xff1\n")
    with pytest.raises(ValueError, match=r"s.csv' is not UTF-8 text"):
        from_csv(path)


def test_csv_time_steps_beyond_any_sensor_are_refused(tmp_path):
    path = tmp_path / "tiny.csv"
    path.write_text("time,fx,fy,fz\n0,0,0,1\n1e-300,0,0,1\n2e-300,0,0,1\n")
    with pytest.raises(ValueError, match=r"tiny.csv' is sampled at 1e\+300 Hz, beyond any force sensor"):
        from_csv(path)


def test_toml_too_deep_or_not_utf8_names_the_file(tmp_path):
    deep = tmp_path / "deep.toml"
    deep.write_text("[a]\nx = " + "[" * 5000 + "]" * 5000 + "\n")
    with pytest.raises(ValueError, match=r"deep.toml' nests arrays or tables too deeply"):
        load_spec(deep)
    latin = tmp_path / "latin.toml"
    latin.write_bytes(b"name = 'caf\xe9'\n")
    with pytest.raises(ValueError, match=r"latin.toml' is not UTF-8 text"):
        load_spec(latin)


def test_load_dataset_checks_the_kind_of_file(tmp_path):
    fake = tmp_path / "fake.nc"
    fake.write_text("not netCDF")
    with pytest.raises(ValueError, match=r"fake.nc' is not a netCDF-4 file ddmm can read"):
        load_dataset(fake)
    array = save_array(tmp_path / "pad.nc", Scene.from_sites(np.ones((5, 2, 3)), Sites([0.0, 1.0], [0.0, 0.0], 1.0),
                                                             fs=1000.0))
    with pytest.raises(ValueError, match=r"pad.nc' is not a ddmm simulation dataset .*sensor-array file"):
        load_dataset(array)


def test_hdf5_links_are_refused(tmp_path):
    import h5py

    from ddmm.population import from_array

    other = tmp_path / "other.h5"
    with h5py.File(other, "w") as fh:
        fh["region"] = np.array(["D2d", "D2d"], dtype=h5py.string_dtype())
    path = tmp_path / "pad.h5"
    with h5py.File(path, "w") as fh:
        fh["forces"] = np.ones((5, 2, 3))
        fh["x_mm"], fh["y_mm"] = [0.0, 1.0], [0.0, 0.0]
        fh.attrs["fs"] = 1000.0
        fh["region"] = h5py.ExternalLink(str(other), "region")
    with pytest.raises(ValueError, match=r"'region' must be a dataset stored in the file, not a link"):
        from_array(path)


@pytest.mark.parametrize("call, text", [
    (lambda: __import__("ddmm.population", fromlist=["birznieks"]).birznieks(90.0, hold_s=np.float64(-1.0)),
     "hold_s must be a finite number >= 0 s, got -1.0"),
    (lambda: __import__("ddmm.population", fromlist=["birznieks"]).birznieks(90.0, angle_deg=np.float64(95.0)),
     "got 95.0"),
    (lambda: __import__("ddmm.models.neuron", fromlist=["NeuronParams"]).NeuronParams(b=np.float64(0.5)),
     "0.5"),
])
def test_numpy_numbers_print_plainly_in_messages(call, text):
    with pytest.raises(ValueError) as info:
        call()
    assert text in str(info.value) and "np." not in str(info.value)
