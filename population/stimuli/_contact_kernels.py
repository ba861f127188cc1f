"""Numerical kernels of the contact stage (`ddmm.population.stimuli.contact`); arguments arrive validated.

- `contact_loads`: the per-sample contact solve, one factorisation per set of touching pins;
- `rate`: time derivatives at a sample rate;
- `distance`, `sigma_z_unit`: pin-to-point distances and Sneddon's stress under a flat punch;
- `bilinear`: a heightmap sampled at fractional pixels (scanned surfaces: 4.5 M points a second of a 6 mm
  window at 5 kHz; numpy's gathers took 3 s, the loop takes a few ms);
- `surface_wave`, `delayed_sum`: TouchSim's delayed surface wave.  Every (pin, point) pair has its own
  delay, so grouping pairs by delay and multiplying dense matrices does the work once per distinct delay
  (measured: 3.8 s for one pin and 12,584 points at 5 kHz); the numba loop does it once.
"""

from __future__ import annotations

import numba as nb
import numpy as np

__all__ = ["bilinear", "contact_loads", "delayed_sum", "distance", "rate", "sigma_z_unit", "surface_wave"]


@nb.njit(cache=True, nogil=True)
def bilinear(h: np.ndarray, u: np.ndarray, v: np.ndarray, periodic: bool) -> np.ndarray:
    """``h`` (n_rows, n_cols) at fractional (column ``u``, row ``v``), same-shaped 2-D ``u`` and ``v``: wrapped
    when ``periodic``, 0 outside otherwise."""
    n_rows, n_cols = h.shape
    out = np.zeros(u.shape)
    for i in range(u.shape[0]):
        for j in range(u.shape[1]):
            c0, r0 = np.floor(u[i, j]), np.floor(v[i, j])
            fu, fv = u[i, j] - c0, v[i, j] - r0
            total = 0.0
            for dr in range(2):
                wr = fv if dr else 1.0 - fv
                for dc in range(2):
                    wc = fu if dc else 1.0 - fu
                    r, c = int(r0) + dr, int(c0) + dc
                    if periodic:
                        total += wr * wc * h[r % n_rows, c % n_cols]
                    elif 0 <= r < n_rows and 0 <= c < n_cols:
                        total += wr * wc * h[r, c]
            out[i, j] = total
    return out


@nb.njit(cache=True, nogil=True)
def delayed_sum(rate_t: np.ndarray, lag: np.ndarray, weight: np.ndarray) -> np.ndarray:
    """``out[j, t] = sum_p weight[j, p] * rate_t[p, t - lag[j, p]]`` (terms with ``t < lag`` left out).

    Parameters
    ----------
    rate_t : ndarray, shape (n_pins, n_samples)
        Each pin's signal over time, C-contiguous (time runs fastest).
    lag : ndarray of int64, shape (n_points, n_pins)
        Delay of pin p's signal at point j, in samples (>= 0).
    weight : ndarray, shape (n_points, n_pins)
        Its scale at point j.

    Returns
    -------
    ndarray, shape (n_points, n_samples)

    Examples
    --------
    >>> delayed_sum(np.array([[1.0, 2.0, 3.0]]), np.array([[1]]), np.array([[10.0]])).tolist()
    [[0.0, 10.0, 20.0]]
    """
    n_pins, n_samples = rate_t.shape
    out = np.zeros((lag.shape[0], n_samples))
    for j in range(lag.shape[0]):
        row = out[j]
        for p in range(n_pins):
            k = lag[j, p]
            w = weight[j, p]
            signal = rate_t[p]
            for t in range(k, n_samples):
                row[t] += w * signal[t - k]
    return out


def _row_groups(mask: np.ndarray):
    """Yield (row indices, column indices) for each distinct row pattern of a boolean matrix."""
    packed = np.ascontiguousarray(np.packbits(mask, axis=1))
    keys = packed.view(np.dtype((np.void, packed.shape[1]))).ravel()
    _, first, inverse = np.unique(keys, return_index=True, return_inverse=True)
    order = np.argsort(inverse, kind="stable")
    bounds = np.r_[0, np.cumsum(np.bincount(inverse.ravel(), minlength=first.size))]
    for g, row in enumerate(first):
        yield order[bounds[g]:bounds[g + 1]], np.flatnonzero(mask[row])


def contact_loads(depth: np.ndarray, compliance: np.ndarray) -> np.ndarray:
    """Loads (N) >= 0 per sample: solve over the pins in contact, drop those pulling, solve again."""
    active = depth > 0.0
    loads = np.zeros_like(depth)
    todo = np.flatnonzero(active.any(axis=1))
    while todo.size:
        again = []
        for rows, pins in _row_groups(active[todo]):
            rows = todo[rows]
            block = np.ix_(rows, pins)
            p = np.linalg.solve(compliance[np.ix_(pins, pins)], depth[block].T).T
            pulling = p < 0.0
            loads[block] = np.where(pulling, 0.0, p)
            if pulling.any():
                active[block] = ~pulling
                again.append(rows[pulling.any(axis=1)])
        todo = np.concatenate(again) if again else todo[:0]
        todo = todo[active[todo].any(axis=1)]
    return loads


def rate(values: np.ndarray, fs: float, ends: str) -> np.ndarray:
    """d/dt along axis 0 at fs Hz: central differences inside; at the ends one-sided or (TouchSim) the neighbour's."""
    if values.shape[0] < 2:
        return np.zeros_like(values)
    out = np.gradient(values, 1.0 / fs, axis=0)
    if ends == "copy" and values.shape[0] > 2:
        out[0], out[-1] = out[1], out[-2]
    return out


def surface_wave(load_rate, dist, a, depth, fs, speed) -> np.ndarray:
    """Sum over pins of each pin's delayed load rate times Sneddon's deflection decay, over depth^2."""
    lag = np.rint(np.maximum(dist - a, 0.0) / speed * fs).astype(np.int64)
    decay = np.full(dist.shape, 1.0 / (2.0 * a))
    outside = dist > a
    decay[outside] = np.arcsin(a / dist[outside]) / (np.pi * a)
    weight = np.ascontiguousarray((decay / depth[None, :] ** 2).T)
    return delayed_sum(np.ascontiguousarray(load_rate.T), np.ascontiguousarray(lag.T), weight).T


def distance(x1, y1, x2, y2) -> np.ndarray:
    """Centre distances in mm, shape (len(x1), len(x2))."""
    return np.hypot(x1[:, None] - x2[None, :], y1[:, None] - y2[None, :])


def sigma_z_unit(rho: np.ndarray, xi: np.ndarray) -> np.ndarray:
    """Sneddon's sigma_z * 2 pi a^2 / P at rho = r / a, xi = z / a > 0 (dimensionless)."""
    s = rho ** 2 + xi ** 2 - 1.0
    big_r = np.sqrt(s ** 2 + 4.0 * xi ** 2)
    phi = np.arctan2(2.0 * xi, s)
    theta = np.arctan(1.0 / xi)
    j1 = np.sin(phi / 2.0) / np.sqrt(big_r)
    j2 = np.sqrt(1.0 + xi ** 2) * np.sin(1.5 * phi - theta) / big_r ** 1.5
    return j1 + xi * j2
