"""The workloads of ``ddmm bench``, each run in a fresh process (``python -m ddmm.experiments.bench.cases``).

Every case runs in a fresh Python process, so peak RSS is the case's own.
In-process cases do two untimed warm-up runs first (the Brian2 build for the
shape and the numba kernels are cached on disk after the first; the second
settles the page cache and the Brian2 binary's memory, which the first
timed runs still paid for), then report the median of five timed runs of
the pipeline spec -> forces -> spikes -> Dataset (the integration kernel
alone is timed the same way).  The cold-start entry is a whole ``ddmm
simulate`` run in its own process.

Scene: Birznieks ramp-hold-release at theta_R = 90 deg, with the plateau
stretched to the case's duration; dt = 0.1 ms (twice TouchSim's 5 kHz).
"""

from __future__ import annotations

import argparse
import json
import resource
import time

__all__ = ["CASES", "EVENT_CASES", "EXTRA_CASES", "GROUPS", "LSL_CASES", "SCALING", "SITE_BASELINES", "kernel_ms_per_ms",
           "run_case", "run_extra"]

#: name -> (population, engine, simulated seconds, warm-up?)
CASES = {
    "fingertip_1s_direct": ("fingertip", "direct", 1.0, True),
    "fingertip_1s_brian2": ("fingertip", "brian2", 1.0, True),
    "hand_1s_direct": ("hand", "direct", 1.0, True),
    "hand_1s_brian2": ("hand", "brian2", 1.0, True),
    "hand_10s_direct": ("hand", "direct", 10.0, False),
}
#: Cases beyond one process: 100,000 afferents in-process and on 2 local Dask
#: workers, and the streaming encoder's per-chunk latency (raw forces, and through the conditioning stage).
EXTRA_CASES = ("scale_100k_inprocess", "scale_100k_2workers", "stream_fingertip", "stream_hand",
               "stream_fingertip_conditioned", "hand_5sites_1s_direct", "fingertip_16taxels_1s_direct",
               "hand_vibration_1s_direct", "fingertip_scan_1s_direct", "fingertip_letters_1s_direct",
               "stimulate_hand_16")
#: ``--cases lsl``: sample-to-spike latency over Lab Streaming Layer beside the in-process push (extra ddmm[lsl]).
LSL_CASES = ("lsl_fingertip", "lsl_hand")
#: ``--cases scaling``: afferents x simulated seconds, each in a fresh process.
SCALING = tuple(f"scaling_{n}k_{t}s" for n in (1, 10, 100) for t in (1, 10))
#: ``--cases events``: latency from the event (contact, release, shear) at 100 Hz, 1 kHz and 5 kHz, and over LSL.
EVENT_CASES = ("events_100hz", "events_1khz", "events_5khz", "events_lsl")
#: The groups ``--cases`` takes by name (a group is added here, and only here).
GROUPS = {"scaling": SCALING, "lsl": LSL_CASES, "events": EVENT_CASES}
#: Multi-site cases and the one-site case each is compared with (same population, same run).
SITE_BASELINES = {"hand_5sites_1s_direct": "hand_1s_direct", "fingertip_16taxels_1s_direct": "fingertip_1s_direct",
                  "hand_vibration_1s_direct": "hand_1s_direct", "fingertip_scan_1s_direct": "fingertip_1s_direct",
                  "fingertip_letters_1s_direct": "fingertip_1s_direct"}
DT = 1e-4


def _pipeline(population: str, engine: str, sim_s: float):
    from ddmm.population import birznieks, sample_population, simulate

    pop = sample_population(population, rng=0)
    scene = birznieks(90.0, hold_s=sim_s - 0.25)
    ds = simulate(pop, scene, engine=engine, dt=DT, seed=0, quiet=True)
    return len(pop), ds


#: Untimed and timed runs of a warm case; its wall time is the timed runs' median (the host is shared and noisy).
WARMUPS, REPEATS = 2, 5


def _median_wall(run, repeats: int = REPEATS):
    """(median wall time in s of ``repeats`` calls of ``run``, the last call's result)."""
    import statistics

    walls = []
    for _ in range(repeats):
        start = time.perf_counter()
        out = run()
        walls.append(time.perf_counter() - start)
    return statistics.median(walls), out


def run_case(name: str) -> dict:
    """Run one case in this process and return its measurements.

    A warm case: `WARMUPS` untimed runs, then the median of `REPEATS` timed runs.
    A cold case (hand x 10 s, for its peak memory): one timed run.
    """
    population, engine, sim_s, warm = CASES[name]
    for _ in range(WARMUPS if warm else 0):
        n = _pipeline(population, engine, sim_s)[0]
    if name == "hand_1s_direct":
        return _against_kernel(name, population, engine, sim_s, n)
    wall, (n, ds) = _median_wall(lambda: _pipeline(population, engine, sim_s), REPEATS if warm else 1)
    return _case_result(name, engine, n, sim_s, wall, ds, REPEATS if warm else 1)


def _case_result(name, engine, n, sim_s, wall, ds, runs) -> dict:
    return {"name": name, "engine": engine, "n_afferents": n, "sim_s": sim_s, "dt_ms": DT * 1e3,
            "wall_s": round(wall, 4), "afferent_s_per_wall_s": round(n * sim_s / wall, 1),
            "peak_rss_mb": round(resource.getrusage(resource.RUSAGE_SELF).ru_maxrss / 1024.0, 1),
            "spikes": int(ds.sizes["spike"]), "timed_runs": runs}


def _against_kernel(name, population, engine, sim_s, n) -> dict:
    """A warm case timed in turn with the integration kernel alone, run by run (pipeline, kernel,
    pipeline, ...): the pipeline over the kernel is the median of the pairs' ratios, so a host's
    drift during the case moves both sides of each ratio alike."""
    import statistics

    kernel = _kernel_alone(n, sim_s)
    kernel()  # warm-up: kernels, thread pool, spike buffers
    walls, kernels = [], []
    for _ in range(REPEATS):
        wall, (n, ds) = _median_wall(lambda: _pipeline(population, engine, sim_s), 1)
        walls.append(wall)
        kernels.append(_median_wall(kernel, 1)[0])
    ratios = sorted(w / k for w, k in zip(walls, kernels))
    result = _case_result(name, engine, n, sim_s, statistics.median(walls), ds, REPEATS)
    result.update(kernel_s=round(statistics.median(kernels), 4),
                  over_kernel=round(statistics.median(ratios), 2),
                  over_kernel_range=[round(ratios[0], 2), round(ratios[-1], 2)])
    return result


def _kernel_alone(n: int, sim_s: float):
    """A call of the direct engine's integration alone (all threads) on a constant 5 mV/ms for n neurons x
    sim_s: the yardstick of the pipeline's cost."""
    import numpy as np

    from ddmm.models.engines import integrate

    current = np.full((int(sim_s * 1000), n), 5.0)
    types = np.array(["RAI"] * n)

    def run():
        return integrate(current, fs=1000.0, dt=DT, afferent_type=types, engine="direct")
    return run


def _population_100k():
    """The hand preset's types with every count x 8 (100,672 afferents), on one ellipse of the hand's area."""
    import dataclasses

    from ddmm.population import load_spec, sample_population
    from ddmm.population.spec import Region

    spec = load_spec("hand")
    counts = spec.n_afferents()
    spec = spec.replace(map=None, region=Region(center_mm=(0.0, -80.0), semi_axes_mm=(45.0, 95.0)),
                        types={k: dataclasses.replace(t, count=counts[k] * 8) for k, t in spec.types.items()})
    return sample_population(spec, rng=0)


def _scale_case(workers: int) -> dict:
    """100k afferents x 1 s: in this process (workers=0) or on a local Dask cluster."""
    from ddmm.population import birznieks, simulate

    pop, scene = _population_100k(), birznieks(90.0, hold_s=0.75)
    result = {"name": "scale_100k_inprocess" if workers == 0 else f"scale_100k_{workers}workers",
              "engine": "direct", "n_afferents": len(pop), "sim_s": 1.0, "dt_ms": DT * 1e3, "workers": workers}
    if workers == 0:
        simulate(pop.select(range(2000)), scene, engine="direct", seed=0, quiet=True)  # warm-up
        start = time.perf_counter()
        simulate(pop, scene, engine="direct", seed=0, quiet=True)
        wall = time.perf_counter() - start
        result["peak_rss_mb"] = round(resource.getrusage(resource.RUSAGE_SELF).ru_maxrss / 1024.0, 1)
    else:
        from distributed import Client, LocalCluster

        with LocalCluster(n_workers=workers, threads_per_worker=1, processes=True, dashboard_address=None) as cl, \
                Client(cl) as client:
            simulate(pop.select(range(2000)), scene, engine="direct", seed=0, quiet=True, scheduler=client)
            start = time.perf_counter()
            simulate(pop, scene, engine="direct", seed=0, quiet=True, scheduler=client)
            wall = time.perf_counter() - start
            rss = client.run(lambda: resource.getrusage(resource.RUSAGE_SELF).ru_maxrss / 1024.0)
        result["peak_rss_per_worker_mb"] = round(max(rss.values()), 1)
        result["peak_rss_mb"] = round(resource.getrusage(resource.RUSAGE_SELF).ru_maxrss / 1024.0, 1)
    result.update(wall_s=round(wall, 3), afferent_s_per_wall_s=round(len(pop) / wall, 1))
    return result


def _stream_case(population: str, seconds: float = 3.0, conditioned: bool = False) -> dict:
    """Per-chunk processing time of the streaming encoder, 1 ms chunks at fs = 1 kHz, paced in real time.

    ``conditioned``: the encoder's default conditioning stage on (a live
    sensor); otherwise the forces are taken as they are (noise-free forces).

    Chunks arrive every millisecond, as from a sensor; each push's processing
    time is measured.  (A loop pushing as fast as it can would measure
    throughput, not latency, and starve the encoder's noise prefetch.)
    """
    import numpy as np

    from ddmm.population import birznieks, sample_population
    from ddmm.population.runtime.stream import Encoder

    pop = sample_population(population, rng=0)
    scene = birznieks(90.0, hold_s=seconds - 0.25)
    forces = np.column_stack([scene.fx, scene.fy, scene.fz])
    enc = Encoder(pop, 1000.0, dt=DT, engine="direct", seed=0, **({} if conditioned else {"conditioning": None}))
    enc.push(forces[:200])  # warm-up (numba kernels)
    enc.reset()
    enc.wait_ready()
    unpaced = np.empty(forces.shape[0])
    for k in range(forces.shape[0]):  # processing time alone, chunks back to back
        start = time.perf_counter()
        enc.push(forces[k:k + 1])
        unpaced[k] = time.perf_counter() - start
    enc.reset()
    enc.wait_ready()  # a stimulator bridge primes the encoder before the stream starts
    kernel = kernel_ms_per_ms(len(pop))  # the yardstick, timed before and after the paced pushes
    laps = np.empty(forces.shape[0])
    t0 = time.perf_counter()
    for k in range(forces.shape[0]):
        wait = t0 + k * 1e-3 - time.perf_counter()  # the next sample arrives at k ms
        if wait > 3e-4:
            time.sleep(wait - 2e-4)  # sleep, not spin: leave the GIL to the noise prefetch
        while time.perf_counter() < t0 + k * 1e-3:
            pass
        start = time.perf_counter()
        enc.push(forces[k:k + 1])
        laps[k] = time.perf_counter() - start
    kernel = kernel + kernel_ms_per_ms(len(pop))
    p99_ms, kernel_ms = float(np.percentile(laps, 99)) * 1e3, float(np.median(kernel))
    return {"name": f"stream_{population}" + ("_conditioned" if conditioned else ""), "engine": "direct", "n_afferents": len(pop), "sim_s": seconds,
            "dt_ms": DT * 1e3, "wall_s": round(float(laps.sum()), 3),
            "afferent_s_per_wall_s": round(len(pop) * seconds / float(laps.sum()), 1),
            "peak_rss_mb": round(resource.getrusage(resource.RUSAGE_SELF).ru_maxrss / 1024.0, 1),
            "chunk_ms": 1.0, "median_ms": round(float(np.median(laps)) * 1e3, 4),
            "p99_ms": round(p99_ms, 4), "max_ms": round(float(laps.max()) * 1e3, 3),
            "unpaced_median_ms": round(float(np.median(unpaced)) * 1e3, 4),
            "unpaced_p99_ms": round(float(np.percentile(unpaced, 99)) * 1e3, 4),
            "kernel_ms_per_sim_ms": round(kernel_ms, 4), "p99_over_kernel": round(p99_ms / kernel_ms, 2)}


def kernel_ms_per_ms(n: int, runs: int = 3) -> list:
    """The integration kernel alone (`_kernel_alone`: n neurons x 1 s, every thread) per simulated millisecond,
    in ms, for each of ``runs`` timed calls after a warm-up: the yardstick of a 1 ms push of n afferents."""
    kernel = _kernel_alone(n, 1.0)
    kernel()
    return [_median_wall(kernel, 1)[0] for _ in range(runs)]  # s per simulated s = ms per simulated ms


def _site_scene(population: str, sim_s: float):
    """The bench's Birznieks forces at five digit tips (hand) or on a 4 x 4 taxel array of 2.5 mm pitch."""
    import numpy as np

    from ddmm.population import Scene, Sites, birznieks, taxel_radius
    from ddmm.population.anatomy.hand_map import get_region

    base = birznieks(90.0, hold_s=sim_s - 0.25)
    f = np.stack([base.fx, base.fy, base.fz], axis=1)
    if population == "hand":
        tips = [get_region(f"D{d}d") for d in range(1, 6)]
        sites = Sites([t.center_mm[0] for t in tips], [t.center_mm[1] for t in tips], 6.0,
                      region=[t.name for t in tips], site_id=[t.name for t in tips])
        return Scene.from_sites(np.repeat(f[:, None, :], 5, axis=1), sites, base.fs, "five_tips")
    grid = (np.arange(4) - 1.5) * 2.5
    x, y = (a.ravel() for a in np.meshgrid(grid, grid))
    sites = Sites(x, y, taxel_radius(2.5), region=["D2d"] * 16)
    return Scene.from_sites(np.repeat(f[:, None, :] / 16, 16, axis=1), sites, base.fs, "taxels16")


def _vibration_scene():
    """A 250 Hz sinusoid of 50 um on a 0.3 mm pre-indentation under a 1 mm probe at the D2 pad, 1 s at 5 kHz
    (TouchSim's stimulus rate), through the default skin mechanics."""
    from ddmm.population.anatomy.hand_map import get_region
    from ddmm.population.stimuli.indentation import indent, probe, sinusoid

    pad = get_region("D2d").center_mm
    depth = sinusoid(250.0, 0.05, pre_indent_mm=0.3, duration_s=1.0, ramp_s=0.05, fs=5000.0)
    return indent(probe(pad[0], pad[1], radius_mm=0.5), depth, fs=5000.0, name="vibration_250hz")


def _scan_scene():
    """The named list's grating for 1 s: 1 mm period scanned at 40 mm/s across a 6 x 6 mm window of 0.2 mm pins
    (900 pins) at the fingertip's centre, contact 0.8 mm, with friction, at 5 kHz."""
    from ddmm.population.stimuli.scanning import scan
    from ddmm.population.stimuli.surfaces import grating

    return scan(grating(1.0, 0.5, 0.5), speed_mm_s=40.0, duration_s=1.0, contact_mm=0.8, window_mm=(6.0, 6.0),
                pitch_mm=0.2, fs=5000.0, name="grating_scan_1s")


def _letters_scene():
    """Embossed letters "AB" (6 mm, raised 0.5 mm) pressed by their base (the default contact 0.8 mm: every pin
    touches) and scanned at 20 mm/s for 1 s across a 10 x 10 mm window of 0.25 mm pins (1,600), with friction,
    at 2.5 kHz: sets of pins in contact no other sample shares (the contact solve's update path)."""
    from ddmm.population.stimuli.scanning import scan
    from ddmm.population.stimuli.surfaces import letters

    return scan(letters("AB"), speed_mm_s=20.0, duration_s=1.0, window_mm=(10.0, 10.0), pitch_mm=0.25,
                name="letters_scan_1s")


#: Indentation cases: their scene's maker, by a word of the case's name.
_SCENES = {"vibration": _vibration_scene, "scan": _scan_scene, "letters": _letters_scene}


def _sites_case(name: str) -> dict:
    """A multi-site case: the whole pipeline on `_site_scene` (or an indentation, its mechanics included in
    the time), after one warm-up."""
    from ddmm.population import sample_population, simulate

    population = name.split("_")[0]
    make = next((m for key, m in _SCENES.items() if key in name), lambda: _site_scene(population, 1.0))
    pop = sample_population(population, rng=0)
    simulate(pop, make(), engine="direct", dt=DT, seed=0, quiet=True)
    start = time.perf_counter()
    scene = make()
    built = time.perf_counter()
    ds = simulate(pop, scene, engine="direct", dt=DT, seed=0, quiet=True)
    wall = time.perf_counter() - start
    return {"name": name, "engine": "direct", "n_afferents": len(pop), "sim_s": 1.0, "dt_ms": DT * 1e3,
            "wall_s": round(wall, 4), "scene_s": round(built - start, 4),
            "afferent_s_per_wall_s": round(len(pop) / wall, 1),
            "peak_rss_mb": round(resource.getrusage(resource.RUSAGE_SELF).ru_maxrss / 1024.0, 1),
            "spikes": int(ds.sizes["spike"]), "n_sites": scene.n_sites}


def _scaling_case(name: str) -> dict:
    """``scaling_<n>k_<t>s``: n thousand afferents of the hand's types for t s, direct, whole pipeline."""
    import dataclasses

    from ddmm.population import birznieks, load_spec, sample_population, simulate
    from ddmm.population.spec import Region

    n_k, seconds = int(name.split("_")[1][:-1]), float(name.split("_")[2][:-1])
    spec = load_spec("hand")
    counts = spec.n_afferents()
    total = sum(counts.values())
    types = {k: dataclasses.replace(t, count=max(1, round(counts[k] * n_k * 1000 / total))) for k, t in spec.types.items()}
    pop = sample_population(spec.replace(map=None, region=Region(center_mm=(0.0, -80.0), semi_axes_mm=(45.0, 95.0)),
                                         types=types), rng=0)
    scene = birznieks(90.0, hold_s=seconds - 0.25)
    simulate(pop.select(range(min(len(pop), 2000))), birznieks(90.0), engine="direct", seed=0, quiet=True)  # warm-up
    start = time.perf_counter()
    ds = simulate(pop, scene, engine="direct", dt=DT, seed=0, quiet=True)
    wall = time.perf_counter() - start
    return {"name": name, "engine": "direct", "n_afferents": len(pop), "sim_s": seconds, "dt_ms": DT * 1e3,
            "wall_s": round(wall, 4), "afferent_s_per_wall_s": round(len(pop) * seconds / wall, 1),
            "us_per_afferent_second": round(wall / (len(pop) * seconds) * 1e6, 3),
            "peak_rss_mb": round(resource.getrusage(resource.RUSAGE_SELF).ru_maxrss / 1024.0, 1),
            "spikes": int(ds.sizes["spike"])}


def _stimulate_case(seconds: float = 2.0) -> dict:
    """The stimulation encoder's cost per 1 ms chunk: the hand, five digit-tip sites, 16 region electrodes
    (biomimetic rule), beside the same encoder's push alone on the same samples, paced in real time."""
    import numpy as np

    from ddmm.population import sample_population
    from ddmm.population.anatomy.hand_map import region_names
    from ddmm.population.neurostim import Electrode, StimulationEncoder
    from ddmm.population.runtime.stream import Encoder

    pop, scene = sample_population("hand", rng=0), _site_scene("hand", seconds)
    table = [Electrode(r, 20.0, 80.0, 200.0, 300.0, 20.0, region=r) for r in region_names()[:16]]
    laps = {}
    for label in ("encoder", "stimulation"):
        enc = Encoder(pop, 1000.0, dt=DT, seed=0, sites=scene.sites, conditioning=None)
        unit = enc if label == "encoder" else StimulationEncoder(enc, table)
        unit.warm_up()
        f, out = scene.site_forces, np.empty(scene.n_samples)
        t0 = time.perf_counter()
        for k in range(scene.n_samples):
            wait = t0 + k * 1e-3 - time.perf_counter()
            if wait > 0:
                time.sleep(wait)
            start = time.perf_counter()
            unit.push(f[k:k + 1])
            out[k] = time.perf_counter() - start
        laps[label] = out * 1e3
    stats = {f"{k}_{s}_ms": round(float(fn(v)), 4) for k, v in laps.items()
             for s, fn in (("median", np.median), ("p99", lambda x: np.percentile(x, 99)))}
    return {"name": "stimulate_hand_16", "engine": "direct", "n_afferents": len(pop), "sim_s": seconds,
            "dt_ms": DT * 1e3, "wall_s": round(float(laps["stimulation"].sum()) / 1e3, 3),
            "afferent_s_per_wall_s": round(len(pop) * seconds / (laps["stimulation"].sum() / 1e3), 1),
            "peak_rss_mb": round(resource.getrusage(resource.RUSAGE_SELF).ru_maxrss / 1024.0, 1),
            "electrodes": len(table), **stats}


def run_extra(name: str) -> dict:
    """Run one of `EXTRA_CASES` or `SCALING` in this process."""
    if name == "stimulate_hand_16":
        return _stimulate_case()
    if name in LSL_CASES:
        from ddmm.experiments.bench.lsl import run_lsl_case
        return run_lsl_case(name)
    if name in EVENT_CASES:
        from ddmm.experiments.bench.events import run_event_case
        return run_event_case(name)
    if name in SCALING:
        return _scaling_case(name)
    if name in SITE_BASELINES:
        return _sites_case(name)
    if name.startswith("scale_100k"):
        return _scale_case(0 if name.endswith("inprocess") else int(name.split("_")[-1][0]))
    population = name.split("_")[1]
    return _stream_case(population, conditioned=name.endswith("_conditioned"))


def _cold_main(engine: str, out: str) -> None:
    from ddmm.experiments.cli import main

    code = main(["simulate", "--population", "fingertip", "--engine", engine, "--quiet", "--out", out])
    if code:
        raise SystemExit(code)
    print(json.dumps({"peak_rss_mb": round(resource.getrusage(resource.RUSAGE_SELF).ru_maxrss / 1024.0, 1)}))


if __name__ == "__main__":  # pragma: no cover - the per-case subprocess entries
    parser = argparse.ArgumentParser()
    parser.add_argument("--case", choices=sorted({*CASES, *EXTRA_CASES, *(n for g in GROUPS.values() for n in g)}))
    parser.add_argument("--cold", nargs=2, metavar=("ENGINE", "OUT"))
    cli_args = parser.parse_args()
    if cli_args.cold:
        _cold_main(*cli_args.cold)
    elif cli_args.case not in CASES:
        print(json.dumps(run_extra(cli_args.case)))
    else:
        print(json.dumps(run_case(cli_args.case)))
