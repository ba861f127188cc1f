"""``ddmm bench``: the whole pipeline's speed and memory, measured side by side.

Every case runs in a fresh Python process, so peak RSS is the case's own.
In-process cases do one untimed warm-up run first (the Brian2 build for the
shape and the numba kernels are cached on disk after it), then time the
pipeline spec -> forces -> spikes -> Dataset.  The cold-start case times a
fresh ``ddmm simulate`` process writing a file, after a first process has
filled the caches; that first process's extra time is reported separately
as the one-time compile.

Scene: Birznieks ramp-hold-release at theta_R = 90 deg, with the plateau
stretched to the case's duration; dt = 0.1 ms (twice TouchSim's 5 kHz).
"""

from __future__ import annotations

import argparse
import json
import os
import resource
import subprocess
import sys
import tempfile
import time

from .reference import TOUCHSIM_SPEED

__all__ = ["CASES", "run_case", "run_bench", "register"]

#: name -> (population, engine, simulated seconds, warm-up?)
CASES = {
    "fingertip_1s_direct": ("fingertip", "direct", 1.0, True),
    "fingertip_1s_brian2": ("fingertip", "brian2", 1.0, True),
    "hand_1s_direct": ("hand", "direct", 1.0, True),
    "hand_1s_brian2": ("hand", "brian2", 1.0, True),
    "hand_10s_direct": ("hand", "direct", 10.0, False),
}
DT = 1e-4


def _pipeline(population: str, engine: str, sim_s: float):
    from population import birznieks, sample_population, simulate

    pop = sample_population(population, rng=0)
    scene = birznieks(90.0, hold_s=sim_s - 0.25)
    ds = simulate(pop, scene, engine=engine, dt=DT, seed=0, quiet=True)
    return len(pop), ds


def run_case(name: str) -> dict:
    """Run one case in this process and return its measurements."""
    population, engine, sim_s, warm = CASES[name]
    if warm:
        _pipeline(population, engine, sim_s)
    start = time.perf_counter()
    n, ds = _pipeline(population, engine, sim_s)
    wall = time.perf_counter() - start
    return {"name": name, "engine": engine, "n_afferents": n, "sim_s": sim_s, "dt_ms": DT * 1e3,
            "wall_s": round(wall, 4), "afferent_s_per_wall_s": round(n * sim_s / wall, 1),
            "peak_rss_mb": round(resource.getrusage(resource.RUSAGE_SELF).ru_maxrss / 1024.0, 1),
            "spikes": int(ds.sizes["spike"])}


def _subprocess_case(name: str) -> dict:
    out = subprocess.run([sys.executable, "-m", "experiments.bench", "--case", name],
                         capture_output=True, text=True, check=True)
    return json.loads(out.stdout.strip().splitlines()[-1])


def _cold_start(engine: str) -> tuple[dict, float]:
    """Time a fresh ``ddmm simulate`` process; first run once to fill caches.

    The process runs the CLI and then prints its own peak RSS; the wall time,
    measured here, includes interpreter start-up and imports.
    """
    with tempfile.TemporaryDirectory() as tmp:
        cmd = [sys.executable, "-m", "experiments.bench", "--cold", engine, os.path.join(tmp, "cold.nc")]
        walls, rss = [], 0.0
        for _ in range(2):
            start = time.perf_counter()
            out = subprocess.run(cmd, check=True, capture_output=True, text=True)
            walls.append(time.perf_counter() - start)
            rss = json.loads(out.stdout.strip().splitlines()[-1])["peak_rss_mb"]
    case = {"name": f"cold_start_{engine}", "engine": engine, "n_afferents": 955, "sim_s": 0.5,
            "dt_ms": DT * 1e3, "wall_s": round(walls[1], 3),
            "afferent_s_per_wall_s": round(955 * 0.5 / walls[1], 1), "peak_rss_mb": rss}
    return case, round(max(0.0, walls[0] - walls[1]), 3)


def _cold_main(engine: str, out: str) -> None:
    from .cli import main

    code = main(["simulate", "--population", "fingertip", "--engine", engine, "--quiet", "--out", out])
    if code:
        raise SystemExit(code)
    print(json.dumps({"peak_rss_mb": round(resource.getrusage(resource.RUSAGE_SELF).ru_maxrss / 1024.0, 1)}))


def run_bench(cases=None) -> dict:
    """All cases, each in a fresh process, plus the cold starts."""
    names = list(CASES) if cases is None else list(cases)
    results = [_subprocess_case(n) for n in names]
    one_time = {}
    for engine in ("direct", "brian2"):
        case, extra = _cold_start(engine)
        results.append(case)
        one_time[f"first_process_extra_s_{engine}"] = extra
    by = {c["name"]: c for c in results}
    ratios = {}
    if "hand_1s_direct" in by and "hand_1s_brian2" in by:
        ratios["brian2_over_direct_hand_1s"] = round(by["hand_1s_brian2"]["wall_s"] / by["hand_1s_direct"]["wall_s"], 2)
    if "hand_1s_direct" in by:
        ratios["touchsim_hand_over_direct"] = round(TOUCHSIM_SPEED["hand_wall_s"] / by["hand_1s_direct"]["wall_s"], 2)
    return {"cases": results, "ratios": ratios, "one_time": one_time}


def _table(result: dict) -> str:
    lines = ["| case | engine | afferents | sim (s) | wall (s) | afferent-s/s | peak RSS (MB) |",
             "|---|---|---|---|---|---|---|"]
    for c in result["cases"]:
        lines.append(f"| {c['name']} | {c['engine']} | {c['n_afferents']} | {c['sim_s']:g} | {c['wall_s']:.3f} "
                     f"| {c['afferent_s_per_wall_s']:.0f} | {c['peak_rss_mb']:.0f} |")
    lines += [f"{k}: {v}" for k, v in {**result["ratios"], **result["one_time"]}.items()]
    return "\n".join(lines)


def register(sub) -> None:
    """Add ``ddmm bench``."""
    p = sub.add_parser("bench", help="speed and memory of the whole pipeline (fresh process per case)")
    p.add_argument("--json", action="store_true")
    p.add_argument("--cases", default=None, help="comma-separated subset of: " + ", ".join(CASES))
    p.set_defaults(func=_run)


def _run(args) -> int:
    cases = None if args.cases is None else [c.strip() for c in args.cases.split(",")]
    for c in cases or []:
        if c not in CASES:
            raise ValueError(f"--cases: {c!r} is unknown; allowed: {', '.join(CASES)}")
    result = run_bench(cases)
    print(json.dumps(result) if args.json else _table(result))
    return 0


if __name__ == "__main__":  # pragma: no cover - the per-case subprocess entries
    parser = argparse.ArgumentParser()
    parser.add_argument("--case", choices=sorted(CASES))
    parser.add_argument("--cold", nargs=2, metavar=("ENGINE", "OUT"))
    cli_args = parser.parse_args()
    if cli_args.cold:
        _cold_main(*cli_args.cold)
    else:
        print(json.dumps(run_case(cli_args.case)))
