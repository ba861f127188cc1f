"""Pulse trains safe by construction: commands of a rule -> biphasic pulses within every limit.

At each model sample of length 1 / fs, an electrode has the force under its
field, a commanded rate and a commanded amplitude (`ddmm.population.neurostim.rules`).
A phase accumulator integrates the commanded rate; a pulse starts where the
phase crosses 1 (placed exactly inside the sample, the rate held constant
over it).  Because the commanded rate never exceeds ``max_rate_hz``, two
crossings are at least ``1 / max_rate_hz`` apart; a final check drops any
pulse closer than that to the one before (float rounding), so the limit
holds exactly.  Out of contact (force under the field <= 0.05 N) the phase
is reset and no pulse starts.  Every amplitude lies in
``[amplitude_min_ua, amplitude_max_ua]`` and, by the table's own check, its
charge per phase within ``charge_limit_nc``.  Pulses are charge-balanced
biphasic: cathodic phase, ``interphase_us``, anodic phase, equal widths and
amplitudes, so the net charge of every pulse is zero.

The kernel is causal and keeps its state (smoothed rate, phase, last pulse,
each afferent's last spike) between calls, so a stream and an offline run of
the same spikes and forces give the same pulses, bit for bit.
"""

from __future__ import annotations

import math
from typing import NamedTuple

import numba as nb
import numpy as np

from ddmm.models.metrics import CONTACT_THRESHOLD
from ddmm.population.neurostim.electrodes import ElectrodeTable
from ddmm.population.neurostim.rules import RULES
from ddmm.utils.validation import check_instance, check_positive

__all__ = ["PulseKernel", "field_weights", "contact_weights", "disc_overlap"]


def disc_overlap(d, r_field, r_site) -> np.ndarray:
    """Fraction of a site's disc (radius ``r_site``) inside a field disc (``r_field``), centres ``d`` apart (mm)."""
    d, r1, r2 = np.broadcast_arrays(np.asarray(d, float), np.asarray(r_field, float), np.asarray(r_site, float))
    out = np.zeros(d.shape)
    inside = d <= np.abs(r1 - r2)
    out[inside] = np.minimum(r1[inside], r2[inside]) ** 2 / r2[inside] ** 2
    part = ~inside & (d < r1 + r2)
    if np.any(part):
        a, b, c = d[part], r1[part], r2[part]
        alpha = np.arccos(np.clip((a ** 2 + b ** 2 - c ** 2) / (2 * a * b), -1, 1))
        beta = np.arccos(np.clip((a ** 2 + c ** 2 - b ** 2) / (2 * a * c), -1, 1))
        area = b ** 2 * (alpha - np.sin(2 * alpha) / 2) + c ** 2 * (beta - np.sin(2 * beta) / 2)
        out[part] = area / (np.pi * c ** 2)
    return out


def field_weights(table, x_mm, y_mm, radius_mm, region) -> np.ndarray:
    """(n_electrodes, n_sites): the fraction of each site's footprint inside each field.

    A disc field takes the area overlap; a region field takes the sites whose
    region starts with its name, whole.  A site with radius ``inf`` is the
    whole skin (every field takes all of it).
    """
    check_instance(table, "table", ElectrodeTable, "an ElectrodeTable")
    x, y, r = (np.atleast_1d(np.asarray(v, float)) for v in (x_mm, y_mm, radius_mm))
    region = np.atleast_1d(np.asarray(region, dtype=object)).astype(str)
    out = np.zeros((len(table), x.size))
    whole = ~np.isfinite(r)
    for i, e in enumerate(table):
        out[i, whole] = 1.0
        if e.region is not None:
            out[i, ~whole] = np.char.startswith(region[~whole], e.region)
        else:
            out[i, ~whole] = disc_overlap(np.hypot(x[~whole] - e.x_mm, y[~whole] - e.y_mm), e.radius_mm, r[~whole])
    return out


def contact_weights(table, x_mm: float, y_mm: float, radius_mm: float) -> np.ndarray:
    """(n_electrodes,): the share of one contact's force under each field.

    The contact is a disc whose region is the hand-map region at its centre;
    a radius that is NaN or None means no contact geometry: the force acts on
    the whole skin, and every field takes all of it.
    """
    from ddmm.population.anatomy.hand_map import region_at

    if radius_mm is None or not np.isfinite(radius_mm):
        return field_weights(table, [0.0], [0.0], [np.inf], [""])[:, 0]
    return field_weights(table, [x_mm], [y_mm], [radius_mm], [str(region_at(x_mm, y_mm))])[:, 0]


def _csr(lists, n_items: int):
    """Forward CSR of ``lists`` (one array of item positions per electrode) and its reverse (electrodes per item)."""
    indptr = np.zeros(len(lists) + 1, np.int64)
    indptr[1:] = np.cumsum([len(m) for m in lists])
    members = np.concatenate([np.asarray(m, np.int64) for m in lists]) if lists else np.empty(0, np.int64)
    owners = np.repeat(np.arange(len(lists)), np.diff(indptr))
    order = np.argsort(members, kind="stable")
    back_ptr = np.zeros(n_items + 1, np.int64)
    np.add.at(back_ptr, members + 1, 1)
    return indptr, members, np.cumsum(back_ptr), owners[order]


class _Wiring(NamedTuple):
    """The fixed tables of one `PulseKernel`: which afferents feed which field, the limits, the rule.

    Attributes
    ----------
    weights : ndarray, shape (n_afferents,)
        Each afferent's spike weight.
    indptr, members : ndarray of int64
        CSR of the afferent positions of each electrode's field (``indptr`` (n_electrodes + 1,)).
    back_ptr, back : ndarray of int64
        The reverse CSR: the electrodes each afferent feeds (``back_ptr`` (n_afferents + 1,)).
    limits : ndarray, shape (n_electrodes, 4)
        Per electrode: amplitude_min_ua, amplitude_max_ua, max_rate_hz, phase_width_us.
    params : ndarray
        The rule's parameters (`rules`' ``params()``).
    code : int
        The rule's code (0 biomimetic, 1 linear amplitude, 2 linear frequency).
    contact : float
        The contact threshold on the force under a field, N.
    fs : float
        Model sample rate, Hz.
    """

    weights: np.ndarray
    indptr: np.ndarray
    members: np.ndarray
    back_ptr: np.ndarray
    back: np.ndarray
    limits: np.ndarray
    params: np.ndarray
    code: int
    contact: float
    fs: float


class _KernelState(NamedTuple):
    """The state a `PulseKernel` carries between calls (arrays, updated in place).

    Attributes
    ----------
    rate : ndarray, shape (n_electrodes,)
        Smoothed aggregate spike rate per electrode, Hz.
    phase : ndarray, shape (n_electrodes,)
        Phase accumulator per electrode (a pulse starts where it crosses 1).
    last_pulse : ndarray, shape (n_electrodes,)
        Time of each electrode's last pulse, s (-inf: none yet).
    last_spike : ndarray of int64, shape (n_afferents,)
        Model sample of each afferent's last spike.
    """

    rate: np.ndarray
    phase: np.ndarray
    last_pulse: np.ndarray
    last_spike: np.ndarray


class _PulseBuffers(NamedTuple):
    """The buffers one `PulseKernel.advance` fills (the pulses up to the count the kernel returns).

    Attributes
    ----------
    time : ndarray, shape (n_max,)
        Pulse start times, s.
    electrode : ndarray of int64, shape (n_max,)
        Pulse electrodes (positions in the table).
    amplitude : ndarray, shape (n_max,)
        Pulse amplitudes, uA.
    traces : ndarray, shape (3, n, n_electrodes)
        Rate command (Hz), amplitude command (uA) and aggregate rate (Hz) per sample.
    """

    time: np.ndarray
    electrode: np.ndarray
    amplitude: np.ndarray
    traces: np.ndarray


class PulseKernel:
    """The pulse generator of one electrode table on one set of afferents (state: real, carried between calls).

    Parameters
    ----------
    table : ElectrodeTable
    rule : Biomimetic, LinearAmplitude or LinearFrequency
    fs : float
        Model sample rate, Hz (commands change once per sample).
    members : list of ndarray
        Per electrode, the positions (on the afferent axis used for spikes) of its field's afferents.
    weights : ndarray, shape (n_afferents,)
        Each afferent's spike weight (the rule's ``type_weights``).
    """

    def __init__(self, table, rule, fs: float, members, weights):
        check_instance(table, "table", ElectrodeTable, "an ElectrodeTable")
        check_instance(rule, "rule", tuple(RULES.values()), f"a rule object ({', '.join(RULES)})")
        if not hasattr(members, "__len__") or len(members) != len(table):
            raise ValueError(f"members must hold one array of afferent positions per electrode ({len(table)})")
        self.table, self.rule, self.fs = table, rule, check_positive(fs, "fs", "Hz")
        n_aff = int(np.asarray(weights).size)
        self._indptr, self._members, self._back_ptr, self._back = _csr(members, n_aff)
        self._weights = np.ascontiguousarray(weights, dtype=float)
        self._limits = np.stack([table.column("amplitude_min_ua"), table.column("amplitude_max_ua"),
                                 table.column("max_rate_hz"), table.column("phase_width_us")], axis=1)
        self._params = rule.params()
        self._wiring = _Wiring(self._weights, self._indptr, self._members, self._back_ptr, self._back, self._limits,
                              self._params, int(self.rule.code), CONTACT_THRESHOLD, self.fs)
        self.reset()

    def reset(self) -> None:
        """Back to the start: no rate, no phase, no pulse yet, no spike seen."""
        n_e = len(self.table)
        self._state = _KernelState(np.zeros(n_e), np.zeros(n_e), np.full(n_e, -np.inf),
                                   np.full(self._weights.size, np.iinfo(np.int64).min // 2, np.int64))
        self._k = 0

    def advance(self, field_force, spike_sample, spike_afferent):
        """Consume ``n`` samples: forces under the fields (n, n_electrodes), N, and the spikes in them.

        ``spike_sample`` are absolute model-sample indices (sorted), ``spike_afferent``
        positions on the afferent axis.  Returns ``(time_s, electrode, amplitude_ua)`` of the
        pulses and the traces ``(rate_command_hz, amplitude_command_ua, aggregate_rate_hz)``,
        each (n, n_electrodes).
        """
        force = np.ascontiguousarray(field_force, dtype=float)
        n = force.shape[0]
        n_max = int(n * len(self.table) * (math.ceil(float(self._limits[:, 2].max()) / self.fs) + 1))
        out = _PulseBuffers(np.empty(n_max), np.empty(n_max, np.int64), np.empty(n_max),
                            np.zeros((3, n, len(self.table))))
        count = _advance(self._k, force, np.ascontiguousarray(spike_sample, np.int64),
                         np.ascontiguousarray(spike_afferent, np.int64), self._wiring, self._state, out)
        self._k += n
        return (out.time[:count], out.electrode[:count], out.amplitude[:count]), out.traces


@nb.njit(cache=True)
def _commands(code, e, force, rate, active_frac, limits, params, contact):
    """(rate command Hz, amplitude command µA) of electrode ``e`` for one sample."""
    a_min, a_max, max_rate = limits[e, 0], limits[e, 1], limits[e, 2]
    if force <= contact:
        return 0.0, a_min
    span = (force - contact) / max(params[5] - contact, 1e-12)
    span = min(max(span, 0.0), 1.0)
    if code == 0:
        return max_rate * min(rate / params[1], 1.0), _between(a_min, a_max, min(active_frac / params[3], 1.0))
    if code == 1:
        return min(params[4], max_rate), _between(a_min, a_max, span)
    return max_rate * span, _between(a_min, a_max, params[6])


@nb.njit(cache=True, inline="always")
def _between(a_min, a_max, x):
    """``a_min + (a_max - a_min) x`` for x in [0, 1], never above ``a_max`` (the sum can round one ulp over)."""
    return min(a_min + (a_max - a_min) * x, a_max)


@nb.njit(cache=True)
def _pulses(e, t0, t1, f, amp, min_interval, state, out, count):
    """Place the pulses of electrode ``e`` in [t0, t1) at rate ``f``; returns the new count.

    ``state`` (`_KernelState`: its ``phase`` and ``last_pulse``) is updated; the pulses go to ``out``
    (`_PulseBuffers`) from position ``count`` on.
    """
    phase, last_pulse, out_t, out_e, out_a = state.phase, state.last_pulse, out.time, out.electrode, out.amplitude
    t = t0
    while f > 0.0:
        need = (1.0 - phase[e]) / f
        if t + need >= t1:
            phase[e] += f * (t1 - t)
            break
        t += need
        phase[e] = 0.0
        if t - last_pulse[e] >= min_interval:  # exact limit, whatever the rounding above
            out_t[count], out_e[count], out_a[count] = t, e, amp
            last_pulse[e] = t
            count += 1
    return count


@nb.njit(cache=True)
def _advance(k0, force, spike_sample, spike_aff, wiring, state, out):
    """Consume the samples ``k0 ..`` of ``force`` (n, n_electrodes) and their spikes; returns the pulse count.

    ``wiring`` is a `_Wiring`, ``state`` a `_KernelState` (updated in place), ``out`` a `_PulseBuffers` (filled).
    """
    weights, indptr, members, back_ptr, back, limits, params, code, contact, fs = wiring
    rate, phase, last_spike, traces = state.rate, state.phase, state.last_spike, out.traces
    n, n_e = force.shape
    decay = math.exp(-1.0 / (fs * params[0]))
    window = max(int(round(params[2] * fs)), 1)
    weighted = np.zeros(n_e)
    j, count = 0, 0
    for i in range(n):
        k = k0 + i
        weighted[:] = 0.0
        while j < spike_sample.size and spike_sample[j] == k:
            a = spike_aff[j]
            last_spike[a] = k
            for q in range(back_ptr[a], back_ptr[a + 1]):
                weighted[back[q]] += weights[a]
            j += 1
        for e in range(n_e):
            size = indptr[e + 1] - indptr[e]
            if size > 0:
                rate[e] = decay * rate[e] + (1.0 - decay) * weighted[e] * fs / size
            active = 0
            if code == 0:
                for q in range(indptr[e], indptr[e + 1]):
                    if k - last_spike[members[q]] < window:
                        active += 1
            f, amp = _commands(code, e, force[i, e], rate[e], active / max(size, 1), limits, params, contact)
            if force[i, e] <= contact:
                phase[e] = 0.0
            count = _pulses(e, k / fs, (k + 1) / fs, f, amp, 1.0 / limits[e, 2], state, out, count)
            traces[0, i, e], traces[1, i, e], traces[2, i, e] = f, amp, rate[e]
    return count
