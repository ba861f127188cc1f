"""The run that `test_regression` digests, made in a child process whose instruction sets are pinned.

`pinned_env` builds the child's environment.  Run as a script under it,
this module prints one line of JSON: the digests of the run (`run_digests`)
and what the child actually ran with (`dispatch_report`), so that the test
can check that the pins took effect.

With the environment pinned, no bit of the run depends on the host's CPU:

* numba compiles for the generic x86-64 target (``NUMBA_CPU_NAME=generic``,
  no extra features) into an empty cache (``NUMBA_CACHE_DIR``), so no
  build for the host's CPU, or from older sources, is reused;
* numpy runs its baseline loops (``NPY_DISABLE_CPU_FEATURES`` names every
  dispatchable feature the host has; the baseline cannot be disabled and is
  the same on every host for one numpy build), so log1p, tanh, sin, tan, ...
  come from the C library rather than numpy's SIMD kernels;
* glibc's libm takes its SSE2 variants (``GLIBC_TUNABLES`` hides FMA, FMA4
  and AVX2 from its ifunc selectors): numpy's baseline loops, numpy's
  random generators and numba's ``math`` calls all go through it;
* OpenBLAS takes its generic SSE3 kernels (``OPENBLAS_CORETYPE``) on one
  thread: numpy's dot products run on it when scipy designs the filters
  (``np.convolve``) and when the hand map rotates its regions (``@``);
* ddmm starts from an empty cache (``DDMM_CACHE_DIR``: the filter designs
  are kept there) on one thread (``DDMM_NUM_THREADS``).

What remains is the platform: the bits of glibc's SSE2 libm and of the
numpy build's baseline loops (x86-64 Linux).
"""

from __future__ import annotations

import hashlib
import json
import os
import platform
import re

#: Afferents of the fingertip population (rng=0) that the run keeps.
AFFERENTS = range(0, 991, 3)
#: Settings of numba, numpy, OpenBLAS and ddmm that could change the arithmetic: none is inherited.
_DROPPED_PREFIXES = ("NUMBA_", "NPY_", "OPENBLAS_", "DDMM_")
#: libm's ifunc selectors take an FMA variant on FMA with AVX2, or on FMA4.
#: glibc >= 2.33 names the features plainly, 2.26-2.32 with ``_Usable``;
#: each ignores the other's names.
_GLIBC_HWCAPS = "glibc.cpu.hwcaps=-AVX2,-FMA,-FMA4,-AVX2_Usable,-FMA_Usable,-FMA4_Usable"


def enabled_dispatch() -> list[str]:
    """numpy's dispatchable CPU features that this process runs with (empty once pinned)."""
    from numpy._core._multiarray_umath import __cpu_dispatch__, __cpu_features__

    return [name for name in __cpu_dispatch__ if __cpu_features__.get(name)]


def pinned_env(cache_dir: str) -> dict:
    """This process's environment with the pins, for the child.

    Parameters
    ----------
    cache_dir : str
        An empty directory; numba's and ddmm's caches go in subdirectories.

    Returns
    -------
    dict
        ``os.environ`` without its numba, numpy, OpenBLAS and ddmm settings,
        plus the pins.  numpy refuses to disable a baseline feature, so
        ``NPY_DISABLE_CPU_FEATURES`` names the dispatchable features present
        here (`enabled_dispatch`) and any this process was already told to
        disable.
    """
    env = {k: v for k, v in os.environ.items() if not k.startswith(_DROPPED_PREFIXES)}
    already = [name for name in re.split(r"[\s,]+", os.environ.get("NPY_DISABLE_CPU_FEATURES", "")) if name]
    tunables = env.get("GLIBC_TUNABLES")
    env.update({
        "NUMBA_CPU_NAME": "generic",
        "NUMBA_CPU_FEATURES": "",  # numba's default for "generic", explicit: host features would add to it
        "NUMBA_CACHE_DIR": os.path.join(cache_dir, "numba"),
        "NPY_DISABLE_CPU_FEATURES": " ".join(dict.fromkeys(enabled_dispatch() + already)),
        "GLIBC_TUNABLES": f"{tunables}:{_GLIBC_HWCAPS}" if tunables else _GLIBC_HWCAPS,
        "OPENBLAS_NUM_THREADS": "1",
        "DDMM_CACHE_DIR": os.path.join(cache_dir, "ddmm"),
        "DDMM_NUM_THREADS": "1",
    })
    if platform.machine().lower() in ("x86_64", "amd64"):
        env["OPENBLAS_CORETYPE"] = "Prescott"  # the SSE3 kernels (OpenBLAS reports them as "Katmai")
    return env


#: The fingertip preset before the last re-recording (issue 37: SA-I depth, shear and transient): with it the code
#: must still give the digests of then.
BEFORE_PRESETS = os.path.join(os.path.dirname(os.path.abspath(__file__)), "data", "fingertip_before.toml")


def run_digests(spec: str = "fingertip") -> dict:
    """SHA-256 digests of the run: its spikes (with their count) and its noise-free currents.

    The ``spec`` population (rng=0; default the fingertip preset), every third afferent, under
    Birznieks ramps at 30 and 200 degrees: two trials of the direct engine
    with seed 5; and the currents of the ramp at 30 degrees.
    """
    import numpy as np

    from ddmm.population import birznieks, sample_population, simulate
    from ddmm.population.simulation import population_currents

    pop = sample_population(spec, rng=0).select(np.asarray(AFFERENTS))
    ds = simulate(pop, [birznieks(30.0), birznieks(200.0)], engine="direct", seed=5, trials=2, quiet=True)
    spikes = hashlib.sha256()
    for name in ("spike_time", "spike_afferent", "spike_trial", "spike_condition", "spike_count"):
        spikes.update(ds[name].values.tobytes())
    currents = population_currents(pop, birznieks(30.0))
    return {"spikes": spikes.hexdigest(), "n_spikes": int(ds.sizes["spike"]),
            "currents": hashlib.sha256(currents.tobytes()).hexdigest()}


def dispatch_report() -> dict:
    """What this process runs with: numba's target CPU and features, numpy's enabled dispatch features."""
    from numba.core import config

    return {"numba_cpu_name": config.CPU_NAME, "numba_cpu_features": config.CPU_FEATURES,
            "numpy_dispatch": enabled_dispatch()}


if __name__ == "__main__":
    print(json.dumps({**run_digests(), "before": run_digests(BEFORE_PRESETS), **dispatch_report()}))
