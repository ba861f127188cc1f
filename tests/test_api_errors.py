"""Every public call refuses a wrong argument by name (issue 40, item 8).

A table of ``(callable, kwargs, argument)`` rows over the names that ``ddmm``,
``ddmm.models``, ``ddmm.population`` and its subpackages export: each row
passes one wrong-typed or out-of-range argument (an int for a path or a
Dataset, a str for a number, None where one is required, NaN, inf, a negative
duration, a wrong shape, an empty list) with every other argument valid.  The
call must raise ValueError or TypeError (or `MissingExtraError`) whose message
names the argument as a word: ``sample_population(5)`` answering with
pathlib's "expected str, not int" fails.

Values written ``_F("pop")`` are built once per module (`env`): a two-afferent
population, Birznieks' scene, their ``direct`` simulation, an encoder, an
electrode table, files in a temporary folder.
"""

from __future__ import annotations

import re

import numpy as np
import pytest

import ddmm
import ddmm.models as M
import ddmm.population as P
import ddmm.population.analysis as A
import ddmm.population.anatomy as H
import ddmm.population.io as IO
import ddmm.population.neurostim as N
import ddmm.population.runtime as R
import ddmm.population.stimuli as S
from ddmm.utils.extras import MissingExtraError

NAN, INF = float("nan"), float("inf")


class _F:
    """A value of the shared `env`, by key (resolved when the row runs)."""

    def __init__(self, key):
        self.key = key

    def __repr__(self):
        return self.key


def _fit(cls, **params):
    """Construct a scikit-learn decoder and fit it (scikit-learn checks parameters in ``fit``)."""
    from ddmm.population.analysis.ml import example_features

    _, X, y, _ = example_features()
    return cls(**params).fit(X, y)


_fit.__qualname__ = "fit"


class _Outlet:
    """Stands in for a pylsl outlet (a row that fails before pushing)."""

    def push_chunk(self, samples, stamps):
        pass


def _entered(context, **kwargs):
    """Enter and leave a context manager (it checks its arguments on entry)."""
    with context(**kwargs):
        pass


POP, SCENE, DS, TMP, NWB, CSV, TABLE, ENC, SITES, CONTACT = (
    _F(k) for k in ("pop", "scene", "ds", "tmp", "nwb", "csv", "table", "enc", "sites", "contact"))
ELEC = {"id": "E1", "amplitude_min_ua": 20.0, "amplitude_max_ua": 80.0, "phase_width_us": 200.0,
        "max_rate_hz": 300.0, "charge_limit_nc": 20.0, "x_mm": 0.0, "y_mm": 0.0, "radius_mm": 4.0}
POP_F = {"afferent_type": np.array(["SAI"], dtype=object), "theta_t": np.zeros(1),
         "nap": np.array(["none"], dtype=object), "k": np.zeros(1), "gain": np.ones(1), "x_mm": np.zeros(1),
         "y_mm": np.zeros(1), "noise_sigma": np.zeros(1), "noise_cv": np.zeros(1), "afferent_id": np.arange(1)}
KERNEL = {"table": TABLE, "rule": N.Biomimetic(), "fs": 1000.0, "members": [np.arange(2)], "weights": np.ones(2)}
F3 = {"fx": [0.0, 0.1, 0.2], "fy": [0.0, 0.0, 0.0], "fz": [0.0, 1.0, 2.0]}
SCENE_F = {"fx": np.zeros(10), "fy": np.zeros(10), "fz": np.ones(10)}

ROWS = [
    # ---- ddmm (the everyday names) ----
    (ddmm.Contact, {"x_mm": "a", "y_mm": 0.0, "radius_mm": 1.0}, "x_mm"),
    (ddmm.Contact, {"x_mm": 0.0, "y_mm": NAN, "radius_mm": 1.0}, "y_mm"),
    (ddmm.Contact, {"x_mm": 0.0, "y_mm": 0.0, "radius_mm": -1.0}, "radius_mm"),
    (ddmm.Contact, {"x_mm": 0.0, "y_mm": 0.0, "radius_mm": None}, "radius_mm"),
    (ddmm.Encoder, {"population": 5, "fs": 1000.0}, "population"),
    (ddmm.Encoder, {"population": POP, "fs": -1.0}, "fs"),
    (ddmm.Encoder, {"population": POP, "fs": "fast"}, "fs"),
    (ddmm.Encoder, {"population": POP, "fs": 1000.0, "dt": 0.0}, "dt"),
    (ddmm.Encoder, {"population": POP, "fs": 1000.0, "engine": 5}, "engine"),
    (ddmm.Encoder, {"population": POP, "fs": 1000.0, "contact": 5}, "contact"),
    (ddmm.Encoder, {"population": POP, "fs": 1000.0, "model_fs": -5.0}, "model_fs"),
    (ddmm.Population, dict(POP_F, current=5), "current"),
    (ddmm.Population, dict(POP_F, theta_t=np.zeros(2)), "theta_t"),
    (ddmm.Population, dict(POP_F, gain=np.array([-1.0])), "gain"),
    (ddmm.PopulationSpec, {"types": 5}, "types"),
    (ddmm.PopulationSpec, {"name": 5}, "name"),
    (ddmm.PopulationSpec, {"receptive_field": "square"}, "receptive_field"),
    (ddmm.Scene, {"fx": "abc", "fy": [0.0], "fz": [1.0]}, "fx"),
    (ddmm.Scene, {"fx": [0.0], "fy": [0.0], "fz": [-1.0]}, "fz"),
    (ddmm.Scene, {"fx": [0.0, 0.0], "fy": [0.0], "fz": [1.0]}, "fy"),
    (ddmm.Scene, dict(**SCENE_F, fs=-1.0), "fs"),
    (ddmm.Scene, dict(**SCENE_F, fs="x"), "fs"),
    (ddmm.Scene, dict(**SCENE_F, name=5), "name"),
    (ddmm.Scene, dict(**SCENE_F, theta_r="up"), "theta_r"),
    (ddmm.Scene, dict(**SCENE_F, contact=5), "contact"),
    (ddmm.Scene, dict(**SCENE_F, stages=5), "stages"),
    (ddmm.Sites, {"x_mm": "a", "y_mm": [0.0], "radius_mm": [1.0]}, "x_mm"),
    (ddmm.Sites, {"x_mm": [0.0], "y_mm": [0.0], "radius_mm": [-1.0]}, "radius_mm"),
    (ddmm.Sites, {"x_mm": [], "y_mm": [], "radius_mm": []}, "x_mm"),
    (ddmm.Stage, {"label": 5, "start": 0.0, "end": 1.0}, "label"),
    (ddmm.Stage, {"label": "a", "start": NAN, "end": 1.0}, "start"),
    (ddmm.Stage, {"label": "a", "start": 1.0, "end": 0.5}, "end"),
    (ddmm.birznieks, {"direction_deg": "up"}, "direction_deg"),
    (ddmm.birznieks, {"normal_n": -1.0}, "normal_n"),
    (ddmm.birznieks, {"angle_deg": NAN}, "angle_deg"),
    (ddmm.birznieks, {"ramp_s": 0.0}, "ramp_s"),
    (ddmm.birznieks, {"hold_s": -1.0}, "hold_s"),
    (ddmm.birznieks, {"fs": INF}, "fs"),
    (ddmm.birznieks, {"contact": 5}, "contact"),
    (ddmm.from_csv, {"path": 5}, "path"),
    (ddmm.from_csv, {"path": None}, "path"),
    (ddmm.from_csv, {"path": CSV, "fs": -1.0}, "fs"),
    (ddmm.from_csv, {"path": CSV, "units": "furlongs"}, "units"),
    (ddmm.from_csv, {"path": CSV, "force_scale": NAN}, "force_scale"),
    (ddmm.from_csv, {"path": CSV, "fz_sign": 2}, "fz_sign"),
    (ddmm.from_csv, {"path": CSV, "negative_fz": "ignore"}, "negative_fz"),
    (ddmm.from_csv, {"path": CSV, "conditioning": 5}, "conditioning"),
    (ddmm.from_csv, {"path": CSV, "columns": 5}, "columns"),
    (ddmm.load_dataset, {"path": 5}, "path"),
    (ddmm.load_dataset, {"path": None}, "path"),
    (ddmm.load_spec, {"source": 5}, "source"),
    (ddmm.load_spec, {"source": None}, "source"),
    (ddmm.make_population, {"afferent_type": 5}, "afferent_type"),
    (ddmm.make_population, {"afferent_type": []}, "afferent_type"),
    (ddmm.make_population, {"afferent_type": ["SAI"], "theta_t": "x"}, "theta_t"),
    (ddmm.make_population, {"afferent_type": ["SAI"], "nap": 5}, "nap"),
    (ddmm.make_population, {"afferent_type": ["SAI"], "nap": "selective", "k": -1.0}, "k"),
    (ddmm.make_population, {"afferent_type": ["SAI"], "gain": NAN}, "gain"),
    (ddmm.make_population, {"afferent_type": ["SAI", "RAI"], "x_mm": [0.0, 1.0, 2.0]}, "x_mm"),
    (ddmm.make_population, {"afferent_type": ["SAI"], "noise_cv": -0.5}, "noise_cv"),
    (ddmm.make_population, {"afferent_type": ["SAI"], "current": 5}, "current"),
    (ddmm.make_population, {"afferent_type": ["SAI"], "receptive_field": 5}, "receptive_field"),
    (ddmm.plan_run, {"population": 5, "scenes": SCENE}, "population"),
    (ddmm.plan_run, {"population": POP, "scenes": 5}, "scenes"),
    (ddmm.plan_run, {"population": POP, "scenes": []}, "scenes"),
    (ddmm.plan_run, {"population": POP, "scenes": SCENE, "trials": 0}, "trials"),
    (ddmm.press_push_lift, {"theta_r": "x"}, "theta_r"),
    (ddmm.press_push_lift, {"press_n": -1.0}, "press_n"),
    (ddmm.press_push_lift, {"ramp_s": NAN}, "ramp_s"),
    (ddmm.press_push_lift, {"fs": 0.0}, "fs"),
    (ddmm.psth, {"ds": 5}, "ds"),
    (ddmm.psth, {"ds": DS, "bin_s": -0.01}, "bin_s"),
    (ddmm.psth, {"ds": DS, "bin_s": "x"}, "bin_s"),
    (ddmm.psth, {"ds": DS, "by": "colour"}, "by"),
    (ddmm.rotating_shear, {"period_s": 0.0}, "period_s"),
    (ddmm.rotating_shear, {"turns": -1.0}, "turns"),
    (ddmm.rotating_shear, {"normal_n": "x"}, "normal_n"),
    (ddmm.rotating_shear, {"start_deg": INF}, "start_deg"),
    (ddmm.sample_population, {"spec": 5}, "spec"),
    (ddmm.sample_population, {"spec": None}, "spec"),
    (ddmm.sample_population, {"spec": "fingertip", "rng": "x"}, "rng"),
    (ddmm.save_dataset, {"ds": 5, "path": TMP}, "ds"),
    (ddmm.save_dataset, {"ds": DS, "path": 5}, "path"),
    (ddmm.simulate, {"population": 5, "scenes": SCENE, "engine": "direct"}, "population"),
    (ddmm.simulate, {"population": POP, "scenes": 5, "engine": "direct"}, "scenes"),
    (ddmm.simulate, {"population": POP, "scenes": [], "engine": "direct"}, "scenes"),
    (ddmm.simulate, {"population": POP, "scenes": SCENE, "engine": 5}, "engine"),
    (ddmm.simulate, {"population": POP, "scenes": SCENE, "engine": "direct", "trials": 0}, "trials"),
    (ddmm.simulate, {"population": POP, "scenes": SCENE, "engine": "direct", "dt": -1e-4}, "dt"),
    (ddmm.simulate, {"population": POP, "scenes": SCENE, "engine": "direct", "seed": "x"}, "seed"),
    (ddmm.simulate, {"population": POP, "scenes": SCENE, "engine": "direct", "record": 5}, "record"),
    (ddmm.simulate, {"population": POP, "scenes": SCENE, "engine": "direct", "no_shear": "drop"}, "no_shear"),
    (ddmm.simulate, {"population": POP, "scenes": SCENE, "engine": "direct", "tolerance": -1.0}, "tolerance"),
    (ddmm.simulate, {"population": POP, "scenes": SCENE, "engine": "direct", "afferent_types": 5}, "afferent_types"),
    (ddmm.simulate, {"population": POP, "scenes": SCENE, "engine": "direct", "chunk_size": 0}, "chunk_size"),
    (ddmm.simulate, {"population": POP, "scenes": SCENE, "engine": "direct", "time_chunk": -1}, "time_chunk"),
    # ---- ddmm.models ----
    (M.CurrentParams, {"cutoff_hz": "x"}, "cutoff_hz"),
    (M.CurrentParams, {"cutoff_hz": -1.0}, "cutoff_hz"),
    (M.CurrentParams, {"filter_order": 0}, "filter_order"),
    (M.CurrentParams, {"i_sat": NAN}, "i_sat"),
    (M.NeuronParams, {"a": "x"}, "a"),
    (M.NeuronParams, {"t_ref": -1.0}, "t_ref"),
    (M.NeuronState, {"v": "x", "u": [0.0]}, "v"),
    (M.NeuronState, {"v": [0.0], "u": None}, "u"),
    (M.TypeParams, {"gain": "x"}, "gain"),
    (M.afferent_current, {"f_a": "x", "fs": 1000.0, "afferent_type": "SAI"}, "f_a"),
    (M.afferent_current, {"f_a": np.ones((3, 1)), "fs": -1.0, "afferent_type": "SAI"}, "fs"),
    (M.afferent_current, {"f_a": np.ones((3, 1)), "fs": 1000.0, "afferent_type": 5}, "afferent_type"),
    (M.afferent_current, {"f_a": np.ones((3, 1)), "fs": 1000.0, "afferent_type": "SAI", "params": 5}, "params"),
    (M.attenuated_force, {"fz": "x", "af": [1.0]}, "fz"),
    (M.attenuated_force, {"fz": [1.0], "af": [[1.0]], "depth": -1.0}, "depth"),
    (M.attenuated_force, {"fz": [1.0, 2.0], "af": [[1.0]]}, "af"),
    (M.attenuation_factor, {"fx": "x", "fy": [0.0], "theta_t": 0.0, "profile": "selective"}, "fx"),
    (M.attenuation_factor, {"fx": [0.0], "fy": [0.0], "theta_t": 0.0, "profile": 5}, "profile"),
    (M.attenuation_factor, {"fx": [0.0], "fy": [0.0], "theta_t": 0.0, "profile": "selective", "k": -1.0}, "k"),
    (M.attenuation_factor, {"fx": [0.0], "fy": [0.0], "theta_t": "x", "profile": "selective"}, "theta_t"),
    (M.attenuation_factor, {"fx": [0.0], "fy": [0.0], "theta_t": 0.0, "profile": "selective", "f_th": NAN}, "f_th"),
    (M.attenuation_factor, {"fx": [0.0], "fy": [0.0], "theta_t": 0.0, "profile": "selective", "no_shear": "x"},
     "no_shear"),
    (M.boundary_radius, {"sin_phi": "x", "cos_phi": [1.0], "profile": "selective", "k": 3.0}, "sin_phi"),
    (M.boundary_radius, {"sin_phi": [0.0], "cos_phi": [1.0], "profile": 5, "k": 3.0}, "profile"),
    (M.compute_currents, dict(**F3, fs=-1.0, afferent_type="SAI"), "fs"),
    (M.compute_currents, dict(**F3, fs=1000.0, afferent_type="SAI", profile="sharp"), "profile"),
    (M.compute_currents, dict(**F3, fs=1000.0, afferent_type="SAI", no_shear="never"), "no_shear"),
    (M.compute_currents, dict(**F3, fs=1000.0, afferent_type="SAI", f_th=0.0), "f_th"),
    (M.compute_currents, dict(**F3, fs=1000.0, afferent_type="SAI", profile="broad", k=1.0), "k"),
    (M.compute_currents, dict(**F3, fs=1000.0, afferent_type="SAI", theta_t=[[1.0]]), "theta_t"),
    (M.DriveTable.of, {"afferent_type": ["SAI"], "params": 5}, "params"),
    (M.DriveTable.of, {"afferent_type": ["SAI", "SA3"], "params": M.CurrentParams()}, "afferent_type"),
    (M.reference_currents, dict(**F3, fs=-1.0, afferent_type="SAI"), "fs"),
    (M.reference_currents, dict(**F3, fs=1000.0, afferent_type=5), "afferent_type"),
    (M.compute_currents, dict(**F3, fs=1000.0, afferent_type=5), "afferent_type"),
    (M.compute_currents, {"fx": "x", "fy": [0.0], "fz": [1.0], "fs": 1000.0, "afferent_type": "SAI"}, "fx"),
    (M.compute_currents, dict(**F3, fs=1000.0, afferent_type="SAI", current_params=5), "current_params"),
    (M.direction_index, {"r0": "x", "r90": 1.0, "r180": 1.0, "r270": 1.0}, "r0"),
    (M.direction_index, {"r0": 1.0, "r90": -1.0, "r180": 1.0, "r270": 1.0}, "r90"),
    (M.filter_force, {"f_a": "x", "fs": 1000.0}, "f_a"),
    (M.filter_force, {"f_a": np.ones((3, 1)), "fs": 0.0}, "fs"),
    (M.filter_force, {"f_a": np.ones((3, 1)), "fs": 1000.0, "params": 5}, "params"),
    (M.get_engine, {"engine": 5}, "engine"),
    (M.get_engine, {"engine": "warp"}, "engine"),
    (M.integrate, {"current": "x", "fs": 1000.0, "dt": 1e-4, "afferent_type": "SAI", "engine": "direct"}, "current"),
    (M.integrate, {"current": np.zeros((1, 10)), "fs": -1.0, "dt": 1e-4, "afferent_type": "SAI", "engine": "direct"},
     "fs"),
    (M.integrate, {"current": np.zeros((1, 10)), "fs": 1000.0, "dt": 0.0, "afferent_type": "SAI", "engine": "direct"},
     "dt"),
    (M.integrate, {"current": np.zeros((1, 10)), "fs": 1000.0, "dt": 1e-4, "afferent_type": "SAI", "engine": 5},
     "engine"),
    (M.integrate, {"current": np.zeros((1, 10)), "fs": 1000.0, "dt": 1e-4, "afferent_type": "SAI", "engine": "direct",
                   "method": "magic"}, "method"),
    (M.k_from_selectivity, {"theta_a_deg": "x", "profile": "selective"}, "theta_a_deg"),
    (M.k_from_selectivity, {"theta_a_deg": 90.0, "profile": 5}, "profile"),
    (M.normalize_type, {"afferent_type": 5}, "afferent_type"),
    (M.normalize_type, {"afferent_type": "XYZ"}, "afferent_type"),
    (M.resting_state, {"b": "x"}, "b"),
    (M.selectivity_from_k, {"k": "x", "profile": "selective"}, "k"),
    (M.selectivity_from_k, {"k": 3.0, "profile": 5}, "profile"),
    (M.shear_magnitude, {"fx": "x", "fy": [0.0]}, "fx"),
    (M.shear_magnitude, {"fx": [0.0], "fy": None}, "fy"),
    (M.simulate_afferents, dict(**F3, fs=1000.0, afferent_type="SAI", engine="direct", dt=-1.0), "dt"),
    (M.simulate_afferents, dict(**F3, fs=1000.0, afferent_type="SAI", engine=5), "engine"),
    (M.simulate_afferents, dict(**F3, fs=NAN, afferent_type="SAI", engine="direct"), "fs"),
    (M.spiking_frequency, {"step": "x", "n_afferents": 1, "fz": [1.0] * 4, "fs": 1000.0, "substeps": 10}, "step"),
    (M.spiking_frequency, {"step": [1], "n_afferents": -1, "fz": [1.0] * 4, "fs": 1000.0, "substeps": 10},
     "n_afferents"),
    (M.spiking_frequency, {"step": [1], "n_afferents": 1, "fz": [1.0] * 4, "fs": -1.0, "substeps": 10}, "fs"),
    (M.spiking_frequency, {"step": [1], "n_afferents": 1, "fz": [1.0] * 4, "fs": 1000.0, "substeps": 0}, "substeps"),
    (M.spiking_frequency, {"step": [1], "n_afferents": 1, "fz": [1.0] * 4, "fs": 1000.0, "substeps": 10,
                           "definition": "x"}, "definition"),
    (M.substeps_for, {"fs": -1.0, "dt": 1e-4}, "fs"),
    (M.substeps_for, {"fs": 1000.0, "dt": 0.0}, "dt"),
    (M.type_label, {"afferent_type": 5}, "afferent_type"),
    # ---- ddmm.population ----
    (S.Pins, {"x_mm": [0.0], "y_mm": [0.0], "radius_mm": 0.0}, "radius_mm"),
    (S.Pins, {"x_mm": [0.0, 1.0], "y_mm": [0.0]}, "y_mm"),
    (S.probe, {"x_mm": NAN}, "x_mm"),
    (S.pin_array, {"rows": 0, "cols": 2}, "rows"),
    (S.pin_array, {"rows": 2, "cols": 2, "pitch_mm": -1.0}, "pitch_mm"),
    (S.bar_pins, {"width_mm": 0.0}, "width_mm"),
    (S.circle_pins, {"radius_mm": 1.0, "curvature_mm": -0.1}, "curvature_mm"),
    (S.ramp_hold, {"depth_mm": -0.5}, "depth_mm"),
    (S.ramp_hold, {"depth_mm": 0.5, "hold_s": 0.0}, "hold_s"),
    (S.sinusoid, {"freq_hz": 0.0, "amplitude_mm": 0.1, "pre_indent_mm": 0.3}, "freq_hz"),
    (S.sinusoid, {"freq_hz": 50.0, "amplitude_mm": 0.1, "pre_indent_mm": 0.3, "fs": 80.0}, "fs"),
    (S.band_noise, {"low_hz": 100.0, "high_hz": 300.0, "sd_mm": 0.0, "pre_indent_mm": 0.3}, "sd_mm"),
    (S.band_noise, {"low_hz": 100.0, "high_hz": 300.0, "sd_mm": 0.01, "pre_indent_mm": 0.3, "rng": "x"}, "rng"),
    (S.impulse, {"amplitude_mm": 0.0}, "amplitude_mm"),
    (S.impulse, {"amplitude_mm": 0.1, "width_s": 1e-4}, "width_s"),
    (S.indent, {"pins": "probe", "depth_mm": [0.1, 0.2]}, "pins"),
    (S.indent, {"pins": S.probe(), "depth_mm": [0.1, -0.2]}, "depth_mm"),
    (S.indent, {"pins": S.probe(), "depth_mm": [0.1, 0.2], "lateral_mm": [[0.0]]}, "lateral_mm"),
    (S.indent, {"pins": S.probe(), "depth_mm": [0.1, 0.2], "skin": "rubber"}, "skin"),
    (S.indentation_from_dict, {"table": 5}, "table"),
    (S.SkinMechanics, {"name": "x", "youngs_modulus_pa": -1.0, "poisson": 0.4, "friction": 0.5,
                       "dynamic": "derivative", "wave_speed_mm_s": None, "cap_pin_radius": False,
                       "receptor_depth_mm": ()}, "youngs_modulus_pa"),
    (S.get_skin_mechanics, {"skin": "rubber"}, "skin"),
    (S.Transduction, {"gain": -1.0}, "gain"),
    (S.Transduction, {"gain": 1.0, "zero_hz": 0.0, "pole_hz": 10.0}, "zero_hz"),
    (S.get_transduction, {"transduction": "fited"}, "transduction"),
    (S.indent, {"pins": S.probe(), "depth_mm": [0.1, 0.2], "transduction": "fited"}, "transduction"),
    (S.solve_pin_loads, {"depth_mm": [[-0.1]], "x_mm": [0.0], "y_mm": [0.0], "radius_mm": 0.5,
                         "skin": S.get_skin_mechanics("default")}, "depth_mm"),
    (S.stress_kernel, {"pin_x": [0.0], "pin_y": [0.0], "radius_mm": 0.5, "x_mm": [0.0], "y_mm": [0.0],
                       "depth_mm": 0.0}, "depth_mm"),
    (S.normal_stress, {"loads": [[-1.0]], "pin_x": [0.0], "pin_y": [0.0], "radius_mm": 0.5, "x_mm": [0.0],
                       "y_mm": [0.0], "depth_mm": 0.5}, "loads"),
    (S.tangential_loads, {"lateral_mm": [[[0.1, 0.0]]], "loads": [[1.0]], "radius_mm": -0.5,
                          "skin": S.get_skin_mechanics("default")}, "radius_mm"),
    (S.Surface, {"height_mm": [[0.0, -1.0]], "pixel_mm": 0.1}, "height_mm"),
    (S.Surface, {"height_mm": [[0.0, 1.0]], "pixel_mm": 0.0}, "pixel_mm"),
    (S.grating, {"period_mm": -1.0}, "period_mm"),
    (S.dot_pattern, {"spacing_mm": 1.0, "dot_radius_mm": 0.6}, "dot_radius_mm"),
    (S.letters, {"text": "A#"}, "text"),
    (S.from_bitmap, {"array": [[0.0, 2.0]], "pixel_mm": 0.1, "relief_mm": 0.5}, "array"),
    (S.min_scan_fs, {"speed_mm_s": 0.0, "pixel_mm": 0.05}, "speed_mm_s"),
    (S.scan, {"surface": "grating"}, "surface"),
    (S.scan_depths, {"surface": "grating"}, "surface"),
    (S.scan_depths, {"surface": S.grating(1.0), "pitch_mm": -0.2}, "pitch_mm"),
    (S.scan, {"surface": S.grating(1.0), "speed_mm_s": 40.0, "fs": 100.0}, "fs"),
    (P.Conditioning, {"noise_n": -1.0}, "noise_n"),
    (P.Conditioning, {"mode": "psychic"}, "mode"),
    (P.Conditioning, {"slow_hz": "x"}, "slow_hz"),
    (P.binned_counts, {"ds": 5, "bin_s": 0.01}, "ds"),
    (P.binned_counts, {"ds": DS, "bin_s": 0.0}, "bin_s"),
    (P.binned_counts, {"ds": DS, "bin_s": 0.01, "t_max": -1.0}, "t_max"),
    (P.binned_rates, {"ds": 5, "bin_s": 0.01}, "ds"),
    (P.binned_rates, {"ds": DS, "bin_s": NAN}, "bin_s"),
    (P.condition_forces, {"forces": "x", "fs_in": 1000.0, "fs_out": 1000.0}, "forces"),
    (P.condition_forces, {"forces": np.zeros((10, 3)), "fs_in": -1.0, "fs_out": 1000.0}, "fs_in"),
    (P.condition_forces, {"forces": np.zeros((10, 3)), "fs_in": 1000.0, "fs_out": 0.0}, "fs_out"),
    (P.condition_forces, {"forces": np.zeros((10, 3)), "fs_in": 1000.0, "fs_out": 1000.0, "conditioning": 5},
     "conditioning"),
    (P.describe_dataset, {"ds": 5}, "ds"),
    (P.from_array, {"path": 5}, "path"),
    (P.from_array, {"path": None}, "path"),
    (P.from_xdf, {"path": 5}, "path"),
    (P.read_xdf, {"path": None}, "path"),
    (P.read_xdf, {"path": CSV, "stream": 5}, "stream"),
    (P.read_xdf, {"path": CSV, "sites": 5}, "sites"),
    (P.read_xdf, {"path": CSV, "recorded_fs": -1.0}, "recorded_fs"),
    (P.read_xdf, {"path": CSV, "units": "furlongs"}, "units"),
    (P.read_xdf, {"path": CSV, "fz_sign": 2}, "fz_sign"),
    (P.read_xdf, {"path": CSV, "conditioning": 5}, "conditioning"),
    (P.read_xdf, {"path": CSV, "max_force_n": NAN}, "max_force_n"),
    (P.from_long_csv, {"forces_csv": 5, "sites_csv": "s.csv"}, "forces_csv"),
    (P.from_long_csv, {"forces_csv": CSV, "sites_csv": 5}, "sites_csv"),
    (P.make_plan, {"population": 5, "scenes": [SCENE]}, "population"),
    (P.make_plan, {"population": POP, "scenes": [SCENE], "trials": 0}, "trials"),
    (P.make_plan, {"population": POP, "scenes": [SCENE], "chunk_size": 0}, "chunk_size"),
    (P.save_array, {"path": 5, "scene": SCENE}, "path"),
    (P.save_array, {"path": TMP, "scene": 5}, "scene"),
    (P.spec_from_dict, {"data": 5}, "data"),
    (P.spec_from_dict, {"data": {}, "default_name": 5}, "default_name"),
    (P.taxel_radius, {"pitch_mm": -1.0}, "pitch_mm"),
    (P.taxel_radius, {"pitch_mm": "x"}, "pitch_mm"),
    (P.to_brian2, {"dataset": 5}, "dataset"),
    (P.to_brian2, {"dataset": DS, "condition": 99}, "condition"),
    (P.to_brian2, {"dataset": DS, "trial": -5}, "trial"),
    (P.to_brian2, {"dataset": DS, "dt": -1.0}, "dt"),
    (P.to_brian2, {"dataset": DS, "gap_s": NAN}, "gap_s"),
    (P.to_neo, {"dataset": 5}, "dataset"),
    (P.to_nwb, {"dataset": 5, "path": NWB}, "dataset"),
    (P.to_nwb, {"dataset": DS, "path": 5}, "path"),
    (P.to_nwb, {"dataset": DS, "path": NWB, "session_start_time": "yesterday"}, "session_start_time"),
    # ---- ddmm.population.analysis ----
    (A.CentroidClassifier, {"shrinkage": -1.0}, "shrinkage"),
    (A.CentroidClassifier, {"shrinkage": "x"}, "shrinkage"),
    (A.FirstSpikeLatency, {"window_s": -1.0}, "window_s"),
    (A.MaximumLikelihood, {"window_s": 0.0}, "window_s"),
    (A.PopulationVector, {"window_s": NAN}, "window_s"),
    (_fit, {"cls": A.FirstSpikeLatencyDecoder, "alpha": -1.0}, "alpha"),
    (_fit, {"cls": A.MaximumLikelihoodDecoder, "ridge": -1.0}, "ridge"),
    (_fit, {"cls": A.PopulationVectorDecoder, "theta_t": "x"}, "theta_t"),
    (A.SlipDetector, {"window_s": -1.0}, "window_s"),
    (A.SlipDetector, {"margin": 0.0}, "margin"),
    (A.SlipDetector, {"start_stage": 5}, "start_stage"),
    (A.angular_error, {"a_deg": "x", "b_deg": 0.0}, "a_deg"),
    (A.angular_error, {"a_deg": [0.0, 1.0], "b_deg": [0.0, 1.0, 2.0]}, "b_deg"),
    (A.circular_score, {"y_true": "x", "y_pred": [0.0]}, "y_true"),
    (A.circular_score, {"y_true": [0.0], "y_pred": [NAN]}, "y_pred"),
    (A.ScanPath, {"speed_mm_s": -1.0, "duration_s": 1.0}, "speed_mm_s"),
    (A.ScanPath, {"speed_mm_s": 40.0, "duration_s": "x"}, "duration_s"),
    (A.ScanPath, {"speed_mm_s": 40.0, "duration_s": 1.0, "direction_deg": INF}, "direction_deg"),
    (A.ScanPath, {"speed_mm_s": 40.0, "duration_s": 1.0, "center_mm": (NAN, 0.0)}, "center_mm"),
    (A.spatial_events, {"dataset": 5, "path": A.ScanPath(40.0, 1.0)}, "dataset"),
    (A.spatial_events, {"dataset": DS, "path": None}, "path"),
    (A.spatial_events, {"dataset": DS, "path": A.ScanPath(40.0, 1.0), "latency_s": NAN}, "latency_s"),
    (A.spatial_events, {"dataset": DS, "path": A.ScanPath(40.0, 1.0), "condition": 99}, "condition"),
    (A.event_rate_map, {"dataset": DS, "path": A.ScanPath(40.0, 1.0), "afferent_type": "XYZ"}, "afferent_type"),
    (A.event_rate_map, {"dataset": DS, "path": A.ScanPath(40.0, 1.0), "afferent_type": "SAI", "bin_mm": INF},
     "bin_mm"),
    (A.relief_correlation, {"rate_map": 5, "surface": S.grating(1.0)}, "rate_map"),
    (A.direction_tuning, {"ds": 5}, "ds"),
    (A.direction_tuning, {"ds": DS, "alpha": 2.0}, "alpha"),
    (A.direction_tuning, {"ds": DS, "correction": "magic"}, "correction"),
    (A.evaluate_slip, {"times": "x", "slip": [True], "onset": 0.1, "duration": 1.0}, "times"),
    (A.evaluate_slip, {"times": [[0.2]], "slip": [True], "onset": 0.1, "duration": -1.0}, "duration"),
    (A.example_features, {"kind": "colour"}, "kind"),
    (A.features, {"dataset": 5}, "dataset"),
    (A.features, {"dataset": DS, "window_s": -1.0}, "window_s"),
    (A.features, {"dataset": DS, "kind": "colour"}, "kind"),
    (A.features, {"dataset": DS, "group_by": "colour"}, "group_by"),
    (A.onset_counts, {"ds": 5, "onset_s": [0.0], "window_s": 0.1}, "ds"),
    (A.onset_counts, {"ds": DS, "onset_s": [0.0], "window_s": -0.1}, "window_s"),
    (A.score_physiology, {"population": 5, "references": {}}, "population"),
    (A.score_physiology, {"population": POP, "references": 5, "properties": ["rest_rate_SAI"]}, "references"),
    (A.select_afferents, {"ds": 5, "positions": [0]}, "ds"),
    (A.select_afferents, {"ds": DS, "positions": "x"}, "positions"),
    (A.select_afferents, {"ds": DS, "positions": [99]}, "positions"),
    (A.stage_onset, {"ds": 5, "label": "loading"}, "ds"),
    (A.stage_onset, {"ds": DS, "label": "nonexistent"}, "label"),
    (A.summarise_scorecard, {"rows": 5}, "rows"),
    (A.tuning_scenes, {"normal_n": -1.0}, "normal_n"),
    (A.tuning_summary, {"tuning": 5}, "tuning"),
    (A.tuning_summary, {"tuning": DS}, "tuning"),
    (A.window_responses, {"ds": 5, "window_s": 0.1}, "ds"),
    (A.window_responses, {"ds": DS, "window_s": -0.1}, "window_s"),
    (A.window_responses, {"ds": DS, "window_s": 0.1, "start_s": NAN}, "start_s"),
    # ---- ddmm.population.anatomy ----
    (H.HandRegion, {"name": 5, "kind": "fingertip", "shape": None}, "name"),
    (H.frame_theta, {"population": 5}, "population"),
    (H.get_region, {"name": 5}, "name"),
    (H.get_region, {"name": "Z9"}, "name"),
    (H.local_mixing, {"x_mm": "x", "y_mm": [0.0], "afferent_type": ["SAI"], "sites": SITES}, "x_mm"),
    (H.local_mixing, {"x_mm": [0.0], "y_mm": [0.0], "afferent_type": ["SAI"], "sites": 5}, "sites"),
    (H.outline, {"name": 5}, "name"),
    (H.outline, {"name": "D2d", "n": 0}, "n"),
    (H.receptive_field_weight, {"x_mm": "x", "y_mm": [0.0], "afferent_type": ["SAI"], "contact": CONTACT}, "x_mm"),
    (H.receptive_field_weight, {"x_mm": [0.0], "y_mm": [0.0], "afferent_type": ["SAI"], "contact": 5}, "contact"),
    (H.receptive_field_weight, {"x_mm": [0.0], "y_mm": [0.0], "afferent_type": ["SAI"], "contact": CONTACT,
                                "shape": "x"}, "shape"),
    (H.region_at, {"x_mm": "x", "y_mm": [0.0]}, "x_mm"),
    (H.region_counts, {"afferent_types": 5}, "afferent_types"),
    (H.region_counts, {"regions": 5}, "regions"),
    (H.region_names, {"kind": "colour"}, "kind"),
    (H.sample_in_region, {"name": 5, "n": 3}, "name"),
    (H.sample_in_region, {"name": "D2d", "n": -1}, "n"),
    (H.sample_in_region, {"name": "D2d", "n": 3, "rng": "x"}, "rng"),
    (H.site_coverage, {"population": 5, "sites": SITES}, "population"),
    (H.site_coverage, {"population": POP, "sites": 5}, "sites"),
    (H.site_weights, {"x_mm": "x", "y_mm": [0.0], "afferent_type": ["SAI"], "sites": SITES}, "x_mm"),
    (H.site_weights, {"x_mm": [0.0], "y_mm": [0.0], "afferent_type": ["SAI"], "sites": 5}, "sites"),
    # ---- ddmm.population.io ----
    (IO.read_sites_csv, {"path": 5}, "path"),
    (IO.save_xdf, {"path": 5, "forces": np.zeros((2, 3)), "stamps": [0.0, 0.01], "fs": 100.0}, "path"),
    (IO.save_xdf, {"path": TMP, "forces": "x", "stamps": [0.0, 0.01], "fs": 100.0}, "forces"),
    (IO.save_xdf, {"path": TMP, "forces": np.zeros((2, 3)), "stamps": [0.0], "fs": 100.0}, "stamps"),
    (IO.save_xdf, {"path": TMP, "forces": np.zeros((2, 3)), "stamps": [0.0, 0.01], "fs": -1.0}, "fs"),
    # ---- ddmm.population.neurostim ----
    (N.Biomimetic, {"tau_s": -1.0}, "tau_s"),
    (N.Biomimetic, {"rate_sat_hz": 0.0}, "rate_sat_hz"),
    (N.Biomimetic, {"weights": 5}, "weights"),
    (N.Electrode, dict(ELEC, id=5), "id"),
    (N.Electrode, dict(ELEC, amplitude_min_ua=-1.0), "amplitude_min_ua"),
    (N.Electrode, dict(ELEC, amplitude_max_ua=10.0), "amplitude_max_ua"),
    (N.Electrode, dict(ELEC, x_mm="x"), "x_mm"),
    (N.ElectrodeTable, {"electrodes": 5}, "electrodes"),
    (N.ElectrodeTable, {"electrodes": []}, "electrodes"),
    (N.LinearAmplitude, {"rate_hz": -1.0}, "rate_hz"),
    (N.LinearAmplitude, {"force_sat_n": 0.0}, "force_sat_n"),
    (N.LinearFrequency, {"amplitude_fraction": 2.0}, "amplitude_fraction"),
    (N.PulseKernel, dict(KERNEL, table=5), "table"),
    (N.PulseKernel, dict(KERNEL, rule="biomimetic"), "rule"),
    (N.PulseKernel, dict(KERNEL, fs=-1.0), "fs"),
    (N.PulseKernel, dict(KERNEL, members=[]), "members"),
    (N.StimulationEncoder, {"encoder": 5, "electrodes": TABLE}, "encoder"),
    (N.StimulationEncoder, {"encoder": ENC, "electrodes": 5}, "electrodes"),
    (N.StimulationEncoder, {"encoder": ENC, "electrodes": TABLE, "rule": "magic"}, "rule"),
    (N.check_pulses, {"pulses": 5}, "pulses"),
    (N.field_weights, {"table": 5, "x_mm": [0.0], "y_mm": [0.0], "radius_mm": [1.0], "region": [""]}, "table"),
    (N.get_rule, {"rule": 5}, "rule"),
    (N.get_rule, {"rule": "magic"}, "rule"),
    (N.load_pulses, {"path": 5}, "path"),
    (N.read_electrodes, {"path": 5}, "path"),
    (N.read_electrodes, {"path": None}, "path"),
    (N.save_pulses, {"pulses": 5, "path": TMP}, "pulses"),
    (N.stimulation_pulses, {"dataset": 5, "electrodes": TABLE}, "dataset"),
    (N.stimulation_pulses, {"dataset": DS, "electrodes": 5}, "electrodes"),
    (N.stimulation_pulses, {"dataset": DS, "electrodes": TABLE, "rule": "magic"}, "rule"),
    # ---- ddmm.population.runtime ----
    (R.Bridge, {"encoder": 5, "force": None, "sink": None}, "encoder"),
    (R.PulseOutlet, {"name": 5, "stimulator": None}, "name"),
    (R.SpikeOutlet, {"name": 5, "encoder": ENC}, "name"),
    (R.SpikeOutlet, {"name": "ddmm-probe", "encoder": 5}, "encoder"),
    (R.SpikeOutlet, {"name": "ddmm-probe", "encoder": ENC, "spike_format": "frames"}, "spike_format"),
    (R.check_stamps, {"stamps": "x", "last": None, "fs": 100.0}, "stamps"),
    (R.check_stamps, {"stamps": [0.0, 0.01], "last": None, "fs": -1.0}, "fs"),
    (R.take_stamps, {"stamps": "x", "last": None, "fs": 100.0, "summary": R.BridgeSummary(), "report": print},
     "stamps"),
    (R.take_stamps, {"stamps": [0.0], "last": None, "fs": 100.0, "summary": 5, "report": print}, "summary"),
    (R.take_stamps, {"stamps": [0.0], "last": None, "fs": 100.0, "summary": R.BridgeSummary(), "report": 5},
     "report"),
    (R.choose_setting, {"tolerance": -1.0, "fs": 1000.0}, "tolerance"),
    (R.choose_setting, {"tolerance": 0.1, "fs": 0.0}, "fs"),
    (_entered, {"context": R.dask_client, "scheduler": 5}, "scheduler"),
    (R.noise_key, {"seed": "x", "condition": 0, "trial": 0}, "seed"),
    (R.noise_key, {"seed": 0, "condition": -1, "trial": 0}, "condition"),
    (R.noise_key, {"seed": 0, "condition": 0, "trial": 1.5}, "trial"),
    (R.open_force_outlet, {"name": 5, "fs": 100.0}, "name"),
    (R.open_force_outlet, {"name": "ddmm-probe", "fs": -1.0}, "fs"),
    (R.open_force_outlet, {"name": "ddmm-probe", "fs": 100.0, "n_sites": 0}, "n_sites"),
    (R.open_force_stream, {"name": 5, "timeout": 0.01}, "name"),
    (R.open_force_stream, {"name": "ddmm-probe", "timeout": -1.0}, "timeout"),
    (R.open_force_stream, {"name": "ddmm-probe", "n_sites": 0, "timeout": 0.01}, "n_sites"),
    (R.play_forces, {"outlet": 5, "forces": np.zeros((2, 3)), "fs": 100.0}, "outlet"),
    (R.play_forces, {"outlet": _Outlet(), "forces": "x", "fs": 100.0}, "forces"),
    (R.play_forces, {"outlet": _Outlet(), "forces": np.zeros((2, 3)), "fs": -100.0}, "fs"),
    (R.read_spike_metadata, {"info": 5}, "info"),
    (R.decode_spikes, {"samples": np.zeros((1, 1), np.int32), "stamps": [0.0], "spike_format": "frames"},
     "spike_format"),
    (R.decode_spikes, {"samples": np.zeros(3, np.int32), "stamps": [0.0], "spike_format": "batched"}, "samples"),
    (R.decode_spikes, {"samples": np.full((1, 8), 9, np.int32), "stamps": [0.0], "spike_format": "batched"},
     "samples"),
    (R.root_seed, {"seed": "x"}, "seed"),
    (R.root_seed, {"seed": -1}, "seed"),
    # ---- ddmm.population.stimuli ----
    (S.Conditioner, {"conditioning": 5, "fs_in": 1000.0, "fs_out": 1000.0}, "conditioning"),
    (S.Conditioner, {"conditioning": P.Conditioning(), "fs_in": -1.0, "fs_out": 1000.0}, "fs_in"),
    (S.Conditioner, {"conditioning": P.Conditioning(), "fs_in": 1000.0, "fs_out": 1000.0, "n_sites": 0}, "n_sites"),
    (S.contact_grid, {"radius_mm": -1.0, "pitch_mm": 1.0}, "radius_mm"),
    (S.contact_grid, {"radius_mm": 3.0, "pitch_mm": 0.0}, "pitch_mm"),
    (S.contact_grid, {"radius_mm": 3.0, "pitch_mm": 1.0, "center_mm": 5}, "center_mm"),
    (S.digit_tip_sites, {"digits": 5}, "digits"),
    (S.digit_tip_sites, {"digits": ["Z9"]}, "digits"),
    (S.digit_tip_sites, {"digits": []}, "digits"),
    (S.grasp, {"digits": 5}, "digits"),
    (S.grasp, {"load_n": -1.0}, "load_n"),
    (S.grasp, {"mu": 0.0}, "mu"),
    (S.grasp, {"hold_s": NAN}, "hold_s"),
    (S.incipient_slip, {"normal_n": -1.0}, "normal_n"),
    (S.incipient_slip, {"mu_s": "x"}, "mu_s"),
    (S.incipient_slip, {"pitch_mm": 0.0}, "pitch_mm"),
    (S.incipient_slip, {"hold_fraction": 2.0}, "hold_fraction"),
    (S.resample_unconditioned, {"forces": "x", "fs_in": 1000.0, "fs": 500.0}, "forces"),
    (S.resample_unconditioned, {"forces": np.zeros((10, 3)), "fs_in": 1000.0, "fs": -1.0}, "fs"),
    (S.resample_unconditioned, {"forces": np.zeros((10, 3)), "fs_in": 0.0, "fs": 500.0}, "fs_in"),
    (S.torsion, {"torque_mnm": "x"}, "torque_mnm"),
    (S.torsion, {"radius_mm": -1.0}, "radius_mm"),
    (S.torsion, {"direction": 0}, "direction"),
    (S.torsion, {"pitch_mm": NAN}, "pitch_mm"),
]


@pytest.fixture(scope="module")
def env(tmp_path_factory):
    """The valid values the rows share (module docstring)."""
    tmp = tmp_path_factory.mktemp("api_errors")
    pop = ddmm.make_population(["SAI", "RAI"], theta_t=[0.0, 90.0], nap="selective")
    scene = ddmm.birznieks(90.0)
    csv = tmp / "forces.csv"
    csv.write_text("time,fx,fy,fz\n0.0,0,0,1\n0.001,0,0,1\n0.002,0,0,1\n0.003,0,0,1\n", encoding="utf-8")
    table = N.ElectrodeTable([N.Electrode(**ELEC)])
    return {"pop": pop, "scene": scene, "ds": ddmm.simulate(pop, scene, engine="direct", seed=0, quiet=True),
            "tmp": tmp / "out.nc", "nwb": tmp / "out.nwb", "csv": csv, "table": table,
            "enc": ddmm.Encoder(pop, 1000.0, engine="direct"),
            "sites": ddmm.Sites(x_mm=[0.0, 2.0], y_mm=[0.0, 0.0], radius_mm=[1.0, 1.0]),
            "contact": ddmm.Contact(0.0, 0.0, 4.0)}


def _resolve(value, env):
    if isinstance(value, _F):
        return env[value.key]
    if isinstance(value, list):
        return [_resolve(v, env) for v in value]
    return value


def _label(row) -> str:
    func, kwargs, name = row
    return f"{getattr(func, '__qualname__', func)}-{name}={kwargs[name]!r}"[:80]


#: Exported callables no row probes, and why.
UNPROBED = {
    "Engine": "the engines' abstract base class",
    "RecordingBandWarning": "a warning category", "XdfStampWarning": "a warning category",
    "DriveTable": "a record its constructor DriveTable.of builds (probed above)",
    "region_table": "takes no argument", "load_table": "takes no argument", "lsl_clock": "takes no argument",
    **dict.fromkeys(("SpikeResult", "PulseEvents", "StreamSpikes", "BridgeSummary", "ConditionPlan", "Plan",
                     "ForceStream", "XdfRecording"), "a record the package builds and returns"),
}
PACKAGES = ("ddmm", "ddmm.models", "ddmm.population", "ddmm.population.analysis", "ddmm.population.anatomy",
            "ddmm.population.data", "ddmm.population.io", "ddmm.population.neurostim", "ddmm.population.runtime",
            "ddmm.population.stimuli")


def test_every_exported_callable_is_probed():
    """Each callable in the packages' ``__all__`` has a row (or a reason in `UNPROBED`); no row misnames its kwargs."""
    import importlib

    probed = {kwargs.get("cls", kwargs.get("context")) if func in (_fit, _entered) else func
              for func, kwargs, _ in ROWS}
    missing = sorted({name for package in PACKAGES for name in importlib.import_module(package).__all__
                      if callable(obj := getattr(importlib.import_module(package), name)) and obj not in probed
                      and name not in UNPROBED})
    assert not missing, f"exported without a row in ROWS: {missing}"
    assert len(ROWS) >= 120 and all(name in kwargs for _, kwargs, name in ROWS)


@pytest.mark.parametrize("row", ROWS, ids=[_label(r) for r in ROWS])
def test_wrong_argument_is_named(row, env):
    func, kwargs, name = row
    kwargs = {k: _resolve(v, env) for k, v in kwargs.items()}
    with pytest.raises((ValueError, TypeError, MissingExtraError)) as info:
        func(**kwargs)
    assert re.search(rf"\b{re.escape(name)}\b", str(info.value)), (
        f"{type(info.value).__name__} does not name {name!r}: {info.value}")
