"""A sender killed mid-stream: ``ddmm stream --lsl-in`` reports it, writes every spike it produced, exits 3.

Over loopback LSL (tests/conftest.py), a sender process and ``ddmm stream`` in two processes; unique stream
names, bounded waits.  The bridge's rules without a network: tests/population/test_lsl_sender.py.
"""

import os
import re
import signal
import subprocess
import sys
import time
import uuid

import numpy as np

from ddmm.population import load_spec, sample_population
from ddmm.population.runtime.stream import Encoder

FS = 500.0
# A sensor glove's driver: a 500 Hz press (the values of `_press`), each sample stamped with its due time, pushed in real time from the
# moment a consumer connects; it prints the first stamp, and a line once 100 samples are out.
SENDER = f"""
import sys, time
import numpy as np
import pylsl
from ddmm.population.runtime.lsl import open_force_outlet

fs = {FS}
outlet = open_force_outlet(sys.argv[1], fs=fs, units="N")
deadline = time.monotonic() + 120.0
while not outlet.have_consumers() and time.monotonic() < deadline:
    time.sleep(0.002)
t0 = pylsl.local_clock()
print(repr(t0), flush=True)
for k in range(100000):
    due = t0 + k / fs
    while pylsl.local_clock() < due:
        time.sleep(0.0005)
    outlet.push_chunk(np.array([[0.0, 0.3 * min(k / 400.0, 1.0), 2.0 * min(k / 150.0, 1.0)]]), [due])
    if k == 100:
        print("100", flush=True)
"""


def _press(n):
    k = np.arange(n)
    return np.column_stack([np.zeros(n), 0.3 * np.minimum(k / 400.0, 1.0), 2.0 * np.minimum(k / 150.0, 1.0)])


def test_a_sender_killed_mid_stream_is_reported_its_spikes_written_and_the_status_is_3():
    name = f"ddmm-cli-killed-{uuid.uuid4().hex[:8]}"
    env = {**os.environ, "DDMM_PROGRESS": "0"}
    sender = subprocess.Popen([sys.executable, "-c", SENDER, name], stdout=subprocess.PIPE, text=True, env=env)
    proc = subprocess.Popen([sys.executable, "-m", "ddmm.experiments.cli", "stream", "--lsl-in", name, "--types",
                             "SAI,RAI", "--seed", "6", "--resolve-timeout", "60"],
                            stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True, env=env)
    try:
        t0 = float(sender.stdout.readline())  # a consumer connected: samples flow
        assert sender.stdout.readline().strip() == "100"
        time.sleep(0.3)
        sender.send_signal(signal.SIGKILL)  # mid-stream, as a crash
        out, err = proc.communicate(timeout=60)
    finally:
        sender.kill()
        proc.kill()
    assert proc.returncode == 3, err
    lines = err.strip().splitlines()
    report = next(line for line in lines if "was lost" in line)
    assert re.fullmatch(rf"ddmm: LSL stream '{name}' was lost [\d.e-]+ s after its last sample, while samples were "
                        r"coming: its sender died \(or closed its stream mid-stream\)", report), report
    taken = int(re.search(r"stream ended: ([\d,]+) samples in, .*\(sender lost\)$", lines[-1]).group(1).replace(",", ""))
    assert taken > 0, lines[-1]  # ~250 sent; fewer when the bridge lags (LSL drops what it has not pulled)
    # every spike of the samples that came, as the offline encoder gives them, and no other
    pop = sample_population(load_spec("fingertip"), rng=6)
    expected = Encoder(pop, FS, seed=6, afferent_types=("SAI", "RAI")).push(_press(taken))
    rows = [line.split(",") for line in out.strip().splitlines()]
    assert len(rows) == expected.afferent.size
    np.testing.assert_array_equal([int(r[1]) for r in rows], pop.afferent_id[expected.afferent])
    np.testing.assert_allclose([float(r[0]) for r in rows], t0 + expected.time, atol=1e-6)
    assert "Traceback" not in err
