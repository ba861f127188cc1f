"""The DDMM pipeline for a set of afferents: forces -> AF -> F_A -> currents -> spikes.

This is paper Fig. 3 end to end.  The CMM of Fig. 1 is the same pipeline
with ``profile="none"`` (AF = 1).
"""

from __future__ import annotations

import numpy as np

from ddmm.models.afferent_types import afferent_type_codes
from ddmm.models.attenuation import (
    F_TH,
    attenuated_force,
    attenuation_factor,
    profile_factor,
    shear_drive,
    stretch_drive,
)
from ddmm.models.current_params import CurrentParams
from ddmm.models.currents import afferent_current
from ddmm.models.engines import SpikeResult, integrate
from ddmm.utils.validation import as_finite_array, check_forces, check_instance, check_positive

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
        ``"SAI"``, ``"RAI"``, ``"RAII"`` or ``"SAII"`` per afferent (or one
        for all).  SA-II is driven by the attenuated shear (skin stretch).
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
        Currents in mV/ms.

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
    check_instance(current_params, "current_params", CurrentParams, "a CurrentParams")
    theta = np.atleast_1d(as_finite_array(theta_t, "theta_t"))
    types = np.broadcast_to(np.asarray(afferent_type, dtype=object), (theta.size,))
    unknown = sorted(set(types) - set(afferent_type_codes()), key=str)
    if unknown:
        raise ValueError(
            f"afferent_type={unknown[0]!r} is unknown; allowed: {', '.join(afferent_type_codes())}"
        )
    af = attenuation_factor(fx, fy, theta, profile, k, f_th=f_th, no_shear=no_shear)
    drive = attenuated_force(fz, af)
    for kind in afferent_type_codes(lambda t: not t.stretch_drive):  # F_A's depth and the presets' shear term
        cols = np.flatnonzero(types == kind)
        stage = current_params.for_type(kind)
        if cols.size and stage.depth != 1.0:
            drive[:, cols] = attenuated_force(fz, af[:, cols], stage.depth)
        if cols.size and stage.shear != 0.0:
            raw = profile_factor(fx, fy, theta[cols], profile, np.broadcast_to(k, theta.shape)[cols])
            drive[:, cols] = shear_drive(drive[:, cols], fx, fy, raw, stage.shear, stage.opponent_shear)
    for kind in afferent_type_codes("stretch_drive"):  # SA-II's: the attenuated shear (skin stretch), not F_Z
        cols = np.flatnonzero(types == kind)
        if cols.size:
            stage = current_params.for_type(kind)
            raw = profile_factor(fx, fy, theta[cols], profile, np.broadcast_to(k, theta.shape)[cols])
            drive[:, cols] = stretch_drive(fx, fy, raw, stage.opponent, fz, stage.normal)
    current = np.empty_like(drive)
    for kind in afferent_type_codes():
        cols = np.flatnonzero(types == kind)
        if cols.size:
            current[:, cols], _ = afferent_current(drive[:, cols], fs, kind, current_params)
    return current


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

