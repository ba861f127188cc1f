"""Atomic writes: a SIGKILLed writer's temporary file is swept by the next write; live and foreign ones stay.
`write_netcdf` writes the bytes ``to_netcdf`` writes, without importing ``dask.distributed``."""

import os
import signal
import subprocess
import sys

import numpy as np
import pytest
import xarray as xr

from ddmm.population import Scene, Sites, birznieks, make_population, sample_population, simulate
from ddmm.utils.files import _tag, atomic_write, sweep_stale_parts, write_netcdf

_WRITER = """
import sys, time
from pathlib import Path
from ddmm.utils.files import atomic_write

def write(tmp):
    Path(tmp).write_text("half")
    print("writing", flush=True)
    time.sleep(60)

atomic_write(Path(sys.argv[1]), write)
"""


def test_a_killed_writer_leaves_a_part_the_next_write_sweeps(tmp_path):
    target = tmp_path / "run.nc"
    proc = subprocess.Popen([sys.executable, "-c", _WRITER, str(target)], stdout=subprocess.PIPE, text=True)
    assert proc.stdout.readline().strip() == "writing"
    os.kill(proc.pid, signal.SIGKILL)
    proc.wait()
    parts = [p for p in tmp_path.iterdir() if p.name.startswith(".run.nc")]
    assert len(parts) == 1 and str(proc.pid) in parts[0].name and not target.exists()
    atomic_write(tmp_path / "other.nc", lambda tmp: open(tmp, "w").write("x"))
    assert sorted(p.name for p in tmp_path.iterdir()) == ["other.nc"]


def test_live_and_foreign_parts_are_kept(tmp_path):
    live = tmp_path / f".a.nc{_tag()}xyz.part"  # this process: alive
    foreign = tmp_path / ".b.nc.ddmm-otherhost-1-xyz.part"
    unrelated = tmp_path / ".c.nc.part"
    for p in (live, foreign, unrelated):
        p.write_text("x")
    assert sweep_stale_parts(tmp_path) == []
    assert live.exists() and foreign.exists() and unrelated.exists()


def test_a_failed_write_leaves_nothing(tmp_path):
    def fail(tmp):
        open(tmp, "w").write("half")
        raise RuntimeError("disk full")

    try:
        atomic_write(tmp_path / "x.nc", fail)
    except RuntimeError:
        pass
    assert list(tmp_path.iterdir()) == []


def _run():
    """Two conditions with stages, two trials."""
    pop = make_population(["SAI", "RAI", "SAII"], [90.0, 270.0, 0.0], "selective")
    return simulate(pop, [birznieks(90.0), birznieks(None)], engine="direct", trials=2, seed=3, quiet=True)


def _site_run():
    """A multi-site run: string site coords, per-site forces."""
    forces = np.zeros((200, 2, 3))
    forces[:, :, 2] = np.linspace(0.0, 1.0, 200)[:, None]
    taxels = sample_population("fingertip", rng=0).select(np.arange(0, 991, 50))
    sites = Sites([0.0, 3.0], [0.0, 0.0], 1.5, region=["D2d"] * 2)
    return simulate(taxels, Scene.from_sites(forces, sites, 1000.0, "sites"), engine="direct", seed=0, quiet=True)


def _hand_made():
    """NaN, non-ASCII strings, a two-dimensional coordinate, NumPy-scalar attrs."""
    return xr.Dataset({"v": (("x", "y"), np.array([[1.0, np.nan], [3.0, 4.0]]), {"units": "N"}),
                       "n": ("x", np.array([1, 2], np.int8))},
                      coords={"x": ("x", np.array(["é", "b"], dtype=object)), "xy": (("x", "y"), np.ones((2, 2)))},
                      attrs={"count": np.int64(3), "scale": np.float32(0.5), "label": "ü", "flag": 1})


@pytest.mark.parametrize("make", [_run, _site_run, _hand_made])
def test_write_netcdf_writes_the_bytes_to_netcdf_writes(tmp_path, make):
    ds = make()
    ds.to_netcdf(tmp_path / "xarray.nc", engine="h5netcdf")
    write_netcdf(ds, tmp_path / "ddmm.nc")
    assert (tmp_path / "ddmm.nc").read_bytes() == (tmp_path / "xarray.nc").read_bytes()


def test_what_to_netcdf_refuses_it_still_refuses(tmp_path):
    ds = xr.Dataset({"a": ("x", np.arange(3.0))}, attrs={"missing": None})
    with pytest.raises(TypeError, match="Invalid value for attr 'missing'"):
        write_netcdf(ds, tmp_path / "x.nc")
    assert list(tmp_path.iterdir()) == []


def test_write_netcdf_does_not_import_dask_distributed(tmp_path):
    code = ("import sys, numpy as np, xarray as xr\n"
            "from ddmm.utils.files import write_netcdf\n"
            "write_netcdf(xr.Dataset({'a': ('x', np.arange(3.0))}), sys.argv[1])\n"
            "print('distributed' in sys.modules)")
    out = subprocess.run([sys.executable, "-c", code, str(tmp_path / "x.nc")], capture_output=True, text=True,
                         timeout=120, check=False)
    assert out.returncode == 0, out.stderr
    assert out.stdout.split() == ["False"]
