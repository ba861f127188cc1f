"""The shear-magnitude term of the pressure types (`TypeParams.shear`, `attenuation.shear_drive`)."""

from dataclasses import replace

import numpy as np
import pytest

from ddmm.models.currents import CurrentParams
from ddmm.models.pipeline import compute_currents
from ddmm.models.reference_pipeline import attenuated_force, shear_drive
from ddmm.population import load_spec, sample_population
from ddmm.population.simulation import simulate
from ddmm.population.stimuli.scenes import Scene

PHYSIO = (load_spec("fingertip").current.with_type("SAI", shear=0.5, opponent_shear=1.0)
          .with_type("RAI", shear=4.0, opponent_shear=1.0).with_type("RAII", shear=1.0, opponent_shear=1.0))


def test_paper_defaults_have_no_shear_term():
    params = CurrentParams()
    sai, rai, raii = (params.type_params(kind) for kind in ("SAI", "RAI", "RAII"))
    assert (sai.shear, rai.shear, raii.shear, sai.opponent_shear) == (0.0, 0.0, 0.0, 0.0)
    f_a = np.array([[2.0, 0.4]])
    np.testing.assert_array_equal(shear_drive(f_a, [0.0], [1.0], [[1.0, 0.2]], 0.0, 1.0), f_a)


@pytest.mark.parametrize("kind", ["SAI", "RAI", "RAII"])
@pytest.mark.parametrize("name", ["shear", "opponent_shear"])
def test_bad_shear_option_is_refused(name, kind):
    with pytest.raises(ValueError, match=rf"^{name} must be a finite number >= 0, got -1\.0"):
        CurrentParams().with_type(kind, **{name: -1.0})


def _held(magnitude, direction_deg, n=1500):
    """2 N normal from the first sample, shear ramped to ``magnitude`` (N) over 0.25 s from 0.5 s and held."""
    t = np.arange(n) / 1000.0
    s = np.interp(t, [0, 0.5, 0.75, 1.5], [0, 0, magnitude, magnitude])
    rad = np.deg2rad(direction_deg)
    return s * np.cos(rad), s * np.sin(rad), np.full(n, 2.0)


@pytest.mark.parametrize("kind", ["SAI", "RAI"])
def test_shear_in_the_preferred_direction_raises_the_drive_and_against_it_lowers_it(kind):
    def current(magnitude, direction):
        fx, fy, fz = _held(magnitude, direction)
        i = compute_currents(fx, fy, fz, fs=1000.0, afferent_type=kind, profile="selective", theta_t=[90.0],
                             no_shear="smooth", current_params=PHYSIO)[:, 0]
        return i[760:].mean() if kind == "SAI" else i[500:760].max()

    pref = [current(m, 90.0) for m in (0.0, 0.25, 0.5, 1.0)]
    assert np.all(np.diff(pref) > 0)  # grows with magnitude along the preferred direction
    if kind == "SAI":
        opp = [current(m, 270.0) for m in (0.0, 0.25, 0.5, 1.0)]
        assert np.all(np.diff(opp) <= 0) and opp[-1] < opp[0]
    paper = PHYSIO.with_type("SAI", shear=0.0).with_type("RAI", shear=0.0)
    fx, fy, fz = _held(1.0, 90.0)
    base = compute_currents(fx, fy, fz, fs=1000.0, afferent_type=kind, profile="selective", theta_t=[90.0],
                            no_shear="smooth", current_params=paper)[:, 0]
    assert (base[760:].mean() if kind == "SAI" else base[500:760].max()) < pref[-1]


def test_plan_keeps_afferents_the_shear_term_drives_without_normal_force():
    """Shear with no normal force: the planner must not skip the pressure afferents (their term drives them)."""
    pop = sample_population("fingertip", rng=3)
    pop = replace(pop, current=PHYSIO)
    pop = pop.select(np.r_[np.flatnonzero(pop.afferent_type == "SAI")[:20], np.flatnonzero(pop.afferent_type == "RAI")[:20]])
    n = 800
    s = np.interp(np.arange(n) / 1000.0, [0, 0.1, 0.4, 0.8], [0, 0, 1.5, 1.5])
    scene = Scene(np.zeros(n), s, np.zeros(n), 1000.0, "shear_only")
    planned = simulate(pop, scene, engine="direct", seed=0, quiet=True)
    brute = simulate(pop, scene, engine="direct", seed=0, quiet=True, plan=False)
    assert planned.spike_time.size > 0
    np.testing.assert_array_equal(planned.spike_time.values, brute.spike_time.values)
    np.testing.assert_array_equal(planned.spike_afferent.values, brute.spike_afferent.values)


def test_the_attenuation_depth_keeps_part_of_the_normal_force_in_every_direction():
    """``TypeParams.depth``: F_A = (1 + depth (AF - 1)) F_Z; 1 is the paper's F_A = AF F_Z, bit for bit."""
    fx, fy, fz = _held(1.0, 270.0)  # against a selective SA-I tuned to 90 deg: AF = 0.2
    paper = CurrentParams()

    def drive(depth):
        return compute_currents(fx, fy, fz, fs=1000.0, afferent_type="SAI", profile="selective", theta_t=[90.0],
                                no_shear="smooth", current_params=paper.with_type("SAI", depth=depth))[1000:, 0].mean()

    np.testing.assert_array_equal(
        compute_currents(fx, fy, fz, fs=1000.0, afferent_type="SAI", profile="selective", theta_t=[90.0],
                         no_shear="smooth", current_params=paper.with_type("SAI", depth=1.0)),
        compute_currents(fx, fy, fz, fs=1000.0, afferent_type="SAI", profile="selective", theta_t=[90.0],
                         no_shear="smooth", current_params=paper))
    assert drive(1.0) < drive(0.5) < drive(0.0)
    np.testing.assert_allclose(attenuated_force([2.0], [[0.2]], 0.5), [[1.2]])
    with pytest.raises(ValueError, match=r"^depth must be a number in \[0, 1\] \(1: the paper's form\), got 1.5"):
        CurrentParams().with_type("SAI", depth=1.5)
