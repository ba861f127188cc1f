"""What the LSL, spike-format and XDF tests share: unique stream names, a spike sink, and a recorded press."""

import threading
import time
import uuid

import numpy as np
import pytest

from ddmm.population import from_csv, sample_population, simulate

FS, DT = 500.0, 1e-4


def unique_name(what):
    """A stream name no other test uses."""
    return f"ddmm-test-{what}-{uuid.uuid4().hex[:8]}"


class Collect:
    """A spike sink that keeps every (positions, stamps) push."""

    def __init__(self):
        self.positions, self.stamps = [], []

    def __call__(self, positions, stamps):
        self.positions.append(np.asarray(positions))
        self.stamps.append(np.asarray(stamps))

    def arrays(self):
        return (np.concatenate(self.positions or [np.empty(0, int)]),
                np.concatenate(self.stamps or [np.empty(0)]))


def start_bridge(bridge, n_samples, outlet, timeout=20.0):
    """Run ``bridge`` over ``n_samples`` samples at FS in a thread (stopped after ``timeout`` s at the latest)
    and wait until it has subscribed to ``outlet``: (the thread, its deadline on `time.monotonic`)."""
    deadline = time.monotonic() + timeout
    worker = threading.Thread(target=bridge.run, kwargs={"duration": n_samples / FS,
                                                         "should_stop": lambda: time.monotonic() > deadline})
    worker.start()
    while not outlet.have_consumers() and time.monotonic() < deadline:  # the bridge opens the inlet
        time.sleep(0.01)
    return worker, deadline


def plate_recording(tmp_path_factory):
    """A noisy 500 Hz force-plate recording in mN (press, push, hold) and its offline run from the file:
    (population, forces in mN, spiking afferent ids, spike steps of DT)."""
    rng = np.random.default_rng(11)
    n = 900
    t = np.arange(n) / FS
    f = np.column_stack([np.interp(t, [0, 0.6, 1.0], [0, 0, 0.8]), np.interp(t, [0, 0.6, 1.2], [0, 0, -0.5]),
                         np.interp(t, [0, 0.1, 0.5, 2], [0, 0, 2.5, 2.5])]) + rng.normal(0, 0.01, (n, 3))
    path = tmp_path_factory.mktemp("plate") / "plate.csv"
    path.write_text("time,fx,fy,fz\n" + "".join(f"{a!r},{b!r},{c!r},{d!r}\n"
                                                for a, (b, c, d) in zip(t.tolist(), (f * 1e3).tolist())))
    pop = sample_population("fingertip", rng=0).select(np.arange(0, 991, 5))
    with pytest.warns(UserWarning, match="FA-II's band"):
        scene = from_csv(path, units="mN")
    offline = simulate(pop, scene, engine="direct", seed=4, quiet=True)
    ids = offline.afferent.values[offline.spike_afferent.values]
    steps = np.round(offline.spike_time.values / DT).astype(np.int64)
    return pop, f * 1e3, ids, steps
