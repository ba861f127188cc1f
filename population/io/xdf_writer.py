"""Writing XDF files: a force stream as LabRecorder records one (`save_xdf`), for tests, demos and replays.

The layout is XDF 1.0, written from the specification
(https://github.com/sccn/xdf/wiki/Specifications): the magic ``XDF:``, a
FileHeader chunk, then per stream a StreamHeader, Samples, ClockOffset
and StreamFooter chunks.  `ddmm.population.io.xdf.read_xdf` reads such a
file back as the live LSL bridge reads the stream.
"""

from __future__ import annotations

import os
import struct
from pathlib import Path
from xml.etree import ElementTree

import numpy as np

from ddmm.population.runtime.lsl import FORCE_STREAM_TYPE, force_channel_labels
from ddmm.population.stimuli.recordings import UNITS
from ddmm.utils.validation import as_float_array, check_instance, check_path, check_positive

__all__ = ["save_xdf"]

_MAGIC = b"XDF:"
_SAMPLES_PER_CHUNK = 1000


def _varlen(n: int) -> bytes:
    """An XDF variable-length integer: the count of bytes (1, 4 or 8), then the value, little-endian."""
    if n < 256:
        return struct.pack("<BB", 1, n)
    if n < 2 ** 32:
        return struct.pack("<BI", 4, n)
    return struct.pack("<BQ", 8, n)


def _chunk(tag: int, content: bytes) -> bytes:
    """A chunk: its length (of the tag and the content), the tag (uint16), the content."""
    return _varlen(len(content) + 2) + struct.pack("<H", tag) + content


def _xml(root: str, fields: dict) -> bytes:
    """``<root>`` with ``fields`` as child elements (a dict: nested elements; a list: repeated ones)."""
    def fill(element, value):
        if isinstance(value, dict):
            for key, child in value.items():
                for item in (child if isinstance(child, list) else [child]):
                    fill(ElementTree.SubElement(element, key), item)
        elif value is not None:
            element.text = str(value)

    element = ElementTree.Element(root)
    fill(element, fields)
    return b'<?xml version="1.0"?>' + ElementTree.tostring(element, encoding="utf-8")


def _samples_chunk(stream_id: int, fmt: str, values, stamps) -> bytes:
    """A Samples chunk: each sample's stamp (8 bytes, or none where ``stamps`` holds None) and its values."""
    out = [struct.pack("<I", stream_id), _varlen(len(stamps))]
    dtype = None if fmt == "string" else np.dtype({"float32": "<f4", "double64": "<f8", "int8": "<i1",
                                                   "int16": "<i2", "int32": "<i4", "int64": "<i8"}[fmt])
    for row, stamp in zip(values, stamps):
        out.append(b"\x00" if stamp is None else b"\x08" + struct.pack("<d", float(stamp)))
        if dtype is None:
            out.extend(_varlen(len(text.encode())) + text.encode() for text in row)
        else:
            out.append(np.asarray(row, dtype=dtype).tobytes())
    return _chunk(3, b"".join(out))


def _stream_chunks(number: int, stream: dict) -> list:
    """One stream's chunks: its StreamHeader (2), Samples (3), ClockOffset (4) and StreamFooter (6)."""
    info = stream["info"]
    parts = [_chunk(2, struct.pack("<I", number) + _xml("info", info))]
    values, stamps = stream["values"], list(stream["stamps"])
    for a in range(0, len(stamps), _SAMPLES_PER_CHUNK):
        parts.append(_samples_chunk(number, info["channel_format"], values[a:a + _SAMPLES_PER_CHUNK],
                                    stamps[a:a + _SAMPLES_PER_CHUNK]))
    offsets = list(stream.get("clock_offsets", ()))
    for time, value in offsets:
        parts.append(_chunk(4, struct.pack("<Idd", number, float(time), float(value))))
    given = [s for s in stamps if s is not None]
    footer = {"first_timestamp": repr(float(given[0])) if given else "0",
              "last_timestamp": repr(float(given[-1])) if given else "0", "sample_count": str(len(stamps)),
              "clock_offsets": {"offset": [{"time": repr(float(t)), "value": repr(float(v))} for t, v in offsets]}}
    parts.append(_chunk(6, struct.pack("<I", number) + _xml("info", footer)))
    return parts


def _write_xdf(path, streams) -> Path:
    """Write ``streams`` to an XDF file: each a dict of ``info`` (the header's fields, ``desc`` nested),
    ``values`` (rows of numbers, or of strings for format ``string``), ``stamps`` (a float or None each:
    None leaves the stamp out, for the reader to deduce) and ``clock_offsets`` ((time, value) pairs).

    The layout of XDF 1.0: the magic ``XDF:``; a FileHeader chunk (tag 1); per stream a StreamHeader (2),
    Samples (3) of up to 1000 samples each, ClockOffset (4) and a StreamFooter (6).  Written whole, then
    renamed into place.
    """
    path = Path(path)
    parts = [_MAGIC, _chunk(1, _xml("info", {"version": "1.0"}))]
    for number, stream in enumerate(streams, start=1):
        parts.extend(_stream_chunks(number, stream))
    partial = path.with_name(f".{path.name}.partial")
    try:  # a reader never sees half a file: written aside, then renamed over the old one
        with open(partial, "wb") as f:
            f.write(b"".join(parts))
        os.replace(partial, path)
    except OSError as exc:
        partial.unlink(missing_ok=True)
        raise ValueError(f"XDF file {str(path)!r} cannot be written: {exc.strerror or exc}") from None
    return path


def save_xdf(path, forces, stamps, *, name: str = "forces", fs: float, units: str = "N", site_ids=None,
             clock_offsets=None) -> Path:
    """Write a force stream to an XDF file, as LabRecorder records one `open_force_outlet` publishes.

    The header is the outlet's: type ``Force``, ``3 n_sites`` double
    channels labelled ``Fx, Fy, Fz`` (``<site>_Fx, ...`` with ``site_ids``)
    in ``units``, the nominal rate ``fs``; every sample carries its stamp.
    For tests, demos and replays: `read_xdf` reads it back.

    Parameters
    ----------
    path : str or Path
        The file to write (replaced whole).
    forces : array_like, shape (n, 3 n_sites)
        The samples, in ``units``.
    stamps : array_like, shape (n,)
        Their stamps in s, on the sender's clock, as sent (out of order and
        gaps included).
    name : str
        The stream's name.
    fs : float
        Its nominal rate in Hz.
    units : {"N", "mN", "gf", "kgf", "lbf"}
        The unit its channels declare.
    site_ids : sequence of str, optional
        Site ids for the channel labels.
    clock_offsets : sequence of (float, float), optional
        ClockOffset measurements (time on the stream's clock, offset to the
        recorder's) in s; default one of 0 s at the first stamp.

    Returns
    -------
    Path

    Examples
    --------
    >>> import pathlib, tempfile
    >>> path = save_xdf(pathlib.Path(tempfile.mkdtemp()) / "s.xdf", np.zeros((3, 3)), [0.0, 0.01, 0.02],
    ...                 name="plate", fs=100.0, units="mN")
    >>> path.read_bytes()[:4]
    b'XDF:'
    """
    path = check_path(path)
    check_instance(name, "name", str, "a str (the stream's name)")
    fs = check_positive(fs, "fs", "Hz")
    if units not in UNITS:
        raise ValueError(f"units={units!r} is not allowed; allowed: {', '.join(UNITS)}")
    forces = as_float_array(forces, "forces", ndim=2)
    if forces.shape[1] % 3 or forces.shape[1] == 0:
        raise ValueError(f"forces must have 3 columns per site (F_X, F_Y, F_Z), got shape {forces.shape}")
    stamps = as_float_array(stamps, "stamps", ndim=1)
    if stamps.size != forces.shape[0] or not np.isfinite(stamps).all():
        raise ValueError(f"stamps must be finite, one per sample; got {stamps.size} for {forces.shape[0]} samples")
    labels = force_channel_labels(forces.shape[1] // 3, site_ids)
    offsets = [(float(stamps[0]) if stamps.size else 0.0, 0.0)] if clock_offsets is None else \
        [(float(t), float(v)) for t, v in clock_offsets]
    info = {"name": name, "type": FORCE_STREAM_TYPE, "channel_count": str(forces.shape[1]),
            "nominal_srate": repr(fs), "channel_format": "double64", "source_id": f"ddmm-xdf-{name}",
            "version": "1.1", "created_at": repr(float(stamps[0]) if stamps.size else 0.0), "hostname": "ddmm",
            "desc": {"channels": {"channel": [{"label": label, "unit": units, "type": "Force"} for label in labels]},
                     "acquisition": {"manufacturer": "ddmm"}}}
    return _write_xdf(path, [{"info": info, "values": forces, "stamps": stamps.tolist(), "clock_offsets": offsets}])
