"""The LSL bench cases: sample-to-spike latency over Lab Streaming Layer, beside the in-process push time.

One case process does, on the same samples (a Birznieks ramp-hold at 1 kHz, 3 s) and host:

1. **In process**: an `Encoder` (the default causal conditioning, as ``ddmm stream``) is
   pushed one sample every millisecond; each push's time is measured.
2. **Over LSL**: ``ddmm stream --lsl-in F --lsl-out S`` runs in its own process; this process
   publishes the samples on a force outlet in real time (one every millisecond, stamped with its
   push time) and reads the spike stream.  A spike's latency is its arrival here minus the push
   time of the force sample it fell in (the sample whose period holds the spike's model time).
   The spike stream's format (``--lsl-spike-format``) is the case's (`FORMATS`): the hand's is
   ``batched`` (one frame per push: in ``events``, one LSL sample per spike, its contact-onset
   bursts of ~2,000 spikes a millisecond cost liblsl most of the period); the fingertip runs both,
   ``events`` first (its ``lsl_latency``).  Frames are decoded after the run (`decode_spikes`), so
   the reader thread only copies what arrives.

Both are reported per force sample that produced spikes (over LSL: until its last spike
arrives; in process: its push, which returns all its spikes) and, in process, over all samples.
``DDMM_NUM_THREADS`` applies to both (the bridge process inherits it); unset, the in-process encoder runs
on every core and the bridge as ``ddmm stream`` defaults (one thread on a host of at most two cores).  Loopback only: the case
writes an LSL config (``ResolveScope = machine``) and points ``LSLAPICFG`` at it.
"""

from __future__ import annotations

import os
import subprocess
import sys
import tempfile
import threading
import time
import uuid

import numpy as np

__all__ = ["FORMATS", "publish", "run_lsl_case"]

#: The spike stream formats each case runs over LSL, its ``lsl_latency`` first.
FORMATS = {"lsl_fingertip": ("events", "batched"), "lsl_hand": ("batched",)}

_FS = 1000.0
_LOOPBACK = ("[ports]\nIPv6 = disable\n[multicast]\nResolveScope = machine\n[lab]\nKnownPeers = {127.0.0.1}\n"
             "[log]\nlevel = -3\n")


def _stats(values_s) -> dict:
    ms = np.asarray(values_s) * 1e3
    return {"median_ms": round(float(np.median(ms)), 4), "p99_ms": round(float(np.percentile(ms, 99)), 4),
            "max_ms": round(float(ms.max()), 3), "n": int(ms.size)}


def _paced(n: int, act) -> np.ndarray:
    """Call ``act(k)`` for k < n, one per millisecond (sleeping, not spinning: the reader thread needs the GIL)."""
    laps = np.empty(n)
    t0 = time.perf_counter() + 0.05
    for k in range(n):
        wait = t0 + k / _FS - time.perf_counter()
        if wait > 0:
            time.sleep(wait)
        laps[k] = act(k)
    return laps


def _in_process(pop, forces):
    from ddmm.experiments.bench.cases import kernel_ms_per_ms
    from ddmm.population.runtime.stream import Encoder

    enc = Encoder(pop, _FS, seed=0)
    enc.warm_up()  # as ddmm stream does
    spiking = np.zeros(forces.shape[0], bool)

    def push(k):
        start = time.perf_counter()
        out = enc.push(forces[k:k + 1])
        lap = time.perf_counter() - start
        spiking[k] = out.afferent.size > 0
        return lap
    kernel = kernel_ms_per_ms(len(pop))  # the yardstick, timed before and after the paced pushes
    laps = _paced(forces.shape[0], push)
    return laps, spiking, float(np.median(kernel + kernel_ms_per_ms(len(pop))))


def _reader(inlet, arrivals, stop):
    """Note each chunk of samples with its arrival: a reader that allocates nothing per pull, as the bridge's,
    and copies the samples as they are (decoded after the run, `_decoded`)."""
    import pylsl

    from ddmm.population.runtime.lsl import ChunkReader

    reader = ChunkReader(inlet, max(64, 4096 // int(inlet.channel_count)))  # events 4,096 spikes; 64 frames
    while not stop.is_set():
        samples, stamps = reader.pull(0.05)
        if len(stamps):
            arrivals.append((pylsl.local_clock(), samples.copy(), stamps.copy()))  # the buffers are reused


def _decoded(arrivals, spike_format: str):
    """[(arrival, spike stamps)] from the reader's [(arrival, samples, sample stamps)]."""
    from ddmm.population.runtime.spike_formats import decode_spikes

    return [(arrived, decode_spikes(samples, stamps, spike_format)[1]) for arrived, samples, stamps in arrivals]


def _over_lsl(population: str, forces, spike_format: str):
    import pylsl

    from ddmm.population.runtime.lsl import open_force_outlet
    from ddmm.population.runtime.lsl_outlets import read_spike_metadata

    names = f"bench-force-{uuid.uuid4().hex[:8]}", f"bench-spikes-{uuid.uuid4().hex[:8]}"
    outlet = open_force_outlet(names[0], fs=_FS)
    proc = subprocess.Popen([sys.executable, "-m", "ddmm.experiments.cli", "stream", "--lsl-in", names[0],
                             "--lsl-out", names[1], "--lsl-spike-format", spike_format, "--population", population,
                             "--seed", "0", "--resolve-timeout", "120"], stdout=subprocess.DEVNULL,
                            stderr=subprocess.PIPE, text=True)
    try:
        found = pylsl.resolve_byprop("name", names[1], 1, 180.0)
        if not found:
            raise RuntimeError(f"the bridge's spike stream did not appear: {proc.stderr.read() if proc.poll() else ''}")
        # max_buflen: x100 samples, an irregular stream's (10 M spikes in events, 10 M frames in batched)
        inlet = pylsl.StreamInlet(found[0], max_buflen=100_000 if spike_format == "events" else 1_000)
        meta = read_spike_metadata(inlet.info(timeout=10.0))
        if meta["format"] != spike_format:
            raise RuntimeError(f"the bridge published {meta['format']!r} spikes, not {spike_format!r}")
        inlet.open_stream(timeout=10.0)
        pushed, t0, arrivals = publish(pylsl, outlet, inlet, forces, _reader)
    finally:
        proc.terminate()
        proc.communicate(timeout=60)
    return pushed, t0 + float(meta["input"]["clock_offset_s"]), _decoded(arrivals, spike_format)


def publish(pylsl, outlet, inlet, forces, reader):
    """Once the bridge subscribes, publish ``forces`` one sample per ms on ``outlet`` while ``reader(inlet,
    arrivals, stop)`` collects the spike stream in a thread: (push times, the first sample's stamp, arrivals)."""
    deadline = time.monotonic() + 60.0
    while not outlet.have_consumers() and time.monotonic() < deadline:
        time.sleep(0.01)
    arrivals, stop = [], threading.Event()
    thread = threading.Thread(target=reader, args=(inlet, arrivals, stop))
    thread.start()
    pushed, t0 = np.empty(forces.shape[0]), pylsl.local_clock() + 0.05

    def push(k):  # stamped with its due time, as a device's clock stamps samples; pushed when the loop gets to it
        pushed[k] = pylsl.local_clock()
        outlet.push_chunk(forces[k:k + 1], [t0 + k / _FS])
        return 0.0
    _paced(forces.shape[0], push)
    time.sleep(1.0)
    stop.set()
    thread.join(10.0)
    return pushed, t0, arrivals


def _latencies(pushed, anchor, arrivals) -> np.ndarray:
    """Per force sample that produced spikes: the arrival of its last spike minus the sample's push time."""
    last = np.full(pushed.size, -np.inf)
    for arrived, stamps in arrivals:
        sample = np.clip(np.floor((stamps - anchor) * _FS + 1e-6).astype(np.int64), 0, pushed.size - 1)
        last[sample] = np.maximum(last[sample], arrived)
    spiking = np.isfinite(last)
    return last[spiking] - pushed[spiking]


def run_lsl_case(name: str, seconds: float = 3.0) -> dict:
    """One of `LSL_CASES`: latency over LSL and in process, side by side (module docstring)."""
    import resource

    with tempfile.TemporaryDirectory() as tmp:
        config = os.path.join(tmp, "lsl_api.cfg")
        with open(config, "w", encoding="utf-8") as f:
            f.write(_LOOPBACK)
        os.environ["LSLAPICFG"] = config  # before pylsl's first use, and inherited by the bridge process
        from ddmm.population import birznieks, sample_population

        population = name.split("_")[1]
        pop = sample_population(population, rng=0)
        scene = birznieks(90.0, hold_s=seconds - 0.25)
        forces = np.column_stack([scene.fx, scene.fy, scene.fz])
        laps, spiking, kernel_ms = _in_process(pop, forces)
        by_format = {}
        for spike_format in FORMATS[name]:
            pushed, anchor, arrivals = _over_lsl(population, forces, spike_format)
            latency = _latencies(pushed, anchor, arrivals)
            by_format[spike_format] = {"spikes": int(sum(a[1].size for a in arrivals)),
                                       "latency": _stats(latency) if latency.size else {}}
    first = by_format[FORMATS[name][0]]
    return {"name": name, "engine": "direct", "n_afferents": len(pop), "sim_s": seconds, "dt_ms": 0.1,
            "wall_s": round(float(laps.sum()), 3), "afferent_s_per_wall_s": round(len(pop) * seconds / laps.sum(), 1),
            "peak_rss_mb": round(resource.getrusage(resource.RUSAGE_SELF).ru_maxrss / 1024.0, 1),
            "spike_format": FORMATS[name][0], "spikes_over_lsl": first["spikes"], "lsl_latency": first["latency"],
            "lsl_by_format": by_format,
            "in_process_spiking": _stats(laps[spiking]), "in_process_all": _stats(laps),
            "kernel_ms_per_sim_ms": round(kernel_ms, 4),
            "in_process_p99_over_kernel": round(float(np.percentile(laps, 99)) * 1e3 / kernel_ms, 2)}
