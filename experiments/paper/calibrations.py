"""Calibrations of the paper reproduction: which constants each paper type is reproduced with.

The paper (eqs 1-19) leaves open the current gains, the derivative filter,
the reproduction scenes' ramp lengths and the shear's onset, the reading of
eq. 17 below F_TH (its text gives two) and how SF is counted.  A
calibration states them for each type (SAI, RAI, RAII), as a `ReproConfig`:

* ``paper``: the paper calibration, fitted type by type to Table III by
  ``ddmm calibrate --target paper`` (`ddmm.experiments.calibration.paper`);
  the equations are the paper's, nothing is added.  Table II and Fig. 8 are
  predictions.  docs/model.md ("The paper calibration") gives the cells and
  what limits SA-I.
* ``gains-only``: one shared setting (eq. 17's pass reading, contact-mean
  SF, 2 s ramps, 20 Hz filter) with only the gains fitted, to Table III's
  CMM column (`ddmm.experiments.calibration.gains`).

These settings are for reproducing the paper only: the physiological presets
(`ddmm.population.presets`) are calibrated to human data and are unchanged
by them.
"""

from __future__ import annotations

from ddmm.experiments.calibration.paper import FIT_CELLS
from ddmm.experiments.paper.reproduce import ReproConfig
from ddmm.models.afferent_types import PAPER_TYPES
from ddmm.models.current_params import CurrentParams

__all__ = ["PAPER_CALIBRATION", "PAPER_OBJECTIVES", "GAINS_ONLY", "CALIBRATIONS", "FITTED_CELLS"]

#: Written by ``ddmm calibrate --target paper --seed 0`` (each type's best reading and SF definition; the
#: objectives, max + mean/10 of the fitted cells' relative errors: SAI 0.411, RAI 0.024, RAII 0.098).
PAPER_CALIBRATION = {
    "SAI": ReproConfig(engine="direct", no_shear="pass", sf_definition="contact_mean", ramp_s=2.8, lift_ramp_s=4.9,
                       shear_delay_s=0.0, birznieks_shear_delay_s=0.0806,
                       current_params=CurrentParams().with_type("SAI", gain=5.050402)),
    "RAI": ReproConfig(engine="direct", no_shear="block", sf_definition="peak_bin", ramp_s=3.5, lift_ramp_s=0.1,
                       shear_delay_s=1.1433, birznieks_shear_delay_s=0.05,
                       current_params=CurrentParams().with_type("RAI", gain=0.256536, cutoff_hz=201.667)),
    "RAII": ReproConfig(engine="direct", no_shear="block", sf_definition="contact_mean", ramp_s=0.2013,
                        lift_ramp_s=0.7, shear_delay_s=0.001, birznieks_shear_delay_s=0.05,
                        current_params=CurrentParams().with_type("RAII", gain=0.49283, cutoff_hz=29.242)),
}
#: The objective of each committed setting (`ddmm.experiments.calibration.paper.objective`), as the fit reported.
PAPER_OBJECTIVES = {"SAI": 0.4109, "RAI": 0.0238, "RAII": 0.0982}

#: The shared gains-only setting (`CurrentParams` defaults: gains fitted to Table III's CMM column).
GAINS_ONLY = {kind: ReproConfig(engine="direct") for kind in PAPER_TYPES}

CALIBRATIONS = {"paper": PAPER_CALIBRATION, "gains-only": GAINS_ONLY}

#: The cells each calibration's fit used, per type (the rest are predictions or reproduced by symmetry).
FITTED_CELLS = {"paper": {kind: FIT_CELLS for kind in PAPER_TYPES},
                "gains-only": {kind: (("III", "cmm", "SF (75°)"),) for kind in PAPER_TYPES}}
