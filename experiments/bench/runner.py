"""``ddmm bench``: the whole pipeline's speed and memory, measured side by side.

Each case (`ddmm.experiments.bench.cases`) runs in a fresh Python process,
so peak RSS is the case's own; warm cases report the median of five timed
runs after two warm-ups.  The cold-start case times a fresh ``ddmm
simulate`` process writing a file, after a first process has filled the
caches; that first process's extra time is reported separately as the
one-time compile.  Every ratio printed is between figures of this one run,
on this one host.
"""

from __future__ import annotations

import json
import os
import subprocess
import sys
import tempfile
import time

from ddmm.experiments.bench.cases import CASES, DT, EXTRA_CASES, GROUPS, SITE_BASELINES
from ddmm.models.engines.registry import engine_names

__all__ = ["run_bench", "format_table"]

def _subprocess_case(name: str) -> dict:
    out = subprocess.run([sys.executable, "-m", "ddmm.experiments.bench.cases", "--case", name],
                         capture_output=True, text=True, check=True)
    return json.loads(out.stdout.strip().splitlines()[-1])


def _cold_start(engine: str) -> tuple[dict, float]:
    """Time a fresh ``ddmm simulate`` process; first run once to fill caches.

    The process runs the CLI and then prints its own peak RSS; the wall time,
    measured here, includes interpreter start-up and imports.  Whether the
    optional Dask extra is installed is recorded: xarray then imports dask
    and distributed to probe arrays, about 0.3 s of every start.
    """
    import importlib.util

    from ddmm.population import load_spec

    with tempfile.TemporaryDirectory() as tmp:
        cmd = [sys.executable, "-m", "ddmm.experiments.bench.cases", "--cold", engine, os.path.join(tmp, "cold.nc")]
        walls, rss = [], 0.0
        for _ in range(2):
            start = time.perf_counter()
            out = subprocess.run(cmd, check=True, capture_output=True, text=True)
            walls.append(time.perf_counter() - start)
            rss = json.loads(out.stdout.strip().splitlines()[-1])["peak_rss_mb"]
    n = sum(load_spec("fingertip").n_afferents().values())
    case = {"name": f"cold_start_{engine}", "engine": engine, "n_afferents": n, "sim_s": 0.5,
            "dt_ms": DT * 1e3, "wall_s": round(walls[1], 3),
            "afferent_s_per_wall_s": round(n * 0.5 / walls[1], 1), "peak_rss_mb": rss,
            "dask_installed": importlib.util.find_spec("distributed") is not None}
    return case, round(max(0.0, walls[0] - walls[1]), 3)


def run_bench(cases=None) -> dict:
    """All cases, each in a fresh process, plus the cold starts; ``cases`` names cases or groups (`GROUPS`:
    ``["scaling"]`` the scaling table, ``["events"]`` latency from the event), each group standing for its cases."""
    names = list(CASES) + list(EXTRA_CASES) if cases is None else [n for c in cases for n in GROUPS.get(c, (c,))]
    results = [_subprocess_case(n) for n in names]
    one_time = {}
    for engine in engine_names() if cases is None else ():
        case, extra = _cold_start(engine)
        results.append(case)
        one_time[f"first_process_extra_s_{engine}"] = extra
    by = {c["name"]: c for c in results}
    ratios = {}
    if "hand_1s_direct" in by and "hand_1s_brian2" in by:
        ratios["brian2_over_direct_hand_1s"] = round(by["hand_1s_brian2"]["wall_s"] / by["hand_1s_direct"]["wall_s"], 2)
    if "over_kernel" in by.get("hand_1s_direct", {}):  # the median of run-by-run ratios, within the case
        ratios["hand_1s_direct_over_integration_kernel"] = by["hand_1s_direct"]["over_kernel"]
    for case, base in SITE_BASELINES.items():
        if case in by and base in by:
            ratios[f"{case}_over_{base}"] = round(by[case]["wall_s"] / by[base]["wall_s"], 2)
    if "scale_100k_inprocess" in by and "scale_100k_2workers" in by:
        ratios["speedup_2workers_over_inprocess_100k"] = round(
            by["scale_100k_inprocess"]["wall_s"] / by["scale_100k_2workers"]["wall_s"], 2)
    return {"cases": results, "ratios": ratios, "one_time": one_time}


def format_table(result: dict) -> str:
    """The printed result: the speed cases' table, each event case's own table (`events.format_event_case`),
    then the ratios and one-time costs."""
    from ddmm.experiments.bench.cases import EVENT_CASES
    from ddmm.experiments.bench.events import format_event_case

    speed = [c for c in result["cases"] if c["name"] not in EVENT_CASES]
    lines = []
    if speed or len(speed) == len(result["cases"]):
        lines += ["| case | engine | afferents | sim (s) | wall (s) | afferent-s/s | peak RSS (MB) | notes |",
                  "|---|---|---|---|---|---|---|---|"]
        lines += [_row(c) for c in speed]
    for c in result["cases"]:
        if c["name"] in EVENT_CASES:
            lines += ([""] if lines else []) + format_event_case(c)
    lines += [f"{k}: {v}" for k, v in {**result["ratios"], **result["one_time"]}.items()]
    return "\n".join(lines)


def _row(c: dict) -> str:
    """One speed case's row of the table."""
    notes = []
    if "median_ms" in c:
        notes.append(f"per 1 ms chunk, real-time paced: median {c['median_ms']:.3f} ms, p99 {c['p99_ms']:.3f} ms; "
                     f"back to back: {c['unpaced_median_ms']:.3f} / {c['unpaced_p99_ms']:.3f} ms")
        if "kernel_ms_per_sim_ms" in c:
            notes.append(f"integration kernel alone {c['kernel_ms_per_sim_ms']:.3f} ms per simulated ms; paced p99 / "
                         f"kernel {c['p99_over_kernel']:.2f}")
    if "electrodes" in c:
        notes.append(f"per 1 ms chunk with {c['electrodes']} electrodes: median {c['stimulation_median_ms']:.3f} "
                     f"ms, p99 {c['stimulation_p99_ms']:.3f} ms; the encoder alone {c['encoder_median_ms']:.3f} / "
                     f"{c['encoder_p99_ms']:.3f} ms")
    if "lsl_latency" in c:
        lsl, own, fmt = c["lsl_latency"], c["in_process_spiking"], c.get("spike_format", "events")
        notes.append(f"sample-to-spike over LSL ({fmt} spikes): median {lsl.get('median_ms', float('nan')):.3f} ms, "
                     f"p99 {lsl.get('p99_ms', float('nan')):.3f} ms, worst {lsl.get('max_ms', float('nan')):.2f} ms; "
                     f"in-process push of the same samples: {own['median_ms']:.3f} / {own['p99_ms']:.3f} / "
                     f"{own['max_ms']:.2f} ms ({c['spikes_over_lsl']:,} spikes)")
        for other, got in c.get("lsl_by_format", {}).items():
            if other != fmt and got["latency"]:
                notes.append(f"{other} spikes over LSL: median {got['latency']['median_ms']:.3f} ms, p99 "
                             f"{got['latency']['p99_ms']:.3f} ms ({got['spikes']:,} spikes)")
        if "kernel_ms_per_sim_ms" in c:
            notes.append(f"integration kernel alone {c['kernel_ms_per_sim_ms']:.3f} ms per simulated ms; in-process "
                         f"p99 / kernel {c['in_process_p99_over_kernel']:.2f}")
    if "over_kernel" in c:
        low, high = c["over_kernel_range"]
        notes.append(f"integration kernel alone {c['kernel_s']:.3f} s; pipeline / kernel {c['over_kernel']:.2f} "
                     f"(median of {c['timed_runs']} alternated pairs, {low:.2f}-{high:.2f})")
    if "us_per_afferent_second" in c:
        notes.append(f"{c['us_per_afferent_second']:.2f} us per afferent-second")
    if "peak_rss_per_worker_mb" in c:
        notes.append(f"{c['workers']} workers, peak {c['peak_rss_per_worker_mb']:.0f} MB per worker")
    return (f"| {c['name']} | {c['engine']} | {c['n_afferents']} | {c['sim_s']:g} | {c['wall_s']:.3f} "
            f"| {c['afferent_s_per_wall_s']:.0f} | {c['peak_rss_mb']:.0f} | {'; '.join(notes)} |")
