"""Paper Table IV: the pilot's analysis (§V) on a press-push-lift recording.

The authors recorded fingertip press-push-lift actions on an AMTI HE6x6
force plate at 100 Hz and ran the model on the mean of five trials; their
data are openly available (University of Southampton repository,
doi:10.5258/SOTON/D3758; docs/recordings.md says how to read them), but
cannot be fetched here, so the analysis runs on the user's copy or on any
recording of the same action.

The recording is read as `ddmm simulate` reads one (`from_csv` with the
recording options; conditioned by default), each type is run with its
calibration's gains, cut-off and reading, and SF is the contact mean for
every type: Table IV's values (16.11, 2.66, ...) are not multiples of a bin
rate.  The misaligned angle is 255 deg in Table IV's header and 225 deg in
the text: both are computed, each beside Table IV's misaligned value.
"""

from __future__ import annotations

import dataclasses
import warnings

from ddmm.experiments.paper.reproduce import PROFILES, scene_sf
from ddmm.models.afferent_types import PAPER_TYPES
from ddmm.models.engines import SpikeCapWarning
from ddmm.models.metrics import CONTACT_THRESHOLD
from ddmm.population.data.published import PAPER_TABLE4

__all__ = ["TABLE4_ANGLES", "table4"]

TABLE4_ANGLES = (75.0, 225.0, 255.0)


def _cells(kind: str, sf: dict) -> list:
    cells = []
    for profile in PROFILES:
        at = dict(zip(TABLE4_ANGLES, (float(v) for v in sf[profile][kind])))
        aligned, misaligned = PAPER_TABLE4[profile][kind]
        rows = [("SF (75°)", aligned, at[75.0]), ("SF (225°)", misaligned, at[225.0]),
                ("SF (255°)", misaligned, at[255.0]), ("SF Diff (75°-225°)", aligned - misaligned, at[75.0] - at[225.0]),
                ("SF Diff (75°-255°)", aligned - misaligned, at[75.0] - at[255.0])]
        for row, paper, model in rows:
            rel = None if paper == 0.0 and model == 0.0 else (float("inf") if paper == 0.0 else
                                                                 round((model - paper) / abs(paper), 4))
            cells.append({"table": "IV", "type": kind, "profile": profile, "row": row, "paper": float(paper),
                          "model": round(model, 4), "rel_error": rel, "role": "prediction"})
    return cells


def table4(path, calibration: dict, args) -> dict:
    """Table IV's cells on the recording at ``path`` (read with the recording options in ``args``).

    Raises
    ------
    ValueError
        If the recording's normal force never exceeds the contact threshold
        (0.05 N): every SF would be 0.
    """
    from ddmm.experiments.cli.recording_options import csv_scene

    scene = csv_scene(path, args, None)
    peak = float(scene.fz.max())
    if not peak > CONTACT_THRESHOLD:  # SF is the mean rate in contact: Table IV would be all zeros
        raise ValueError(f"recording {str(path)!r} never reaches contact: its normal force peaks at {peak:g} N (as "
                         f"read and conditioned), never above the contact threshold {CONTACT_THRESHOLD:g} N, so Table "
                         "IV's SF (the mean rate in contact) has nothing to average")
    cells = []
    with warnings.catch_warnings():
        warnings.simplefilter("ignore", SpikeCapWarning)
        for kind in PAPER_TYPES:
            config = dataclasses.replace(calibration[kind], sf_definition="contact_mean")
            sf, _ = scene_sf(scene, TABLE4_ANGLES, config, afferent_types=(kind,))
            cells += _cells(kind, sf)
    return {"cells": cells, "scene": {"name": scene.name, "fs": scene.fs, "duration_s": scene.duration}}
