"""The spike stream's sample formats: how spikes become LSL samples, and back (`decode_spikes`).

Both formats carry the same spikes, in the same order, with the same stamps,
bit for bit; they differ in what one LSL sample holds.

- **events** (the default): one int32 channel; **one sample per spike**,
  holding the afferent's id, stamped with the spike's time.  Every LSL tool
  reads it as it is, but liblsl spends ~0.2-0.5 µs on each sample: the whole
  hand at contact onset (about 2,000 spikes in a millisecond) costs the
  sender most of its 1 ms period.
- **batched**: `FRAME_CAPACITY` int32 channels; **one sample (a frame) per
  push** of the encoder, or several when a push has more spikes than a frame
  holds.  A frame is a run of groups, one per spike time::

      count, stamp_hi, stamp_lo, id_1, ..., id_count,  count, stamp_hi, ...,  -1, -1, ...

  ``count`` (>= 1) spikes share the stamp whose IEEE-754 binary64 bits are
  ``stamp_hi`` (high 32 bits) and ``stamp_lo`` (low 32 bits), each read as
  an int32; the ids follow in the events format's order.  The frame ends at
  a ``count`` of -1 (the padding filling the rest) or at its last channel; a
  group that does not fit goes on in the next frame under its own header.
  The frame's LSL stamp is its first group's stamp.  The spike stamps are
  carried as bits, not as offsets from the frame's stamp, so a consumer gets
  the events format's stamps exactly, whatever the LSL stamp went through
  (a recorder's clock synchronisation, pyxdf's dejitter).

The formats are `SPIKE_FORMATS`, a table: `SpikeOutlet` and ``ddmm stream
--lsl-spike-format`` take their names from it.  This module needs numpy and
numba only (numba at the first frame), so `decode_spikes` reads recorded
samples (an XDF file's) without pylsl.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

__all__ = ["FRAME_CAPACITY", "SPIKE_FORMATS", "SpikeFormat", "decode_spikes"]

#: The batched format's channels per frame.  The whole hand's busiest millisecond (contact onset, 12,584
#: afferents) holds about 2,000 spikes over 10 steps, 2,030 slots: one frame a push even then, where liblsl's
#: cost is per sample.  A frame is 8 KiB whatever it holds: quiet pushes send a frame only when they spike.
FRAME_CAPACITY = 2048


@dataclass(frozen=True)
class SpikeFormat:
    """One spike stream format: its channels, its description, and its encoding both ways.

    Attributes
    ----------
    name : str
        As ``--lsl-spike-format`` names it.
    channels : int
        int32 channels per LSL sample.
    labels : tuple of str
        Channel labels in the meta-data (one for the events format; the frame's layout for the batched).
    convention : str
        The meta-data's ``desc/convention``.
    max_buffered : int
        pylsl's ``max_buffered`` for the outlet (an irregular stream: hundreds of samples).
    pack : callable
        ``pack(ids, stamps) -> (samples, sample_stamps)``: int32 (n, channels) C-contiguous, float64 (n,).
    unpack : callable
        ``unpack(samples, stamps) -> (ids, stamps)``: int64, float64.
    """

    name: str
    channels: int
    labels: tuple
    convention: str
    max_buffered: int
    pack: object
    unpack: object


def _pack_events(ids, stamps):
    return np.ascontiguousarray(ids, np.int32).reshape(-1, 1), np.ascontiguousarray(stamps, np.float64)


def _unpack_events(samples, stamps):
    samples = np.asarray(samples)
    if samples.size == 0:
        return np.empty(0, np.int64), np.empty(0)
    return samples.reshape(len(samples), -1)[:, 0].astype(np.int64), np.asarray(stamps, np.float64).reshape(-1)


def _frames(ids, bits, stamps, capacity):
    """Frames of (ids, stamps) spikes: groups of equal stamps (``bits``: the stamps' binary64 bits), split
    across frames when full; int32 (n_frames, capacity) padded with -1, and each frame's first stamp."""
    n = ids.size
    # One walk lays the pieces out (a piece: a group's spikes that fit in one frame; at most one a spike),
    # then the frames are filled from the layout.
    start, count = np.empty(n, np.int64), np.empty(n, np.int64)
    frame, where = np.empty(n, np.int64), np.empty(n, np.int64)
    pieces, f, pos, i = 0, 0, 0, 0
    while i < n:
        j = i + 1
        while j < n and bits[j] == bits[i]:
            j += 1
        while i < j:
            if capacity - pos < 4:
                f, pos = f + 1, 0
            m = min(j - i, capacity - pos - 3)
            start[pieces], count[pieces], frame[pieces], where[pieces] = i, m, f, pos
            pieces, pos, i = pieces + 1, pos + 3 + m, i + m
    out = np.full((f + 1, capacity), -1, np.int32)
    first = np.empty(f + 1)
    for p in range(pieces):
        i, m, f, pos = start[p], count[p], frame[p], where[p]
        if pos == 0:
            first[f] = stamps[i]
        out[f, pos] = m
        out[f, pos + 1] = np.int32(bits[i] >> 32)
        out[f, pos + 2] = np.int32(bits[i] & 0xFFFFFFFF)
        for k in range(m):
            out[f, pos + 3 + k] = ids[i + k]
    return out, first


def _read_frames(frames):
    """The spikes of int32 frames (n, capacity): ids and the stamps' binary64 bits; count -1 for a malformed
    frame (its index in the second value)."""
    n, capacity = frames.shape
    total = 0
    for f in range(n):  # a first pass counts and checks
        pos = 0
        while pos + 3 <= capacity:
            c = frames[f, pos]
            if c < 0:
                break
            if c == 0 or pos + 3 + c > capacity:
                return np.empty(0, np.int64), np.full(1, f, np.int64), -1
            total += c
            pos += 3 + c
    ids, bits = np.empty(total, np.int64), np.empty(total, np.int64)
    k = 0
    for f in range(n):
        pos = 0
        while pos + 3 <= capacity:
            c = frames[f, pos]
            if c < 0:
                break
            b = (np.int64(frames[f, pos + 1]) << 32) | (np.int64(frames[f, pos + 2]) & 0xFFFFFFFF)
            for j in range(c):
                ids[k] = frames[f, pos + 3 + j]
                bits[k] = b
                k += 1
            pos += 3 + c
    return ids, bits, total


_JIT = {}


def _jit(function):
    """``function`` compiled by numba, at its first use: the table's names stay importable without numba
    (``ddmm --help`` builds its options from them)."""
    compiled = _JIT.get(function.__name__)
    if compiled is None:
        import numba as nb

        compiled = _JIT[function.__name__] = nb.njit(cache=True, nogil=True)(function)
    return compiled


def _pack_batched(ids, stamps):
    ids = np.ascontiguousarray(ids, np.int32)
    stamps = np.ascontiguousarray(stamps, np.float64)
    if ids.size == 0:
        return np.empty((0, FRAME_CAPACITY), np.int32), np.empty(0)
    return _jit(_frames)(ids, stamps.view(np.int64), stamps, FRAME_CAPACITY)


def _unpack_batched(samples, stamps):
    frames = np.asarray(samples)
    if frames.size == 0:
        return np.empty(0, np.int64), np.empty(0)
    if frames.ndim != 2 or frames.shape[1] < 4:
        raise ValueError(f"samples must be batched spike frames, (n, channels >= 4), got shape {frames.shape}")
    ids, bits, total = _jit(_read_frames)(np.ascontiguousarray(frames, np.int32))
    if total < 0:
        raise ValueError(f"samples: batched spike frame {int(bits[0])} is malformed: a group's count is 0 or runs "
                         "past the frame's end (is the stream in the events format?)")
    return ids, bits.view(np.float64)


_EVENTS_CONVENTION = ("one sample per spike: the afferent id; stamp: the spike time on the input stream's clock "
                      "(first sample's stamp + model time, moved on by reported gaps)")  # as before the batched
_BATCHED_CONVENTION = ("batched: one sample (a frame of int32 channels) per push of the encoder, or more when full; a "
                       "frame is groups 'count, stamp_hi, stamp_lo, id x count', one per spike time, then -1 padding; "
                       "stamp_hi/stamp_lo: the high/low 32 bits of the spike stamp's IEEE-754 binary64 (the events "
                       "format's stamp, exactly); the frame's LSL stamp: its first group's; decode with "
                       "ddmm.population.runtime.decode_spikes")

#: The spike stream formats by name (``--lsl-spike-format``); ``events`` is the default.
SPIKE_FORMATS = {
    "events": SpikeFormat("events", 1, ("afferent_id",), _EVENTS_CONVENTION, 3600, _pack_events, _unpack_events),
    # 60: 6,000 frames of 8 KiB kept for a slow consumer, 6 s of pushes (up to 12 M spikes).
    "batched": SpikeFormat("batched", FRAME_CAPACITY, ("count", "stamp_hi", "stamp_lo", "afferent_id"),
                           _BATCHED_CONVENTION, 60, _pack_batched, _unpack_batched),
}


def decode_spikes(samples, stamps, spike_format: str = "events"):
    """The spikes of received spike-stream samples: afferent ids and stamps, as the events format gives them.

    Parameters
    ----------
    samples : array_like, shape (n, channels)
        int32 samples as pulled (``inlet.pull_chunk(..., as_numpy=True)``) or
        read from a recording, in the order they came.
    stamps : array_like, shape (n,)
        Their LSL stamps (used by the events format; the batched format
        carries its spike stamps inside the frames).
    spike_format : str
        A name in `SPIKE_FORMATS`: ``read_spike_metadata(info)["format"]``.

    Returns
    -------
    ids : ndarray of int64
        The spiking afferents' ids, by time (then id).
    stamps : ndarray of float64
        The spikes' stamps, bit for bit the events format's.

    Examples
    --------
    >>> frames, frame_stamps = SPIKE_FORMATS["batched"].pack([7, 3, 9], [0.0012, 0.0012, 0.0013])
    >>> frames.shape, frames[0, :10].tolist()
    ((1, 2048), [2, 1062447402, 810889825, 7, 3, 1, 1062554776, 1594291860, 9, -1])
    >>> ids, stamps = decode_spikes(frames, frame_stamps, "batched")
    >>> ids.tolist(), stamps.tolist()
    ([7, 3, 9], [0.0012, 0.0012, 0.0013])
    """
    try:
        spike_format = SPIKE_FORMATS[spike_format]
    except (KeyError, TypeError):
        raise ValueError(f"spike_format must be one of {', '.join(SPIKE_FORMATS)}, got {spike_format!r}") from None
    return spike_format.unpack(samples, stamps)
