"""The fused pipeline's per-sample drive: shear, profile AF, F_A or stretch, and site mixing.

Numba kernels of `ddmm.models.fused` (its front pass calls them per sample
and group), reading the tables of `ddmm.models._fused_tables`; the
arithmetic and its order are those of `ddmm.models.attenuation`, so the
fused path stays bit-identical to the reference oracle (`ddmm.models.reference_pipeline`).  The helpers take
arrays one by one and scalars in scalar-only named tuples (`GroupDrive`,
`ShearSample`, `DriveConstants`): an inlined helper pays a reference count
for every array it is handed.
"""

from __future__ import annotations

import math

import numba as nb
import numpy as np

from ddmm.models._fused_tables import (
    _COS,
    _K,
    _P1,
    _P2,
    _P3,
    _P4,
    _P5,
    _SIN,
    _TIP,
    ShearSample,
)
from ddmm.models.attenuation import profile_value

__all__ = ["mix_forces", "mixing_matrix"]


@nb.njit(cache=True, nogil=True, inline="always")
def _shear(fx, fy, two_fth):
    """Shear magnitude (N), unit direction and the smooth reading's weight (`transition_weight`)."""
    mag = math.hypot(fx, fy)
    ux, uy = (fx / mag, fy / mag) if mag > 0.0 else (0.0, 0.0)
    x = min(max(mag / two_fth, 0.0), 1.0)
    return mag, ux, uy, x * x * (3.0 - 2.0 * x)


@nb.njit(cache=True, nogil=True, inline="always")
def _sheared(p, fz, mag, w, reading, group):
    """F_A of a pressure afferent plus its shear-magnitude term (`reference_pipeline.shear_drive`), from its profile
    AF ``p`` (1 when untuned), in the oracle's order of operations; ``group.depth`` as
    `reference_pipeline.attenuated_force` (``reading``: `DriveConstants`, ``group``: `GroupDrive`)."""
    if not group.tuned:
        fa = fz
    else:
        a = (((p - 1.0) * w) + 1.0) if reading.smooth_reading else (p if mag > reading.f_th else reading.outside_value)
        depth = group.depth
        fa = (a if depth == 1.0 else 1.0 + depth * (a - 1.0)) * fz
    if group.shear_g == 0.0:
        return fa  # `shear_drive` with no term: F_A as it is
    x = fa + group.shear_g * (mag * (p - group.opp_s * (1.0 - p)))
    return x if x > 0.0 else 0.0  # `shear_drive`'s floor


@nb.njit(cache=True, nogil=True, inline="always")
def needs_profile(mag, reading, group):
    """Whether a group's drive needs its profile AF at shear magnitude ``mag`` (N)."""
    return group.tuned and mag > 0.0 and (reading.smooth_reading or group.stretch or group.shear_g != 0.0
                                          or mag > reading.f_th)


@nb.njit(cache=True, nogil=True, inline="always")
def shared_drive(f, lo, hi, aff_f, af, cached, sample, reading, group):
    """The drive (newtons) of a group that feels one force ``sample`` (`ShearSample`), in passes: the
    profile AF where needed (`attenuation.profile_value`), then F_A = AF F_Z under the no-shear reading,
    or SA-II's stretch (`stretch_drive`).  As one loop, the profile's branches kept the whole body scalar,
    3-4x slower.

    AF depends on the shear direction alone, so ``af[lo:hi]`` keeps the last
    values computed; with ``cached`` (same ``ux``, ``uy`` as then) they are
    reused: the same bits, and a fixed-direction ramp or hold costs no
    profile evaluations after its first sample.
    """
    fz, mag, ux, uy, w = sample
    if needs_profile(mag, reading, group):
        if not cached:
            for j in range(lo, hi):
                af[j] = profile_value(ux, uy, aff_f[_COS, j], aff_f[_SIN, j], aff_f[_K, j],
                                      (aff_f[_P1, j], aff_f[_P2, j], aff_f[_P3, j], aff_f[_P4, j], aff_f[_P5, j]),
                                      aff_f[_TIP, j])
        f[lo:hi] = af[lo:hi]
    else:
        f[lo:hi] = 1.0
    f = f[lo:hi]  # a view from 0: loops over range(lo, hi) vectorise worse
    if group.stretch:
        opponent, normal = group.opponent, group.normal
        for j in range(f.size):
            f[j] = mag * (f[j] - opponent * (1.0 - f[j]))
        if normal != 0.0:  # SA-II's normal-force drive (`stretch_drive`)
            for j in range(f.size):
                f[j] = f[j] + normal * fz
    elif group.shear_g != 0.0 or group.depth != 1.0:
        for j in range(f.size):
            f[j] = _sheared(f[j], fz, mag, w, reading, group)
    elif reading.smooth_reading:
        for j in range(f.size):
            f[j] = (((f[j] - 1.0) * w) + 1.0) * fz
    else:
        f_th, outside_value = reading.f_th, reading.outside_value
        for j in range(f.size):
            f[j] = (f[j] if mag > f_th else outside_value) * fz


def mixing_matrix(indptr, indices, coeff, n_sites: int) -> np.ndarray:
    """The sparse local-force coefficients (`ddmm.population.anatomy.receptive_fields.local_mixing`) as a dense (n_sites, n_afferents)."""
    m = indptr.size - 1
    out = np.zeros((n_sites, m))
    rows = np.repeat(np.arange(m), np.diff(indptr))
    out[indices, rows] = coeff
    return out


@nb.njit(cache=True, nogil=True, inline="always")
def local_drive(f, lo, hi, local, aff_f, mags, wts, reading, group):
    """`shared_drive` for afferents that each feel their own force ``local`` (3, n_afferents), in passes:
    shear magnitude and weight, the profile where needed, then the drive (the same arithmetic)."""
    f_th = reading.f_th
    two_fth = 2.0 * f_th
    for j in range(lo, hi):
        mags[j] = math.hypot(local[0, j], local[1, j])
    for j in range(lo, hi):
        x = min(max(mags[j] / two_fth, 0.0), 1.0)
        wts[j] = x * x * (3.0 - 2.0 * x)  # `transition_weight`
    for j in range(lo, hi):
        mag = mags[j]
        p = 1.0
        if needs_profile(mag, reading, group):
            p = profile_value(local[0, j] / mag, local[1, j] / mag, aff_f[_COS, j], aff_f[_SIN, j], aff_f[_K, j],
                              (aff_f[_P1, j], aff_f[_P2, j], aff_f[_P3, j], aff_f[_P4, j], aff_f[_P5, j]),
                              aff_f[_TIP, j])
        f[j] = p
    if group.stretch:
        for j in range(lo, hi):
            f[j] = mags[j] * (f[j] - group.opponent * (1.0 - f[j]))
        if group.normal != 0.0:
            for j in range(lo, hi):
                f[j] = f[j] + group.normal * local[2, j]
    elif group.shear_g != 0.0 or group.depth != 1.0:
        for j in range(lo, hi):
            f[j] = _sheared(f[j], local[2, j], mags[j], wts[j], reading, group)
    elif not group.tuned:
        for j in range(lo, hi):
            f[j] = local[2, j]
    elif reading.smooth_reading:
        for j in range(lo, hi):
            f[j] = (((f[j] - 1.0) * wts[j]) + 1.0) * local[2, j]
    else:
        for j in range(lo, hi):
            f[j] = (f[j] if mags[j] > f_th else reading.outside_value) * local[2, j]


@nb.njit(cache=True, nogil=True, inline="always")
def sample_shear(shared, sites, weights, local, i, a0, a1, mixed, two_fth):
    """Sample ``i``'s force as a `ShearSample`; with site mixing (``mixed``), the afferents ``a0..a1``'s own
    forces go into ``local`` instead (the sample is then zeros, unread)."""
    if mixed:
        _mix_sample(sites[i], weights, local, a0, a1)
        return ShearSample(0.0, 0.0, 0.0, 0.0, 0.0)
    fz = shared[i, 2]
    mag, ux, uy, w = _shear(shared[i, 0], shared[i, 1], two_fth)
    return ShearSample(fz, mag, ux, uy, w)


@nb.njit(cache=True, nogil=True, inline="always")
def front_scratch(m, n_groups):
    """Work arrays of a front pass over ``m`` afferents in ``n_groups`` groups: the drive, the profile AF
    (kept while the shear direction holds), local shear magnitudes and weights, local forces (3, m),
    noise words and draws, and the direction each group's AF was computed for (2, n_groups; NaN: none)."""
    return (np.empty(m), np.empty(m), np.empty(m), np.empty(m), np.empty((3, m)), np.empty(m, np.uint64),
            np.empty(m), np.full((2, n_groups), np.nan))


@nb.njit(cache=True, nogil=True, inline="always")
def _mix_sample(forces_i, weights, out, a0, a1):
    """``out[axis, a] = sum_s weights[s, a] forces_i[s, axis]`` for afferents a0..a1, over sites in increasing order."""
    for axis in range(3):
        row = out[axis]
        row[a0:a1] = 0.0
        for s in range(weights.shape[0]):
            c = forces_i[s, axis]
            if c != 0.0:  # adding 0 * w leaves every sum as it is
                for j in range(a0, a1):
                    row[j] += weights[s, j] * c


@nb.njit(cache=True, nogil=True)
def mix_forces(forces, weights):
    """Each afferent's local force, shape (n_samples, 3, n_afferents), from site forces (n_samples, n_sites, 3).

    ``F_a = sum_s weights[s, a] F_s``, summed over sites in increasing order
    whatever the chunking, so any split of time gives the same bits (the
    fused kernel mixes sample by sample with the same code).
    """
    out = np.empty((forces.shape[0], 3, weights.shape[1]))
    local = np.empty((3, weights.shape[1]))
    for i in range(forces.shape[0]):
        _mix_sample(forces[i], weights, local, 0, weights.shape[1])
        out[i] = local
    return out
