"""Numerical kernels of the contact stage (`ddmm.population.stimuli.contact`); arguments arrive validated.

- `contact_loads`: the per-sample contact solve, warm-started from the sample before;
- `rate`: time derivatives at a sample rate; `box_average`: a centred moving average (a scan's pin lattice);
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

__all__ = ["bilinear", "box_average", "contact_loads", "delayed_sum", "distance", "rate", "sigma_z_unit",
           "surface_wave"]


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


_MAX_ROUNDS = 64  # pivoting rounds a sample may take before the drop-only solve takes over
_REBUILD_AFTER = 1024  # pins added or dropped by updates before the inverse is computed afresh
_RESIDUAL = 1e-10  # a solve's first residual, relative to the depths, above which the inverse is computed afresh
_SHARED = 8  # samples that share a set of pins in contact to have it factorised for them (else: updates)


@nb.njit(cache=True, nogil=True)
def _deflection(compliance, cols, load):
    """Skin deflection (mm) at every pin under the loads ``load`` (N) on the pins ``cols``.

    Sums whole rows (the compliance is symmetric), which streams memory where a column gather would not."""
    out = np.zeros(compliance.shape[0])
    for j in range(cols.size):
        row, p = compliance[cols[j]], load[j]
        for i in range(out.size):
            out[i] += p * row[i]
    return out


@nb.njit(cache=True, nogil=True)
def _kept_block(inverse, keep):
    """``inverse[keep][:, keep]``, gathered in one pass."""
    out = np.empty((keep.size, keep.size))
    for i in range(keep.size):
        src = inverse[keep[i]]
        for j in range(keep.size):
            out[i, j] = src[keep[j]]
    return out


class _ContactInverse:
    """The inverse of ``compliance`` over the pins in contact, updated as pins join and leave the set.

    A scan's contact set changes by a few pins a sample (2 a sample, 23 at the 90th percentile, of 362-1,600
    in contact, in the letters scanned pressed by their base), so a rank-k update (Schur complements) costs a
    few k n^2 where a factorisation costs n^3 / 3; one step of iterative refinement against the compliance
    itself keeps each solve as accurate as a direct one.
    """

    def __init__(self, compliance: np.ndarray):
        self.compliance = compliance
        self.idx = np.zeros(0, dtype=np.intp)
        self.inverse = np.zeros((0, 0))
        self._updated = 0

    def set_to(self, active: np.ndarray) -> None:
        """Make the inverse that of the pins ``active`` (a boolean mask)."""
        current = np.zeros(active.size, dtype=bool)
        current[self.idx] = True
        leave, join = np.flatnonzero(current & ~active), np.flatnonzero(active & ~current)
        n_change = leave.size + join.size
        if not n_change:
            return
        if self._updated + n_change > _REBUILD_AFTER or 4 * n_change > max(self.idx.size, 16):
            self._rebuild(np.flatnonzero(active))
            return
        if leave.size:
            self._drop(np.isin(self.idx, leave))
        if join.size:
            self._add(join)
        self._updated += n_change

    def _rebuild(self, idx: np.ndarray) -> None:
        """The inverse over the pins ``idx`` computed afresh."""
        self.idx = idx
        self.inverse = np.linalg.inv(self.compliance[np.ix_(idx, idx)])
        self._updated = 0

    def _drop(self, out: np.ndarray) -> None:
        """Remove the positions ``out`` (mask over idx): M_SS - M_SX M_XX^-1 M_XS."""
        keep, gone = np.flatnonzero(~out), np.flatnonzero(out)
        m = self.inverse
        w = np.linalg.solve(m[np.ix_(gone, gone)], m[np.ix_(gone, keep)])
        self.inverse = _kept_block(m, keep)
        self.inverse -= m[np.ix_(keep, gone)] @ w
        self.idx = self.idx[keep]

    def _add(self, join: np.ndarray) -> None:
        """Border the inverse with the pins ``join`` through the Schur complement of the old set."""
        c = self.compliance
        b = c[np.ix_(self.idx, join)]
        mb = self.inverse @ b
        schur_inv = np.linalg.inv(c[np.ix_(join, join)] - b.T @ mb)
        corner = mb @ schur_inv
        n = self.idx.size
        new = np.empty((n + join.size, n + join.size))
        new[:n, :n] = self.inverse + corner @ mb.T
        new[:n, n:] = -corner
        new[n:, :n] = -corner.T
        new[n:, n:] = schur_inv
        self.inverse, self.idx = new, np.concatenate([self.idx, join])

    def solve(self, depth: np.ndarray) -> np.ndarray:
        """Loads (N) on the pins ``idx`` that give them the depths ``depth[idx]`` (mm), refined once.

        Updates let rounding errors in the inverse grow (measured: a residual of 2.5e-13 of the depths after 500-1000
        pins changed, 3e-7 after 1000-2000, 0.2 beyond), so a solve whose first residual exceeds `_RESIDUAL`
        of the depths computes the inverse afresh first.
        """
        d = depth[self.idx]
        bound = _RESIDUAL * max(float(np.abs(d).max(initial=0.0)), 1e-300)
        p = self.inverse @ d
        residual = d - _deflection(self.compliance, self.idx, p)[self.idx]
        if np.abs(residual).max(initial=0.0) > bound and self._updated:
            self._rebuild(self.idx)
            p = self.inverse @ d
            residual = d - _deflection(self.compliance, self.idx, p)[self.idx]
        return p + self.inverse @ residual


def _sample_loads(depth, touching, active, contact, tol):
    """(loads, active) of one sample: loads >= 0 under which no touching pin out of contact sinks below the skin.

    Block pivoting from the set ``active``: solve over the set and drop the pins pulling; when none pulls, add
    the touching pins the others' loads leave above their depth (the skin not pressed down to them), and
    solve again.  Returns None when it has not settled in `_MAX_ROUNDS` rounds.
    """
    for _ in range(_MAX_ROUNDS):
        contact.set_to(active)
        p = contact.solve(depth)
        if (p < 0.0).any():
            active = active.copy()
            active[contact.idx[p < 0.0]] = False
            continue
        out = np.flatnonzero(touching & ~active)
        sinking = out[_deflection(contact.compliance, contact.idx, p)[out] < depth[out] - tol]
        if not sinking.size:
            load = np.zeros_like(depth)
            load[contact.idx] = p
            return load, active
        active = active.copy()
        active[sinking] = True
    return None


def _dropped_loads(depth, touching, contact):
    """(loads, active) of one sample by dropping the pins pulling until none does (TouchSim's way)."""
    active, load = touching.copy(), np.zeros_like(depth)
    while active.any():
        contact.set_to(active)
        p = contact.solve(depth)
        if not (p < 0.0).any():
            load[contact.idx] = p
            break
        active[contact.idx[p < 0.0]] = False
    return load, active


def _row_groups(mask: np.ndarray):
    """Yield (row indices, column indices) for each distinct row pattern of a boolean matrix."""
    packed = np.ascontiguousarray(np.packbits(mask, axis=1))
    keys = packed.view(np.dtype((np.void, packed.shape[1]))).ravel()
    _, first, inverse = np.unique(keys, return_index=True, return_inverse=True)
    order = np.argsort(inverse, kind="stable")
    bounds = np.r_[0, np.cumsum(np.bincount(inverse.ravel(), minlength=first.size))]
    for g, row in enumerate(first):
        yield order[bounds[g]:bounds[g + 1]], np.flatnonzero(mask[row])


def _shared_set_loads(depth, compliance, loads, tol) -> np.ndarray:
    """Solve the samples whose set of pins in contact at least `_SHARED` samples share, a solve per set; returns
    the mask of samples left to `contact_loads`' sequence (their set is their own).

    From every touching pin, a sample whose loads pull drops those pins and is grouped again; a group that
    settles is checked that no touching pin out of contact sinks below the skin (else it joins the sequence).
    """
    active = depth > 0.0
    left = np.zeros(depth.shape[0], dtype=bool)
    todo = np.flatnonzero(active.any(axis=1))
    while todo.size:
        again = []
        for rows, pins in _row_groups(active[todo]):
            rows = todo[rows]
            if rows.size < _SHARED:
                left[rows] = True
                continue
            p = np.linalg.solve(compliance[np.ix_(pins, pins)], depth[np.ix_(rows, pins)].T).T
            pulling = (p < 0.0).any(axis=1)
            again.append(rows[pulling])
            active[np.ix_(rows[pulling], pins)] = p[pulling] >= 0.0
            done, p = rows[~pulling], p[~pulling]
            sinks = (p @ compliance[pins] < depth[done] - tol).any(axis=1)  # in contact: equal; untouching: above
            loads[np.ix_(done, pins)] = p
            left[done[sinks]] = True
        todo = np.concatenate(again) if again else todo[:0]
        todo = todo[active[todo].any(axis=1)]
    return left


def contact_loads(depth: np.ndarray, compliance: np.ndarray) -> np.ndarray:
    """Loads (N) >= 0 per sample, shape of ``depth``: no pin pulls, and no touching pin out of contact sinks below
    the skin.

    Sets of pins in contact that many samples share (a probe, a periodic grating) are solved once for them all
    (`_shared_set_loads`); the other samples, in order, each start from the sample before's set and update
    the inverse of the compliance over it (`_ContactInverse`), or drop pins from their touching ones when
    that does not settle in `_MAX_ROUNDS` rounds.
    """
    loads = np.zeros_like(depth)
    compliance = np.ascontiguousarray(compliance, dtype=float)
    tol = 1e-12 * max(float(np.abs(depth).max(initial=0.0)), 1e-300)
    left = _shared_set_loads(depth, compliance, loads, tol)
    contact = _ContactInverse(compliance)
    for s in np.flatnonzero(left):
        row = depth[s]
        touching = row > 0.0
        start = touching & (loads[s - 1] > 0.0) if s else touching
        solved = _sample_loads(row, touching, start if start.any() else touching, contact, tol)
        loads[s] = (solved if solved is not None else _dropped_loads(row, touching, contact))[0]
    return loads


_BOX_COLUMNS = 256  # columns averaged at a time: the padded copies stay a few MB


def box_average(values: np.ndarray, fs: float, length_s: float, out: np.ndarray | None = None) -> np.ndarray:
    """``values`` (time on axis 0) averaged over a centred window of ``length_s`` seconds, fractional samples
    included (the trapezoidal integral interpolated), the ends held beyond the record; its response is zero at
    every multiple of ``1 / length_s``.  Written to ``out`` (``values`` itself allowed: the columns go a block at
    a time); a window under one sample copies ``values``.

    Examples
    --------
    >>> box_average(np.array([0.0, 0.0, 3.0, 0.0, 0.0]), 1.0, 3.0).tolist()  # the samples joined by lines
    [0.25, 0.75, 1.0, 0.75, 0.25]
    """
    out = np.empty_like(values) if out is None else out
    half = 0.5 * length_s * fs  # samples
    if 2.0 * half < 1.0:
        out[...] = values
        return out
    flat_in, flat_out = values.reshape(values.shape[0], -1), out.reshape(values.shape[0], -1)
    for c in range(0, flat_in.shape[1], _BOX_COLUMNS):
        flat_out[:, c:c + _BOX_COLUMNS] = _box_block(flat_in[:, c:c + _BOX_COLUMNS], half)
    return out


def _box_block(x: np.ndarray, half: float) -> np.ndarray:
    """`box_average` of the columns ``x`` over ``2 half`` samples (>= 1)."""
    k, frac = int(half), half - int(half)
    pad = k + 2
    x = np.concatenate([np.repeat(x[:1], pad, axis=0), x, np.repeat(x[-1:], pad, axis=0)])
    integral = np.concatenate([np.zeros_like(x[:1]), np.cumsum(0.5 * (x[1:] + x[:-1]), axis=0)])
    n = np.arange(x.shape[0] - 2 * pad) + pad
    upper = integral[n + k] + frac * (integral[n + k + 1] - integral[n + k])
    lower = integral[n - k] - frac * (integral[n - k] - integral[n - k - 1])
    return (upper - lower) / (2.0 * half)


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
