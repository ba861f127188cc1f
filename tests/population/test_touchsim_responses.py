"""TouchSim's recorded responses (`tests/population/data/touchsim_responses.json`) and the side-by-side script.

The recording was made by `experiments/validation/touchsim_responses.py` in TouchSim's own environment
(public repository, commit 4ec9f5c); `ddmm.experiments.validation.touchsim_side_by_side` reads it.
"""

import json
from pathlib import Path

import numpy as np

from ddmm.experiments.validation.touchsim_side_by_side import PAIRS, named_list, touchsim_summary

RECORDING = json.loads((Path(__file__).parent / "data" / "touchsim_responses.json").read_text())


def test_every_named_stimulus_has_touchsims_response_for_every_class():
    for name, (depth, key) in named_list().items():
        summary = touchsim_summary(RECORDING, key)
        assert set(summary) == set(PAIRS), name
        assert RECORDING[key[0]][key[1]]["duration_s"] == depth.size / 5000.0, name


def test_the_recording_names_touchsims_commit_and_its_single_models():
    assert RECORDING["touchsim"]["commit"].startswith("4ec9f5c")
    classes = [u["class"] for u in RECORDING["ramp"]["d0.5"]["afferents"]]
    assert {c: classes.count(c) for c in PAIRS} == {"SA1": 4, "RA": 9, "PC": 4}


def test_touchsim_grows_with_depth_and_pc_follows_250_hz():
    ramp = [touchsim_summary(RECORDING, ("ramp", f"d{d:g}"))["SA1"]["rate"] for d in (0.25, 0.5, 1.0)]
    assert np.all(np.diff(ramp) > 0)
    assert touchsim_summary(RECORDING, ("sine", "f250_a0.05"))["PC"]["rate"] >= 250.0


def test_the_side_by_side_runs_ddmm_on_the_whole_named_list():
    from ddmm.experiments.validation.touchsim_side_by_side import HELD_OUT_SEEDS, ddmm_responses

    ours = ddmm_responses(seed=0)  # the units of the 10 fingertips the transduction fit never saw
    assert set(ours) == set(named_list()) | {"grating_40mm_s"}
    assert all(np.isfinite(v["rate"]) for by_type in ours.values() for v in by_type.values())
    assert ours["ramp_1mm"]["SAI"]["rate"] > ours["ramp_0.25mm"]["SAI"]["rate"]
    # The shipped transduction on the held-out fingertips (measured, noise seed 0): within 2x of TouchSim where
    # it fires, fitted and held-out cells, SA-I 14/15 and 12/12, FA-I 10/12 and 8/9, FA-II 13/14 and 11/11;
    # at most 2 imp/s where TouchSim is silent, FA-I 3/3 and 2/3, FA-II 1/1 and 1/1.
    from ddmm.experiments.calibration.displacement import agreement, is_fitted_cell, touchsim_rates
    from ddmm.experiments.validation.touchsim_side_by_side import _agreement_lines

    expected = {"SAI": (14, 12, 0, 0), "RAI": (10, 8, 3, 2), "RAII": (13, 11, 1, 1)}
    printed = _agreement_lines(ours, RECORDING).splitlines()
    for (cls, kind), line in zip(PAIRS.items(), printed):
        fitted, held, quiet_fitted, quiet_held = expected[kind]
        mine = {name: ours[name][kind]["rate"] for name in named_list()}
        theirs = touchsim_rates(RECORDING, kind)
        on_fitted = agreement(mine, theirs, [n for n in mine if is_fitted_cell(n)])
        on_held = agreement(mine, theirs, [n for n in mine if not is_fitted_cell(n)])
        assert on_fitted["within_2x"] >= fitted and on_fitted["quiet"] >= quiet_fitted, (kind, on_fitted)
        assert on_held["within_2x"] >= held and on_held["quiet"] >= quiet_held, (kind, on_held)
        assert line == (f"{kind} / {cls}: fitted cells {on_fitted['within_2x']}/{on_fitted['firing']} within 2x, "
                        f"{on_fitted['quiet']}/{on_fitted['silent']} quiet; held out cells {on_held['within_2x']}/"
                        f"{on_held['firing']} within 2x, {on_held['quiet']}/{on_held['silent']} quiet"), line
    # The grating (held out): every type's mean rate within 2x of TouchSim's (SA-I 1.62x, FA-I 1.00x, FA-II
    # 0.57x), and SA-I lock to its 40 Hz (median VS 0.88) at least twice as well as FA-II (0.06).
    grating = touchsim_summary(RECORDING, ("grating", None))
    for cls, kind in PAIRS.items():
        assert 0.5 <= ours["grating_40mm_s"][kind]["rate"] / grating[cls]["rate"] <= 2.0, kind
    assert ours["grating_40mm_s"]["SAI"]["vs"] >= 2.0 * ours["grating_40mm_s"]["RAII"]["vs"]
    assert ours["grating_40mm_s"]["RAI"]["vs"] > 0.5  # FA-I follow the grating's 40 Hz
    assert len(HELD_OUT_SEEDS) == 10


def test_the_side_by_side_takes_a_variant_of_the_force_path():
    """``population`` (``--population``): the same units, sampled from another spec, with its force path."""
    from ddmm.experiments.validation.touchsim_side_by_side import named_units
    from ddmm.population import load_spec

    spec = load_spec("fingertip")
    variant = spec.replace(current=spec.current.with_type("RAI", tau_s=0.002))
    base, alt = named_units((0, 3)), named_units((0, 3), population=variant)
    assert np.array_equal(base.afferent_id, alt.afferent_id) and np.array_equal(base.gain, alt.gain)
    assert (base.current.type_params("RAI").tau_s, alt.current.type_params("RAI").tau_s) == (0.012, 0.002)


SPREAD = json.loads((Path(__file__).parent / "data" / "touchsim_probe_spread.json").read_text())


def test_probe_spread_and_slow_press_beside_touchsim():
    """Held out: units off the probe's axis, and a 2 mm/s press (`touchsim_probe_spread`).  Measured, the
    units of fingertip seed 0, noise seed 0: SA-I fire through the hold at 0 and 0.5 mm and are silent in it
    from 1 mm, as TouchSim's SA1; FA-I answer the 10 mm/s ramp (7/9 at the axis, as TouchSim's RA) and barely
    the 2 mm/s one (1/9; TouchSim 0/9); FA-II answer the fast press's onset up to 2 mm (3/4 or more, as
    TouchSim's PC).  SA-I hold at the axis: 12.8 imp/s against TouchSim's 20.6 (0.62x)."""
    from ddmm.experiments.validation.touchsim_probe_spread import DISTANCES_MM, ddmm_spread, summarise

    assert SPREAD["touchsim"]["commit"].startswith("4ec9f5c")
    theirs, ours = SPREAD["responses"], ddmm_spread(seed=0)
    near = [DISTANCES_MM.index(d) for d in (0.0, 0.5)]
    for responses, sa, ra, pc in ((ours, "SAI", "RAI", "RAII"), (theirs, "SA1", "RA", "PC")):
        hold = summarise(responses, sa, "fast", "hold")
        assert all(hold[i][0] >= 3 for i in near), (sa, hold)  # units with a spike in the hold
        assert all(n_spiking == 0 for n_spiking, _, _ in hold[DISTANCES_MM.index(1.0):]), (sa, hold)
        fast, slow = summarise(responses, ra, "fast", "on")[0], summarise(responses, ra, "slow", "on")[0]
        assert fast[0] >= 7 and slow[0] <= 3, (ra, fast, slow)
        assert all(n_spiking >= 3 for n_spiking, _, _ in summarise(responses, pc, "fast", "on")), pc
    ratio = summarise(ours, "SAI", "fast", "hold")[0][2] / summarise(theirs, "SA1", "fast", "hold")[0][2]
    assert 0.3 <= ratio <= 2.0, ratio
