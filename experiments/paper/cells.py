"""The paper's Tables II-III and Fig. 8, cell by cell, under a calibration.

A *calibration* maps each paper type (SAI, RAI, RAII) to the `ReproConfig`
it is reproduced with: the reading of eq. 17, the SF definition, the
reproduction scenes' ramps and shear onset, and the unpublished constants
(gain, derivative cut-off).  Each type is simulated on its own scenes, so a
per-type calibration is as cheap as a shared one.

Every cell is reported as ``{"table", "type", "profile", "row", "paper",
"model", "rel_error", "role"}``; ``role`` is ``fitted`` (an objective of the
calibration's fit), ``reproduced`` (zero or equal by the model's symmetry:
bipolar and CMM PRSI, the bipolar and CMM SF at 255 deg and their SF Diff)
or ``prediction`` (in no fit).
"""

from __future__ import annotations

import dataclasses
import warnings

import numpy as np

from ddmm.experiments.paper.reproduce import FIG8_ANGLES, PROFILES, ReproConfig, scene_sf
from ddmm.models.afferent_types import PAPER_TYPES
from ddmm.models.engines import SpikeCapWarning
from ddmm.models.metrics import direction_index
from ddmm.population.data.published import PAPER_TABLE2, PAPER_TABLE3

__all__ = ["TABLES", "cell_keys", "paper_value", "type_cells", "reproduce_cells", "fig8_peaks", "with_engine"]

TABLES = ("table2", "table3", "fig8")
_PRSI_ANGLES = (0.0, 90.0, 180.0, 270.0)
_SYMMETRIC = {("II", "bipolar", "PRSI"), ("II", "cmm", "PRSI"), ("III", "bipolar", "SF (255°)"),
              ("III", "cmm", "SF (255°)"), ("III", "bipolar", "SF Diff"), ("III", "cmm", "SF Diff")}


def cell_keys(table: str | None = None) -> list:
    """``(table, profile, row)`` of every cell of Table II (``"II"``) and Table III (``"III"``)."""
    keys = [("II", p, "PRSI") for p in PROFILES]
    keys += [("III", p, row) for p in PROFILES for row in ("SF (75°)", "SF (255°)", "SF Diff")]
    return keys if table is None else [k for k in keys if k[0] == table]


def paper_value(kind: str, key) -> float:
    """The paper's value of one cell ``(table, profile, row)`` for type ``kind`` (Table II PRSI or Table III SF)."""
    table, profile, row = key
    if table == "II":
        return PAPER_TABLE2[profile][kind]
    at75, at255 = PAPER_TABLE3[profile][kind]
    return {"SF (75°)": at75, "SF (255°)": at255, "SF Diff": at75 - at255}[row]


def with_engine(calibration: dict, engine: str) -> dict:
    """The calibration with every type's engine set to ``engine``."""
    return {kind: dataclasses.replace(config, engine=engine) for kind, config in calibration.items()}


def _table2(kind: str, config: ReproConfig) -> dict:
    # PRSI is a ratio of responses: the spike count over the contact period (contact_mean) whatever the SF reading
    sf, _ = scene_sf(config.birznieks(90.0), _PRSI_ANGLES, config, afferent_types=(kind,), definition="contact_mean")
    return {("II", p, "PRSI"): float(direction_index(*sf[p][kind])) for p in PROFILES}


def _press_push_lift(kind: str, config: ReproConfig, angles) -> dict:
    sf, _ = scene_sf(config.press_push_lift(90.0), angles, config, afferent_types=(kind,))
    return {p: np.asarray(sf[p][kind], dtype=float) for p in PROFILES}


def type_cells(kind: str, config: ReproConfig, angles=(75.0, 255.0)) -> tuple:
    """The model's Table II and III cells of one type, and its press-push-lift SF curves over ``angles``.

    Returns ``({(table, profile, row): model value}, {profile: SF over angles})``;
    ``angles`` must include 75 and 255 deg.
    """
    angles = [float(a) for a in angles]
    with warnings.catch_warnings():
        warnings.simplefilter("ignore", SpikeCapWarning)  # reported by the CLI from its own run
        cells = _table2(kind, config)
        curves = _press_push_lift(kind, config, angles)
    for p in PROFILES:
        at75, at255 = curves[p][angles.index(75.0)], curves[p][angles.index(255.0)]
        cells.update({("III", p, "SF (75°)"): float(at75), ("III", p, "SF (255°)"): float(at255),
                      ("III", p, "SF Diff"): float(at75 - at255)})
    return cells, curves


def _role(key, fitted) -> str:
    if key in fitted:
        return "fitted"
    return "reproduced" if key in _SYMMETRIC else "prediction"


def _rel_error(model: float, paper: float):
    if paper == 0.0:
        return None if model == 0.0 else float("inf")
    return round((model - paper) / abs(paper), 4)


def fig8_peaks(curves: dict, angles) -> list:
    """Peak theta_T of each type's and profile's SF curve, and its distance from alignment (theta_R = 90 deg).

    For the bipolar profile alignment is 90 or 270 deg.  A flat curve (CMM)
    has no peak: ``peak_theta_t`` is None.
    """
    out = []
    for kind, by_profile in curves.items():
        for profile, sf in by_profile.items():
            sf = np.asarray(sf, dtype=float)
            if profile == "cmm" or np.ptp(sf) == 0.0:
                out.append({"type": kind, "profile": profile, "peak_theta_t": None, "off_alignment_deg": None})
                continue
            peak = float(angles[int(np.argmax(sf))])
            targets = (90.0, 270.0) if profile == "bipolar" else (90.0,)
            off = min(abs((peak - t + 180.0) % 360.0 - 180.0) for t in targets)
            out.append({"type": kind, "profile": profile, "peak_theta_t": peak, "off_alignment_deg": off})
    return out


def reproduce_cells(calibration: dict, fitted=None, tables=TABLES) -> dict:
    """Every cell of Tables II-III and the Fig. 8 peaks under ``calibration`` ({type: ReproConfig}).

    ``fitted`` maps each type to the cell keys its fit used (roles); the
    result is ``{"cells": [...], "fig8": [...], "curves": {type: {profile:
    {angle: SF}}}}`` restricted to ``tables``.
    """
    fitted = fitted or {}
    angles = [float(a) for a in FIG8_ANGLES]
    cells, curves = [], {}
    for kind in PAPER_TYPES:
        values, curves[kind] = type_cells(kind, calibration[kind], angles)
        for key in cell_keys():
            if {"II": "table2", "III": "table3"}[key[0]] not in tables:
                continue
            paper = float(paper_value(kind, key))
            cells.append({"table": key[0], "type": kind, "profile": key[1], "row": key[2], "paper": paper,
                          "model": round(values[key], 4), "rel_error": _rel_error(values[key], paper),
                          "role": _role(key, set(fitted.get(kind, ())))})
    out = {"cells": cells}
    if "fig8" in tables:
        out["fig8"] = fig8_peaks(curves, angles)
        out["curves"] = {k: {p: {f"{a:g}": round(float(v), 4) for a, v in zip(angles, sf)} for p, sf in c.items()}
                         for k, c in curves.items()}
    return out
