"""The DDMM for a set of afferents with one NAP: forces -> AF -> F_A -> currents -> spikes.

This is paper Fig. 3 end to end, on the production path
(`ddmm.models.fused.FusedPipeline`, the path `simulate` and the streaming
encoder run); `ddmm.models.reference_pipeline` computes the same currents
stage by stage, as the oracle the tests hold it to.  The CMM of Fig. 1 is
the same pipeline with ``profile="none"`` (AF = 1).
"""

from __future__ import annotations

import numpy as np

from ddmm.models.afferent_types import afferent_type_codes
from ddmm.models.attenuation import F_TH, NO_SHEAR_READINGS, UNTUNED
from ddmm.models.current_filters import check_fs
from ddmm.models.current_params import CurrentParams
from ddmm.models.engines import SpikeResult, integrate
from ddmm.models.fused import AfferentColumns, FusedPipeline
from ddmm.models.nap import PROFILES, validate_k
from ddmm.utils.validation import (
    as_finite_array,
    check_choice,
    check_forces,
    check_instance,
    check_positive,
)

__all__ = ["compute_currents", "simulate_afferents"]


def compute_currents(
    fx,
    fy,
    fz,
    *,
    fs: float,
    afferent_type,
    profile: str = "selective",
    theta_t=90.0,
    k=3.0,
    no_shear: str = "pass",
    f_th: float = F_TH,
    current_params: CurrentParams = CurrentParams(),
) -> np.ndarray:
    """Input currents of N afferents sharing one NAP profile (eqs 1-3, 16-18).

    Parameters
    ----------
    fx, fy, fz : array_like, shape (n_samples,)
        Fingertip force in newtons: shear components (+X radial, +Y distal)
        and the normal force (>= 0).
    fs : float
        Sample rate of the forces in Hz.
    afferent_type : str or sequence of str
        A registered type code (``"SAI"``, ``"RAI"``, ``"RAII"``, ``"SAII"``,
        ...) per afferent, or one for all.  SA-II is driven by the
        attenuated shear (skin stretch).
    profile : str
        ``"selective"``, ``"broad"``, ``"bipolar"`` or ``"none"`` (CMM).
    theta_t : float or array_like
        Tuning angle(s) theta_T in degrees.
    k : float or array_like
        Sharpness (eq. 12).
    no_shear : {"pass", "block", "smooth"}
        Reading of eq. 17 when the shear is below F_TH.
    f_th : float
        Shear threshold F_TH in newtons.
    current_params : CurrentParams
        Gains and derivative filter.

    Returns
    -------
    current : ndarray, shape (n_samples, n_afferents)
        Currents in mV/ms, noise-free: bit for bit those of
        `ddmm.models.reference_pipeline.reference_currents`.

    Examples
    --------
    >>> fz = np.r_[np.linspace(0, 4, 125), np.full(250, 4.0)]
    >>> i = compute_currents(np.zeros(375), np.zeros(375), fz, fs=1000.0,
    ...                      afferent_type="SAI", profile="none", theta_t=[0.0])
    >>> i.shape
    (375, 1)
    """
    fx, fy, fz = check_forces(fx, fy, fz)
    fs = check_positive(fs, "fs", "Hz")
    f_th = check_positive(f_th, "f_th", "N")
    check_choice(no_shear, "no_shear", NO_SHEAR_READINGS)
    check_instance(current_params, "current_params", CurrentParams, "a CurrentParams")
    theta, types, k = check_afferents(theta_t, afferent_type, profile, k)
    check_fs(fs, current_params, tuple(sorted(set(types.tolist()))))
    # No afferent ids here, so no unit has its own tonic spread (`<TYPE>.bias_cv`): each has its type's bias.
    params = current_params.with_all_types(bias_cv=0.0)
    columns = AfferentColumns.filled(types, nap=str(profile), theta_t=theta, k=k)
    pipeline = FusedPipeline(columns, params, fs, no_shear=no_shear, f_th=f_th)
    return pipeline.currents(np.column_stack([fx, fy, fz]), pipeline.new_state(), False)


def check_afferents(theta_t, afferent_type, profile: str, k):
    """(theta_t, afferent_type, k) of afferents sharing one NAP ``profile``, validated, one entry per afferent.

    Raises ``ValueError`` naming ``profile``, ``theta_t``, ``afferent_type`` or ``k``.

    Examples
    --------
    >>> theta, types, k = check_afferents([0.0, 90.0], "SAI", "selective", 3.0)
    >>> types.tolist(), k.tolist()
    (['SAI', 'SAI'], [3.0, 3.0])
    """
    check_choice(profile, "profile", (*PROFILES, UNTUNED))
    theta = np.atleast_1d(as_finite_array(theta_t, "theta_t"))
    if theta.ndim != 1:
        raise ValueError(f"theta_t must be a scalar or 1-D, got shape {theta.shape}")
    types = np.broadcast_to(np.asarray(afferent_type, dtype=object), (theta.size,))
    unknown = sorted(set(types) - set(afferent_type_codes()), key=str)
    if unknown:
        raise ValueError(
            f"afferent_type={unknown[0]!r} is unknown; allowed: {', '.join(afferent_type_codes())}"
        )
    if profile == UNTUNED:
        k = np.zeros(theta.size)  # the CMM reads no sharpness
    else:
        k = np.array(np.broadcast_to(validate_k(k, profile), theta.shape), dtype=float)
    return theta, types.astype(str), k


def simulate_afferents(
    fx,
    fy,
    fz,
    *,
    fs: float,
    afferent_type,
    profile: str = "selective",
    theta_t=90.0,
    k=3.0,
    dt: float = 1e-4,
    engine: str = "brian2",
    method: str = "euler",
    no_shear: str = "pass",
    f_th: float = F_TH,
    current_params: CurrentParams = CurrentParams(),
) -> SpikeResult:
    """Spikes of N afferents with one NAP profile for a force trace.

    Parameters are those of `compute_currents`, plus

    dt : float
        Integration step in seconds (default 0.1 ms); must divide ``1/fs``.
    engine : {"brian2", "direct"}
        Simulation engine; both give identical spikes.
    method : str
        Integration scheme (``"euler"``).

    Returns
    -------
    SpikeResult
        Spikes as (afferent index, step index) pairs.

    Examples
    --------
    >>> t = np.arange(500) / 1000.0
    >>> fz = np.interp(t, [0, 0.125, 0.375, 0.5], [0, 4, 4, 0])
    >>> fy = fz * np.tan(np.deg2rad(20.0))
    >>> res = simulate_afferents(np.zeros(500), fy, fz, fs=1000.0, afferent_type="SAI",
    ...                profile="selective", theta_t=[90.0, 270.0], engine="direct")
    >>> c = res.counts(2)
    >>> bool(c[0] > c[1])
    True
    """
    current = compute_currents(
        fx, fy, fz, fs=fs, afferent_type=afferent_type, profile=profile, theta_t=theta_t,
        k=k, no_shear=no_shear, f_th=f_th, current_params=current_params,
    )
    types = np.broadcast_to(np.asarray(afferent_type, dtype=object), (current.shape[1],))
    return integrate(current, fs=fs, dt=dt, afferent_type=types, engine=engine, method=method)

