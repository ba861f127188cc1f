"""The pipeline from force to spikes fused into two numba passes over samples (the streaming hot path).

The per-stage functions (`ddmm.models.attenuation`, `ddmm.models.currents`,
`ddmm.models.engines`) stay the definition of the model.  `FusedPipeline` runs the
same arithmetic, sample by sample, with every per-call constant packed once
into tables:

1. **front** (one numba pass): shear magnitude and direction, each
   afferent's profile AF (`attenuation.profile_value`), the no-shear
   reading, F_A (with the presets' shear-magnitude term) or SA-II's stretch drive, then the type's linear stage
   (`_stage_kernels.filter_sections` and `stage_tail`: filter, derivative,
   adaptation, gain, receptor noise);
2. **transducers**: numpy's vectorised log1p/tanh on each type's columns (a
   scalar libm call in numba would differ in the last bit from numpy's SIMD
   ones, and is several times slower);
3. **back** (one numba pass): the current's low-pass, the bias and the
   additive noise, then the direct engine's integrator.

The per-sample drive of the front pass (table layout, shear, profile AF, F_A or
stretch, site mixing) is in `ddmm.models._fused_drive`.

For the streaming encoder's large populations, both passes also run on
afferent ranges in parallel (`_front_parts`, `ddmm.models.engines.direct.integrate_parts`):
afferents are independent, so the bits are the same.

Because the scalar helpers are the very functions the per-stage kernels
call, and every operation keeps their order, the result is bit-identical to
the stage-by-stage path (``tests/population/test_stream.py`` holds the
streaming encoder, which runs on this, to the offline `simulate`).
"""

from __future__ import annotations

import numba as nb
import numpy as np

from ddmm.models._fused_drive import (
    _ADAPT,
    _ALPHA_ADAPT,
    _ALPHA_DYN,
    _ALPHA_RISE,
    _ALPHA_SMOOTH,
    _ALPHA_TRANSIENT,
    _BIAS,
    _COS,
    _CV,
    _DEAD,
    _DEPTH,
    _DYN,
    _DYNC,
    _FALL,
    _FASTC,
    _GAIN,
    _K,
    _N_AFF_ROWS,
    _N_GRP_ROWS,
    _N_STATE,
    _NEGATIVE,
    _NO_FORCES,
    _NO_NORMALS,
    _NO_SITES,
    _NO_WEIGHTS,
    _NOISY,
    _NSEC,
    _OFFSET,
    _OPP_SHEAR,
    _ORDER,
    _P1,
    _P5,
    _PLAIN,
    _RANGE,
    _RISEC,
    _SHEAR_G,
    _SIGMA,
    _SIGNED,
    _SIN,
    _SLICE,
    _SLOW,
    _SMOOTH,
    _SMOOTHED,
    _START,
    _STOP,
    _THRESHOLD,
    _TIP,
    _TRANSIENT,
    _TONIC,
    _TUNED_G,
    _Y1,
    _Y2,
    _local_drive,
    _mix_sample,
    _shared_drive,
    _shear,
    mix_forces,
    mixing_matrix,
)
from ddmm.models._stage_kernels import (
    dynamic_step,
    filter_sections,
    receptor_noise_keyed,
    stage_tail,
    transduce_columns,
    transduce_inplace,
)
from ddmm.models.afferent_types import type_mask
from ddmm.models.attenuation import UNTUNED
from ddmm.models.currents import excitability, initial_phase, tonic_current, type_filter_constants, unit_thresholds
from ddmm.models.engines import NeuronState, check_integration, check_stability, get_engine, run_checked, substeps_for
from ddmm.models.engines.direct import BLOCK, METHOD_CODES, integrate_parts, integrate_range, part_bounds, spike_checks
from ddmm.models.nap import get_profile, tip_radius
from ddmm.models.neuron import V_FLOOR, V_PEAK, neuron_arrays, refractory_steps, resting_state
from ddmm.models.rng import normal_row

__all__ = ["FusedPipeline", "mix_forces", "mixing_matrix"]

#: Rows (samples) of a drive from which the transducers run fused (`transduce_columns`): below, its
#: per-call set-up costs more than numpy's few passes save (a streaming push is one row).
_FUSED_ROWS = 64


@nb.njit(cache=True, nogil=True)
def _front(forces, sites, weights, mixed, key, noisy_any, ids, sample0, state, started, aff_f, grp_f, grp_i,
           sos, fs, smooth_reading, outside_value, f_th, opponent, normal, out):
    """Force to linear drive into ``out`` (n, n_afferents); ``state`` in place (`_front_range` on every afferent).

    Afferents go in ranges of `_RANGE`, whose state and scratch stay in
    cache over all samples (one range of Brian2's 4096-wide blocks cost
    about twice as much per afferent-sample).
    """
    m = aff_f.shape[1]
    for a0 in range(0, m, _RANGE):
        _front_range(forces, sites, weights, mixed, key, noisy_any, ids, sample0, state, started, aff_f,
                     grp_f, grp_i, sos, fs, smooth_reading, outside_value, f_th, opponent, normal, out, a0,
                     min(m, a0 + _RANGE))
    return out


@nb.njit(cache=True, nogil=True, parallel=True)
def _front_parts(forces, sites, weights, mixed, key, noisy_any, ids, sample0, state, started, aff_f, grp_f,
                 grp_i, sos, fs, smooth_reading, outside_value, f_th, opponent, normal, out, bounds):
    """`_front` with the afferent ranges ``bounds[p]..bounds[p+1]`` in parallel (afferents are independent)."""
    for p in nb.prange(bounds.size - 1):
        _front_range(forces, sites, weights, mixed, key, noisy_any, ids, sample0, state, started, aff_f,
                     grp_f, grp_i, sos, fs, smooth_reading, outside_value, f_th, opponent, normal, out, bounds[p],
                     bounds[p + 1])
    return out


@nb.njit(cache=True, nogil=True)
def _front_range(forces, sites, weights, mixed, key, noisy_any, ids, sample0, state, started, aff_f, grp_f,
                 grp_i, sos, fs, smooth_reading, outside_value, f_th, opponent, normal, out, a0, a1):
    """Force to linear drive of the afferents ``a0..a1`` into ``out`` (n, n_afferents); their ``state`` in place.

    ``forces`` (n, 3) is felt by every afferent, or with ``mixed`` each
    afferent feels its own mix (``weights``, (n_sites, n_afferents)) of the
    site forces ``sites`` (n, n_sites, 3), mixed here sample by sample.  Groups (runs of
    one type, tuned or not) are the outer loop, so each inner loop over
    afferents has loop-invariant constants and branches.
    """
    n, m, rows = out.shape[0], aff_f.shape[1], 2 * sos.shape[1]
    z, offset = state[:rows], state[rows + _OFFSET]
    y1, y2, slow = state[rows + _Y1], state[rows + _Y2], state[rows + _SLOW]
    f, words, xi, af = np.empty(m), np.empty(m, np.uint64), np.empty(m), np.empty(m)
    mags, wts, local = np.empty(m), np.empty(m), np.empty((3, m))
    gain, cv_scale, dead, two_fth = aff_f[_GAIN], aff_f[_CV], aff_f[_DEAD], 2.0 * f_th
    af_ux, af_uy = np.full(grp_i.shape[1], np.nan), np.full(grp_i.shape[1], np.nan)  # direction of each group's af
    for i in range(n):
        fz, mag, ux, uy, w = 0.0, 0.0, 0.0, 0.0, 0.0
        if mixed:
            _mix_sample(sites[i], weights, local, a0, a1)
        else:
            fz = forces[i, 2]
            mag, ux, uy, w = _shear(forces[i, 0], forces[i, 1], two_fth)
        for g in range(grp_i.shape[1]):
            lo, hi = max(a0, grp_i[_START, g]), min(a1, grp_i[_STOP, g])
            if lo >= hi:
                continue
            tuned, stretch = grp_i[_TUNED_G, g] != 0, grp_i[_SIGNED, g] != 0
            shear_g, opp_s, depth = grp_f[_SHEAR_G, g], grp_f[_OPP_SHEAR, g], grp_f[_DEPTH, g]
            if mixed:
                _local_drive(f, lo, hi, local, aff_f, tuned, stretch, two_fth, smooth_reading, outside_value,
                             f_th, opponent, normal, mags, wts, shear_g, opp_s, depth)
            elif not tuned and not stretch and shear_g == 0.0:
                f[lo:hi] = fz  # untuned pressure afferents: F_A = F_Z
            else:
                profiled = tuned and mag > 0.0 and (smooth_reading or stretch or shear_g != 0.0 or mag > f_th)
                cached = profiled and ux == af_ux[g] and uy == af_uy[g]
                _shared_drive(f, lo, hi, aff_f, tuned, stretch, fz, mag, ux, uy, w, smooth_reading, outside_value,
                              f_th, opponent, normal, af, cached, shear_g, opp_s, depth)
                if profiled:
                    af_ux[g], af_uy[g] = ux, uy
            if i == 0 and not started and grp_i[_PLAIN, g] == 0:
                offset[lo:hi] = f[lo:hi]  # `initial_filter_state`: at rest on the first sample
            f[lo:hi] -= offset[lo:hi]
            filter_sections(f, lo, hi, sos, g, grp_i[_NSEC, g], z)
            stage_tail(f, lo, hi, offset, y1, y2, slow, fs, grp_i[_ORDER, g], grp_f[_ADAPT, g],
                       grp_f[_ALPHA_ADAPT, g], grp_f[_THRESHOLD, g] > 0.0, dead, grp_f[_NEGATIVE, g], gain,
                       _NO_NORMALS, i, cv_scale, False, grp_i[_SIGNED, g] != 0)
            if noisy_any and grp_i[_NOISY, g] != 0:
                receptor_noise_keyed(f, lo, hi, key, ids, sample0 + i, cv_scale, grp_i[_SIGNED, g] != 0, words,
                                     xi)
        out[i, a0:a1] = f[a0:a1]


@nb.njit(cache=True, nogil=True)
def _back(current, key, additive, ids, sample0, state, rows, aff_f, grp_f, grp_i, sigma_idx, track=True):
    """Low-pass, bias and additive noise of the transduced drive, in place; returns the smallest current
    (with ``track``; else inf).

    Additive noise is drawn for the afferents ``sigma_idx`` (those with
    sigma > 0) only: adding 0 * xi would leave every other current as it is.
    """
    smooth, dync = state[rows + _SMOOTH], state[rows + _DYNC]
    fastc, risec = state[rows + _FASTC], state[rows + _RISEC]
    lowest = np.inf
    sub_ids = ids[sigma_idx]
    words, xi = np.empty(sigma_idx.size, np.uint64), np.empty(sigma_idx.size)
    for i in range(current.shape[0]):
        for g in range(grp_i.shape[1]):  # groups outside, views from 0: the loops vectorise
            lo, hi = grp_i[_START, g], grp_i[_STOP, g]
            x, alpha, bias = current[i, lo:hi], grp_f[_ALPHA_SMOOTH, g], grp_f[_BIAS, g]
            if grp_i[_SMOOTHED, g] != 0:
                c = smooth[lo:hi]
                for j in range(hi - lo):
                    c[j] = c[j] + alpha * (x[j] - c[j])  # `smooth_kernel`
                    x[j] = c[j]
            depth, fall, transient = grp_f[_DYN, g], grp_f[_FALL, g], grp_f[_TRANSIENT, g]
            if depth > 0.0 or fall > 0.0 or transient > 0.0:
                c, k, r = dync[lo:hi], fastc[lo:hi], risec[lo:hi]
                alpha, alpha_k, alpha_r = grp_f[_ALPHA_DYN, g], grp_f[_ALPHA_TRANSIENT, g], grp_f[_ALPHA_RISE, g]
                for j in range(hi - lo):
                    x[j], c[j], k[j], r[j] = dynamic_step(x[j], c[j], k[j], r[j], alpha, alpha_k, alpha_r, depth,
                                                          transient, fall)
            if bias != 0.0:
                tonic = aff_f[_TONIC, lo:hi]
                for j in range(hi - lo):
                    x[j] = x[j] + tonic[j]
        if additive and sigma_idx.size:
            normal_row(key, sub_ids, 0, sub_ids.size, sample0 + i, words, xi)
            for k in range(sigma_idx.size):
                j = sigma_idx[k]
                current[i, j] = current[i, j] + xi[k] * aff_f[_SIGMA, j]  # `noise_current`
        if track:  # only an explicit method's stability check reads it
            for j in range(current.shape[1]):
                lowest = min(lowest, current[i, j])
    return lowest


@nb.njit(cache=True, nogil=True)
def _back_and_integrate(current, key, additive, ids, sample0, state, rows, aff_f, grp_f, grp_i, sigma_idx,
                        substeps, method, h, half, a, b, c, d, nr, v, u, r, v_peak, v_floor, block, integrate):
    """`_back`, then (if ``integrate``) the direct engine on the current.

    Returns spikes, the smallest current (inf for Euler, whose check does not
    read it), whether the state stayed finite and whether a neuron spiked on
    consecutive steps (the one-spike-per-step cap bound): the seam's checks
    need the full spike lists only then.
    """
    lowest = _back(current, key, additive, ids, sample0, state, rows, aff_f, grp_f, grp_i, sigma_idx, method != 0)
    if not integrate:
        return np.empty(0, np.int64), np.empty(0, np.int64), lowest, True, False
    idx, stp = integrate_range(current, substeps, method, h, half, a, b, c, d, nr, v, u, r, v_peak, v_floor, block,
                                0, v.size)
    finite, capped, _ = spike_checks(idx, stp, v, u)
    return idx, stp, lowest, finite, capped


class FusedPipeline:
    """Tables of the fused pipeline for one population, ordered so that each type's afferents are contiguous.

    Parameters
    ----------
    afferent_type, nap : array_like of str, shape (n_afferents,)
        Type and NAP per afferent (``"none"`` for untuned).
    theta_t : array_like of float
        Tuning angles in degrees.
    k : array_like of float
        Sharpness (dimensionless).
    scale : array_like of float
        Per-afferent multiplier of the stage gain (population gain times
        receptive-field weight).
    noise_cv : array_like of float
        Receptor-noise intensity in sqrt(ms).
    noise_sigma : array_like of float
        Additive-noise intensity in mV/ms * sqrt(ms).
    params : CurrentParams
    fs : float
        Sample rate in Hz.
    no_shear : {"pass", "block", "smooth"}
    f_th : float
        Shear threshold in newtons.
    afferent_id : array_like of int, optional
        Stable ids keying each afferent's noise (default 0..n-1).
    mixing : ndarray, shape (n_sites, n_afferents), optional
        Each afferent's coefficients of the site forces (`mixing_matrix`):
        the pipeline then takes site forces and mixes them in its kernel.
    neuron : dict, optional
        `ddmm.models.neuron.NeuronParams` by type code, overriding
        `NEURON_PARAMS` (both engines integrate with them).
    sensitivity : array_like of float, optional
        Each afferent's sensitivity (dimensionless, > 0; default 1): it
        multiplies the gain and divides the dead zone (`unit_thresholds`).

    Examples
    --------
    >>> from ddmm.models.currents import CurrentParams
    >>> pipe = FusedPipeline(["SAI"], ["none"], [0.0], [1.0], [1.0], [0.0], [0.0], CurrentParams(), 1000.0, "pass", 0.1)
    >>> pipe.currents(np.array([[0.0, 0.0, 2.0]]), pipe.new_state(), False).shape
    (1, 1)
    """

    def __init__(self, afferent_type, nap, theta_t, k, scale, noise_cv, noise_sigma, params, fs, no_shear, f_th,
                 afferent_id=None, mixing=None, neuron=None, sensitivity=None):
        afferent_type, nap = np.asarray(afferent_type), np.asarray(nap)
        self.afferent_type, self._neuron_cache, self._bounds = afferent_type, {}, {}
        self.neuron = dict(neuron or {})  # `NeuronParams` overrides by type (eqs 4-6 otherwise)
        self.mixing = None if mixing is None else np.ascontiguousarray(mixing, dtype=float)
        self.afferent_id = np.ascontiguousarray(np.arange(afferent_type.size) if afferent_id is None else afferent_id,
                                                dtype=np.int64)
        self.n_afferents, self.fs, self.f_th = afferent_type.size, float(fs), float(f_th)
        self.smooth_reading, self.outside_value = no_shear == "smooth", 1.0 if no_shear == "pass" else 0.0
        self.opponent, self.normal = float(params.opponent_saii), float(params.normal_saii)
        self.phase_saii = float(params.phase_saii)
        change = (afferent_type[1:] != afferent_type[:-1]) | ((nap[1:] == UNTUNED) != (nap[:-1] == UNTUNED))
        bounds = np.flatnonzero(np.r_[True, change, True])  # runs of one type, tuned or not
        spans = list(zip(bounds[:-1], bounds[1:]))
        consts = [type_filter_constants(params, str(afferent_type[a]), self.fs) for a, _ in spans]
        noise_cv, noise_sigma = np.asarray(noise_cv, dtype=float), np.asarray(noise_sigma, dtype=float)
        self.aff_f = self._afferent_tables(afferent_type, nap, theta_t, k, scale, noise_cv, noise_sigma,
                                           spans, consts, sensitivity)
        self.grp_f, self.grp_i, self.sos = self._group_tables(spans, consts, noise_cv, nap != UNTUNED)
        self.rows = 2 * self.sos.shape[1]
        self.additive = bool(np.any(noise_sigma > 0))
        self.excite_cv = np.zeros(self.n_afferents)  # per afferent: its type's trial excitability CV
        for (a, b) in spans:
            self.excite_cv[a:b] = params.excite_cv(str(afferent_type[a]))
        self.excite_any, self._excite = bool(np.any(self.excite_cv > 0)), (None, None)
        self.sigma_idx = np.flatnonzero(noise_sigma > 0).astype(np.int64)
        self.transducers, self._plain = [], []  # (columns, stage) per run of one type: numpy's calls cost per call
        for (a, b), (st, *_) in zip(spans, consts):
            if st.i_sat is None and st.i_max is None and not st.signed:
                self._plain.append(slice(int(a), int(b)))
                continue
            if self.transducers and self.transducers[-1][1] is st and self.transducers[-1][0].stop == a:
                self.transducers[-1] = (slice(self.transducers[-1][0].start, int(b)), st)
            else:
                self.transducers.append((slice(int(a), int(b)), st))

    def _afferent_tables(self, afferent_type, nap, theta_t, k, scale, noise_cv, noise_sigma, spans, consts,
                         sensitivity):
        n = self.n_afferents
        aff_f = np.zeros((_N_AFF_ROWS, n))
        tuned = nap != UNTUNED
        rad = np.deg2rad(np.asarray(theta_t, dtype=float))
        aff_f[_COS], aff_f[_SIN], aff_f[_K] = np.cos(rad), np.sin(rad), np.asarray(k, dtype=float)
        aff_f[_TIP] = 1.0
        for name in sorted(set(nap[tuned].tolist())):  # per profile, not per afferent (this runs once per block)
            profile, rows = get_profile(str(name)), nap == name
            aff_f[_P1:_P5 + 1, rows] = np.array([profile.p1, profile.p2, profile.p3, profile.p4, profile.p5])[:, None]
            aff_f[_TIP, rows] = tip_radius(str(name))
        scale = np.asarray(scale, dtype=float)
        sens = None if sensitivity is None else np.asarray(sensitivity, dtype=float)
        for (a, b), (stage, *_) in zip(spans, consts):
            aff_f[_GAIN, a:b] = stage.gain * scale[a:b]  # as `current_core`
            if sens is not None:
                aff_f[_GAIN, a:b] *= sens[a:b]
            aff_f[_DEAD, a:b] = unit_thresholds(stage, None if sens is None else sens[a:b], b - a)
            aff_f[_TONIC, a:b] = tonic_current(stage, self.afferent_id[a:b], b - a)  # as `current_core`
        aff_f[_CV] = noise_cv / np.sqrt(1000.0 / self.fs)  # as `current_core` and `_receptor_noise`
        aff_f[_SIGMA] = noise_sigma / np.sqrt(1000.0 / self.fs)  # as `noise_current`
        return aff_f

    def _group_tables(self, spans, consts, noise_cv, tuned):
        n_groups, n_sec = len(spans), max([sos.shape[0] for _, sos, _, _ in consts] + [1])
        grp_f, grp_i = np.zeros((_N_GRP_ROWS, n_groups)), np.zeros((9, n_groups), dtype=np.int64)
        sos_all = np.zeros((n_groups, n_sec, 6))
        for g, ((a, b), (st, sos, alpha_adapt, alpha_smooth)) in enumerate(zip(spans, consts)):
            sos_all[g, :sos.shape[0]] = sos
            plain = st.derivative == 0 and st.cutoff_hz is None and st.adapt == 0.0 and st.tau_s is None
            grp_f[:, g] = [st.adapt, alpha_adapt, st.threshold, alpha_smooth, st.bias, st.negative_weight, st.dynamic,
                           float(-np.expm1(-1.0 / (self.fs * st.tau_dynamic_s))), st.fall,  # `currents._alpha`
                           st.shear, st.opponent_shear, st.depth, st.transient,
                           float(-np.expm1(-1.0 / (self.fs * st.tau_transient_s))),
                           float(-np.expm1(-1.0 / (self.fs * 0.5 * st.tau_transient_s)))]
            grp_i[:, g] = [sos.shape[0], st.derivative, st.signed, plain, np.any(noise_cv[a:b] > 0),
                           st.tau_s is not None, tuned[a], a, b]
        return grp_f, grp_i, sos_all

    def advance(self, forces, state, sample0, key, neuron, *, dt, method, engine, parts=1):
        """One chunk through the whole pipeline: (afferent, step within the chunk, neuron state after).

        ``forces`` and ``key`` as `currents`; ``sample0`` is the chunk's first
        sample (0 starts the filters at rest on it); ``neuron`` the
        `NeuronState` before (None: at rest).  The direct engine runs fused
        (`spikes`) with the seam's checks, integrating ``parts`` column ranges
        in parallel; other engines get the currents.
        """
        started = sample0 > 0
        args = self._neuron_args(dt, method)
        if neuron is None:
            v, u = self.initial_neuron(key, args[5], args[7], args[6])
            r = np.zeros(v.size)
        else:
            v, u = neuron.v.copy(), neuron.u.copy()
            r = np.zeros(v.size) if neuron.r is None else neuron.r.copy()
        if not get_engine(engine).fused:  # the pipeline's currents need no second check at the seam
            params = {**dict(zip("abcd", args[4:8])), "t_ref": self._t_ref}
            res = run_checked(self.currents(forces, state, started, sample0, key), args[0], dt, params, v, u,
                              engine, method, r)
            return res.afferent, res.step, res.state
        current, afferent, step, lowest, finite, capped = self.spikes(forces, state, started, sample0, key, args, v,
                                                                     u, parts, r)
        if method != "euler":
            check_stability(np.array([lowest]), dt, method)
        if not finite or capped:
            check_integration(afferent, step, v, u, current, method, dt)
        return afferent, step, NeuronState(v, u, r)

    def initial_neuron(self, key, b, d, c):
        """Neuron state (v, u) before the first sample: at rest, or with ``phase_saii`` and a stream ``key``
        each afferent of a `AfferentType.phase_spread` type (SA-II) at its own phase
        (`ddmm.models.currents.initial_phase`): ``v = c``, ``u = u_rest + phase_saii U d``."""
        v, u = (np.array(x, dtype=float) for x in resting_state(b))
        tonic = type_mask(self.afferent_type, "phase_spread")
        if self.phase_saii > 0.0 and key is not None and tonic.any():
            cols = np.flatnonzero(tonic)
            v[cols] = np.asarray(c, dtype=float)[cols] if np.ndim(c) else c
            spread = self.phase_saii * initial_phase(key, self.afferent_id[cols])
            u[cols] = u[cols] + spread * (np.asarray(d)[cols] if np.ndim(d) else d)
        return v, u

    def _neuron_args(self, dt, method):
        """The direct engine's arguments for (dt, method), cached (as `ddmm.models.engines.direct.run_direct` computes them)."""
        key = (float(dt), method)
        if key not in self._neuron_cache:
            p = neuron_arrays(self.afferent_type, self.neuron)
            h, half = 1.0 * dt / 0.001, (1.0 * (0.5 * dt)) / 0.001
            self._t_ref = p["t_ref"]
            self._neuron_cache[key] = (substeps_for(self.fs, dt), METHOD_CODES[method], h, half, p["a"], p["b"],
                                       p["c"], p["d"], refractory_steps(p["t_ref"], dt), V_PEAK, V_FLOOR, BLOCK)
        return self._neuron_cache[key]

    def new_state(self) -> np.ndarray:
        """Filter, offset, difference, adaptation, smoothing and dynamic-response state at rest, shape (n_rows, n_afferents)."""
        return np.zeros((self.rows + _N_STATE, self.n_afferents))

    def _drive(self, forces, state, started, sample0, key, bounds=None, out=None):
        noisy, mixed = key is not None, self.mixing is not None
        if forces.ndim != (3 if mixed else 2):
            raise ValueError(f"forces must be {'(n, n_sites, 3) site forces' if mixed else '(n, 3)'} for this pipeline, "
                             f"got shape {forces.shape}")
        args = (_NO_FORCES if mixed else forces, forces if mixed else _NO_SITES, self.mixing if mixed else _NO_WEIGHTS,
                mixed, np.uint64(key or 0), noisy, self.afferent_id, int(sample0), state, started, self.aff_f,
                self.grp_f, self.grp_i, self.sos, self.fs, self.smooth_reading, self.outside_value,
                self.f_th, self.opponent, self.normal, np.empty((forces.shape[0], self.n_afferents)) if out is None else out)
        # The parallel kernel is called from here, never from a cached kernel
        # (numba's cache does not track a cached caller's parallel callee).
        drive = _front(*args) if bounds is None or bounds.size <= 2 else _front_parts(*args, bounds)
        excite = self.excitability(key) if noisy and self.excite_any else None
        for cols, stage in self.transducers:  # as `current_core`; a push of a few rows: numpy's passes cost least
            if stage.signed or drive.shape[0] < _FUSED_ROWS:
                transduce_inplace(drive[:, cols], stage, None if excite is None else excite[cols])
            else:
                transduce_columns(drive, cols, stage, None if excite is None else excite[cols])
        if excite is not None:
            for cols in self._plain:  # runs without a transducer: the factor alone
                drive[:, cols] *= excite[cols]
        return drive

    def excitability(self, key) -> np.ndarray:
        """The trial's excitability factor per afferent (`ddmm.models.currents.excitability`), cached per key."""
        if self._excite[0] != key:
            self._excite = (key, excitability(key, self.afferent_id, self.excite_cv))
        return self._excite[1]

    def currents(self, forces, state, started, sample0=0, key=None):
        """Currents (mV/ms), shape (n_samples, n_afferents), of forces in newtons.

        ``forces`` is (n_samples, 3), felt by every afferent, or for a pipeline
        with a ``mixing`` the site forces (n_samples, n_sites, 3); long inputs
        run in slices of time of `_SLICE` elements, with the same result.
        ``state`` is updated in place; ``started`` is False on the first
        chunk, whose first sample is sample ``sample0`` of the scene.  With
        a stream ``key`` (`ddmm.models.rng.stream_key`), the noise of sample n of
        afferent a is ``ddmm.models.rng.normal(key, a, n)``; None: noise-free.
        """
        n, step = forces.shape[0], max(1, _SLICE // max(1, self.n_afferents))
        if n <= step:
            return self._current_slice(forces, state, started, sample0, key)
        out = np.empty((n, self.n_afferents))
        for t0 in range(0, n, step):  # slices of time, contiguous rows of ``out``: each one's passes stay in cache
            rows = slice(t0, t0 + step)
            self._current_slice(forces[rows], state, started or t0 > 0, sample0 + t0, key, out[rows])
        return out

    def _current_slice(self, forces, state, started, sample0, key, out=None):
        current = self._drive(forces, state, started, sample0, key, out=out)
        _back(current, np.uint64(key or 0), key is not None and self.additive, self.afferent_id, int(sample0), state,
              self.rows, self.aff_f, self.grp_f, self.grp_i, self.sigma_idx, False)  # the engines check currents
        return current

    def spikes(self, forces, state, started, sample0, key, neuron, v, u, parts=1, r=None):
        """Currents, then the direct engine: (current, afferent, step, smallest current, finite, capped).

        Arguments as `currents`; ``neuron`` is (substeps, method code, h,
        half, a, b, c, d, refractory steps, v_peak, v_floor, block) as
        `ddmm.models.engines.direct` takes them; ``v``, ``u``, ``r`` (refractory
        steps left; None: zeros) and ``state`` are updated in place.  With
        ``parts`` > 1 the integration runs on that many column ranges in
        parallel (the spikes are the same, ordered range by range).
        """
        if parts not in self._bounds:
            self._bounds[parts] = part_bounds(v.size, parts)
        bounds = self._bounds[parts]
        current = self._drive(forces, state, started, sample0, key, bounds)
        substeps, method, h, half, a, b, c, d, nr, v_peak, v_floor, block = neuron
        r = np.zeros(v.size) if r is None else r
        serial = bounds.size <= 2
        out = _back_and_integrate(current, np.uint64(key or 0), key is not None and self.additive, self.afferent_id,
                                  int(sample0), state, self.rows, self.aff_f, self.grp_f, self.grp_i,
                                  self.sigma_idx, substeps, method, h, half, a, b, c, d, nr, v, u, r, v_peak, v_floor,
                                  block, serial)
        if not serial:  # from Python, as the front's parallel kernel
            idx, stp = integrate_parts(current, substeps, method, h, half, a, b, c, d, nr, v, u, r, v_peak, v_floor,
                                       block, bounds)
            out = (idx, stp, out[2], *spike_checks(idx, stp, v, u)[:2])
        return (current, *out)
