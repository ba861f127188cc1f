"""Scenes: the paper's stimuli, and recorded CSV data with its errors."""

import numpy as np
import pytest

from ddmm.population.stimuli.recordings import from_csv
from ddmm.population.stimuli.scenes import Contact, Scene, birznieks, press_push_lift, rotating_shear


def test_birznieks():
    s = birznieks(90.0)
    assert s.duration == 0.5 and s.fs == 1000.0
    assert s.fz.max() == pytest.approx(4.0)
    assert s.fy.max() == pytest.approx(4.0 * np.tan(np.deg2rad(20.0)))
    np.testing.assert_allclose(s.fx, 0.0, atol=1e-12)
    assert [st.label for st in s.stages] == ["loading", "plateau", "unloading"]
    assert birznieks(None).max_shear() == 0.0 and birznieks(None).name == "normal"


def test_press_push_lift_stages():
    s = press_push_lift()
    t = s.time
    assert s.fz[(t > 8) & (t < 15)].max() == pytest.approx(3.0)
    assert s.fz[(t > 18) & (t < 25)].min() == pytest.approx(6.0)
    assert np.all(s.fz[t < 5] == 0) and np.all(s.fz[t > 27.01] == 0)


def test_rotating_shear_turns_once():
    s = rotating_shear(period_s=1.0)
    angle = np.unwrap(np.arctan2(s.fy, s.fx)[(s.time >= 0.125) & (s.time <= 1.125)])
    assert np.ptp(angle) == pytest.approx(2 * np.pi, abs=0.05)


def test_scene_validation():
    with pytest.raises(ValueError, match="fz"):
        Scene([0.0], [0.0], [-1.0])
    with pytest.raises(ValueError, match="equal length"):
        Scene([0.0, 1.0], [0.0], [0.0])
    with pytest.raises(ValueError, match="fx"):
        Scene([np.nan], [0.0], [0.0])
    with pytest.raises(ValueError, match="radius"):
        Contact(0.0, 0.0, 0.0)


def write(tmp_path, text, name="f.csv"):
    path = tmp_path / name
    path.write_text(text)
    return path


def test_csv_resamples_100hz_without_conditioning(tmp_path):
    t = np.arange(0, 1.0, 0.01)
    rows = "\n".join(f"{a:.2f},{0.0},{0.5 * a},{2 * a}" for a in t)
    s = from_csv(write(tmp_path, "time,fx,fy,fz\n" + rows), conditioning=None)
    assert s.fs == 1000.0 and s.n_samples == 991
    np.testing.assert_allclose(s.fz, 2 * s.time, atol=1e-12)


def test_csv_column_mapping_and_units(tmp_path):
    s = from_csv(write(tmp_path, "t_ms,Fx,Fy,Fz\n0,0,0,1\n10,0,0,2\n"), conditioning=None,
                 columns={"time": "t_ms", "fx": "Fx", "fy": "Fy", "fz": "Fz"}, time_scale=1e-3)
    assert s.n_samples == 11 and s.fz[-1] == 2.0


@pytest.mark.parametrize("text,match", [
    ("time,fx,fy,fz\n0,0,0,1\n0,0,0,1\n", "time must increase strictly"),
    ("time,fx,fy,fz\n0,0,0,1\n0.01,nan,0,1\n", "not finite"),
    ("time,fx,fy,fz\n0,0,0,1\n0.01,0,0,-2\n", r"normal force down to -2 N \(line 3\)"),
    ("time,fx,fy,fz\n0,0,0,1\n0.01,0,0\n", "line 3 has 3 values but the header has 4"),
    ("", "empty"),
    ("time,fx,fy\n0,0,0\n", "no column 'fz'"),
    ("time,fx,fy,fz\n", "no data rows"),
    ("time,fx,fy,fz\n0,a,0,1\n", "not a number"),
])
def test_csv_errors(tmp_path, text, match):
    with pytest.raises(ValueError, match=match):
        from_csv(write(tmp_path, text))


def test_csv_negative_fz_can_be_clipped(tmp_path):
    s = from_csv(write(tmp_path, "time,fx,fy,fz\n0,0,0,-0.01\n0.01,0,0,1\n"), negative_fz="clip", conditioning=None)
    assert s.fz.min() == 0.0


def test_reproduction_scene_ramps_and_shear_onset():
    s = press_push_lift(90.0, ramp_s=0.5, lift_ramp_s=1.0, shear_delay_s=0.2)
    t = s.time
    assert np.all(s.fy[(t >= 15.0) & (t <= 15.2)] == 0.0) and s.fy[t > 15.2][0] > 0.0
    assert s.fy[(t > 15.5) & (t < 25)].min() == pytest.approx(6.0 * np.tan(np.deg2rad(20.0)))
    assert s.fz[(t > 25.99) & (t < 26.0)].max() < 0.1 and np.all(s.fz[t >= 26.0] == 0.0)
    assert [(st.start, st.end) for st in s.stages][4] == (25.0, 26.0)
    b = birznieks(90.0, shear_delay_s=0.05)
    assert np.all(b.fy[b.time <= 0.05] == 0.0) and b.fy.max() == pytest.approx(birznieks(90.0).fy.max())
    np.testing.assert_array_equal(press_push_lift().fy, press_push_lift(shear_delay_s=0.0, lift_ramp_s=2.0).fy)


def test_a_five_second_lift_leaves_no_static_stage():
    """The longest lift the scene allows (the paper calibration's search reaches it) ends with the scene."""
    s = press_push_lift(90.0, lift_ramp_s=5.0)
    assert [st.label for st in s.stages][-1] == "stage3_dynamic" and s.stages[-1].end == 30.0


@pytest.mark.parametrize("kwargs,match", [
    ({"shear_delay_s": 2.0}, r"shear_delay_s must be in \[0, ramp_s = 2\) s, got 2.0"),
    ({"shear_delay_s": -0.1}, "shear_delay_s must be in"),
    ({"lift_ramp_s": 6.0}, r"lift_ramp_s must be in \(0, 5\] s, got 6.0"),
    ({"ramp_s": 0.0}, r"ramp_s must be in \(0, 10\] s"),
])
def test_reproduction_scene_bad_parameters(kwargs, match):
    with pytest.raises(ValueError, match=match):
        press_push_lift(**kwargs)
