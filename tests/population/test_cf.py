"""The package's netCDF files against CF: units UDUNITS parses, labels without units, global attributes, a T axis."""

import cf_units
import cf_xarray  # noqa: F401 - registers the .cf accessor
import numpy as np
import pytest

from ddmm.population import (Scene, Sites, birznieks, load_dataset, make_population, sample_population, save_dataset,
                             simulate)
from ddmm.population.neurostim import Electrode, load_pulses, save_pulses, stimulation_pulses

GLOBAL = ("Conventions", "title", "institution", "source", "history", "references", "comment")


@pytest.fixture(scope="module")
def files(tmp_path_factory):
    folder = tmp_path_factory.mktemp("cf")
    pop = make_population(["SAI", "RAI"])
    one = simulate(pop, birznieks(90.0), engine="direct", seed=0, quiet=True)
    forces = np.zeros((300, 2, 3))
    forces[:, :, 2] = np.interp(np.arange(300), [0, 50, 150], [0.0, 0.0, 1.0])[:, None]  # a ramp, not a step
    taxels = sample_population("fingertip", rng=0).select(np.arange(0, 991, 20))
    two = simulate(taxels, Scene.from_sites(forces, Sites([0.0, 3.0], [0.0, 0.0], 1.5, region=["D2d"] * 2), 1000.0,
                                         "sites"), engine="direct", seed=0, quiet=True)
    table = [Electrode("E1", 20.0, 80.0, 200.0, 300.0, 20.0, x_mm=0.0, y_mm=0.0, radius_mm=5.0)]
    pulses = stimulation_pulses(one, table)
    return [load_dataset(save_dataset(one, folder / "one.nc")), load_dataset(save_dataset(two, folder / "two.nc")),
            load_pulses(save_pulses(pulses, folder / "pulses.nc"))]


@pytest.mark.parametrize("which", [0, 1, 2], ids=["single-site run", "multi-site run", "pulses"])
def test_every_variable_follows_cf(files, which):
    ds = files[which]
    for name in list(ds.coords) + list(ds.data_vars):
        attrs = ds[name].attrs
        if ds[name].dtype.kind in "OSU":
            assert "units" not in attrs and attrs.get("long_name"), name
        else:
            cf_units.Unit(attrs["units"])  # raises for a unit UDUNITS cannot parse
    assert ds.attrs["Conventions"].startswith("CF-") and all(ds.attrs.get(k) for k in GLOBAL)
    assert ds.cf["T"].name == "time"


def test_angles_are_degrees_and_noise_a_power_of_ms(files):
    ds = files[0]
    assert ds.theta_t.attrs["units"] == "degree" and ds.theta_r.attrs["units"] == "degree"
    # UDUNITS parses a fractional power but keeps only integer ones (it reads "mV ms-0.5" as mV): the string
    # is the one both UDUNITS and pint accept, and the variable says how to read it
    assert ds.noise_sigma.attrs["units"] == "mV ms-0.5" and ds.noise_cv.attrs["units"] == "ms0.5"
    assert "integer powers" in ds.noise_sigma.attrs["units_note"]
