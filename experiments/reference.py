"""Published reference numbers, each with its source, in one place.

Experiments print our values beside these; tests check against them.
"""

from __future__ import annotations

__all__ = [
    "PAPER_RADII_K3",
    "PAPER_TABLE2",
    "PAPER_TABLE3",
    "HUMAN_DSI",
    "HUMAN_TUNED_FRACTION",
    "HUMAN_DIRECTION_THRESHOLD_DEG",
    "TOUCHSIM_COUNTS",
    "TOUCHSIM_SPEED",
]

#: NAP boundary radii at k = 3 for phi = 0, 15, 30, 45, 60, 90, 120, 150, 165,
#: 180 deg (DDMM-NOTES §1.2; checked there by scanning rays numerically).
PAPER_RADII_K3 = {
    "phi_deg": (0, 15, 30, 45, 60, 90, 120, 150, 165, 180),
    "bipolar": (1.000, 0.574, 0.423, 0.354, 0.323, 0.333, 0.323, 0.423, 0.574, 1.000),
    "selective": (1.000, 0.574, 0.423, 0.354, 0.323, 0.200, 0.146, 0.146, 0.163, 0.200),
    "broad": (0.867, 0.708, 0.315, 0.141, 0.095, 0.067, 0.065, 0.085, 0.115, 0.200),
}

#: Paper Table II: PRSI (eq. 19) on the Birznieks scene, theta_R = 90 deg, k = 3.
PAPER_TABLE2 = {
    "selective": {"SAI": 0.38, "RAI": 0.31, "RAII": 0.33},
    "broad": {"SAI": 0.45, "RAI": 0.36, "RAII": 0.33},
    "bipolar": {"SAI": 0.0, "RAI": 0.0, "RAII": 0.0},
    "cmm": {"SAI": 0.0, "RAI": 0.0, "RAII": 0.0},
}

#: Paper Table III: SF (pulses/s) at theta_T = 75 / 255 deg on press-push-lift.
PAPER_TABLE3 = {
    "selective": {"SAI": (37.5, 15.0), "RAI": (17.5, 7.5), "RAII": (15.0, 7.5)},
    "broad": {"SAI": (47.5, 10.0), "RAI": (20.0, 7.5), "RAII": (20.0, 7.5)},
    "bipolar": {"SAI": (37.5, 37.5), "RAI": (17.5, 17.5), "RAII": (15.0, 15.0)},
    "cmm": {"SAI": (47.5, 47.5), "RAI": (15.0, 15.0), "RAII": (10.0, 10.0)},
}

#: Human DSI (eq. 7), mean and SD, Birznieks et al. 2001 as the paper reports it.
HUMAN_DSI = {"SAI": (0.23, 0.18), "RAI": (0.24, 0.18)}

#: Fraction of afferents significantly direction tuned, Birznieks et al. 2001
#: (5 force directions; as reported in the paper's introduction).
HUMAN_TUNED_FRACTION = {"all": 0.86, "SAI": 0.93, "RAI": 0.83}

#: Human discrimination threshold for force direction in the tangential plane
#: (Panarese & Edin 2011), degrees.
HUMAN_DIRECTION_THRESHOLD_DEG = 7.1

#: TouchSim's populations (Saal et al. 2017): index fingertip pad and whole hand.
TOUCHSIM_COUNTS = {
    "fingertip": {"SAI": 282, "RAI": 573, "RAII": 100},
    "hand": {"SAI": 3658, "RAI": 6956, "RAII": 1905},
}

#: TouchSim (Python port) on a 2-core machine of this kind (DDMM-NOTES §2):
#: wall seconds for 1 s simulated at 5 kHz, and peak memory.
TOUCHSIM_SPEED = {
    "fingertip_wall_s": (0.3, 0.5),
    "hand_wall_s": 7.0,
    "hand_peak_gb": 2.8,
    "import_to_first_result_s": (3.5, 4.8),
}
