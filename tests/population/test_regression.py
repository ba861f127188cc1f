"""Spikes, currents and noise frozen across optimisations: stored digests of one run.

The fused path is held to the per-stage functions bit for bit, but both run
through shared kernels (`ddmm.models._stage_kernels`, `ddmm.models.rng`); a
change to those would move both together.  So one run's spikes and
noise-free currents are stored as digests (the spikes' since 1add058), and
every rewrite of the kernels must keep them.  Spikes move only when a change
crosses a 0.1 ms step, so the bits of the currents and of the noise are
pinned too.

Why the run is made under pinned dispatch
-----------------------------------------
The currents' last bits depend on the instruction sets a host dispatches
to: numpy's SIMD log1p, tanh, sin, tan, ... (AVX2, AVX512_SKX), glibc's FMA
variants of exp, log, sin, cos, tan, atan, log1p and tanh (which numpy's
baseline loops and random generators call) and OpenBLAS's per-core dot
products.  A digest recorded under one instruction set can be checked only
on hosts that have it, and a digest recomputed by the code under test can
catch no regression.  So the run is made in a child process
(`tests.population._pinned_digest`) whose environment pins every one of
them to what any x86-64 host has: numba's generic target, numpy's baseline
loops, glibc's SSE2 libm, OpenBLAS's SSE3 kernels, all from empty caches.
The digests recorded there hold on every x86-64 Linux host and are never
skipped.

The noise is integer arithmetic and one multiply per draw, the same on
every machine, so it is checked in this process.
"""

import hashlib
import json
import os
import platform
import subprocess
import sys
import tempfile
from pathlib import Path

import numpy as np

import ddmm
from ddmm.models.rng import normals, stream_key

from . import _pinned_digest
from ._pinned_digest import AFFERENTS, pinned_env

#: Digests of the run under pinned dispatch (`_pinned_digest.run_digests`).  The spikes' are also
#: what every host's own dispatch gave, on every instruction set tried; the currents' are not.
#: Re-recorded when the presets switched on the physiological mechanisms of docs/model.md ("What
#: changed in the model": the half-wave FA-I drive, trial excitability, SA-II's normal drive and
#: spread, SA-I's dynamic response, the refitted NAP mixes); each branch that added one showed that
#: with the earlier presets the code still gives the earlier digests (41521a8f..., 19849, 24d8967e...).
#: Re-recorded again when the presets switched on the shear-magnitude term and its refitted NAP mixes
#: (with the term off the code gave the previous digests, 81fadf15..., 15031, e97eab25...).
#: Re-recorded when FA-II took a refractory period, the half-wave unsmoothed drive and D = 2, and the NAP
#: mixes were refitted (with the earlier presets the code gave the previous digests, 3bf6cf0d..., 21492,
#: 0468a5e7...).  Re-recorded when FA-II's high-pass went 120 -> 200 Hz and D 2 -> 0.5 (preset values only,
#: no code: the earlier presets give the earlier digests, 789a4251..., 21973, 1ceee0e5...).
#: Re-recorded when units took a per-unit sensitivity (docs/model.md, "Units that differ"): the presets
#: switched on its spread, FA-I's dead zone went 2 -> 0.75 N/s and the NAP mixes were refitted (with the
#: presets of before the code gave the previous digests, afb0ae7e..., 22108, 196b701d...).
#: Re-recorded when SA-I took `SAI.depth` 0.5, the re-tuned shear term and the fast transient
#: (`SAI.transient`, `SAI.adapt` 1 -> 0.7).  With the presets of before (`BEFORE`, run from
#: `_pinned_digest.BEFORE_PRESETS`) the code still gives the earlier digests, and this test holds it to them.
RECORDED = {
    "spikes": "3028bfece619d2c9463dd24e1451fa6df75f114205f3248187f1b21fe8913ce5",
    "n_spikes": 26392,
    "currents": "1a4f9672c69722ac1c68023aad1e59b7dd19041bd48c2a921bb5f0f653a82d8c",
}
#: The digests of the presets before the SA-I transient and depth (the previous `RECORDED`).
BEFORE = {
    "spikes": "ada45d4b20781082fbb1cfa913091ad745d94f8e68934690708f9d48d10cfc79",
    "n_spikes": 22056,
    "currents": "51376b60c856540f8c8c3621b4dd708f8fa899dbbccb5d8f76162f71a2b06f0a",
}
#: Where they were recorded: the bits of libm and of numpy's baseline loops are the platform's.
RECORDED_ON = "x86_64 Linux, glibc 2.36, numpy 2.3 (baseline SSE SSE2 SSE3)"
NOISE_DIGEST = "46fec17f2e6c2c67e82d6b0432fd9c1f236a389244c9247f025a0d62b1e67bde"


def _pinned_run() -> dict:
    """The child's digests and what it ran with (about 15 s, most of it numba compiling from an empty cache)."""
    with tempfile.TemporaryDirectory() as cache:
        env = pinned_env(cache)
        # The child imports the ddmm this process imported (a source checkout or an installed copy).
        env["PYTHONPATH"] = os.pathsep.join(filter(None, [str(Path(ddmm.__file__).resolve().parents[1]),
                                                          env.get("PYTHONPATH")]))
        done = subprocess.run([sys.executable, _pinned_digest.__file__], env=env, capture_output=True, text=True,
                              check=False, timeout=600)
    assert done.returncode == 0, f"the pinned run failed:\n{done.stderr}"
    return json.loads(done.stdout.splitlines()[-1])


def test_spikes_and_currents_under_pinned_dispatch_equal_the_recorded_digests():
    """One child run (one test, so that pytest-xdist never starts two): the pins took effect, then the digests."""
    run = _pinned_run()
    assert (run["numba_cpu_name"], run["numba_cpu_features"], run["numpy_dispatch"]) == ("generic", "", [])
    host = f"{platform.machine()} {platform.system()}, {' '.join(platform.libc_ver())}, numpy {np.__version__}"
    assert {key: run[key] for key in RECORDED} == RECORDED, f"recorded on {RECORDED_ON}; this host: {host}"
    assert run["before"] == BEFORE, "with the presets of before, the code must give the earlier digests"


def test_noise_equals_the_recorded_digest():
    """Integer arithmetic and one multiply per draw on the fast path: the same on every machine."""
    values = normals(stream_key(5, 1, 2), np.asarray(AFFERENTS), 0, 1000)
    assert hashlib.sha256(values.tobytes()).hexdigest() == NOISE_DIGEST
