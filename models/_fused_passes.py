"""The numba passes of `ddmm.models.fused.FusedPipeline`: the front pass (force to linear drive), its
parallel and streaming forms, and the back pass (the current's low-pass, bias and additive noise).

Kept apart from the class that packs their tables; the arithmetic and its order are documented in
`ddmm.models.fused`, and every kernel here is bit-identical to the reference oracle's
(``tests/models/test_reference_pipeline.py``).
"""

from __future__ import annotations

import numba as nb
import numpy as np

from ddmm.models._fused_drive import (
    front_scratch,
    local_drive,
    needs_profile,
    sample_shear,
    shared_drive,
)
from ddmm.models._fused_tables import (
    _ADAPT,
    _ALPHA_ADAPT,
    _ALPHA_DYN,
    _ALPHA_RISE,
    _ALPHA_SMOOTH,
    _ALPHA_TRANSIENT,
    _BIAS,
    _CV,
    _DEAD,
    _DEPTH,
    _DYN,
    _DYNC,
    _FALL,
    _FASTC,
    _GAIN,
    _NEGATIVE,
    _NOISY,
    _NORMAL,
    _NSEC,
    _OFFSET,
    _OPP_SHEAR,
    _OPP_STRETCH,
    _ORDER,
    _PLAIN,
    _RANGE,
    _RISEC,
    _SHEAR_G,
    _SIGMA,
    _SIGNED,
    _SLOW,
    _SMOOTH,
    _SMOOTHED,
    _START,
    _STOP,
    _THRESHOLD,
    _TONIC,
    _TRANSIENT,
    _TUNED_G,
    _Y1,
    _Y2,
    DriveConstants,
    ForceInput,
    FusedTables,
    GroupDrive,
    NoiseKey,
    PushState,
)
from ddmm.models._kernel_options import VECTOR_KERNEL
from ddmm.models._stage_kernels import (
    StageConstants,
    TailState,
    UnitScales,
    dynamic_step,
    filter_sections,
    receptor_noise_keyed,
    stage_tail,
)
from ddmm.models._transducer_kernels import TransducerPass, transduce_pre
from ddmm.models.rng import normal_row


@nb.njit(cache=True, nogil=True)
def _front(tables, state, forces, noise, started, out):
    """Force to linear drive into ``out`` (n, n_afferents); ``state`` in place (`_front_range` on every afferent).

    ``tables``, ``forces`` and ``noise`` are a `FusedTables`, a `ForceInput`
    and a `NoiseKey`, as plain tuples from Python (named again here).
    Afferents go in ranges of `_RANGE`, whose state and scratch stay in
    cache over all samples (one range of Brian2's 4096-wide blocks cost
    about twice as much per afferent-sample).
    """
    tables, forces, noise = FusedTables(*tables), ForceInput(*forces), NoiseKey(*noise)
    m = tables.aff_f.shape[1]
    scratch = front_scratch(m, tables.grp_i.shape[1])
    for a0 in range(0, m, _RANGE):
        scratch[7][:] = np.nan  # each range computes its own profiles
        _front_range(tables, state, forces, noise, started, out, a0, min(m, a0 + _RANGE), scratch)
    return out


@nb.njit(cache=True, nogil=True, parallel=True)
def _front_parts(tables, state, forces, noise, started, out, bounds):
    """`_front` with the afferent ranges ``bounds[p]..bounds[p+1]`` in parallel (afferents are independent)."""
    tables, forces, noise = FusedTables(*tables), ForceInput(*forces), NoiseKey(*noise)
    for p in nb.prange(bounds.size - 1):
        scratch = front_scratch(tables.aff_f.shape[1], tables.grp_i.shape[1])
        _front_range(tables, state, forces, noise, started, out, bounds[p], bounds[p + 1], scratch)
    return out


@nb.njit(cache=True, nogil=True)
def _front_part(tables, push, forces, noise, started, out, a0, a1, scratch, trans):
    """A streaming push's front pass on the afferents ``a0..a1``: their columns of ``push.source`` copied into
    ``push.state`` first (when the source has the state's shape; else the state in place; ``push`` is a
    `PushState`), `_front_range`, then the transducers' first pass (`transduce_pre`; ``trans`` is the
    `TransducerPass`)."""
    state, source = push.state, push.source
    if source.shape[0] == state.shape[0] and source.shape[1] == state.shape[1]:
        for r in range(state.shape[0]):
            state[r, a0:a1] = source[r, a0:a1]
    _front_range(tables, state, forces, noise, started, out, a0, a1, scratch)
    transduce_pre(out, trans.runs_i, trans.runs_f, trans.negative, a0, a1)


@nb.njit(cache=True, nogil=True)
def _front_push(tables, push, forces, noise, started, out, scratch, af_dirs, trans):
    """`_front_part` on every afferent, in one part (``af_dirs[0]``: its profiles' direction; ``push`` and
    ``trans`` a `PushState` and a `TransducerPass` as plain tuples from Python, named again here)."""
    tables, forces, noise = FusedTables(*tables), ForceInput(*forces), NoiseKey(*noise)
    push, trans = PushState(*push), TransducerPass(*trans)
    f, af, mags, wts, local, words, xi = scratch
    _front_part(tables, push, forces, noise, started, out, 0, out.shape[1],
                (f, af, mags, wts, local, words, xi, af_dirs[0]), trans)
    return out


@nb.njit(cache=True, nogil=True, parallel=True)
def _front_push_parts(tables, push, forces, noise, started, out, scratch, af_dirs, trans, bounds):
    """`_front_part` on the afferent ranges ``bounds[p]..bounds[p+1]`` in parallel (``af_dirs[p]`` each)."""
    tables, forces, noise = FusedTables(*tables), ForceInput(*forces), NoiseKey(*noise)
    push, trans = PushState(*push), TransducerPass(*trans)
    f, af, mags, wts, local, words, xi = scratch
    for p in nb.prange(bounds.size - 1):
        _front_part(tables, push, forces, noise, started, out, bounds[p], bounds[p + 1],
                    (f, af, mags, wts, local, words, xi, af_dirs[p]), trans)
    return out


@nb.njit(**VECTOR_KERNEL)
def _front_range(tables, state, forces, noise, started, out, a0, a1, scratch):
    """Force to linear drive of the afferents ``a0..a1`` into ``out`` (n, n_afferents); their ``state`` in place.

    ``forces`` (`ForceInput`) is felt by every afferent, or with
    ``tables.mixed`` each afferent feels its own mix (``tables.weights``) of
    the site forces, mixed here sample by sample.  Groups (runs of one type,
    tuned or not) are the outer loop, so each inner loop over afferents has
    loop-invariant constants and branches.  ``noise`` (`NoiseKey`) keys the
    receptor noise; ``started`` is False on a scene's first chunk.  ``scratch`` is `front_scratch`'s work
    arrays (columns ``a0..a1`` are used); its profile AF and their direction (``scratch[7]``, NaN: none) are
    kept from call to call, so a caller that hands the same scratch to the same range reuses them.
    """
    aff_f, grp_f, grp_i, sos, rows = tables.aff_f, tables.grp_f, tables.grp_i, tables.sos, 2 * tables.sos.shape[1]
    reading = DriveConstants(tables.smooth_reading, tables.outside_value, tables.f_th)
    z, offset, (key, noisy, ids, sample0) = state[:rows], state[rows + _OFFSET], noise
    tail = TailState(offset, state[rows + _Y1], state[rows + _Y2], state[rows + _SLOW])
    unit = UnitScales(aff_f[_GAIN], aff_f[_DEAD], aff_f[_CV])
    f, af, mags, wts, local, words, xi, af_dir = scratch
    shared, sites, weights, mixed, cv_scale = forces.shared, forces.sites, tables.weights, tables.mixed, unit.cv_scale
    for i in range(out.shape[0]):
        sample = sample_shear(shared, sites, weights, local, i, a0, a1, mixed, 2.0 * reading.f_th)
        for g in range(grp_i.shape[1]):  # inlined helpers get arrays one by one: each costs a reference count
            lo, hi = max(a0, grp_i[_START, g]), min(a1, grp_i[_STOP, g])
            if lo >= hi:
                continue
            group = GroupDrive(grp_i[_TUNED_G, g] != 0, grp_i[_SIGNED, g] != 0, grp_f[_SHEAR_G, g],
                               grp_f[_OPP_SHEAR, g], grp_f[_DEPTH, g], grp_f[_OPP_STRETCH, g], grp_f[_NORMAL, g])
            if mixed:
                local_drive(f, lo, hi, local, aff_f, mags, wts, reading, group)
            elif not group.tuned and not group.stretch and group.shear_g == 0.0:
                f[lo:hi] = sample.fz  # untuned pressure afferents: F_A = F_Z
            else:
                profiled = needs_profile(sample.mag, reading, group)
                cached = profiled and sample.ux == af_dir[0, g] and sample.uy == af_dir[1, g]
                shared_drive(f, lo, hi, aff_f, af, cached, sample, reading, group)
                if profiled:
                    af_dir[0, g], af_dir[1, g] = sample.ux, sample.uy
            if i == 0 and not started and grp_i[_PLAIN, g] == 0:
                offset[lo:hi] = f[lo:hi]  # `initial_filter_state`: at rest on the first sample
            f[lo:hi] -= offset[lo:hi]
            filter_sections(f, lo, hi, sos, g, grp_i[_NSEC, g], z)
            stage = StageConstants(tables.fs, grp_i[_ORDER, g], grp_f[_ADAPT, g], grp_f[_ALPHA_ADAPT, g],
                                   grp_f[_THRESHOLD, g] > 0.0, grp_f[_NEGATIVE, g], group.stretch)
            stage_tail(f, lo, hi, tail, stage, unit)
            if noisy and grp_i[_NOISY, g] != 0:
                receptor_noise_keyed(f, lo, hi, key, ids, sample0 + i, cv_scale, stage.signed, words, xi)
        out[i, a0:a1] = f[a0:a1]


@nb.njit(cache=True, nogil=True)
def _back(tables, state, noise, current, track):
    """Low-pass, bias and additive noise of the transduced drive ``current``, in place; returns the smallest
    current (with ``track``; else inf).

    Additive noise (keyed by ``noise``, a `NoiseKey`) is drawn for the
    afferents ``tables.sigma_idx`` (those with sigma > 0) only: adding
    0 * xi would leave every other current as it is.  ``tables`` and
    ``noise`` may come as plain tuples (from Python).
    """
    tables, noise = FusedTables(*tables), NoiseKey(*noise)
    return _back_range(tables, state, noise, current, track, 0, current.shape[1])


@nb.njit(cache=True, nogil=True)
def _back_range(tables, state, noise, current, track, a0, a1):
    """`_back` on the afferents ``a0..a1`` alone (each afferent's back pass is its own: the same bits)."""
    aff_f, grp_f, grp_i, sigma_idx = tables.aff_f, tables.grp_f, tables.grp_i, tables.sigma_idx
    rows = 2 * tables.sos.shape[1]
    smooth, dync = state[rows + _SMOOTH], state[rows + _DYNC]
    fastc, risec = state[rows + _FASTC], state[rows + _RISEC]
    lowest = np.inf
    k0, k1 = np.searchsorted(sigma_idx, a0), np.searchsorted(sigma_idx, a1)  # sorted: those in a0..a1
    sub_idx = sigma_idx[k0:k1]
    sub_ids = noise.ids[sub_idx]
    words, xi = np.empty(sub_idx.size, np.uint64), np.empty(sub_idx.size)
    for i in range(current.shape[0]):
        for g in range(grp_i.shape[1]):  # groups outside, views from 0: the loops vectorise
            lo, hi = max(a0, grp_i[_START, g]), min(a1, grp_i[_STOP, g])
            if lo >= hi:
                continue
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
        if noise.noisy and sub_idx.size:
            normal_row(noise.key, sub_ids, 0, sub_ids.size, noise.sample0 + i, words, xi)
            for k in range(sub_idx.size):
                j = sub_idx[k]
                current[i, j] = current[i, j] + xi[k] * aff_f[_SIGMA, j]  # `noise_current`
        if track:  # only an explicit method's stability check reads it
            for j in range(a0, a1):
                lowest = min(lowest, current[i, j])
    return lowest
