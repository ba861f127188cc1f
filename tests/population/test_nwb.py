"""NWB export: a `ddmm simulate` dataset written, validated (pynwb, nwbinspector), read back spike for spike."""

import json
import os
import subprocess
import sys
import textwrap
from datetime import datetime, timezone

import numpy as np
import pytest

from ddmm.experiments.cli import main
from ddmm.population import Scene, Sites, birznieks, load_dataset, sample_population, simulate, to_nwb

pynwb = pytest.importorskip("pynwb")

SPEC = """name = "tiny"
[types.SAI]
count = 3
noise_sigma = 2.0
[types.RAI]
count = 2
noise_sigma = 2.0
"""
START = datetime(2024, 5, 6, 7, 8, 9, tzinfo=timezone.utc)


@pytest.fixture(scope="module")
def nc(tmp_path_factory):
    """Press-push-lift (not the default scene) at two shear directions, two noisy trials, from the CLI."""
    tmp = tmp_path_factory.mktemp("nwb")
    (tmp / "tiny.toml").write_text(SPEC)
    out = tmp / "x.nc"
    assert main(["simulate", "--population", str(tmp / "tiny.toml"), "--scene", "press-push-lift", "--theta-r",
                 "90,180", "--engine", "direct", "--dt", "0.5", "--trials", "2", "--seed", "3", "--quiet",
                 "--out", str(out)]) == 0
    return out


@pytest.fixture(scope="module")
def exported(nc):
    ds = load_dataset(nc)
    path = to_nwb(ds, nc.with_suffix(".nwb"), identifier="ddmm-test", session_start_time=START)
    return ds, path


def _events(ds, c, t, a):
    keep = (ds.spike_condition.values == c) & (ds.spike_trial.values == t) & (ds.spike_afferent.values == a)
    return ds.spike_time.values[keep]


def test_spike_times_read_back_per_afferent_and_trial(exported):
    ds, path = exported
    assert ds.spike_trial.values.max() == 1 and ds.sizes["spike"] > 1000
    assert not np.array_equal(_events(ds, 0, 0, 0), _events(ds, 0, 1, 0))  # the trials differ (noise)
    with pynwb.NWBHDF5IO(path, "r") as io:
        f = io.read()
        trials, units = f.trials.to_dataframe(), f.units
        assert units.id[:].tolist() == ds.afferent.values.tolist() and units.resolution == ds.attrs["dt"]
        for k, row in enumerate(trials.itertuples()):
            c, t = row.condition_index, row.trial
            assert (c, t) == divmod(k, 2) and row.condition == ds.condition.values[c]
            assert row.stop_time - row.start_time == pytest.approx(float(ds.duration[c]))
            for a in range(ds.sizes["afferent"]):
                times = np.asarray(units["spike_times"][a])
                stored = times[(times >= row.start_time) & (times < row.stop_time)]
                want = _events(ds, c, t, a)
                # Stored is start + t in float64, to the bit; subtracting start back is exact to half an ulp of
                # the session time (< 1e-13 s here, sessions of 120 s), so 1e-12 s bounds the round trip.
                np.testing.assert_array_equal(stored, np.float64(row.start_time) + want)
                np.testing.assert_allclose(stored - row.start_time, want, rtol=0, atol=1e-12)
        assert sum(len(units["spike_times"][a]) for a in range(len(units))) == ds.sizes["spike"]


def test_metadata_columns_stages_and_forces(exported):
    ds, path = exported
    with pynwb.NWBHDF5IO(path, "r") as io:
        f = io.read()
        units = f.units.to_dataframe()
        for name in ("afferent_type", "theta_t", "nap", "k", "gain", "sensitivity", "x_mm", "y_mm", "region",
                     "frame_deg"):
            assert units[name].tolist() == ds[name].values.tolist(), name
        assert "deg" in f.units["theta_t"].description and "millimetres" in f.units["x_mm"].description
        trials = f.trials.to_dataframe()
        assert trials.theta_r.tolist() == [90.0, 90.0, 180.0, 180.0] and trials.has_theta_r.all()
        assert "stage2_dynamic 15-17" in trials.stages.iloc[3].split("; ")  # the stage labels, on the trials table
        stages = f.intervals["stages"].to_dataframe(index=True)
        assert len(stages) == 4 * ds.sizes["stage"]
        row = stages[(stages.trial == 3) & (stages.stage == "stage2_dynamic")].iloc[0]
        start3 = trials.start_time.iloc[3]
        assert (row.start_time - start3, row.stop_time - start3) == pytest.approx((15.0, 17.0))
        force = f.stimulus["fingertip_force"]
        assert force.unit == "N" and force.rate == ds.attrs["fs"] and force.data.shape == (4 * 30000, 3)
        n = 30000
        for k in range(4):  # trial k is condition k // 2 (the conditions differ in fx, fy only)
            want = np.stack([ds[name].values[k // 2] for name in ("fx", "fy", "fz")], axis=1)
            np.testing.assert_array_equal(force.data[k * n: (k + 1) * n], want)
        assert json.loads(f.notes) == {k: v.item() if hasattr(v, "item") else v for k, v in ds.attrs.items()}
        assert f.session_start_time == START and f.identifier == "ddmm-test"
        assert ["ddmm", ds.attrs["ddmm_version"]] in [list(row) for row in f.was_generated_by]


def test_pynwb_validate_and_nwbinspector(exported):
    _, path = exported
    assert pynwb.validate(path=str(path)) == []
    inspector = pytest.importorskip("nwbinspector")
    messages = list(inspector.inspect_nwbfile(nwbfile_path=str(path)))
    serious = [m for m in messages if m.importance.value >= inspector.Importance.BEST_PRACTICE_VIOLATION.value]
    assert serious == [], [m.message for m in serious]


def test_schema_comes_from_the_installed_package_and_nothing_goes_online(nc, tmp_path):
    """Import, export, validate and inspect in a process where any network use or a git run is an error."""
    code = textwrap.dedent(f"""
        import os, sys
        opened = []
        def hook(event, args):
            if event in ("socket.connect", "socket.getaddrinfo", "urllib.Request"):
                raise RuntimeError("offline test: " + event)
            if event == "subprocess.Popen" and "git" in str(args[1]):  # pynwb clones its schema if missing
                raise RuntimeError("offline test: " + str(args[1]))
            if event == "open" and isinstance(args[0], str) and args[0].endswith(".yaml"):
                opened.append(os.path.realpath(args[0]))
        sys.addaudithook(hook)
        import pynwb, hdmf
        from ddmm.population import Scene, Sites, birznieks, load_dataset, sample_population, simulate, to_nwb
        to_nwb(load_dataset({str(nc)!r}), {str(tmp_path / "o.nwb")!r})
        assert pynwb.validate(path={str(tmp_path / "o.nwb")!r}) == []
        try:
            import nwbinspector
            list(nwbinspector.inspect_nwbfile(nwbfile_path={str(tmp_path / "o.nwb")!r}))
        except ImportError:
            pass
        roots = [os.path.realpath(os.path.dirname(m.__file__)) for m in (pynwb, hdmf)]
        core = [p for p in opened if os.path.basename(p).startswith("nwb.")]
        schema = [p for p in opened if "schema" in p]  # NWB core and hdmf-common
        print(len(core), all(p.startswith(roots[0] + os.sep) for p in core),
              all(any(p.startswith(r + os.sep) for r in roots) for p in schema))
    """)
    env = dict(os.environ, PYNWB_NO_CACHE_DIR="1")  # no pickled type map: the schema YAML is read
    out = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, env=env, timeout=120)
    assert out.returncode == 0, out.stderr[-2000:]
    n_core, core_in_pynwb, all_in_packages = out.stdout.split()
    assert int(n_core) >= 10 and core_in_pynwb == "True" and all_in_packages == "True"


def two_sites():
    """Two contact sites with opposite distal shear (a crude twist), as in tests/population/test_sites.py."""
    base = birznieks(90.0)
    f = np.zeros((base.n_samples, 2, 3))
    f[:, :, 2] = base.fz[:, None] / 2
    f[:, 0, 1], f[:, 1, 1] = base.fy / 2, -base.fy / 2
    return Scene.from_sites(f, Sites([-4.0, 4.0], [0.0, 0.0], 3.0, region=["D2d"] * 2, site_id=["L", "R"]),
                            base.fs, "twist")


@pytest.mark.parametrize("record", [("spikes", "forces"), ("spikes",)])
def test_multi_site_forces_and_no_forces(tmp_path, record):
    pop = sample_population("fingertip", rng=0).select(range(0, 991, 60))
    ds = simulate(pop, two_sites(), engine="direct", trials=2, quiet=True, record=record)
    path = to_nwb(ds, tmp_path / "o.nwb")
    assert pynwb.validate(path=str(path)) == []
    with pynwb.NWBHDF5IO(path, "r") as io:
        stimulus = io.read().stimulus
        if "fx" not in ds:
            assert len(stimulus) == 0
            return
        site = stimulus["site_force"]
        assert site.data.shape == (2 * 500, 2, 3) and "L (x -4 mm, y 0 mm, radius 3 mm, region 'D2d'); R" in \
            site.description
        np.testing.assert_array_equal(site.data[500:], two_sites().site_forces)  # trial 1
        np.testing.assert_array_equal(stimulus["fingertip_force"].data[:500, 1], ds.fy.values[0])


def test_missing_pynwb_is_a_one_line_import_error(exported, monkeypatch, tmp_path):
    ds, _ = exported
    monkeypatch.setitem(sys.modules, "pynwb", None)
    with pytest.raises(ImportError) as info:
        to_nwb(ds, tmp_path / "o.nwb")
    assert str(info.value) == 'to_nwb needs pynwb: pip install "ddmm[nwb]"'
    assert list(tmp_path.iterdir()) == []


@pytest.mark.parametrize("kwargs,error,match", [
    ({"dataset": 42}, TypeError, "dataset must be an xarray.Dataset.*got int"),
    ({"path": 3}, TypeError, "path must be a str or os.PathLike.*got int"),
    ({"path": "o.txt"}, ValueError, r"path must end in .nwb, got 'o.txt'"),
    ({"path": "/no/such/dir/o.nwb"}, ValueError, "is not a writable directory"),
    ({"identifier": 5}, TypeError, "identifier must be a str or None, got int 5"),
    ({"session_description": " "}, ValueError, "session_description must not be empty"),
    ({"session_start_time": datetime(2024, 1, 1)}, TypeError, "session_start_time must be a timezone-aware"),
    ({"session_start_time": "2024-01-01"}, TypeError, "session_start_time must be a timezone-aware"),
])
def test_bad_arguments_name_themselves(exported, tmp_path, monkeypatch, kwargs, error, match):
    monkeypatch.chdir(tmp_path)
    args = {"dataset": exported[0], "path": tmp_path / "o.nwb", **kwargs}
    with pytest.raises(error, match=match):
        to_nwb(args.pop("dataset"), args.pop("path"), **args)
    assert list(tmp_path.iterdir()) == []


def test_dataset_without_events_is_refused(exported, tmp_path):
    with pytest.raises(ValueError, match="no spike events"):
        to_nwb(exported[0].drop_vars("spike_time"), tmp_path / "o.nwb")


def test_existing_file_is_replaced_atomically_and_a_failure_leaves_it(exported, tmp_path, monkeypatch):
    ds, _ = exported
    target = tmp_path / "o.nwb"
    target.write_bytes(b"old")
    real_write = pynwb.NWBHDF5IO.write

    def write_then_fail(self, *args, **kwargs):
        real_write(self, *args, **kwargs)  # the temporary file is complete on disk...
        raise RuntimeError("disk full")    # ...when the writer fails

    monkeypatch.setattr(pynwb.NWBHDF5IO, "write", write_then_fail)
    with pytest.raises(RuntimeError, match="disk full"):
        to_nwb(ds, target)
    assert target.read_bytes() == b"old" and [p.name for p in tmp_path.iterdir()] == ["o.nwb"]
    monkeypatch.undo()
    to_nwb(ds, target)
    assert [p.name for p in tmp_path.iterdir()] == ["o.nwb"] and pynwb.validate(path=str(target)) == []


# --- stimulation pulses (to_nwb(..., pulses=...), ddmm export --pulses) ---

ELECTRODES = "\n".join([
    "id,x_mm,y_mm,radius_mm,region,amplitude_min_ua,amplitude_max_ua,phase_width_us,max_rate_hz,charge_limit_nc,"
    "interphase_us",
    "E1,0,0,10,,20,80,200,300,20,0",
    "E2,-5,2,3,,10,60,100,200,10,50",
    "far,500,0,1,,10,60,100,200,10,0",  # no afferent under it: no pulses
]) + "\n"


@pytest.fixture(scope="module")
def stimulated(nc, tmp_path_factory):
    """The `nc` run, its pulses on three electrodes (one far from every afferent: no pulses) and their NWB file."""
    from ddmm.population.neurostim import stimulation_pulses

    tmp = tmp_path_factory.mktemp("stim")
    (tmp / "electrodes.csv").write_text(ELECTRODES)
    ds = load_dataset(nc)
    pulses = stimulation_pulses(ds, tmp / "electrodes.csv")
    path = to_nwb(ds, tmp / "stim.nwb", identifier="ddmm-stim", session_start_time=START, pulses=pulses)
    return ds, pulses, path


def test_pulses_read_back_on_the_session_clock(stimulated):
    ds, pulses, path = stimulated
    counts = np.bincount(pulses.pulse_electrode.values, minlength=3)
    assert counts[0] > 100 and counts[1] > 10 and counts[2] == 0
    assert set(pulses.pulse_condition.values * 2 + pulses.pulse_trial.values) == {0, 1, 2, 3}
    with pynwb.NWBHDF5IO(path, "r") as io:
        f = io.read()
        table = f.intervals["stimulation_pulses"].to_dataframe()
        trials = f.trials.to_dataframe()
        assert len(table) == pulses.sizes["pulse"]
        c, t, e = (pulses[n].values for n in ("pulse_condition", "pulse_trial", "pulse_electrode"))
        k = c * ds.sizes["trial"] + t
        starts = trials.start_time.values[k]
        np.testing.assert_array_equal(trials.condition_index.values[k], c)  # trial k is (c, t) on the trials table
        # start_time = trials.start_time + pulse_time in float64, to the bit, as for spikes
        np.testing.assert_array_equal(table.start_time.values, starts + pulses.pulse_time.values)
        np.testing.assert_allclose(table.start_time.values - starts, pulses.pulse_time.values, rtol=0, atol=1e-12)
        duration = (2 * pulses.phase_width_us.values[e] + pulses.interphase_us.values[e]) * 1e-6
        np.testing.assert_allclose(table.stop_time.values - table.start_time.values, duration, rtol=0, atol=1e-12)
        assert set(np.round((table.stop_time - table.start_time).values * 1e6, 6)) == {400.0, 250.0}
        np.testing.assert_array_equal(table.amplitude_ua.values, pulses.pulse_amplitude.values)
        np.testing.assert_array_equal(table.charge_nc.values, pulses.pulse_charge.values)
        np.testing.assert_array_equal(table.phase_width_us.values, pulses.phase_width_us.values[e])
        np.testing.assert_array_equal(table.interphase_us.values, pulses.interphase_us.values[e])
        assert table.electrode.tolist() == pulses.electrode.values[e].tolist()
        assert table.condition.tolist() == ds.condition.values[c].tolist() and table.trial.tolist() == t.tolist()
        assert "biphasic" in f.intervals["stimulation_pulses"].description
        electrodes = f.processing["stimulation"]["stimulation_electrodes"].to_dataframe()
        assert electrodes.electrode.tolist() == ["E1", "E2", "far"]
        for name in ("x_mm", "radius_mm", "amplitude_min_ua", "amplitude_max_ua", "max_rate_hz", "charge_limit_nc"):
            np.testing.assert_array_equal(electrodes[name].values, pulses[name].values, err_msg=name)


def test_pulses_file_validates_and_inspects_clean(stimulated):
    _, _, path = stimulated
    assert pynwb.validate(path=str(path)) == []
    inspector = pytest.importorskip("nwbinspector")
    messages = list(inspector.inspect_nwbfile(nwbfile_path=str(path)))
    serious = [m for m in messages if m.importance.value >= inspector.Importance.BEST_PRACTICE_VIOLATION.value]
    assert serious == [], [m.message for m in serious]


def test_run_without_pulses_writes_the_electrodes_and_no_empty_table(stimulated, tmp_path):
    ds, pulses, _ = stimulated
    none = pulses.isel(electrode=[2], pulse=[])
    path = to_nwb(ds, tmp_path / "o.nwb", pulses=none)
    with pynwb.NWBHDF5IO(path, "r") as io:
        f = io.read()
        assert "stimulation_pulses" not in f.intervals
        assert f.processing["stimulation"]["stimulation_electrodes"].electrode[:] == ["far"]


@pytest.mark.parametrize("edit,match", [
    (lambda p: p.isel(condition=[1]), r"pulses are of conditions \['press_push_lift_180'\]"),
    (lambda p: p.assign_coords(condition=["a", "b"]), r"pulses are of conditions \['a', 'b'\]"),
    (lambda p: p.isel(trial=[0]), "pulses have 1 trial"),
    (lambda p: p.assign_attrs(fs=500.0), "pulses were made at fs 500.0 Hz"),
    (lambda p: p.assign_attrs(run_seed=4), "pulses come from a run with seed 4"),
])
def test_pulses_of_another_run_are_refused(stimulated, tmp_path, edit, match):
    ds, pulses, _ = stimulated
    with pytest.raises(ValueError, match=match):
        to_nwb(ds, tmp_path / "o.nwb", pulses=edit(pulses))
    with pytest.raises(TypeError, match="pulses must be a pulses Dataset"):
        to_nwb(ds, tmp_path / "o.nwb", pulses=ds)
    assert list(tmp_path.iterdir()) == []


def test_cli_export_with_pulses(stimulated, nc, tmp_path, capsys):
    from ddmm.population.neurostim import save_pulses

    ds, pulses, _ = stimulated
    pulses_nc = save_pulses(pulses, tmp_path / "pulses.nc")
    out = tmp_path / "x.nwb"
    assert main(["export", str(nc), "--nwb", str(out), "--pulses", str(pulses_nc)]) == 0
    assert capsys.readouterr().out.endswith(f", {pulses.sizes['pulse']} stimulation pulses on 3 electrode(s))\n")
    with pynwb.NWBHDF5IO(out, "r") as io:
        table = io.read().intervals["stimulation_pulses"]
        assert len(table) == pulses.sizes["pulse"]
        np.testing.assert_array_equal(table["amplitude_ua"][:], pulses.pulse_amplitude.values)
    assert main(["export", str(nc), "--nwb", str(tmp_path / "y.nwb"), "--pulses", str(tmp_path / "none.nc")]) == 2
    assert "does not exist" in capsys.readouterr().err and not (tmp_path / "y.nwb").exists()


def test_two_exports_of_one_dataset_hold_the_same_content(tmp_path):
    """Identifier, start time and object ids come from the Dataset; only file_create_date may differ."""
    import h5py

    from ddmm.population import birznieks, make_population, save_dataset, simulate
    from ddmm.population.io.nwb import PAPER_DOI, REFERENCE_START

    nc = save_dataset(simulate(make_population(["SAI", "RAI"]), birznieks(90.0), engine="direct", seed=3,
                               quiet=True), tmp_path / "run.nc")
    ds = load_dataset(nc)
    paths = [to_nwb(ds, tmp_path / f"{k}.nwb", experimenter="Doe, Jane", institution="Lab") for k in "ab"]

    def content(path):
        out = {}
        with h5py.File(path) as f:
            def visit(name, obj):
                if isinstance(obj, h5py.Dataset) and name != "file_create_date":
                    value = obj[()]
                    out[name] = repr(value.tolist()) if isinstance(value, np.ndarray) else repr(value)
                out[name + "@"] = repr(sorted((k, str(v)) for k, v in obj.attrs.items()))
            f.visititems(visit)
        return out
    first, second = content(paths[0]), content(paths[1])
    assert first == second and len(first) > 100
    with pynwb.NWBHDF5IO(paths[0], "r") as io:
        f = io.read()
        assert f.experimenter == ("Doe, Jane",) and f.institution == "Lab" and f.related_publications == (PAPER_DOI,)
        assert f.session_start_time == REFERENCE_START
        assert f.subject.subject_id == f"ddmm-{ds.attrs['population']}-seed3"
        identifier = f.identifier
    other = simulate(make_population(["SAI", "RAI"]), birznieks(90.0), engine="direct", seed=4, quiet=True)
    with pynwb.NWBHDF5IO(to_nwb(other, tmp_path / "c.nwb"), "r") as io:
        assert io.read().identifier != identifier  # another run, another identifier
