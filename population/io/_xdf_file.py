"""Reading an XDF file's chunks and stream headers (pyxdf underneath), for `ddmm.population.io.xdf`.

The file is walked by its chunk lengths before pyxdf reads it (a truncated or damaged recording is refused
in one line, naming the chunk); pyxdf's own errors, which it logs and reads past, are raised; a stream's
header is read through the calls of ``pylsl.StreamInfo`` (`_XdfInfo`), so the live path's reading
(`ddmm.population.runtime.lsl.read_force_info`) applies to it unchanged.
"""

from __future__ import annotations

import gzip
import logging
from pathlib import Path

from ddmm.population.io.xdf_writer import _MAGIC
from ddmm.population.runtime.lsl import _NUMERIC
from ddmm.utils.extras import require

_CODES = {name: code for code, name in _NUMERIC.items()}  # liblsl's channel-format code of each XDF name
_STRING = 3  # liblsl's cf_string

# --- the stream header, read as pylsl reads a live stream's info ------------------------------------------


class _Element:
    """One element of an XDF header (pyxdf's nested dicts of lists), with pylsl's ``XMLElement`` calls."""

    def __init__(self, siblings=(), index: int = 0, name: str = ""):
        self._siblings, self._index, self._name = list(siblings or ()), index, name

    @property
    def _node(self):
        return self._siblings[self._index] if self._index < len(self._siblings) else None

    def empty(self) -> bool:
        return self._node is None

    def child(self, name: str) -> _Element:
        node = self._node
        return _Element(node.get(name, ()) if isinstance(node, dict) else (), 0, name)

    def child_value(self, name: str) -> str:
        node = self.child(name)._node
        return node if isinstance(node, str) else ""

    def next_sibling(self, name: str) -> _Element:
        return _Element(self._siblings, self._index + 1, name) if name == self._name else _Element()


class _XdfInfo:
    """An XDF stream header's ``info`` with the calls of ``pylsl.StreamInfo`` that `read_force_info` makes."""

    def __init__(self, info: dict, where: str):
        self._info, self._where = info, where

    def _value(self, key: str) -> str:
        value = (self._info.get(key) or [""])[0]
        return value.strip() if isinstance(value, str) else ""

    def _number(self, key: str, kind):
        try:
            return kind(self._value(key))
        except ValueError:
            raise ValueError(f"{self._where}: the header's {key} is {self._value(key)!r}, not a number") from None

    def name(self) -> str:
        return self._value("name")

    def type(self) -> str:
        return self._value("type")

    def source_id(self) -> str:
        return self._value("source_id")

    def hostname(self) -> str:
        return self._value("hostname")

    def channel_count(self) -> int:
        return self._number("channel_count", int)

    def channel_format(self) -> int:
        return _CODES.get(self._value("channel_format"), _STRING)

    def nominal_srate(self) -> float:
        return self._number("nominal_srate", float)

    def desc(self) -> _Element:
        return _Element(self._info.get("desc", ()), 0, "desc")


# --- reading ----------------------------------------------------------------------------------------------


def _open(path: Path):
    return gzip.open(path, "rb") if path.suffix.lower() == ".xdfz" or path.suffixes[-2:] == [".xdf", ".gz"] \
        else open(path, "rb")


def _check_chunks(path: Path, where: str) -> None:
    """Walk the file's chunks by their lengths: the magic, then whole chunks to the last byte (no truncation)."""
    try:
        with _open(path) as f:
            if f.read(4) != _MAGIC:
                raise ValueError(f"{where} is not an XDF file (it does not start with 'XDF:')")
            number = 0
            while True:
                size = f.read(1)
                if not size:
                    return
                number += 1
                if size[0] not in (1, 4, 8):
                    raise ValueError(f"{where} is damaged: chunk {number} has a length of {size[0]} bytes (1, 4 or "
                                     "8 allowed)")
                field = f.read(size[0])
                length = int.from_bytes(field, "little") if len(field) == size[0] else -1
                if length < 2:
                    raise ValueError(f"{where} is truncated or damaged: chunk {number} has no whole length")
                left = length
                while left:
                    got = len(f.read(min(left, 1 << 20)))
                    if not got:
                        raise ValueError(f"{where} is truncated: chunk {number} ends {left:,} bytes short (the "
                                         "recording was cut off)")
                    left -= got
    except OSError as exc:
        raise ValueError(f"{where} cannot be read: {exc.strerror or exc}") from None
    except EOFError:  # a gzip member cut off
        raise ValueError(f"{where} is truncated (the compressed data end early)") from None


class _Errors(logging.Handler):
    """pyxdf's log while it reads: its errors (it skips a damaged chunk and reads on) are ours to raise."""

    def __init__(self):
        super().__init__(logging.ERROR)
        self.messages = []

    def emit(self, record):
        self.messages.append(record.getMessage())


def _pyxdf_call(where: str, call, *args, **kwargs):
    log = logging.getLogger("pyxdf.pyxdf")
    errors, propagate = _Errors(), log.propagate
    log.addHandler(errors)
    log.propagate = False  # nothing of pyxdf's on the terminal: one line of ours instead
    try:
        out = call(*args, **kwargs)
    except Exception as exc:  # noqa: BLE001 - pyxdf raises what its parsing meets: the file is damaged
        raise ValueError(f"{where} cannot be read: {type(exc).__name__}: {exc}") from None
    finally:
        log.removeHandler(errors)
        log.propagate = propagate
    if errors.messages:
        raise ValueError(f"{where} is damaged: {errors.messages[0]}")
    return out


def _select(pyxdf, path: Path, where: str, stream: str | None) -> int:
    """The id of the stream named ``stream`` (the only stream when None)."""
    found = _pyxdf_call(where, pyxdf.resolve_streams, str(path))
    listed = ", ".join(f"{s['name']!r} ({s['type'] or 'no type'}, {s['channel_count']} channels)" for s in found)
    if not found:
        raise ValueError(f"{where} holds no stream")
    named = [s for s in found if stream is None or s["name"] == stream]
    if stream is None and len(found) > 1:
        raise ValueError(f"{where} holds {len(found)} streams: give one by name (stream=..., --stream NAME); its "
                         f"streams: {listed}")
    if not named:
        raise ValueError(f"{where} has no stream named {stream!r} (stream=..., --stream); its streams: {listed}")
    if len(named) > 1:
        ids = ", ".join(repr(s["source_id"]) for s in named)
        raise ValueError(f"{where} holds {len(named)} streams named {stream!r} (source ids {ids}): one name must "
                         "pick one stream")
    return int(named[0]["stream_id"])


def _load(path: Path, where: str, stream: str | None) -> dict:
    """The chosen stream as pyxdf loads it, raw: no clock synchronisation, dejitter or clock-reset handling."""
    if not path.is_file():
        raise ValueError(f"{where} does not exist")
    pyxdf = require("pyxdf", "read_xdf", "xdf")
    _check_chunks(path, where)
    chosen = _select(pyxdf, path, where, stream)
    loaded, _ = _pyxdf_call(where, pyxdf.load_xdf, str(path), select_streams=[chosen], synchronize_clocks=False,
                            dejitter_timestamps=False, handle_clock_resets=False)
    return loaded[0]
