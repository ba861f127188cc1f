"""Indentation stimuli (`ddmm.population.stimuli.indentation`): generators, the scene, and the model on it."""

import re
import subprocess
import sys

import numpy as np
import pytest

from ddmm.population import sample_population, simulate
from ddmm.population.stimuli.indentation import (
    ContactSpread,
    band_noise,
    bar_pins,
    circle_pins,
    impulse,
    indent,
    pin_array,
    probe,
    ramp_hold,
    sinusoid,
)
from ddmm.population.stimuli.indentation_spec import indentation_from_dict, parse_indent_option

FS = 5000.0


@pytest.fixture(scope="module")
def fingertip():
    return sample_population("fingertip", rng=0)


def _near(pop, r_mm, types=("SAI", "RAI", "RAII", "SAII")):
    keep = (np.hypot(pop.x_mm, pop.y_mm) <= r_mm) & np.isin(pop.afferent_type, types)
    return pop.select(np.flatnonzero(keep))


def test_waveforms_have_their_shape():
    d = ramp_hold(0.5, ramp_s=0.1, hold_s=0.2, fs=1000.0)
    assert d.size == 400 and d[0] == 0.0 and d[150] == 0.5 and d[-1] == 0.0
    s = sinusoid(100.0, 0.05, pre_indent_mm=0.2, duration_s=0.5, ramp_s=0.0, fs=FS)
    assert np.isclose(s.max(), 0.25, atol=1e-4) and np.isclose(s.min(), 0.15, atol=1e-4)
    n = band_noise(100.0, 300.0, 0.01, pre_indent_mm=0.3, duration_s=1.0, ramp_s=0.0, rng=1)
    spectrum = np.abs(np.fft.rfft(n - n.mean())) ** 2
    f = np.fft.rfftfreq(n.size, 1 / FS)
    assert spectrum[(f > 100) & (f < 300)].sum() > 0.8 * spectrum.sum()
    assert np.array_equal(n, band_noise(100.0, 300.0, 0.01, pre_indent_mm=0.3, duration_s=1.0, ramp_s=0.0, rng=1))
    assert np.isclose(impulse(0.03, pre_indent_mm=0.1).max(), 0.13)


def test_shapes_place_their_pins():
    assert len(pin_array(2, 3, pitch_mm=1.0)) == 6
    bar = bar_pins(2.0, 0.5, angle_deg=90.0, pins_per_mm=4.0)
    assert np.ptp(bar.y_mm) > np.ptp(bar.x_mm)  # turned to +Y
    dome = circle_pins(1.0, pins_per_mm=5.0, curvature_mm=0.3)
    assert dome.offset_mm.min() >= -0.3 and dome.offset_mm.max() == pytest.approx(0.0, abs=0.05)


@pytest.mark.parametrize(("make", "message"), [
    (lambda: indent(probe(), np.array([0.0, -0.1, 0.2])), r"depth_mm must be >= 0 mm .* -0.1 at sample 1"),
    (lambda: sinusoid(300.0, 0.02, pre_indent_mm=0.3, fs=500.0), r"freq_hz=300 Hz needs fs above 600 Hz"),
    (lambda: sinusoid(50.0, 0.4, pre_indent_mm=0.3), r"amplitude_mm=0.4 mm exceeds pre_indent_mm=0.3"),
    (lambda: band_noise(100.0, 3000.0, 0.01, pre_indent_mm=0.3), r"high_hz < fs / 2"),
    (lambda: impulse(0.03, width_s=0.001, fs=1000.0), r"a pulse needs 5"),
    (lambda: indent("probe", ramp_hold(0.5)), r"pins must be a Pins"),
    (lambda: indent(probe(), np.full(10, 20.0)), r"depth_mm must be <= 10"),
    (lambda: probe(radius_mm=-1.0), r"radius_mm"),
    (lambda: indentation_from_dict({"kind": "square"}), r"kind 'square' is unknown; allowed: ramp, sine"),
    (lambda: indentation_from_dict({"kind": "ramp", "depth_mm": 0.5, "freq_hz": 3.0}), r"'freq_hz' does not apply"),
    (lambda: indentation_from_dict({"kind": "ramp", "depth_mm": 0.5, "pins": "star"}), r"pins 'star' is unknown"),
])
def test_bad_stimuli_are_refused_in_one_line(make, message):
    with pytest.raises((ValueError, TypeError), match=message) as info:
        make()
    assert "\n" not in str(info.value)


@pytest.mark.parametrize("pins_per_mm", [3.0, 5.0, 7.0, 10.0, 20.0])
def test_bars_and_discs_of_touching_pins_are_not_refused_as_overlapping(pins_per_mm):
    """A bar's and a disc's pins are 2 radii apart, up to rounding (0.1 mm read as 0.09999999999999998)."""
    depth = ramp_hold(0.5, ramp_s=0.01, hold_s=0.01, fs=FS)
    for pins in (bar_pins(pins_per_mm=pins_per_mm), bar_pins(angle_deg=30.0, pins_per_mm=pins_per_mm),
                 circle_pins(1.0, pins_per_mm=pins_per_mm)):
        assert indent(pins, depth, fs=FS).n_sites == len(pins) > 1
    for shape in ("bar", "circle"):  # the defaults, as --indent ramp:depth_mm=0.5,pins=bar gives them
        assert indentation_from_dict({"kind": "ramp", "depth_mm": 0.5, "hold_s": 0.01, "pins": shape}).n_sites > 1
    with pytest.raises(ValueError, match=r"overlap: .* use a smaller radius_mm, more room between the pins "
                                         r"\(pitch_mm\) or the 'touchsim' skin"):
        indent(pin_array(1, 2, pitch_mm=1.0, radius_mm=0.6), depth, fs=FS)


@pytest.mark.parametrize(("make", "message"), [
    (lambda: ramp_hold(0.5, ramp_s=-1), r"^ramp_s must be a finite number >= 0 s, got -1$"),
    (lambda: ramp_hold(0.5, hold_s=-1), r"^hold_s must be a finite number > 0 s, got -1$"),
    (lambda: sinusoid(50.0, 0.1, pre_indent_mm=0.3, fs=None), r"^fs must be a real number, got NoneType$"),
    (lambda: sinusoid(50.0, 0.1, pre_indent_mm=0.3, ramp_s=-1), r"^ramp_s must be .*, got -1$"),
    (lambda: sinusoid(50.0, 0.1, pre_indent_mm=0.3, duration_s=-1), r"^duration_s must be .*, got -1$"),
    (lambda: band_noise(100.0, 300.0, 0.01, pre_indent_mm=0.3, fs=None), r"^fs must be a real number, got NoneType$"),
    (lambda: band_noise(100.0, None, 0.01, pre_indent_mm=0.3), r"^high_hz must be a real number, got NoneType$"),
    (lambda: band_noise(100.0, 300.0, 0.01, pre_indent_mm=0.3, ramp_s=-1), r"^ramp_s must be .*, got -1$"),
    (lambda: impulse(0.03, fs=None), r"^fs must be a real number, got NoneType$"),
    (lambda: impulse(0.03, pad_s=-1), r"^pad_s must be .*, got -1$"),
])
def test_a_waveform_names_the_argument_it_refuses(make, message):
    with pytest.raises((ValueError, TypeError), match=message.replace("-1$", r"-1(\.0)?$")):
        make()


def test_a_stimulus_too_long_or_too_wide_for_memory_is_refused_before_it_is_built(monkeypatch):
    monkeypatch.setenv("DDMM_MEMORY_LIMIT", "200M")
    with pytest.raises(ValueError, match=r"an indentation of 2000.1 s at 5000 Hz would need about .*MEMORY_LIMIT"):
        ramp_hold(0.5, hold_s=2000.0)
    with pytest.raises(ValueError, match=r"an indentation of 10500 samples x 1264 pins would need about"):
        indent(circle_pins(), ramp_hold(0.5, hold_s=2.0), fs=FS)
    with pytest.raises(ValueError, match=r"a bar of 1.0 x 0.5 mm at pins_per_mm=1000 would take about 500000 pins, "
                                         r"more than the 4000 allowed; use a lower pins_per_mm or a smaller bar"):
        bar_pins(pins_per_mm=1000)
    with pytest.raises(ValueError, match=r"a disc of radius 15 mm at pins_per_mm=10.0 would take about 70686 pins"):
        circle_pins(15)


def test_a_pin_off_the_skin_is_refused(fingertip):
    scene = indent(probe(40.0, 0.0), ramp_hold(0.3, fs=FS, hold_s=0.05), fs=FS)
    with pytest.raises(ValueError, match=r"pin 'pin0' at \(40, 0\) mm is off the skin of population 'fingertip'"):
        simulate(fingertip.select(range(50)), scene, engine="direct", quiet=True)


def test_the_scene_carries_pin_loads_and_the_mechanics_spread():
    scene = indent(pin_array(1, 2, pitch_mm=3.0, radius_mm=0.5), ramp_hold(0.5, fs=FS, hold_s=0.1), fs=FS)
    assert scene.n_sites == 2 and isinstance(scene.sites.spread, ContactSpread)
    loads = scene.site_forces[:, :, 2]
    assert np.all(loads >= 0) and loads.max() > 0 and np.allclose(loads[:, 0], loads[:, 1])
    assert np.all(scene.site_forces[:, :, :2] == 0.0)  # no sideways motion, no traction


def test_a_probe_drives_the_afferents_under_it_and_skips_the_far_ones(fingertip):
    scene = indent(probe(0.0, 0.0), ramp_hold(0.5, ramp_s=0.05, hold_s=0.3, fs=FS), fs=FS, name="press")
    ds = simulate(fingertip, scene, engine="direct", seed=0, quiet=True)
    r = np.hypot(ds.x_mm.values, ds.y_mm.values)
    counts = ds.spike_count.sum(("condition", "trial")).values
    sai = ds.afferent_type.values == "SAI"
    assert counts[sai & (r < 1.0)].mean() > 5 * max(counts[sai & (r > 4.0)].mean(), 0.1)


def test_both_engines_give_the_same_spikes(fingertip):
    pop = _near(fingertip, 2.5)
    scene = indent(probe(), sinusoid(40.0, 0.1, pre_indent_mm=0.3, duration_s=0.3, fs=FS), fs=FS)
    a = simulate(pop, scene, engine="direct", seed=3, quiet=True)
    b = simulate(pop, scene, engine="brian2", seed=3, quiet=True)
    assert int(a.sizes["spike"]) > 0
    for name in ("spike_time", "spike_afferent"):
        np.testing.assert_array_equal(a[name].values, b[name].values)


def _slide(direction_deg):
    """A 2 mm probe pressed 0.8 mm, then slid 0.6 mm along ``direction_deg`` (it slips: friction 0.5)."""
    return indentation_from_dict({"kind": "ramp", "depth_mm": 0.8, "ramp_s": 0.05, "hold_s": 0.6, "radius_mm": 1.0,
                                  "lateral_mm": 0.6, "lateral_deg": direction_deg, "fs": 2000.0,
                                  "name": f"slide_{direction_deg:g}"})


def test_a_sideways_slide_changes_responses_by_direction(fingertip):
    pop = _near(fingertip, 3.0, ("SAI", "RAI"))
    tuned = pop.select(np.flatnonzero(pop.nap != "none"))
    directions = np.arange(0.0, 360.0, 45.0)
    ds = simulate(tuned, [_slide(d) for d in directions], engine="direct", seed=0, quiet=True)
    counts = ds.spike_count.sum("trial").values  # (condition, afferent)
    assert np.all(counts.std(axis=0)[counts.max(axis=0) > 3] > 0)  # every responding afferent changes with direction
    theta = np.deg2rad(ds.theta_t.values)  # each afferent's best slide lies nearer its theta_T than its worst one
    best, worst = np.deg2rad(directions[counts.argmax(0)]), np.deg2rad(directions[counts.argmin(0)])
    live = counts.max(axis=0) > 3
    near = np.cos(best - theta) > np.cos(worst - theta)
    assert live.sum() >= 10 and near[live].mean() > 0.7


def test_the_indent_option_parses_numbers_and_names():
    table = parse_indent_option("sine:freq_hz=250,amplitude_mm=0.02,pre_indent_mm=0.3,skin=touchsim,pins=probe")
    assert table == {"kind": "sine", "freq_hz": 250.0, "amplitude_mm": 0.02, "pre_indent_mm": 0.3,
                     "skin": "touchsim", "pins": "probe"}
    assert indentation_from_dict({**table, "duration_s": 0.1}).name == "sine_250hz"


def test_ddmm_simulate_runs_an_indentation_and_refuses_a_bad_one(tmp_path):
    run = [sys.executable, "-m", "ddmm", "simulate", "--population", "fingertip", "--engine", "direct", "--quiet"]
    ok = subprocess.run(run + ["--indent", "ramp:depth_mm=0.4,hold_s=0.1,fs=2000", "--types", "SAI",
                               "--out", str(tmp_path / "a.nc")], capture_output=True, text=True)
    assert ok.returncode == 0, ok.stderr
    bad = subprocess.run(run + ["--indent", "ramp:depth_mm=-0.4", "--out", str(tmp_path / "b.nc")],
                         capture_output=True, text=True)
    assert bad.returncode == 2 and len(bad.stderr.strip().splitlines()) == 1 and "depth_mm" in bad.stderr
    assert not (tmp_path / "b.nc").exists()
    (tmp_path / "bar.toml").write_text('kind = "ramp"\ndepth_mm = 0.3\nhold_s = 0.1\nfs = 2000.0\npins = "bar"\n'
                                       'width_mm = 2.0\nheight_mm = 0.5\npins_per_mm = 4.0\nlateral_mm = 0.2\n')
    toml = subprocess.run(run + ["--indent", str(tmp_path / "bar.toml"), "--types", "SAI", "--out",
                                 str(tmp_path / "c.nc")], capture_output=True, text=True)
    assert toml.returncode == 0, toml.stderr
    off = subprocess.run(run + ["--indent", "ramp:depth_mm=0.3,x_mm=40", "--out", str(tmp_path / "d.nc")],
                         capture_output=True, text=True)
    assert off.returncode == 2 and "off the skin" in off.stderr and len(off.stderr.strip().splitlines()) == 1


@pytest.mark.parametrize(("extra", "toml", "message"), [
    (["--scene", "birznieks"], None, r"give either --indent or --scene, not both \(--scene 'birznieks'\)"),
    (["--fs", "1000"], None, (r"--fs reads a recorded --scene and does not apply to an --indent stimulus: set its "
                              r"rate as --indent \.\.\.,fs=HZ")),
    (["--sensor-noise", "0.1"], None, r"--sensor-noise reads a recorded --scene and does not apply to an --indent"),
    (["--indent", "ramp:depth_mm=0.5,pins=bar,pins_per_mm=1000"], None,
     r"a bar of .* would take about 500000 pins, more than the 4000 allowed; use a lower pins_per_mm"),
    (["--indent", "ramp:depth_mm=0.5,pins=circle,disc_radius_mm=15"], None, r"a disc of radius 15.0 mm .* smaller "),
    (["--indent", "ramp:depth_mm=0.5,pins=circle,disc_radius_mm=-1"], None, r"disc_radius_mm must be .* got -1.0"),
    (["--indent", "ramp:depth_mm=0.5,hold_s=0.1,depth_mm=0.3"], None, r"--indent key 'depth_mm' is given twice"),
    ([], '[pins]\nkind = "bar"\n', r"indent key 'pins' must be text, got a table"),
    ([], "kind = [1]\n", r"indent key 'kind' must be text, got a list"),
    ([], 'kind = "ramp"\ndepth_mm = 0.5\nhold_s = [0.1]\n', r"indent key 'hold_s' must be a number, got a list"),
])
def test_ddmm_simulate_refuses_a_conflicting_or_oversized_indentation_in_one_line(tmp_path, capsys, extra, toml,
                                                                                 message):
    from ddmm.experiments.cli import main

    if toml is not None:
        (tmp_path / "in.toml").write_text(toml)
    indent_arg = ["--indent", str(tmp_path / "in.toml") if toml is not None else "ramp:depth_mm=0.5,hold_s=0.1"]
    code = main(["simulate", "--quiet", "--engine", "direct", "--out", str(tmp_path / "o.nc"), *indent_arg, *extra])
    err = capsys.readouterr().err
    assert code == 2 and len(err.strip().splitlines()) == 1 and re.search(message, err), err


def test_the_spread_is_the_stress_at_each_types_depth_times_the_reference_area():
    from ddmm.population.anatomy.receptive_fields import REFERENCE_AREA_MM2, local_mixing
    from ddmm.population.stimuli.contact import get_skin_mechanics

    scene = indent(probe(radius_mm=0.5), ramp_hold(0.3, fs=FS, hold_s=0.05), fs=FS, transduction="none")
    types = np.array(["SAI", "RAII", "SAI"])
    indptr, sites, coeff, cover = local_mixing([0.0, 0.0, 3.0], [0.0, 0.0, 0.0], types, scene.sites)
    a, skin = 0.5, get_skin_mechanics("default")
    for j, (kind, r) in enumerate(zip(types, (0.0, 0.0, 3.0))):
        z = skin.depth_mm(kind)
        if r == 0.0:  # on the axis: P (a^2 + 3 z^2) / (2 pi (a^2 + z^2)^2) per newton (Sneddon; docs/model.md)
            assert coeff[indptr[j]] == pytest.approx(REFERENCE_AREA_MM2 * (a * a + 3 * z * z)
                                                     / (2 * np.pi * (a * a + z * z) ** 2), rel=1e-9)
    assert cover.tolist() == [1.0, 1.0, 1.0] and coeff[2] < 0.01 * coeff[0]  # 3 mm away: far less


def test_the_plan_skips_the_afferents_no_pin_reaches():
    from ddmm.population.anatomy.hand_map import get_region
    from ddmm.population.runtime.plan import make_plan

    hand = sample_population("hand", rng=0)
    pad = get_region("D2d").center_mm
    scene = indent(probe(*pad), ramp_hold(0.5, fs=2000.0, hold_s=0.1), fs=2000.0)
    quiet = make_plan(hand, [scene]).conditions[0].member_unit == -2
    r = np.hypot(hand.x_mm - pad[0], hand.y_mm - pad[1])
    untonic = hand.afferent_type != "SAII"  # SA-II keep their resting discharge wherever they are
    assert quiet[(r > 40.0) & untonic].all() and not quiet[r < 2.0].any()
    assert 0.8 < quiet[untonic].mean() < 1.0


def test_streaming_an_indentation_equals_the_offline_run(fingertip):
    from ddmm.population.runtime.stream import Encoder

    pop = _near(fingertip, 3.0)
    scene = indent(probe(0.5, 0.0), sinusoid(30.0, 0.1, pre_indent_mm=0.3, duration_s=0.3, fs=2000.0), fs=2000.0)
    offline = simulate(pop, scene, engine="direct", seed=4, quiet=True)
    enc = Encoder(pop, scene.fs, seed=4, sites=scene.sites, conditioning=None)
    edges = [0, 1, 97, 98, 400, scene.n_samples]
    outs = [enc.push(scene.site_forces[a:b]) for a, b in zip(edges[:-1], edges[1:])]
    assert offline.sizes["spike"] > 0
    np.testing.assert_array_equal(np.concatenate([o.afferent for o in outs]), offline.spike_afferent.values)
    np.testing.assert_array_equal(np.concatenate([o.time for o in outs]), offline.spike_time.values)
