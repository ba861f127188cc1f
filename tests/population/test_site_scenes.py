"""Torsion and incipient-slip scenes: the fields integrate to what they claim."""

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from ddmm.population.stimuli.site_scenes import contact_grid, incipient_slip, torsion


@settings(max_examples=20, deadline=None)
@given(torque=st.floats(0.5, 10.0), normal=st.floats(0.5, 5.0), radius=st.floats(3.0, 8.0),
       direction=st.sampled_from([1, -1]))
def test_torsion_integrates_to_its_torque_with_no_net_shear(torque, normal, radius, direction):
    s = torsion(torque, normal, radius, direction)
    f, x, y = s.site_forces, s.sites.x_mm, s.sites.y_mm
    moment = (x[None] * f[:, :, 1] - y[None] * f[:, :, 0]).sum(axis=1)
    np.testing.assert_allclose(moment.max() if direction > 0 else -moment.min(), torque, rtol=1e-12)
    np.testing.assert_allclose(f[:, :, :2].sum(axis=1), 0.0, atol=1e-12)
    np.testing.assert_allclose(s.fz.max(), normal, rtol=1e-12)
    # tangential: perpendicular to the radius, growing with it
    k = int(np.argmax(np.abs(moment)))
    radial = f[k, :, 0] * x + f[k, :, 1] * y
    np.testing.assert_allclose(radial, 0.0, atol=1e-12)
    shear = np.hypot(f[k, :, 0], f[k, :, 1])
    r = np.hypot(x, y)
    np.testing.assert_allclose(shear / r, (shear / r)[0], rtol=1e-9)


def test_torsion_timing_and_bad_input():
    s = torsion(5.0, 3.0, preload_s=0.3, ramp_s=0.1, hold_s=0.5)
    stages = {st.label: (st.start, st.end) for st in s.stages}
    assert stages["torque_ramp"] == (0.3, 0.4) and stages["torque_hold"][1] == pytest.approx(0.9)
    with pytest.raises(ValueError, match="direction must be"):
        torsion(5.0, 3.0, direction=0)
    with pytest.raises(ValueError, match="torque_mnm must be finite and >= 0"):
        torsion(-1.0, 3.0)
    with pytest.raises(ValueError, match="too coarse"):
        contact_grid(1.0, 5.0)


def test_contact_grid_tiles_the_disc():
    sites, dx, dy = contact_grid(6.0, 1.0, center_mm=(2.0, -1.0), region="D2d")
    assert np.all(np.hypot(dx, dy) <= 6.0) and len(sites) == dx.size
    np.testing.assert_allclose(dx.size * 1.0, np.pi * 36.0, rtol=0.05)  # cells cover the disc's area
    assert set(sites.region) == {"D2d"} and np.isclose(sites.x_mm.mean(), 2.0)


def test_incipient_slip_follows_cattaneo_mindlin():
    s = incipient_slip(2.0, mu_s=1.0, load_rate_n_s=4.0, preload_s=0.2, vibration=0.0)
    onset = next(st.start for st in s.stages if st.label == "slip")
    assert onset == pytest.approx(0.2 + 2.0 / 4.0)
    f, r = s.site_forces, np.hypot(s.sites.x_mm, s.sites.y_mm)
    shear = np.hypot(f[:, :, 0], f[:, :, 1])
    k = int(round(0.45 * s.fs))  # Q = 1 N of mu N = 2 N: stick radius a (1/2)^(1/3)
    np.testing.assert_allclose(shear[k].sum(), 1.0, rtol=1e-12)
    # in the slip annulus the traction is mu p: shear / normal = mu_s exactly there, below it inside
    ratio = shear[k] / f[k, :, 2]
    c = 6.0 * 0.5 ** (1 / 3)
    outer, inner = r > c + 0.3, r < c - 0.5
    np.testing.assert_allclose(ratio[outer], ratio[outer][0], rtol=1e-9)
    assert ratio[inner].max() < ratio[outer].min()
    # the stick region shrinks from the edge inward as the load grows
    early, late = shear[int(0.3 * s.fs)] / f[int(0.3 * s.fs), :, 2], shear[int(0.6 * s.fs)] / f[int(0.6 * s.fs), :, 2]
    full = lambda ratio_row: r[np.isclose(ratio_row, ratio_row.max(), rtol=1e-9)].min()  # noqa: E731
    assert full(late) < full(early)


def test_slip_control_never_slips():
    s = incipient_slip(2.0, slip=False, hold_fraction=0.8)
    assert [st.label for st in s.stages] == ["loading", "tangential_ramp", "hold"]
    assert np.hypot(s.fx, s.fy).max() == pytest.approx(1.6)
    with pytest.raises(ValueError, match="mu_k <= mu_s"):
        incipient_slip(2.0, mu_s=0.5, mu_k=0.8)


def test_grasp_shares_the_load_and_grips_above_the_slip_limit():
    from ddmm.population.anatomy.hand_map import get_region
    from ddmm.population.stimuli.site_scenes import grasp

    s = grasp(("D1", "D2", "D3", "D4", "D5"), load_n=2.5, mu=0.8, safety=1.4)
    f = s.site_forces
    hold = slice(int(0.5 * s.fs), int(1.3 * s.fs))
    tangential = np.hypot(f[hold, :, 0], f[hold, :, 1])
    np.testing.assert_allclose(tangential.sum(axis=1), 2.5, rtol=1e-12)  # the weight, shared
    np.testing.assert_allclose(f[hold, :, 2] * 0.8 / tangential, 1.4, rtol=1e-12)  # grip/load over slip ratio
    # each tip's load acts proximally in its own digit frame
    for j, d in enumerate(["D1", "D2", "D3", "D4", "D5"]):
        angle = np.rad2deg(np.arctan2(f[hold, j, 1], f[hold, j, 0]))[0]
        assert np.isclose((angle - get_region(f"{d}d").frame_deg) % 360.0, 270.0)
    assert [st.label for st in s.stages] == ["preload", "loading", "hold", "replacement", "release"]
    with pytest.raises(ValueError):
        grasp(("D9",))
