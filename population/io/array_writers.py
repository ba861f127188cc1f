"""Writing sensor-array files: `save_array`, in the layouts `ddmm.population.io.arrays` reads.

The layouts (``.npz``, ``.nc``, ``.h5`` / ``.hdf5``) are described in
`ddmm.population.io.arrays`, the reader; every file is written atomically.
"""

from __future__ import annotations

from pathlib import Path

import numpy as np

from ddmm.population.io.formats import array_format
from ddmm.population.stimuli.scenes import Scene, Sites
from ddmm.utils.files import atomic_write
from ddmm.utils.validation import check_path

__all__ = ["save_array"]


def _fields_of(scene: Scene) -> dict:
    """The layout's fields of a scene (a one-site scene with a contact becomes one site)."""
    if not isinstance(scene, Scene):
        raise TypeError(f"scene must be a Scene, got {type(scene).__name__}")
    if scene.sites is not None:
        sites, forces = scene.sites, scene.site_forces
    elif scene.contact is not None:
        c = scene.contact
        sites = Sites([c.x_mm], [c.y_mm], c.radius_mm)
        forces = np.stack([scene.fx, scene.fy, scene.fz], axis=1)[:, None, :]
    else:
        raise ValueError("scene has no sites and no contact: nothing says where the force acts "
                         "(use Scene.from_sites)")
    return {"fs": float(scene.fs), "forces": np.asarray(forces, dtype=float), "x_mm": np.asarray(sites.x_mm),
            "y_mm": np.asarray(sites.y_mm), "radius_mm": np.asarray(sites.radius_mm),
            "region": np.array(sites.region.tolist(), dtype=str), "site": np.array(sites.site_id.tolist(), dtype=str)}


def _write_npz(tmp, fields: dict) -> None:
    with open(tmp, "wb") as fh:  # a file object: np.savez would append ".npz" to a path
        np.savez(fh, **fields)


def _write_netcdf(tmp, fields: dict) -> None:
    import xarray as xr

    n_samples = fields["forces"].shape[0]
    ds = xr.Dataset(
        {"forces": (("time", "site", "axis"), fields["forces"], {"units": "N"}),
         "x_mm": ("site", fields["x_mm"], {"units": "mm"}), "y_mm": ("site", fields["y_mm"], {"units": "mm"}),
         "radius_mm": ("site", fields["radius_mm"], {"units": "mm"}),
         "region": ("site", fields["region"].astype(object))},
        coords={"time": ("time", np.arange(n_samples) / fields["fs"], {"units": "s"}),
                "site": fields["site"].astype(object), "axis": np.array(["x", "y", "z"], dtype=object)},
        attrs={"fs": fields["fs"], "fs_units": "Hz", "layout": "ddmm sensor array"},
    )
    ds.to_netcdf(tmp, engine="h5netcdf")


def _write_hdf5(tmp, fields: dict) -> None:
    import h5py

    with h5py.File(tmp, "w") as fh:
        fh.attrs["fs"] = fields["fs"]
        for key in ("forces", "x_mm", "y_mm", "radius_mm"):
            fh.create_dataset(key, data=fields[key])
        for key in ("region", "site"):
            fh.create_dataset(key, data=fields[key].astype(object), dtype=h5py.string_dtype())


_WRITERS = {"npz": _write_npz, "netcdf": _write_netcdf, "hdf5": _write_hdf5}


def save_array(path, scene: Scene) -> Path:
    """Write a multi-site scene in the layout its extension names, atomically.

    The file is written under a temporary name in the same directory and
    renamed into place, so a failed write leaves no file (and an existing
    ``path`` untouched).  All optional fields are written.

    Parameters
    ----------
    path : str or Path
        ``.npz``, ``.nc``, ``.h5`` or ``.hdf5``.
    scene : Scene
        A multi-site scene, or a one-site scene with a contact (written as
        one site at the contact).

    Returns
    -------
    Path
        ``path``.

    Examples
    --------
    >>> import tempfile, pathlib
    >>> from ddmm.population.stimuli.scenes import Scene, Sites
    >>> scene = Scene.from_sites(np.ones((10, 2, 3)), Sites([0.0, 3.0], [0.0, 0.0], 1.5))
    >>> with tempfile.TemporaryDirectory() as tmp:
    ...     print(save_array(pathlib.Path(tmp) / "s.h5", scene).name)
    s.h5
    """
    check_path(path)
    kind = array_format(path)
    fields = _fields_of(scene)
    return atomic_write(path, lambda tmp: _WRITERS[kind](tmp, fields))
