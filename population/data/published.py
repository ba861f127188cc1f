"""Published reference numbers, each with its source, in one place.

Experiments print our values beside these; tests check against them.
"""

from __future__ import annotations

__all__ = [
    "PAPER_RADII_K3",
    "PAPER_TABLE2",
    "PAPER_TABLE3",
    "PAPER_TABLE4",
    "HUMAN_DSI",
    "HUMAN_TUNED_FRACTION",
    "HUMAN_DIRECTION_THRESHOLD_DEG",
    "TOUCHSIM_COUNTS",
    "TOUCHSIM_SPEED",
    "PHYSIOLOGY_REFERENCE",
]

#: NAP boundary radii at k = 3 for phi = 0, 15, 30, 45, 60, 90, 120, 150, 165,
#: 180 deg (docs/model.md §1.2; tests/models/test_nap.py checks them by scanning rays numerically).
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

#: Paper Table IV: SF (pulses/s) of the pilot recording (§V, 100 Hz force plate, mean of 5 trials), aligned
#: (75 deg) / misaligned (255 deg in the table's header, 225 deg in the text).
PAPER_TABLE4 = {
    "selective": {"SAI": (13.4, 4.5), "RAI": (2.5, 1.0), "RAII": (1.0, 0.5)},
    "broad": {"SAI": (16.11, 2.66), "RAI": (3.0, 0.5), "RAII": (1.5, 0.0)},
    "bipolar": {"SAI": (13.05, 13.05), "RAI": (2.5, 2.5), "RAII": (0.5, 0.5)},
    "cmm": {"SAI": (17.8, 17.8), "RAI": (3.0, 3.0), "RAII": (1.0, 1.0)},
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

#: TouchSim (Python port) and ddmm measured side by side on one 2-core host of this
#: machine kind (hosts of the kind differ by more than 2x: compare only within a row):
#: TouchSim hand x 1 s at 5 kHz, its peak memory and its import-to-first-result time,
#: against `ddmm bench`'s hand x 1 s direct case and its integration kernel alone.
TOUCHSIM_SPEED = {
    "hand_wall_s": 6.71,
    "hand_peak_gb": 2.7,
    "import_to_first_result_s": 3.6,
    "ddmm_hand_1s_direct_wall_s": (0.23, 0.27),
    "ddmm_hand_1s_kernel_s": 0.146,
}


def _physiology_reference() -> dict:
    """Reference ranges of the physiology scorecard (`ddmm.population.analysis.physiology`), from docs/references.md.

    Rows marked R there are recalled, not read: they become broad ranges here.
    Roles: ``fitted`` (an objective of ``ddmm calibrate``), ``constrained``
    (bounds the calibration or was set by hand from it), ``held out`` (never in
    any objective or hand setting).
    """
    from ddmm.population.analysis.physiology import Reference as R

    return {**_core_reference(R), **_dynamic_reference(R)}


def _dynamic_reference(R) -> dict:
    """Reference ranges of the protocol modules beyond the core battery (phase locking, variability, shear)."""
    return {**_vibration_reference(R), **_variability_reference(R), **_shear_reference(R), **_slow_reference(R),
            **_field_reference(R), **_everyday_reference(R), **_tilt_reference(R)}


def _tilt_reference(R) -> dict:
    """Tilted loads against the normal load alone (docs/references.md rows 9, 22;
    `ddmm.population.analysis.physiology_tilt`)."""
    src = ("docs/references.md rows 9, 22: in its preferred direction tangential load adds to a unit's response to "
           "the normal load, against it the load subtracts")
    most, variant = ": most units rise in some direction (R: a broad range)", "; a variant: 2 N tilted 30 deg, 8 directions"
    return {
        "tilt_above_SAI": R(0.5, 1.0, src + most + "; SAI.shear and SAI.depth set by hand to it", "constrained", "R"),
        "tilt_silenced_SAI": R(0.0, 0.2, src + ": it lowers, seldom silences (R); SAI.shear and SAI.depth set by "
                               "hand to it", "constrained", "R"),
        "tilt_above_RAI": R(0.5, 1.0, src + most, "held out", "R"),
        "tilt_above_SAII": R(0.5, 1.0, src + most, "held out", "R"),
        "tilt_variant_above_SAI": R(0.5, 1.0, src + most + variant, "held out", "R"),
        "tilt_variant_above_RAI": R(0.5, 1.0, src + most + variant, "held out", "R"),
    }


def _everyday_reference(R) -> dict:
    """Releases, recruitment and threshold spread at everyday touches (docs/references.md rows 3, 27-29;
    `ddmm.population.analysis.physiology_everyday`)."""
    inf = float("inf")
    off = ("docs/references.md rows 3, 27: FA-I fire at unloading in ordinary grip and release (a few N/s), the "
           "OFF burst usually smaller than the ON burst but present in most units")
    rate = ("docs/references.md rows 28, 29: thresholds spread over an order of magnitude within a type, so "
            "recruitment grows gradually with loading rate; FA-I respond to the slow loading of manipulation")
    spread = "docs/references.md row 28: thresholds of one type differ by an order of magnitude or more"
    chosen = "; RAI.threshold set by hand to it"
    return {
        "release_2Ns_RAI": R(0.05, 1.0, off, "held out", "R"),
        "release_4Ns_RAI": R(0.5, 1.0, off + chosen, "constrained", "R"),
        "off_on_8Ns_RAI": R(0.2, 1.0, off, "held out", "R"),
        "release_variant_RAI": R(0.5, 1.0, off + " (a variant: 4 N held 3 s)", "held out", "R"),
        "release_conditioned_RAI": R(0.5, 2.0, "the same touch read as a recording: the default conditioning "
                                     "must keep FA-I's release response (within a factor of 2)", "held out", "R"),
        "recruit_2Ns_RAI": R(0.3, 1.0, rate, "held out", "R"),
        "recruit_range_RAI": R(4.0, inf, rate + chosen, "constrained", "R"),
        "threshold_spread_RAI": R(5.0, inf, spread + "; sensitivity_sd set to it", "constrained", "R"),
        "threshold_spread_RAII": R(5.0, inf, spread + "; sensitivity_sd set to it", "constrained", "R"),
    }


def _field_reference(R) -> dict:
    """Receptive fields grow with force (docs/references.md row 17; the growth recalled: R)."""
    source = ("docs/references.md row 17 (Johansson & Vallbo 1980): fields measured at threshold; they grow with "
              "force (R): every doubling of a point probe's force must widen the field")
    return {f"field_growth_{kind}": R(1.05, float("inf"), source, "held out", "R") for kind in ("SAI", "RAI", "RAII")}


def _vibration_reference(R) -> dict:
    """Phase locking to vibration (docs/references.md rows 8, 21;
    `ddmm.population.analysis.physiology_vibration`).

    Row 21 is recalled (R): "VS typically > 0.8 at 1:1", so the ranges are
    broad.  The 1 N rows at 10-60 Hz are ``constrained``: ``RAI.tau_s``,
    ``RAI.i_max`` and ``RAI.negative_weight`` of the presets were chosen on
    them, and FA-II's ``t_ref``, drive and smoothing on its 1 N rows at
    100-250 Hz.  The 2 N variants (15 and 45 Hz; 125 and 175 Hz) are ``held
    out``.
    """
    lock = "docs/references.md row 21 (R): FA-I entrain at a fixed phase, VS typically > 0.8 at 1:1"
    lock2 = "docs/references.md row 21 (R): FA-II entrain at a fixed phase, VS typically > 0.8 at 1:1"
    return {
        "vs_RAI": R(0.8, 1.0, lock, "constrained", "R"),
        "locked_RAI": R(0.5, 1.0, lock + "; most afferents 1:1 and locked", "constrained", "R"),
        "vs_2f_ratio_RAI": R(0.0, 1.0, lock + ": one phase per cycle, so VS at 2f < VS at f (locking to both "
                             "half-cycles gives VS at 2f > VS at f)", "constrained", "R"),
        "vs_RAI_2N": R(0.8, 1.0, lock + "; a 2 N preload at 15 and 45 Hz, never used to set the model",
                       "held out", "R"),
        "locked_RAI_2N": R(0.5, 1.0, lock + "; a 2 N preload at 15 and 45 Hz, never used to set the model",
                           "held out", "R"),
        "vs_2f_ratio_RAI_2N": R(0.0, 1.0, lock + "; a 2 N preload at 15 and 45 Hz, never used to set the model",
                                "held out", "R"),
        "vs_RAII": R(0.8, 1.0, lock2, "constrained", "R"),
        "locked_RAII": R(0.5, 1.0, lock2 + "; most afferents 1:1 and locked", "constrained", "R"),
        "vs_2f_ratio_RAII": R(0.0, 1.0, lock2 + ": one phase per cycle, so VS at 2f < VS at f", "constrained", "R"),
        "vs_RAII_2N": R(0.8, 1.0, lock2 + "; a 2 N preload at 125 and 175 Hz, never used to set the model",
                        "held out", "R"),
        "locked_RAII_2N": R(0.5, 1.0, lock2 + "; a 2 N preload at 125 and 175 Hz, never used to set the model",
                            "held out", "R"),
        "vs_2f_ratio_RAII_2N": R(0.0, 1.0, lock2 + "; a 2 N preload at 125 and 175 Hz, never used to set the "
                                 "model", "held out", "R"),
    }


def _variability_reference(R) -> dict:
    """Trial-to-trial variability (docs/references.md rows 14, 23).

    20 presses to 2 N (`ddmm.population.analysis.physiology_variability`).
    Row 23 (R) gives Fano factors of roughly 0.1-1 and row 14 (R) a jitter of
    a few ms, the broad range of the core ``jitter_RAI`` row.  The trial
    excitability CVs (``<TYPE>.excite_cv``) were set by hand on the SA-I and
    FA-II Fano rows (constrained); the FA-I Fano row and every jitter row
    are held out.
    """
    fano = "docs/references.md row 23: Fano factors of roughly 0.1-1 in the dynamic phase (R: a broad range)"
    jitter = "docs/references.md rows 14, 23: first-spike jitter of a few ms (R: a broad range)"
    return {
        "fano_SAI": R(0.1, 1.0, fano + "; SAI.excite_cv set by hand to it", "constrained", "R"),
        "fano_RAI": R(0.1, 1.0, fano, "held out", "R"),
        "fano_RAII": R(0.1, 1.0, fano + "; RAII.excite_cv set by hand to it", "constrained", "R"),
        "first_jitter_SAI": R(0.5, 10.0, jitter, "held out", "R"),
        "first_jitter_RAI": R(0.5, 10.0, jitter, "held out", "R"),
        "first_jitter_RAII": R(0.5, 10.0, jitter, "held out", "R"),
    }


def _shear_reference(R) -> dict:
    """Tangential force magnitude, SA-II and SA-I dynamics (docs/references.md rows 4-6, 12, 22, 24)."""
    inf = float("inf")
    src = "docs/references.md rows 18, 22: every type responds to tangential force, rising with its magnitude in the "
    pref, shape = src + "preferred direction", " (shape only, R: a broad range)"
    return {
        "shear_pref_SAI": R(1.1, inf, pref + "; SAI.shear set by hand to it", "constrained", "R"),
        "shear_opp_SAI": R(0.0, 0.9, src + "opposite direction lowering the rate" + shape, "held out", "R"),
        "shear_growth_SAI": R(0.01, inf, pref + ": monotonic growth" + shape, "held out", "R"),
        "shear_fall_SAI": R(-inf, 0.0, src + "opposite direction: no rise with magnitude" + shape, "held out", "R"),
        "shear_growth_RAI": R(0.01, inf, pref + ": FA-I ramp responses grow" + shape, "held out", "R"),
        "shear_dir_RAI": R(1.0, inf, pref + ": FA-I respond more in it than against it" + shape, "held out", "R"),
        "shear_ramp_RAI": R(0.5, 1.0, src + "FA-I fire during a tangential ramp; RAI.shear set by hand to it",
                            "constrained", "R"),
        "shear_dir_RAII": R(1.0, inf, pref + ": FA-II respond more in it than against it" + shape, "held out", "R"),
        "shear_growth_SAII": R(0.01, inf, pref + ": SA-II rates grow with stretch" + shape, "held out", "R"),
        "shear_variant_SAI": R(0.0, inf, src + "4 N normal, 4 N/s: a variant no gain was set on" + shape,
                               "held out", "R"),
        "shear_variant_RAI": R(0.0, inf, src + "4 N normal, 4 N/s: a variant no gain was set on" + shape,
                               "held out", "R"),
    }


def _slow_reference(R) -> dict:
    """SA-II under normal force and at rest, SA-I dynamics and adaptation (docs/references.md rows 1, 4, 5, 12, 24;
    `ddmm.population.analysis.physiology_slow`)."""
    inf = float("inf")
    rest = "docs/references.md rows 1, 24: SA-II resting discharge differs from unit to unit, about 5-20 imp/s"
    adapt = ("docs/references.md row 4: SA keep firing and adapt through a hold (monkey: -38% over 12 s); the fall "
             "neither vanishes nor is complete (R: a broad range)")
    peak = "docs/references.md row 5: SA-I peak 100-300 imp/s in fast loading against 10-60 in the plateau"
    return {
        "rest_spread_SAII": R(4.0, 15.0, rest + "; SAII.bias_cv set by hand to it", "constrained", "R"),
        "rest_active_SAII": R(0.5, 1.0, rest + ": most SA-II fire at rest", "held out", "R"),
        "start_synchrony_SAII": R(0.0, 0.5, "docs/references.md row 24: units fire independently (each its own "
                                  "rate and phase); 1 = every unit in step", "held out", "R"),
        "normal_coding_SAII": R(1.05, inf, "docs/references.md rows 12, 24: every nail-border SA-II responded to "
                                "4 N normal forces (rates rise with normal force)", "held out", "V"),
        "adaptation_05N_SAI": R(0.1, 0.75, adapt + "; SAI.dynamic set by hand to it", "constrained", "V"),
        "adaptation_2N_SAI": R(0.1, 0.75, adapt, "held out", "V"),
        "adaptation_8N_SAI": R(0.1, 0.75, adapt + "; SAI.dynamic set by hand to it", "constrained", "V"),
        "peak_plateau_SAI": R(1.5, inf, peak + "; SAI.dynamic set by hand to it", "constrained", "R"),
        "peak_plateau_2N_SAI": R(1.5, inf, peak + " (a variant: 20 N/s to 2 N)", "held out", "R"),
        "peak_rate_SAI": R(100.0, 300.0, peak + "; SAI.transient set by hand to it", "constrained", "R"),
        "peak_rate_2N_SAI": R(100.0, 300.0, peak + " (a variant: 20 N/s to 2 N)", "held out", "R"),
        "plateau_rate_SAI": R(0.8, 1.25, "docs/references.md rows 5, 6: the SA-I plateau codes the force, not how "
                              "fast it was reached (R: within 20%)", "held out", "R"),
    }


def _core_reference(R) -> dict:
    """Reference ranges of the core battery (rest, on-off, rates, force and rate coding, frequency, direction,
    timing, continuity)."""
    inf = float("inf")
    rest = "docs/references.md row 1 (Vallbo & Johansson 1984; Knibestol 1975); row 2 (foot sole, V)"
    onoff = "docs/references.md rows 3-5 (Westling & Johansson 1987; J Neurosci 3:2652)"
    rates = "docs/references.md row 5: no afferent sustains rates near 1 kHz; bar 500 pulses/s"
    tuned = "docs/references.md rows 10-11 (Birznieks et al. 2001 via the DDMM paper)"
    return {
        "rest_rate_RAI": R(0.0, 0.0, rest, "constrained", "R"),
        "rest_rate_RAII": R(0.0, 0.0, rest, "constrained", "R"),
        "rest_rate_SAI": R(0.0, 1.0, rest, "constrained", "R"),
        "rest_silent_SAI": R(0.9, 1.0, rest, "constrained", "R"),
        "rest_rate_SAII": R(5.0, 20.0, rest + "; SA-II bias set by hand to it", "constrained", "R"),
        "hold_ratio_RAI": R(0.0, 0.1, onoff, "constrained", "R"),
        "release_fraction_RAI": R(0.5, 1.0, onoff, "constrained", "R"),
        "off_transient_RAII": R(0.0, 0.0, onoff + ": FA-II fire only at transients (within 100 ms)", "constrained", "R"),
        "hold_rate_SAI": R(10.0, 60.0, "docs/references.md row 5: SA-I plateau 10-60 imp/s, 2-4 N", "constrained", "R"),
        "adaptation_SAI": R(0.0, 0.99, "docs/references.md row 4: SA adapt in a hold (V, monkey)", "constrained", "V"),
        "max_rate_SAI": R(0.0, 500.0, rates, "constrained", "R"),
        "max_rate_RAI": R(0.0, 500.0, rates, "constrained", "R"),
        "max_rate_RAII": R(0.0, 500.0, rates, "constrained", "R"),
        "max_rate_SAII": R(0.0, 500.0, rates, "constrained", "R"),
        "capped_spikes": R(0.0, 0.0, "nothing near one spike per integration step", "constrained", "R"),
        "force_coding_SAI": R(1.05, inf, "docs/references.md row 6: SA-I rates rise with normal force (shape only)",
                              "held out", "V"),
        "rate_coding_RAI": R(1.05, inf, "docs/references.md rows 6, 29: FA-I discharge rates grow with indentation "
                             "and loading rate", "held out", "V"),
        "best_frequency_RAI": R(8.0, 64.0, "docs/references.md row 8 (Johansson, Landstrom & Lundstrom 1982)",
                                "held out", "V"),
        "best_frequency_RAII": R(200.0, 300.0, "docs/references.md row 8: FA-II best at 200-300 Hz; FA-II's high-pass "
                                 "and d set by hand on it", "constrained", "V"),
        "tuned_SAI": R(0.89, 0.97, tuned + ": 93 +- 4%", "fitted", "R"),
        "tuned_RAI": R(0.79, 0.87, tuned + ": 83 +- 4%", "fitted", "R"),
        "dsi_mean_SAI": R(0.20, 0.26, tuned + ": 0.23 +- 0.03", "fitted", "V"),
        "dsi_sd_SAI": R(0.13, 0.23, tuned + ": SD 0.18 +- 0.05", "fitted", "V"),
        "dsi_mean_RAI": R(0.21, 0.27, tuned + ": 0.24 +- 0.03", "fitted", "V"),
        "dsi_sd_RAI": R(0.13, 0.23, tuned + ": SD 0.18 +- 0.05", "fitted", "V"),
        "tuned_SAII": R(0.5, 1.0, "docs/references.md rows 9, 12: most SA-II direction tuned (broad range, R)",
                        "held out", "R"),
        "tuned_recorded": R(0.83, 0.89, tuned + ": 86% pooled over SA-I, SA-II and FA-I; not independent of the "
                            "fitted SA-I and FA-I rows", "held out", "R"),
        "latency_vs_count": R(0.0, 1.5, "docs/references.md row 13 (Saal et al. 2009): first spike ~ counts",
                              "held out", "V"),
        "jitter_RAI": R(0.5, 10.0, "docs/references.md row 14: jitter of a few ms (R: a broad range)", "held out", "R"),
        "continuity": R(0.0, 0.2, "docs/model.md (the smooth reading): F_A continuous for continuous forces (the step "
                        "shrinks with the sample interval: 0.1 when continuous, 1 at a jump)", "held out", "V"),
    }


#: Reference ranges of ``ddmm physiology``, by property name.


def __getattr__(name):
    """``PHYSIOLOGY_REFERENCE`` is built on first use: it needs `ddmm.population.analysis.physiology`, which
    registering the command line must not import."""
    if name == "PHYSIOLOGY_REFERENCE":
        value = globals()["PHYSIOLOGY_REFERENCE"] = _physiology_reference()
        return value
    raise AttributeError(f"module {__name__!r} has no attribute {name!r}")
