"""The fused pipeline's typed tables: their row layouts, the named tuples its kernels take, and their builders.

`ddmm.models.fused.FusedPipeline` packs every per-call constant once into
a `FusedTables`; each numba kernel of both passes then takes roughly
``(tables, state, forces, noise, out)``: the tables, the filter state
(updated in place), the chunk's forces (`ForceInput`), which noise it draws
(`NoiseKey`) and where the result goes.  Named tuples cost nothing in numba
(it unpacks them at compile time) and keep each kernel's signature short.
"""

from __future__ import annotations

from dataclasses import dataclass, fields
from typing import NamedTuple

import numpy as np

from ddmm.models.attenuation import UNTUNED
from ddmm.models.currents import tonic_current, unit_thresholds
from ddmm.models.nap import get_profile, tip_radius

__all__ = [
    "AfferentColumns",
    "DriveConstants",
    "ForceInput",
    "FusedTables",
    "GroupDrive",
    "NoiseKey",
    "PushState",
    "ShearSample",
    "afferent_table",
    "group_tables",
    "rest_state",
    "transducer_runs",
    "type_runs",
]

# Rows of the per-afferent float table.
_COS, _SIN, _K, _P1, _P2, _P3, _P4, _P5, _TIP, _GAIN, _CV, _SIGMA, _TONIC, _DEAD = range(14)
_N_AFF_ROWS = 14
# Rows of the per-group float and integer tables.
(_ADAPT, _ALPHA_ADAPT, _THRESHOLD, _ALPHA_SMOOTH, _BIAS, _NEGATIVE, _DYN, _ALPHA_DYN, _FALL, _SHEAR_G, _OPP_SHEAR,
 _DEPTH, _TRANSIENT, _ALPHA_TRANSIENT, _ALPHA_RISE, _OPP_STRETCH, _NORMAL) = range(17)
_N_GRP_ROWS = 17
_NSEC, _ORDER, _SIGNED, _PLAIN, _NOISY, _SMOOTHED, _TUNED_G, _START, _STOP = range(9)
_N_GRP_INT_ROWS = 9
# Rows of the state after the 2 * n_sections filter rows.
_OFFSET, _Y1, _Y2, _SLOW, _SMOOTH, _DYNC, _FASTC, _RISEC = range(8)
_N_STATE = 8

_RANGE = 512  # afferents per range of the front pass: its state and scratch fit in cache
_SLICE = 1 << 17  # current elements per time slice of `FusedPipeline.currents`
_NO_FORCES, _NO_SITES, _NO_WEIGHTS = np.zeros((0, 3)), np.zeros((0, 0, 3)), np.zeros((0, 0))


class FusedTables(NamedTuple):
    """Every constant of a population's fused pipeline, built once (`FusedPipeline.tables`); both passes read it.

    Afferents are ordered so that each group (a run of one type, tuned or
    untuned) is contiguous; the per-group tables hold one column per group.

    Attributes
    ----------
    aff_f : ndarray
        Per-afferent floats, shape (14, n_afferents): rows `_COS`..`_DEAD` (direction, profile, gain, noise).
    grp_f : ndarray
        Per-group floats, shape (17, n_groups): rows `_ADAPT`..`_NORMAL` (stage constants).
    grp_i : ndarray
        Per-group integers, shape (9, n_groups): rows `_NSEC`..`_STOP` (sections, flags, span).
    sos : ndarray
        Each group's filter sections, shape (n_groups, n_sections, 6).
    fs : float
        Sample rate (Hz).
    smooth_reading : bool
        The "smooth" reading of no shear (`ddmm.models.attenuation`).
    outside_value : float
        AF at or below ``f_th`` otherwise: 1.0 ("pass") or 0.0 ("block").
    f_th : float
        Shear threshold (N).
    weights : ndarray
        Each afferent's coefficients of the site forces, (n_sites, n_afferents); (0, 0) if none.
    mixed : bool
        Whether each afferent feels its own mix of site forces (``weights``).
    sigma_idx : ndarray
        The afferents with additive noise (sigma > 0), int64.
    """

    aff_f: np.ndarray
    grp_f: np.ndarray
    grp_i: np.ndarray
    sos: np.ndarray
    fs: float
    smooth_reading: bool
    outside_value: float
    f_th: float
    weights: np.ndarray
    mixed: bool
    sigma_idx: np.ndarray


class ForceInput(NamedTuple):
    """A chunk's forces (N): one force felt by every afferent, or site forces that each afferent mixes.

    Attributes
    ----------
    shared : ndarray
        Forces felt by every afferent, shape (n_samples, 3); (0, 3) with site forces.
    sites : ndarray
        Site forces, shape (n_samples, n_sites, 3), mixed with `FusedTables.weights`; (0, 0, 3) without.
    """

    shared: np.ndarray
    sites: np.ndarray


class NoiseKey(NamedTuple):
    """Which noise a call draws (`ddmm.models.rng`): the draw of afferent a at sample n is keyed by (key, ids[a], n).

    Attributes
    ----------
    key : numpy.uint64
        The stream key (`ddmm.models.rng.stream_key`; 0 when not ``noisy``).
    noisy : bool
        Whether any noise is drawn (a key was given).
    ids : ndarray
        Stable afferent ids keying each afferent's draws, int64.
    sample0 : int
        The scene's index of the chunk's first sample.
    """

    key: np.uint64
    noisy: bool
    ids: np.ndarray
    sample0: int


class PushState(NamedTuple):
    """A streaming push's filter state: where it is written and where it is read from
    (`ddmm.models.fused.FusedPipeline.push_drive`).

    Attributes
    ----------
    state : ndarray
        The filter state after the chunk, (n_rows, n_afferents), written.
    source : ndarray
        The state before, left as it is; of another shape ((0, 0)): ``state`` holds it and is updated in place.
    """

    state: np.ndarray
    source: np.ndarray


class GroupDrive(NamedTuple):
    """A group's constants of the drive (the front pass reads them from `FusedTables` per group).

    Attributes
    ----------
    tuned : bool
        Whether its afferents have a profile (else AF = 1).
    stretch : bool
        SA-II's signed stretch drive instead of F_A.
    shear_g : float
        Gain of the shear-magnitude term (`reference_pipeline.shear_drive`; 0: none).
    opp_s : float
        Its opponent weight.
    depth : float
        Depth of the normal force's attenuation (`reference_pipeline.attenuated_force`).
    opponent : float
        A stretch drive's weight of stretch against the preferred direction (`TypeParams.opponent`).
    normal : float
        A stretch drive's normal-force weight (`TypeParams.normal`).
    """

    tuned: bool
    stretch: bool
    shear_g: float
    opp_s: float
    depth: float
    opponent: float
    normal: float


class ShearSample(NamedTuple):
    """One sample of a force felt by every afferent, as the drive reads it.

    Attributes
    ----------
    fz : float
        Normal force (N).
    mag : float
        Shear magnitude F_S (N).
    ux : float
        Unit shear direction, x.
    uy : float
        Unit shear direction, y.
    w : float
        The smooth reading's weight (`attenuation.transition_weight`).
    """

    fz: float
    mag: float
    ux: float
    uy: float
    w: float


class DriveConstants(NamedTuple):
    """The scalars of `FusedTables` that the per-afferent drive reads (no arrays: an inlined helper that takes
    arrays pays a reference count per array and call, so the per-element ones take scalars only).

    Attributes
    ----------
    smooth_reading : bool
        The "smooth" reading of no shear.
    outside_value : float
        AF at or below ``f_th`` otherwise.
    f_th : float
        Shear threshold (N).
    """

    smooth_reading: bool
    outside_value: float
    f_th: float


@dataclass(frozen=True, kw_only=True)
class AfferentColumns:
    """Per-afferent columns of a `FusedPipeline`, one value per afferent each (fields by name only).

    Attributes
    ----------
    afferent_type : array_like of str, shape (n_afferents,)
        Type code per afferent; its length sets the number of afferents.
    nap : array_like of str
        NAP profile per afferent (``"none"``: untuned).
    theta_t : array_like of float
        Tuning angle in degrees.
    k : array_like of float
        Profile sharpness (dimensionless; unused by untuned afferents).
    scale : array_like of float
        Multiplier of the stage gain (dimensionless: population gain times
        receptive-field weight).
    noise_cv : array_like of float
        Receptor-noise intensity in sqrt(ms).
    noise_sigma : array_like of float
        Additive-noise intensity in mV/ms * sqrt(ms).
    afferent_id : array_like of int, optional
        Stable ids keying each afferent's noise (None: 0..n-1).
    sensitivity : array_like of float, optional
        Sensitivity (dimensionless, > 0; None: 1): it multiplies the gain and
        divides the dead zone (`ddmm.models.currents.unit_thresholds`).

    Raises
    ------
    ValueError
        When a column does not hold one value per afferent (the message names it).

    Examples
    --------
    >>> AfferentColumns.filled(["SAI", "RAI"], scale=[1.0, 2.0]).k
    array([0., 0.])
    """

    afferent_type: np.ndarray
    nap: np.ndarray
    theta_t: np.ndarray
    k: np.ndarray
    scale: np.ndarray
    noise_cv: np.ndarray
    noise_sigma: np.ndarray
    afferent_id: np.ndarray | None = None
    sensitivity: np.ndarray | None = None

    def __post_init__(self):
        n = np.shape(self.afferent_type)
        if len(n) != 1:
            raise ValueError(f"AfferentColumns.afferent_type must be 1-D (one type per afferent), got shape {n}")
        for field in fields(self)[1:]:
            value = getattr(self, field.name)
            if value is not None and np.shape(value) != n:
                raise ValueError(f"AfferentColumns.{field.name} must hold one value per afferent ({n[0]}), "
                                 f"got shape {np.shape(value)}")

    @classmethod
    def filled(cls, afferent_type, *, nap=UNTUNED, theta_t=0.0, k=0.0, scale=1.0, noise_cv=0.0, noise_sigma=0.0,
               afferent_id=None, sensitivity=None) -> AfferentColumns:
        """The columns of the afferents ``afferent_type``, each other field a scalar (the same for every
        afferent) or one value per afferent; by default untuned, unscaled and noise-free."""
        n = len(afferent_type)

        def each(value):  # a scalar: the same for every afferent (a string keeps its own width)
            return np.full(n, value, dtype=None if isinstance(value, str) else float) if np.ndim(value) == 0 else value

        return cls(afferent_type=afferent_type, nap=each(nap), theta_t=each(theta_t), k=each(k), scale=each(scale),
                   noise_cv=each(noise_cv), noise_sigma=each(noise_sigma), afferent_id=afferent_id,
                   sensitivity=sensitivity)


def rest_state(n_sections: int, n_afferents: int) -> np.ndarray:
    """Filter and stage state at rest, the one layout of both paths: rows ``2s`` and ``2s + 1`` hold filter
    section s, then `_OFFSET`, `_Y1`, `_Y2`, `_SLOW`, `_SMOOTH`, `_DYNC`, `_FASTC`, `_RISEC`; a column per afferent.

    Examples
    --------
    >>> rest_state(2, 3).shape
    (12, 3)
    """
    return np.zeros((2 * n_sections + _N_STATE, n_afferents))


def type_runs(afferent_type, nap) -> list:
    """(start, stop) of each run of one type, tuned or untuned: the groups of the tables.

    Examples
    --------
    >>> type_runs(np.array(["SAI", "SAI", "RAI"]), np.array(["broad", "none", "none"]))
    [(0, 1), (1, 2), (2, 3)]
    """
    change = (afferent_type[1:] != afferent_type[:-1]) | ((nap[1:] == UNTUNED) != (nap[:-1] == UNTUNED))
    bounds = np.flatnonzero(np.r_[True, change, True])
    return [(int(a), int(b)) for a, b in zip(bounds[:-1], bounds[1:])]


def afferent_table(nap, theta_t, k, spans, consts, unit, fs) -> np.ndarray:
    """The per-afferent float table (rows `_COS`..`_DEAD`) of afferents in groups ``spans``.

    ``consts`` holds each group's `type_filter_constants`; ``unit`` is
    (scale, sensitivity or None, afferent_id, noise_cv, noise_sigma), per afferent.
    """
    scale, sens, afferent_id, noise_cv, noise_sigma = unit
    aff_f = np.zeros((_N_AFF_ROWS, nap.size))
    tuned = nap != UNTUNED
    rad = np.deg2rad(np.asarray(theta_t, dtype=float))
    aff_f[_COS], aff_f[_SIN], aff_f[_K] = np.cos(rad), np.sin(rad), np.asarray(k, dtype=float)
    aff_f[_TIP] = 1.0
    for name in sorted(set(nap[tuned].tolist())):  # per profile, not per afferent (this runs once per block)
        profile, rows = get_profile(str(name)), nap == name
        aff_f[_P1:_P5 + 1, rows] = np.array([profile.p1, profile.p2, profile.p3, profile.p4, profile.p5])[:, None]
        aff_f[_TIP, rows] = tip_radius(str(name))
    for (a, b), (stage, *_) in zip(spans, consts):
        aff_f[_GAIN, a:b] = stage.gain * scale[a:b]  # as the oracle's `current_core`
        if sens is not None:
            aff_f[_GAIN, a:b] *= sens[a:b]
        aff_f[_DEAD, a:b] = unit_thresholds(stage, None if sens is None else sens[a:b], b - a)
        aff_f[_TONIC, a:b] = tonic_current(stage, afferent_id[a:b], b - a)  # as the oracle's `current_core`
    aff_f[_CV] = noise_cv / np.sqrt(1000.0 / fs)  # as the oracle's `current_core` and `_receptor_noise`
    aff_f[_SIGMA] = noise_sigma / np.sqrt(1000.0 / fs)  # as `noise_current`
    return aff_f


_IDENTITY = np.array([[1.0, 0.0, 0.0, 1.0, 0.0, 0.0]])  # an identity section (`current_filters._PASS_THROUGH`)


def group_tables(spans, consts, noise_cv, tuned, fs):
    """(grp_f, grp_i, sos) of the groups ``spans``: each group's stage constants, flags and filter sections."""
    n_groups, n_sec = len(spans), max([sos.shape[0] for _, sos, _, _ in consts] + [1])
    grp_f, grp_i = np.zeros((_N_GRP_ROWS, n_groups)), np.zeros((_N_GRP_INT_ROWS, n_groups), dtype=np.int64)
    sos_all = np.zeros((n_groups, n_sec, 6))
    for g, ((a, b), (st, sos, alpha_adapt, alpha_smooth)) in enumerate(zip(spans, consts)):
        sos_all[g, :sos.shape[0]] = sos
        plain = (st.derivative == 0 and st.cutoff_hz is None and st.adapt == 0.0 and st.tau_s is None
                 and np.array_equal(sos, _IDENTITY))  # a front end's sections are not plain
        grp_f[:, g] = [st.adapt, alpha_adapt, st.threshold, alpha_smooth, st.bias, st.negative_weight, st.dynamic,
                       float(-np.expm1(-1.0 / (fs * st.tau_dynamic_s))), st.fall,  # `currents._alpha`
                       st.shear, st.opponent_shear, st.depth, st.transient,
                       float(-np.expm1(-1.0 / (fs * st.tau_transient_s))),
                       float(-np.expm1(-1.0 / (fs * 0.5 * st.tau_transient_s))), st.opponent, st.normal]
        grp_i[:, g] = [sos.shape[0], st.derivative, st.signed, plain, np.any(noise_cv[a:b] > 0),
                       st.tau_s is not None, tuned[a], a, b]
    return grp_f, grp_i, sos_all


def transducer_runs(spans, consts):
    """(transducers, plain): (columns, stage) per run of groups that share a transducer, and the column
    slices with none (numpy's calls cost per call, so adjacent groups of one stage are merged)."""
    transducers, plain = [], []
    for (a, b), (st, *_) in zip(spans, consts):
        if st.i_sat is None and st.i_max is None and not st.signed:
            plain.append(slice(int(a), int(b)))
            continue
        if transducers and transducers[-1][1] is st and transducers[-1][0].stop == a:
            transducers[-1] = (slice(transducers[-1][0].start, int(b)), st)
        else:
            transducers.append((slice(int(a), int(b)), st))
    return transducers, plain
