"""Reproductions of the paper's Table II, Table III and Fig. 8 (and Figs 6-7).

Every afferent of a reproduction is simulated in one `models.integrate`
call, so the engines are compared on exactly the paper's scenes.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from models.attenuation import UNTUNED
from models.currents import AFFERENT_TYPES, CurrentParams
from models.engines import integrate, substeps_for
from models.metrics import direction_index, spiking_frequency
from models.pipeline import compute_currents
from population.scenes import Scene, birznieks, press_push_lift

__all__ = [
    "PROFILES",
    "PAPER_TABLE2",
    "PAPER_TABLE3",
    "ReproConfig",
    "scene_sf",
    "table2",
    "table3",
    "fig8",
    "reproduce_all",
]

#: Profiles in the reproductions; "cmm" is the conventional model (AF = 1).
PROFILES = ("selective", "broad", "bipolar", "cmm")
#: Paper Table II: PRSI at theta_R = 90 deg, k = 3.
PAPER_TABLE2 = {
    "selective": {"SAI": 0.38, "RAI": 0.31, "RAII": 0.33},
    "broad": {"SAI": 0.45, "RAI": 0.36, "RAII": 0.33},
    "bipolar": {"SAI": 0.0, "RAI": 0.0, "RAII": 0.0},
    "cmm": {"SAI": 0.0, "RAI": 0.0, "RAII": 0.0},
}
#: Paper Table III: SF in pulses/s at theta_T = 75 / 255 deg (press-push-lift).
PAPER_TABLE3 = {
    "selective": {"SAI": (37.5, 15.0), "RAI": (17.5, 7.5), "RAII": (15.0, 7.5)},
    "broad": {"SAI": (47.5, 10.0), "RAI": (20.0, 7.5), "RAII": (20.0, 7.5)},
    "bipolar": {"SAI": (37.5, 37.5), "RAI": (17.5, 17.5), "RAII": (15.0, 15.0)},
    "cmm": {"SAI": (47.5, 47.5), "RAI": (15.0, 15.0), "RAII": (10.0, 10.0)},
}
FIG8_ANGLES = tuple(range(0, 360, 15))


@dataclass(frozen=True)
class ReproConfig:
    """Settings shared by the reproductions.

    Attributes
    ----------
    engine : {"brian2", "direct"}
        Simulation engine.
    no_shear : {"pass", "block"}
        Reading of eq. 17 below F_TH.
    dt : float
        Integration step in seconds.
    k : float
        NAP sharpness (the paper uses k = 3).
    current_params : CurrentParams
        Gains and derivative filter.
    """

    engine: str = "brian2"
    no_shear: str = "pass"
    dt: float = 1e-4
    k: float = 3.0
    current_params: CurrentParams = CurrentParams()


def _model_profile(profile: str) -> str:
    return UNTUNED if profile == "cmm" else profile


def scene_sf(scene: Scene, theta_ts, config: ReproConfig = ReproConfig(), profiles=PROFILES):
    """SF (pulses/s) of every profile x type x theta_T on one scene.

    Returns
    -------
    dict
        ``{profile: {type: ndarray over theta_ts}}``.
    result : SpikeResult
        The spikes, columns ordered profile-major, then type, then angle.
    """
    theta_ts = np.asarray(theta_ts, dtype=float)
    blocks, types = [], []
    for profile in profiles:
        for kind in AFFERENT_TYPES:
            blocks.append(compute_currents(
                scene.fx, scene.fy, scene.fz, fs=scene.fs, afferent_type=kind,
                profile=_model_profile(profile), theta_t=theta_ts, k=config.k,
                no_shear=config.no_shear, current_params=config.current_params,
            ))
            types += [kind] * theta_ts.size
    current = np.hstack(blocks)
    result = integrate(current, fs=scene.fs, dt=config.dt, afferent_type=np.array(types, object),
                       engine=config.engine)
    sf = spiking_frequency(result.step, current.shape[1], fz=scene.fz, fs=scene.fs,
                           substeps=substeps_for(scene.fs, config.dt), afferent=result.afferent)
    sf = sf.reshape(len(profiles), len(AFFERENT_TYPES), theta_ts.size)
    table = {p: {t: sf[i, j] for j, t in enumerate(AFFERENT_TYPES)} for i, p in enumerate(profiles)}
    return table, result


def table2(config: ReproConfig = ReproConfig()) -> dict:
    """Table II: PRSI (eq. 19) on the Birznieks scene, theta_R = 90 deg.

    Returns ``{"prsi": {profile: {type: value}}}``.
    """
    sf, _ = scene_sf(birznieks(90.0), [0.0, 90.0, 180.0, 270.0], config)
    prsi = {p: {t: round(float(direction_index(*sf[p][t])), 4) for t in AFFERENT_TYPES} for p in sf}
    return {"prsi": prsi}


def _press_push_lift_sf(angles, config):
    sf, _ = scene_sf(press_push_lift(90.0), angles, config)
    return sf


def table3(config: ReproConfig = ReproConfig(), sf=None) -> dict:
    """Table III: SF at theta_T = 75 and 255 deg on press-push-lift (theta_R = 90 deg).

    Returns ``{"sf": {profile: {type: {"75": sf, "255": sf}}}}``.
    """
    angles = [75.0, 255.0]
    sf = _press_push_lift_sf(angles, config) if sf is None else sf
    return {"sf": {p: {t: {f"{a:g}": _sf_at(sf, p, t, a, angles) for a in angles}
                       for t in AFFERENT_TYPES} for p in sf}}


def _sf_at(sf, profile, kind, angle, angles):
    return round(float(sf[profile][kind][list(angles).index(angle)]), 3)


def fig8(config: ReproConfig = ReproConfig(), sf=None) -> dict:
    """Fig. 8: SF against theta_T = 0-345 deg in 15 deg steps on press-push-lift.

    Returns ``{"sf": {profile: {type: {"<angle>": sf}}}}``.
    """
    angles = [float(a) for a in FIG8_ANGLES]
    sf = _press_push_lift_sf(angles, config) if sf is None else sf
    return {"sf": {p: {t: {f"{a:g}": _sf_at(sf, p, t, a, angles) for a in angles}
                       for t in AFFERENT_TYPES} for p in sf}}


def reproduce_all(config: ReproConfig = ReproConfig()) -> dict:
    """All three reproductions; Table III is read from the Fig. 8 run (75 and 255 are on its grid)."""
    angles = [float(a) for a in FIG8_ANGLES]
    sf = _press_push_lift_sf(angles, config)
    sub = {p: {t: sf[p][t][[angles.index(75.0), angles.index(255.0)]] for t in AFFERENT_TYPES} for p in sf}
    return {"table2": table2(config), "table3": table3(config, sub), "fig8": fig8(config, sf)}
