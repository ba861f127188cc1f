"""Sensor-array input: NPZ / netCDF / HDF5 round trips, the long CSV, and every validation error."""

import h5py
import numpy as np
import pytest
import xarray as xr
from hypothesis import given, settings
from hypothesis import strategies as st

from ddmm.population.io import array_writers, arrays
from ddmm.population.io.arrays import default_radius, from_array, from_long_csv, save_array
from ddmm.population.stimuli.scenes import Contact, Scene, Sites, birznieks, taxel_radius

EXTS = (".npz", ".nc", ".h5", ".hdf5")


def make_scene(n_samples=30, n_sites=3, seed=0, fs=500.0):
    rng = np.random.default_rng(seed)
    forces = rng.normal(size=(n_samples, n_sites, 3))
    forces[:, :, 2] = np.abs(forces[:, :, 2])
    sites = Sites(rng.uniform(-10, 10, n_sites), rng.uniform(-10, 10, n_sites), rng.uniform(0.5, 3, n_sites),
                  region=[f"r{i % 2}" if i % 3 else "" for i in range(n_sites)],
                  site_id=[f"taxel-{i}" for i in range(n_sites)])
    return Scene.from_sites(forces, sites, fs=fs, name="orig")


def assert_same(a, b):
    assert a.fs == b.fs
    np.testing.assert_array_equal(a.site_forces, b.site_forces)
    for key in ("x_mm", "y_mm", "radius_mm", "region", "site_id"):
        np.testing.assert_array_equal(getattr(a.sites, key), getattr(b.sites, key), err_msg=key)


def npz(tmp_path, name="a.npz", **fields):
    base = {"fs": 100.0, "forces": np.ones((5, 2, 3)), "x_mm": [0.0, 2.0], "y_mm": [0.0, 0.0]}
    base.update(fields)
    path = tmp_path / name
    np.savez(path, **{k: v for k, v in base.items() if v is not None})
    return path


# --- round trips -------------------------------------------------------------------------------

@pytest.mark.parametrize("ext", EXTS)
def test_round_trip_each_format(tmp_path, ext):
    scene = make_scene()
    back = from_array(save_array(tmp_path / f"taxels{ext}", scene), conditioning=None)
    assert_same(scene, back)
    assert back.name == "taxels" and from_array(tmp_path / f"taxels{ext}", name="x", conditioning=None).name == "x"
    np.testing.assert_allclose(back.fz, scene.site_forces[:, :, 2].sum(axis=1))


@settings(max_examples=15)
@given(n_samples=st.integers(1, 40), n_sites=st.integers(1, 12), seed=st.integers(0, 2**32 - 1),
       fs=st.floats(1.0, 1e5), ext=st.sampled_from(EXTS))
def test_round_trip_property(tmp_path_factory, n_samples, n_sites, seed, fs, ext):
    scene = make_scene(n_samples, n_sites, seed, fs)
    assert_same(scene, from_array(save_array(tmp_path_factory.mktemp("rt") / f"s{ext}", scene), conditioning=None))


def test_one_site_scene_with_contact_is_saved_as_one_site(tmp_path):
    scene = birznieks(90.0, contact=Contact(1.0, 2.0, 3.0))
    back = from_array(save_array(tmp_path / "one.npz", scene), conditioning=None)
    assert back.n_sites == 1 and back.sites.radius_mm[0] == 3.0
    np.testing.assert_array_equal(back.fy, scene.fy)


def test_save_needs_sites_or_contact(tmp_path):
    with pytest.raises(ValueError, match="no sites and no contact"):
        save_array(tmp_path / "a.npz", birznieks(90.0))
    with pytest.raises(TypeError, match="must be a Scene"):
        save_array(tmp_path / "a.npz", np.ones((3, 1, 3)))
    assert list(tmp_path.iterdir()) == []


def test_foreign_netcdf_and_hdf5_layouts(tmp_path):
    """Files written by other tools: fs as a variable / dataset, integer ids, scalar radius, no optionals."""
    forces = np.ones((4, 2, 3))
    xr.Dataset({"forces": (("time", "site", "axis"), forces), "x_mm": ("site", [0.0, 1.0]),
                "y_mm": ("site", [0.0, 0.0]), "fs": 200.0, "radius_mm": 0.7},
               coords={"site": [7, 9]}).to_netcdf(tmp_path / "a.nc", engine="h5netcdf")
    s = from_array(tmp_path / "a.nc", conditioning=None)
    assert s.fs == 200.0 and list(s.sites.site_id) == ["7", "9"] and list(s.sites.radius_mm) == [0.7, 0.7]
    with h5py.File(tmp_path / "b.h5", "w") as fh:
        fh["forces"], fh["x_mm"], fh["y_mm"], fh["fs"] = forces, [0.0, 2.5], [0.0, 0.0], 50.0
    s = from_array(tmp_path / "b.h5", conditioning=None)
    assert s.fs == 50.0 and s.sites.radius_mm[0] == pytest.approx(taxel_radius(2.5))
    assert list(s.sites.region) == ["", ""] and list(s.sites.site_id) == ["0", "1"]
    with h5py.File(tmp_path / "b.h5", "a") as fh:
        del fh["fs"]
        fh.attrs["fs"] = np.array([75.0])  # a one-element attribute, as netCDF-C tools write scalars
    assert from_array(tmp_path / "b.h5", conditioning=None).fs == 75.0


def test_default_radius_is_equal_area_of_median_pitch(tmp_path):
    x = [0.0, 2.0, 4.0, 0.0, 2.0, 4.0, 100.0]  # a 2 mm grid plus one outlier: the median ignores it
    y = [0.0, 0.0, 0.0, 2.0, 2.0, 2.0, 0.0]
    assert default_radius(x, y) == pytest.approx(2.0 / np.sqrt(np.pi))
    path = npz(tmp_path, forces=np.ones((3, 7, 3)), x_mm=x, y_mm=y)
    assert from_array(path, conditioning=None).sites.radius_mm == pytest.approx(np.full(7, 2.0 / np.sqrt(np.pi)))


# --- atomicity ---------------------------------------------------------------------------------

@pytest.mark.parametrize("ext", EXTS)
def test_failing_write_leaves_no_file(tmp_path, monkeypatch, ext):
    kind = arrays.EXTENSIONS[ext]
    real = array_writers._WRITERS[kind]

    def half_then_fail(tmp, fields):
        real(tmp, fields)  # the whole file exists under its temporary name...
        raise OSError("disk full")  # ...then the write fails

    monkeypatch.setitem(array_writers._WRITERS, kind, half_then_fail)
    with pytest.raises(OSError, match="disk full"):
        save_array(tmp_path / f"s{ext}", make_scene())
    assert list(tmp_path.iterdir()) == []


def test_failing_write_keeps_the_old_file(tmp_path, monkeypatch):
    path = save_array(tmp_path / "s.npz", make_scene(seed=1))
    monkeypatch.setitem(array_writers._WRITERS, "npz", lambda tmp, fields: (_ for _ in ()).throw(OSError("boom")))
    with pytest.raises(OSError):
        save_array(path, make_scene(seed=2))
    assert_same(make_scene(seed=1), from_array(path, conditioning=None))
    assert [p.name for p in tmp_path.iterdir()] == ["s.npz"]


# --- from_array errors -------------------------------------------------------------------------

ARRAY_ERRORS = [
    ({"forces": None}, "missing field 'forces'"),
    ({"x_mm": None}, "missing field 'x_mm'"),
    ({"fs": None}, "missing field 'fs'"),
    ({"radius": 1.0}, "unknown field 'radius'"),
    ({"forces": np.ones((5, 2))}, r"field 'forces' must have shape \(n, n, 3\), got \(5, 2\)"),
    ({"forces": np.ones((5, 2, 2))}, r"field 'forces' must have shape"),
    ({"forces": np.ones((0, 2, 3))}, "at least one sample"),
    ({"x_mm": [0.0, 1.0, 2.0]}, r"field 'x_mm' must have shape \(2,\), got \(3,\)"),
    ({"y_mm": [[0.0, 1.0]]}, r"field 'y_mm' must have shape \(2,\)"),
    ({"forces": np.where(np.arange(30).reshape(5, 2, 3) == 13, np.nan, 1.0)},
     r"field 'forces' has a non-finite value nan at index \[2, 0, 1\]"),
    ({"forces": np.where(np.arange(30).reshape(5, 2, 3) == 11, -0.5, 1.0)},
     r"field 'forces' has a negative normal force -0.5 N at index \[1, 1, 2\]"),
    ({"x_mm": [0.0, np.inf]}, r"field 'x_mm' has a non-finite value inf at index \[1\]"),
    ({"fs": -3.0}, "field 'fs' must be > 0 Hz"),
    ({"fs": [100.0, 200.0]}, r"field 'fs' must have shape \(\)"),
    ({"forces": np.array([["a"] * 3] * 2)[None]}, "field 'forces' must be numeric"),
    ({"site": ["a", "a"]}, r"field 'site' has duplicate id 'a' at index \[1\] \(first at \[0\]\)"),
    ({"site": ["a"]}, r"field 'site' must have shape \(2,\)"),
    ({"region": ["D2", "D2", "D3"]}, r"field 'region' must have shape \(2,\)"),
    ({"radius_mm": [1.0, 0.0]}, r"field 'radius_mm' must be > 0 mm, got 0.0 at index \[1\]"),
    ({"radius_mm": [1.0, np.nan]}, r"field 'radius_mm' has a non-finite value nan at index \[1\]"),
    ({"x_mm": [0.0, 0.0]}, "coincident sites"),
    ({"forces": np.ones((5, 1, 3)), "x_mm": [0.0], "y_mm": [0.0]}, "radius_mm is required with 1 site"),
]


@pytest.mark.parametrize("fields,match", ARRAY_ERRORS)
def test_array_errors_name_file_field_index(tmp_path, fields, match):
    path = npz(tmp_path, **fields)
    with pytest.raises(ValueError, match=match) as info:
        from_array(path)
    assert str(path) in str(info.value) and "\n" not in str(info.value)


@pytest.mark.parametrize("ext", (".nc", ".h5"))
def test_array_errors_in_netcdf_and_hdf5(tmp_path, ext):
    scene = make_scene()
    path = save_array(tmp_path / f"s{ext}", scene)
    if ext == ".nc":
        ds = xr.open_dataset(path).load()
        ds["forces"][3, 1, 2] = -1.0
        ds["extra"] = ("site", np.zeros(3))
        ds.to_netcdf(tmp_path / "bad.nc", engine="h5netcdf")
        with pytest.raises(ValueError, match=r"'.*bad.nc'.*unknown variable 'extra'"):
            from_array(tmp_path / "bad.nc")
        ds = ds.drop_vars("extra")
        ds.to_netcdf(tmp_path / "neg.nc", engine="h5netcdf")
        with pytest.raises(ValueError, match=r"'.*neg.nc'.*negative normal force -1 N at index \[3, 1, 2\] \(below the sensor-noise allowance of -0.13 N\)"):
            from_array(tmp_path / "neg.nc")
        ds = ds.assign_coords(time=ds.time.values * 1.01)
        ds.to_netcdf(tmp_path / "time.nc", engine="h5netcdf")
        with pytest.raises(ValueError, match=r"field 'time' is not uniform at fs = 500.0 Hz: .* at index \[1\]"):
            from_array(tmp_path / "time.nc")
        ds.transpose("site", "time", "axis").to_netcdf(tmp_path / "dims.nc", engine="h5netcdf")
        with pytest.raises(ValueError, match=r"'forces' must have dimensions \(time, site, axis\)"):
            from_array(tmp_path / "dims.nc")
    else:
        with h5py.File(path, "a") as fh:
            del fh["forces"]
        with pytest.raises(ValueError, match=r"'.*s.h5': missing field 'forces'"):
            from_array(path)
        with h5py.File(path, "a") as fh:
            fh["force"] = scene.site_forces
        with pytest.raises(ValueError, match="unknown dataset 'force'"):
            from_array(path)


@pytest.mark.parametrize("name,content,match", [
    ("a.mat", b"", r"unknown extension '.mat'; allowed: .npz, .nc, .h5, .hdf5"),
    ("a", b"", r"unknown extension '\(none\)'"),
    ("a.npz", b"not a zip", "cannot be read as NPZ"),
    ("a.nc", b"not netcdf", "cannot be read as netCDF"),
    ("a.h5", b"not hdf5", "cannot be read as HDF5"),
    ("missing.npz", None, "does not exist"),
])
def test_unreadable_files(tmp_path, name, content, match):
    path = tmp_path / name
    if content is not None:
        path.write_bytes(content)
    with pytest.raises(ValueError, match=match) as info:
        from_array(path)
    assert str(path) in str(info.value)


def test_save_rejects_unknown_extension_before_writing(tmp_path):
    with pytest.raises(ValueError, match="unknown extension '.csv'"):
        save_array(tmp_path / "a.csv", make_scene())
    assert list(tmp_path.iterdir()) == []


# --- the long CSV ------------------------------------------------------------------------------

SITES = "site,x_mm,y_mm,region,radius_mm\na,0,0,D2d,1.5\nb,3,0,D2d,1.5\n"
FORCES = "time,site,fx,fy,fz\n0,a,0,0,1\n0,b,0.5,0,2\n0.01,b,0,0.25,2\n0.01,a,0,0.1,1\n0.02,a,0,0,0\n0.02,b,0,0,0\n"


def long_csv(tmp_path, forces=FORCES, sites=SITES):
    (tmp_path / "f.csv").write_text(forces)
    (tmp_path / "s.csv").write_text(sites)
    return tmp_path / "f.csv", tmp_path / "s.csv"


def test_long_csv(tmp_path):
    scene = from_long_csv(*long_csv(tmp_path), conditioning=None)
    assert scene.fs == pytest.approx(100.0) and scene.name == "f" and list(scene.sites.site_id) == ["a", "b"]
    np.testing.assert_array_equal(scene.site_forces[1], [[0, 0.1, 1], [0, 0.25, 2]])
    np.testing.assert_array_equal(scene.site_forces[0, 1], [0.5, 0, 2])
    assert list(scene.sites.region) == ["D2d", "D2d"] and list(scene.sites.radius_mm) == [1.5, 1.5]
    assert from_long_csv(*long_csv(tmp_path), fs=100.0, name="n", conditioning=None).name == "n"


def test_long_csv_matches_array_round_trip(tmp_path):
    """The same scene written as a long CSV and as NPZ reads back the same."""
    scene = make_scene(n_samples=8, n_sites=4, fs=250.0)
    rows = ["time,site,fx,fy,fz"] + [",".join([repr(k / 250.0), s, *map(repr, f.tolist())])
                                     for k in range(8) for s, f in zip(scene.sites.site_id, scene.site_forces[k])]
    s = scene.sites
    table = ["site,x_mm,y_mm,region,radius_mm"] + [
        ",".join([i, repr(x), repr(y), g, repr(r)])
        for i, x, y, g, r in zip(s.site_id, s.x_mm.tolist(), s.y_mm.tolist(), s.region, s.radius_mm.tolist())]
    back = from_long_csv(*long_csv(tmp_path, "\n".join(rows), "\n".join(table)), fs=250.0, conditioning=None)
    assert_same(scene, back)


def test_long_csv_default_radius_and_single_time(tmp_path):
    sites = "site,x_mm,y_mm\na,0,0\nb,2.5,0\n"
    scene = from_long_csv(*long_csv(tmp_path, sites=sites), conditioning=None)
    assert scene.sites.radius_mm[0] == pytest.approx(taxel_radius(2.5)) and list(scene.sites.region) == ["", ""]
    one = "time,site,fx,fy,fz\n0.5,a,0,0,1\n0.5,b,0,0,1\n"
    assert from_long_csv(*long_csv(tmp_path, one), fs=10.0, conditioning=None).n_samples == 1
    with pytest.raises(ValueError, match="single time stamp; pass fs"):
        from_long_csv(*long_csv(tmp_path, one), conditioning=None)


LONG_ERRORS = [
    # (forces text, sites text, fs, file, match)
    (FORCES.replace("0.01,a,0,0.1,1", "0.01,c,0,0.1,1"), SITES, None, "f.csv",
     r"column 'site', line 5: site 'c' is not in the sites table"),
    (FORCES.replace("0.02,b,0,0,0\n", ""), SITES, None, "f.csv",
     r"column 'site': site 'b' \(sites file line 3\) has no sample at time 0.02 s"),
    (FORCES, SITES + "c,6,0,D2d,1.5\n", None, "f.csv", r"site 'c' \(sites file line 4\) has no sample at time 0.0 s"),
    (FORCES + "0.01,a,0,0,1\n", SITES, None, "f.csv",
     r"line 8: duplicate row for site 'a' at time 0.01 s \(first on line 5\)"),
    (FORCES, SITES + "a,6,0,D2d,1.5\n", None, "s.csv", r"column 'site', line 4: duplicate site id 'a' \(first on line 2\)"),
    (FORCES.replace("0.01,b", "0.0105,b"), SITES, None, "f.csv",
     r"column 'time', line 5: 0.01 s is off the uniform grid"),
    (FORCES.replace("0.02", "0.03"), SITES, None, "f.csv", r"column 'time', line 4: 0.01 s is off the uniform grid"),
    (FORCES, SITES, 200.0, "f.csv", r"column 'time' has a step of 0.01 s, which does not match fs = 200.0 Hz"),
    (FORCES.replace("0,0.25,2", "0,nan,2"), SITES, None, "f.csv", r"column 'fy', line 4: non-finite value 'nan'"),
    (FORCES.replace("0,0.25,2", "0,inf,2"), SITES, None, "f.csv", r"column 'fy', line 4: non-finite value 'inf'"),
    (FORCES.replace("0,0.25,2", "0,x,2"), SITES, None, "f.csv", r"column 'fy', line 4: 'x' is not a number"),
    (FORCES.replace("0.01,a,0,0.1,1", "0.01,a,0,0.1,-1"), SITES, None, "f.csv",
     r"column 'fz', line 5: negative normal force -1 N \(below the sensor-noise allowance of -0.13 N\)"),
    (FORCES.replace("0.01,a,0,0.1,1", "0.01,a,0,0.1"), SITES, None, "f.csv", "line 5 has 4 values but the header has 5"),
    (FORCES.replace("fz", "f_z"), SITES, None, "f.csv", "has no column 'fz'"),
    ("time,site,fx,fy,fz\n", SITES, None, "f.csv", "has a header but no data rows"),
    ("", SITES, None, "f.csv", "is empty"),
    (FORCES, SITES.replace("3,0,D2d", "nan,0,D2d"), None, "s.csv", r"column 'x_mm', line 3: non-finite value 'nan'"),
    (FORCES, SITES.replace("3,0,D2d,1.5", "3,0,D2d,-1"), None, "s.csv", r"column 'radius_mm', line 3: must be > 0 mm"),
    (FORCES, "site,x_mm\na,0\nb,1\n", None, "s.csv", "has no column 'y_mm'"),
    (FORCES, "site,x_mm,y_mm\na,0,0\nb,0,0\n", None, "s.csv", "coincident sites"),
]


@pytest.mark.parametrize("forces,sites,fs,file,match", LONG_ERRORS)
def test_long_csv_errors_name_file_column_line(tmp_path, forces, sites, fs, file, match):
    paths = long_csv(tmp_path, forces, sites)
    with pytest.raises(ValueError, match=match) as info:
        from_long_csv(*paths, fs=fs)
    assert str(tmp_path / file) in str(info.value) and "\n" not in str(info.value)


def test_long_csv_fs_is_checked(tmp_path):
    with pytest.raises(ValueError, match="fs must be a finite number > 0 Hz"):
        from_long_csv(*long_csv(tmp_path), fs=-1.0)
    with pytest.raises(ValueError, match="cannot be read"):
        from_long_csv(tmp_path / "nope.csv", long_csv(tmp_path)[1])
