"""Reproductions of the paper's Table II, Table III and Fig. 8 (and Figs 6-7).

Every afferent of a reproduction is simulated in one `ddmm.models.integrate`
call, so the engines are compared on exactly the paper's scenes.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from ddmm.models.afferent_types import PAPER_TYPES
from ddmm.models.attenuation import UNTUNED
from ddmm.models.current_params import CurrentParams
from ddmm.models.engines import integrate, substeps_for
from ddmm.models.metrics import direction_index, spiking_frequency
from ddmm.models.pipeline import compute_currents
from ddmm.population.stimuli.scenes import Scene, birznieks, press_push_lift
from ddmm.utils.deprecation import renamed_keyword

__all__ = [
    "PROFILES",
    "ReproConfig",
    "scene_sf",
    "table2",
    "table3",
    "fig8",
    "reproduce_all",
    "response_data",
    "FIGURE_SCENES",
]

#: Profiles in the reproductions; "cmm" is the conventional model (AF = 1).
PROFILES = ("selective", "broad", "bipolar", "cmm")
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
    sf_definition : {"contact_mean", "peak_bin"}
        The reading of Table III's SF (`ddmm.models.metrics.SF_DEFINITIONS`).
    bin_s : float
        Bin length in seconds of the ``peak_bin`` reading.
    ramp_s, lift_ramp_s, shear_delay_s : float
        Press-push-lift's press/push ramps, its lift ramp (None: ``ramp_s``)
        and the shear's onset into the push ramp, s (`press_push_lift`).
    birznieks_shear_delay_s : float
        The shear's onset into Birznieks' loading ramp, s (`birznieks`).
    """

    engine: str = "brian2"
    no_shear: str = "pass"
    dt: float = 1e-4
    k: float = 3.0
    current_params: CurrentParams = CurrentParams()
    sf_definition: str = "contact_mean"
    bin_s: float = 0.4
    ramp_s: float = 2.0
    lift_ramp_s: float | None = None
    shear_delay_s: float = 0.0
    birznieks_shear_delay_s: float = 0.0

    def birznieks(self, theta_r: float = 90.0) -> Scene:
        """The Table II scene (Birznieks' ramp-hold-release) with this configuration's shear onset."""
        return birznieks(theta_r, shear_delay_s=self.birznieks_shear_delay_s)

    def press_push_lift(self, theta_r: float = 90.0) -> Scene:
        """The Table III / Fig. 8 scene with this configuration's ramps and shear onset."""
        return press_push_lift(theta_r, ramp_s=self.ramp_s, lift_ramp_s=self.lift_ramp_s,
                               shear_delay_s=self.shear_delay_s)


def _model_profile(profile: str) -> str:
    return UNTUNED if profile == "cmm" else profile


@renamed_keyword("types", "afferent_types")
def scene_sf(scene: Scene, theta_ts, config: ReproConfig = ReproConfig(), profiles=PROFILES, afferent_types=PAPER_TYPES,
             definition: str | None = None):
    """SF (pulses/s) of every profile x type x theta_T on one scene.

    Returns
    -------
    dict
        ``{profile: {type: ndarray over theta_ts}}``.
    result : SpikeResult
        The spikes, columns ordered profile-major, then type, then angle.
    """
    theta_ts = np.asarray(theta_ts, dtype=float)
    blocks, column_types = [], []
    for profile in profiles:
        for kind in afferent_types:
            blocks.append(compute_currents(
                scene.fx, scene.fy, scene.fz, fs=scene.fs, afferent_type=kind,
                profile=_model_profile(profile), theta_t=theta_ts, k=config.k,
                no_shear=config.no_shear, current_params=config.current_params,
            ))
            column_types += [kind] * theta_ts.size
    current = np.hstack(blocks)
    result = integrate(current, fs=scene.fs, dt=config.dt, afferent_type=np.array(column_types, object),
                       engine=config.engine)
    sf = spiking_frequency(result.step, current.shape[1], fz=scene.fz, fs=scene.fs,
                           substeps=substeps_for(scene.fs, config.dt), afferent=result.afferent,
                           definition=definition or config.sf_definition, bin_s=config.bin_s)
    sf = sf.reshape(len(profiles), len(afferent_types), theta_ts.size)
    table = {p: {t: sf[i, j] for j, t in enumerate(afferent_types)} for i, p in enumerate(profiles)}
    return table, result


def table2(config: ReproConfig = ReproConfig()) -> dict:
    """Table II: PRSI (eq. 19) on the Birznieks scene, theta_R = 90 deg.

    Returns ``{"prsi": {profile: {type: value}}}``.
    """
    sf, _ = scene_sf(birznieks(90.0), [0.0, 90.0, 180.0, 270.0], config)
    prsi = {p: {t: round(float(direction_index(*sf[p][t])), 4) for t in PAPER_TYPES} for p in sf}
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
                       for t in PAPER_TYPES} for p in sf}}


def _sf_at(sf, profile, kind, angle, angles):
    return round(float(sf[profile][kind][list(angles).index(angle)]), 3)


def fig8(config: ReproConfig = ReproConfig(), sf=None) -> dict:
    """Fig. 8: SF against theta_T = 0-345 deg in 15 deg steps on press-push-lift.

    Returns ``{"sf": {profile: {type: {"<angle>": sf}}}}``.
    """
    angles = [float(a) for a in FIG8_ANGLES]
    sf = _press_push_lift_sf(angles, config) if sf is None else sf
    return {"sf": {p: {t: {f"{a:g}": _sf_at(sf, p, t, a, angles) for a in angles}
                       for t in PAPER_TYPES} for p in sf}}


def reproduce_all(config: ReproConfig = ReproConfig()) -> dict:
    """All three reproductions; Table III is read from the Fig. 8 run (75 and 255 are on its grid)."""
    angles = [float(a) for a in FIG8_ANGLES]
    sf = _press_push_lift_sf(angles, config)
    sub = {p: {t: sf[p][t][[angles.index(75.0), angles.index(255.0)]] for t in PAPER_TYPES} for p in sf}
    return {"table2": table2(config), "table3": table3(config, sub), "fig8": fig8(config, sf)}


@renamed_keyword("types", "afferent_types")
def response_data(scene: Scene, profile: str, angles, config: ReproConfig = ReproConfig(),
                  afferent_types=PAPER_TYPES) -> dict:
    """Data for a Fig. 6/7 panel: forces, AF(t) and spike times per type and theta_T.

    Parameters
    ----------
    scene : Scene
        The stimulus.
    profile : str
        A profile of `PROFILES`.
    angles : sequence of (label, theta_T in deg)
        Conditions, e.g. ``[("aligned", 90.0), ("misaligned", 180.0)]``.
    config : ReproConfig
        Reading, gains and SF definition.
    afferent_types : sequence of str
        The paper types to simulate (each condition's ``spikes`` has these keys).
    """
    from ddmm.models.attenuation import attenuation_factor

    thetas = [a for _, a in angles]
    _, result = scene_sf(scene, thetas, config, profiles=(profile,), afferent_types=afferent_types)
    af = attenuation_factor(scene.fx, scene.fy, thetas, _model_profile(profile), config.k,
                            no_shear=config.no_shear)
    conditions = []
    for j, (label, theta) in enumerate(angles):
        spikes = {kind: result.time[result.afferent == i * len(angles) + j]
                  for i, kind in enumerate(afferent_types)}
        conditions.append({"label": f"{profile}, {label} (theta_T = {theta:g} deg)",
                           "af": af[:, j], "spikes": spikes})
    return {"time": scene.time, "forces": {"fx": scene.fx, "fy": scene.fy, "fz": scene.fz},
            "conditions": conditions}


#: Conditions of paper Figs 6 (Birznieks scene) and 7 (press-push-lift): the scene of a `ReproConfig`, the angles.
FIGURE_SCENES = {
    "fig6": (lambda config: config.birznieks(90.0), (("aligned", 90.0), ("misaligned", 180.0))),
    "fig7": (lambda config: config.press_push_lift(90.0), (("near-aligned", 75.0), ("near-misaligned", 255.0))),
}
