"""Recorded force files and the conditioning stage: readers, errors, chunk invariance, silence on noise,
sample-rate invariance."""

import warnings
from dataclasses import replace

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from ddmm.population import Scene, sample_population, simulate
from ddmm.population.stimuli.conditioning import Conditioner, Conditioning, condition_forces
from ddmm.population.stimuli.recordings import RecordingBandWarning, from_csv

KNOTS = [0, 0.5, 1.0, 2.0, 2.5, 3.5, 4.0, 5.0]
PHASES = {"rest": (0.1, 0.5), "press": (0.5, 1.0), "hold": (1.3, 2.0), "push": (2.0, 2.5), "hold2": (2.8, 3.5),
          "lift": (3.5, 4.0), "after": (4.3, 5.0)}


def profile(fs, noise, seed=0):
    """Press to 3 N, hold, push 1 N distal, hold, lift: (t, forces) with white sensor noise of SD ``noise``."""
    t = np.arange(0, 5.0, 1 / fs)
    f = np.column_stack([np.zeros_like(t), np.interp(t, KNOTS, [0, 0, 0, 0, 1, 1, 0, 0]),
                         np.interp(t, KNOTS, [0, 0, 3, 3, 3, 3, 0, 0])])
    return t, f + np.random.default_rng(seed).normal(0, noise, f.shape)


def write(path, t, f, header="Time,Fx,Fy,Fz", fz_sign=1):
    rows = "".join(f"{a:.6f},{b:.6f},{c:.6f},{fz_sign * d:.6f}\n" for a, (b, c, d) in zip(t, f))
    path.write_text(header + "\n" + rows)
    return path


@pytest.fixture(scope="module")
def pop():
    return sample_population("fingertip", rng=0).select(np.arange(0, 991, 3))


def rates(pop, scene):
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        ds = simulate(pop, scene, engine="direct", seed=0, quiet=True)
    st_, sa, types = ds.spike_time.values, ds.spike_afferent.values, ds.afferent_type.values
    out = {}
    for kind in ("SAI", "RAI", "RAII"):
        sel = types[sa] == kind
        out[kind] = {p: ((st_[sel] >= a) & (st_[sel] < b)).sum() / (types == kind).sum() / (b - a)
                     for p, (a, b) in PHASES.items()}
    return out


def test_an_amti_style_file_with_pressing_negative_reads_with_options_alone(tmp_path):
    t, f = profile(1000.0, 0.0)
    path = write(tmp_path / "amti.csv", t, f, fz_sign=-1)
    with pytest.raises(ValueError, match=r"normal force down to -3 N \(line \d+\) and it is never positive: .*"
                                         r"fz_sign=-1"):
        from_csv(path)
    scene = from_csv(path, fz_sign=-1)
    # A noise-free file passes as recorded: the conditioning measures the sensor's noise (adapt_noise) and
    # takes off next to nothing, not the contact threshold (test_conditioning_latency.py).
    np.testing.assert_allclose(scene.fz[1500:2000], 3.0, atol=1e-3)
    assert scene.fs == 1000.0


def test_units_time_scale_and_a_file_without_time(tmp_path):
    t, f = profile(1000.0, 0.0)
    a = from_csv(write(tmp_path / "a.csv", t * 1e3, f * 1e3, "t_ms,FX,FY,FZ"), units="mN", time_scale=1e-3,
                 columns={"time": "t_ms"})
    path = tmp_path / "b.csv"
    path.write_text("Fx,Fy,Fz\n" + "".join(f"{b},{c},{d}\n" for b, c, d in f))
    b = from_csv(path, recorded_fs=1000.0)
    np.testing.assert_allclose(a.fz, b.fz, atol=1e-9)
    with pytest.raises(ValueError, match="units='kN' is not allowed; allowed: N, mN, gf, kgf, lbf"):
        from_csv(path, recorded_fs=1000.0, units="kN")


def test_gaps_are_refused_with_their_time_and_length_or_filled(tmp_path):
    t, f = profile(100.0, 0.0)
    keep = (t < 1.0) | (t >= 1.2)
    path = write(tmp_path / "gap.csv", t[keep], f[keep])
    with pytest.raises(ValueError, match=r"a gap of 0.21 s at t = 0.99 s \(line 101"):
        from_csv(path)
    with pytest.warns(RecordingBandWarning, match="FA-II's band"):
        scene = from_csv(path, gaps="interpolate")
    assert scene.duration == pytest.approx(5.0, abs=0.02)


def test_an_offset_is_removed_from_the_quiet_baseline(tmp_path):
    t, f = profile(1000.0, 0.002)
    path = write(tmp_path / "offset.csv", t, f - [0.1, -0.05, 0.4])
    with pytest.raises(ValueError, match="negative_fz='offset'"):
        from_csv(path, conditioning=None)
    scene = from_csv(path, negative_fz="offset")
    assert np.all(scene.fz[:400] == 0.0) and np.all(scene.fy[:400] == 0.0)


@settings(max_examples=25, deadline=None)
@given(fs_in=st.sampled_from([100.0, 250.0, 1000.0, 5000.0]), cuts=st.lists(st.integers(0, 120), max_size=6),
       start=st.sampled_from([0.0, 1.9]))
def test_a_stream_of_any_chunking_equals_the_offline_conditioning(fs_in, cuts, start):
    """From rest (contact onset) or from a pressed hold into the push (the shear hold at work)."""
    _, f = profile(fs_in, 0.02)
    f = f[int(start * fs_in): int((start + 0.6) * fs_in)]
    whole, contact = condition_forces(f, fs_in, 1000.0)
    c = Conditioner(Conditioning(), fs_in, 1000.0)
    edges = sorted({0, f.shape[0], *[min(x, f.shape[0]) for x in cuts]})
    parts = [c.push(f[a:b]) for a, b in zip(edges[:-1], edges[1:])]
    np.testing.assert_array_equal(np.concatenate([p[0] for p in parts]), whole)
    np.testing.assert_array_equal(np.concatenate([p[1] for p in parts]), contact)


@pytest.mark.parametrize("fs_in", [100.0, 1000.0])
def test_noise_on_a_free_sensor_is_not_contact_and_zero_shear_does_not_spin(fs_in):
    _, f = profile(fs_in, 0.02)
    out, contact = condition_forces(f, fs_in, 1000.0)
    rest, hold = slice(0, 450), slice(1300, 2000)
    assert not contact[rest].any() and np.all(out[rest] == 0.0)
    assert contact[hold].all() and np.all(out[hold, :2] == 0.0) and np.all(out[:, 2] >= 0.0)


@pytest.mark.parametrize("fs_in", [100.0, 1000.0])
def test_the_shear_hold_keeps_a_noisy_sheared_hold_still(fs_in):
    """20 mN of noise on a 1 N sheared hold: the shear moves at up to 0.23-0.69 N/s without the hold; with it,
    below 0.1 N/s (measured 0.029-0.056), and on the same mean."""
    _, f = profile(fs_in, 0.02, seed=3)
    hold2 = slice(2800, 3500)
    held = condition_forces(f, fs_in, 1000.0)[0][hold2, 1]
    free = condition_forces(f, fs_in, 1000.0, Conditioning(shear_hold_n=0.0))[0][hold2, 1]
    speed = [np.abs(np.diff(x)).max() * 1000.0 for x in (held, free)]
    assert speed[0] < 0.1 and speed[1] > 0.2, speed
    assert abs(held.mean() - free.mean()) < 0.005


@pytest.mark.parametrize(("mode", "lag_n"), [("causal", 0.025), ("zero_phase", 0.0)])
def test_the_shear_hold_passes_a_ramp_with_its_slope(mode, lag_n):
    """A 1 N/s shear ramp: the same slope; the causal hold trails it by its width, the two-way one not at all
    (the settling after a drag cannot close a gap that grows at 1 N/s)."""
    t = np.arange(0, 3, 1e-3)
    f = np.column_stack([np.zeros_like(t), np.interp(t, [0, 1, 2, 3], [0, 0, 1, 1]), np.full_like(t, 2.0)])
    mid = slice(1300, 1700)
    declared = Conditioning(mode=mode, adapt_noise=False)  # a noise-free ramp read as if the sensor were noisy
    held = condition_forces(f, 1000.0, 1000.0, declared)[0][mid, 1]
    free = condition_forces(f, 1000.0, 1000.0, replace(declared, shear_hold_n=0.0))[0][mid, 1]
    np.testing.assert_allclose(np.diff(held), np.diff(free), atol=1e-9)
    np.testing.assert_allclose(free - held, lag_n, atol=1e-9)


@pytest.mark.parametrize("fs_in", [100.0, 250.0])
def test_the_normal_hold_keeps_a_noisy_pressed_hold_still(fs_in):
    """20 mN of noise on a 3 N hold: without the hold F_Z wanders at up to about 1 N/s (the most sensitive FA-I
    fired); with it, at most a quarter as fast (measured 0.15 and 0.04 N/s against 0.72 and 0.34), on the same
    mean."""
    _, f = profile(fs_in, 0.02, seed=5)
    hold = slice(1300, 2000)
    held = condition_forces(f, fs_in, 1000.0)[0][hold, 2]
    free = condition_forces(f, fs_in, 1000.0, Conditioning(normal_hold_n=0.0))[0][hold, 2]
    speed = [np.abs(np.diff(x)).max() * 1000.0 for x in (held, free)]
    assert speed[0] < 0.25 * speed[1] and speed[1] > 0.3, speed
    assert abs(held.mean() - free.mean()) < 0.015


@pytest.mark.parametrize("mode", ["causal", "zero_phase"])
def test_the_normal_hold_passes_a_press_with_its_slope_and_contact_as_before(mode):
    """A 10 N/s press: the same slope in the middle of the ramp, at most the width behind (and the
    smoothing's overshoot); the onset, where the hold narrows to nothing, is where it was."""
    t = np.arange(0, 3, 1e-3)
    f = np.column_stack([np.zeros_like(t), np.zeros_like(t), np.interp(t, [0, 1, 1.4, 3], [0, 0, 4, 4])])
    held, on_held = condition_forces(f, 1000.0, 1000.0, Conditioning(mode=mode))
    free, on_free = condition_forces(f, 1000.0, 1000.0, Conditioning(mode=mode, normal_hold_n=0.0))
    mid = slice(1200, 1350)
    np.testing.assert_allclose(np.diff(held[mid, 2]), np.diff(free[mid, 2]), atol=1e-4)
    assert np.all(free[:, 2] - held[:, 2] <= 0.027)
    np.testing.assert_array_equal(on_held, on_free)


@pytest.mark.parametrize(("kwargs", "match"), [
    ({"noise_n": -0.01}, "noise_n must be a finite number >= 0"),
    ({"contact_on_n": 0.01}, "contact_on_n must be a finite number > contact_off_n = 0.015"),
    ({"bandwidth_hz": 0.0}, "bandwidth_hz must be a finite number > 0"),
    ({"mode": "acausal"}, "mode='acausal' is not allowed; allowed: causal, zero_phase"),
    ({"shear_hold_n": -0.01}, "shear_hold_n must be a finite number >= 0 \\(N\\), got -0.01"),
    ({"normal_hold_n": float("nan")}, "normal_hold_n must be a finite number >= 0 \\(N\\), got nan"),
])
def test_bad_conditioning_is_named(kwargs, match):
    with pytest.raises(ValueError, match=match):
        Conditioning(**kwargs)


@pytest.mark.parametrize("fs_in", [100.0, 1000.0])
def test_fast_afferents_are_silent_at_rest_and_in_holds_with_20_mN_of_noise(pop, fs_in):
    _, f = profile(fs_in, 0.02, seed=int(fs_in))
    out, _ = condition_forces(f, fs_in, 1000.0)
    r = rates(pop, Scene(*out.T, fs=1000.0, name="plate"))
    for kind in ("RAI", "RAII"):
        for phase in ("rest", "hold", "hold2", "after"):
            # hold2 is sheared: without the shear hold FA-I fired 1.6 pulses/s there at 100 Hz
            assert r[kind][phase] == 0.0, (kind, phase, r[kind][phase])


def test_100_hz_and_1_khz_recordings_give_the_same_rates_within_20_percent(pop):
    """SA-I and FA-I, every phase with at least 2 imp/s, 5 mN of noise (docs/recordings.md has 10 and 20 mN)."""
    got = {}
    for fs_in in (100.0, 1000.0):
        _, f = profile(fs_in, 0.005, seed=int(fs_in))
        got[fs_in] = rates(pop, Scene(*condition_forces(f, fs_in, 1000.0)[0].T, fs=1000.0, name="plate"))
    for kind in ("SAI", "RAI"):
        for phase in PHASES:
            a, b = got[100.0][kind][phase], got[1000.0][kind][phase]
            if max(a, b) >= 2.0:
                assert max(a, b) / min(a, b) <= 1.2, (kind, phase, a, b)
