"""A synthetic dataset in the simulator's schema, for analytic decoder and tuning tests."""

import numpy as np
import xarray as xr


def cosine_dataset(directions_deg, theta_t_deg, *, peak=40, base=20, latency_s=None, nap="selective",
                   window_s=0.2, duration=0.5, fs=1000.0):
    """Noiseless cosine-tuned afferents: count = round(base + (peak - base) * (1 + cos) / 2).

    Spikes are spread evenly over [onset, onset + window); with ``latency_s``
    (a function of the angle difference) the first spike sits at that latency.
    """
    directions = np.asarray(directions_deg, float)
    theta = np.asarray(theta_t_deg, float)
    n_c, n_a = directions.size, theta.size
    diff = np.deg2rad(directions[:, None] - theta[None, :])
    counts = np.round(base + (peak - base) * (1 + np.cos(diff)) / 2).astype(int)
    onset = 2.0 / fs
    t, c, a = [], [], []
    for ci in range(n_c):
        for ai in range(n_a):
            first = onset + (latency_s(diff[ci, ai]) if latency_s else 0.0)
            times = first + np.arange(counts[ci, ai]) * (window_s - (first - onset)) / max(counts[ci, ai], 1)
            t.append(times)
            c.append(np.full(times.size, ci))
            a.append(np.full(times.size, ai))
    t, c, a = np.concatenate(t), np.concatenate(c), np.concatenate(a)
    order = np.lexsort((a, t, c))
    n_time = int(duration * fs)
    fz = np.tile(np.where(np.arange(n_time) / fs >= onset, 4.0, 0.0), (n_c, 1))  # contact at the onset
    return xr.Dataset(
        {"spike_count": (("condition", "trial", "afferent"), counts[:, None, :]),
         "spike_time": ("spike", t[order]), "spike_afferent": ("spike", a[order].astype(np.int32)),
         "spike_trial": ("spike", np.zeros(t.size, np.int32)),
         "spike_condition": ("spike", c[order].astype(np.int32)),
         "fz": (("condition", "time"), fz)},
        coords={"condition": [f"c{i}" for i in range(n_c)], "trial": [0], "afferent": np.arange(n_a),
                "afferent_type": ("afferent", np.array(["SAI"] * n_a, dtype=object)),
                "theta_t": ("afferent", theta), "nap": ("afferent", np.array([nap] * n_a, dtype=object)),
                "duration": ("condition", np.full(n_c, duration)), "theta_r": ("condition", directions % 360.0),
                "has_theta_r": ("condition", np.ones(n_c, np.int8)), "time": np.arange(n_time) / fs})
