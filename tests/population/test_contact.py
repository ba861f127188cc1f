"""The skin contact-mechanics stage (issue 42, part 1): closed forms, contact detection, stick-slip, refusals."""

import dataclasses

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st
from scipy import integrate

from ddmm.population.stimuli import _contact_kernels as kernels
from ddmm.population.stimuli.contact import (
    SKIN_MODELS,
    SkinMechanics,
    dynamic_stress,
    effective_radius,
    get_skin_mechanics,
    normal_stress,
    pin_compliance,
    solve_pin_loads,
    stress_kernel,
    tangential_loads,
)
from ddmm.population.stimuli.scanning import scan_depths
from ddmm.population.stimuli.surfaces import letters

DEFAULT, TOUCHSIM = get_skin_mechanics("default"), get_skin_mechanics("touchsim")
SKINS = pytest.mark.parametrize("skin", [DEFAULT, TOUCHSIM], ids=lambda s: s.name)


def _e_star(skin):
    """E / (1 - nu^2) in N/mm^2."""
    return skin.youngs_modulus_pa * 1e-6 / (1.0 - skin.poisson ** 2)


def _axial_closed_form(a, z):
    """sigma_z (Pa) per newton on the axis of a flat punch of radius a mm, depth z mm."""
    return 1e6 * (a * a + 3 * z * z) / (2 * np.pi * (a * a + z * z) ** 2)


def _boussinesq(s, z, a):
    """sigma_z (Pa) per newton at horizontal distance s, depth z: Boussinesq's point load over the punch pressure."""
    def ring(r):  # the 1/sqrt(a - r) edge singularity is quad's weight
        inner = integrate.quad(lambda psi: 3 * z ** 3 / (2 * np.pi) / (r * r + s * s - 2 * r * s * np.cos(psi)
                                                                        + z * z) ** 2.5, 0, 2 * np.pi)[0]
        return inner * r / (2 * np.pi * a * np.sqrt(a + r))
    if s == 0.0:
        def ring(r):  # the axis: the angular integral is 2 pi times the integrand
            return 3 * z ** 3 / (r * r + z * z) ** 2.5 * r / (2 * np.pi * a * np.sqrt(a + r))
    return 1e6 * integrate.quad(ring, 0, a, weight="alg", wvar=(0, -0.5), epsabs=0, epsrel=1e-10)[0]


# --- closed forms --------------------------------------------------------------------------------------------------

@SKINS
@pytest.mark.parametrize("a,delta", [(0.25, 0.1), (0.5, 0.5), (2.0, 1.5)])
def test_one_pin_follows_the_flat_punch_law(skin, a, delta):
    p = solve_pin_loads([[delta]], [0.0], [0.0], a, skin)
    assert p[0, 0] == pytest.approx(2 * a * _e_star(skin) * delta, rel=1e-12)


@pytest.mark.parametrize("a", [0.25, 0.5, 2.0])
@pytest.mark.parametrize("z", [0.3, 1.0, 2.0])
def test_axial_stress_matches_the_closed_form_and_boussinesq_quadrature(a, z):
    k = stress_kernel([0.0], [0.0], a, [0.0], [0.0], z)[0, 0]
    assert k == pytest.approx(_axial_closed_form(a, z), rel=1e-12)
    assert k == pytest.approx(_boussinesq(0.0, z, a), rel=1e-6)


@pytest.mark.parametrize("s,z", [(0.25, 0.25), (0.5, 0.15), (1.0, 0.5), (2.0, 1.6)])
def test_off_axis_stress_matches_boussinesq_quadrature(s, z):
    a = 0.5
    k = stress_kernel([0.0], [0.0], a, [s * np.cos(1.0)], [s * np.sin(1.0)], z)[0, 0]
    assert k == pytest.approx(_boussinesq(s, z, a), rel=1e-5)


def test_stress_is_continuous_off_axis_and_across_the_punch_edge():
    a, z = 0.5, 0.1
    r = np.linspace(0.0, 3 * a, 30001)
    k = stress_kernel([0.0], [0.0], a, r, 0 * r, z)[0]
    assert np.all(np.isfinite(k)) and np.all(k > 0)
    assert np.max(np.abs(np.diff(k))) < 2e-3 * k.max()
    edge = stress_kernel([0.0], [0.0], a, [a * (1 - 1e-9), a, a * (1 + 1e-9)], [0, 0, 0], z)[0]
    assert np.ptp(edge) < 1e-6 * edge.max()


def test_stress_near_the_surface_is_the_punch_pressure_and_balances_the_load():
    a, r = 0.5, np.array([0.0, 0.2, 0.4])
    near = stress_kernel([0.0], [0.0], a, r, 0 * r, 1e-7)[0]
    np.testing.assert_allclose(near, 1e6 / (2 * np.pi * a * np.sqrt(a * a - r * r)), rtol=1e-5)
    for z in (0.2, 1.0):
        def ring(s, z=z):
            return stress_kernel([0.0], [0.0], a, [s], [0.0], z)[0, 0] * 2 * np.pi * s
        total = integrate.quad(ring, 0, np.inf, limit=200)[0]
        assert total * 1e-6 == pytest.approx(1.0, rel=1e-6)  # Pa mm^2 per newton -> N


def test_normal_stress_is_loads_times_the_kernel():
    px, py, x, y, z = [0.0, 3.0], [0.0, 0.0], [0.0, 1.0, 3.0], [0.5, 0.0, 0.0], [0.3, 0.7, 2.0]
    loads = np.array([[0.1, 0.0], [0.05, 0.2]])
    kernel = stress_kernel(px, py, 0.5, x, y, z)
    np.testing.assert_allclose(normal_stress(loads, px, py, 0.5, x, y, z), loads @ kernel, rtol=1e-14)


# --- contact --------------------------------------------------------------------------------------------------------

def test_two_pins_far_apart_behave_as_one_each_and_close_pins_share_the_load():
    one = solve_pin_loads([[0.5]], [0.0], [0.0], 0.5, DEFAULT)[0, 0]
    far = solve_pin_loads([[0.5, 0.5]], [0.0, 200.0], [0.0, 0.0], 0.5, DEFAULT)[0]
    np.testing.assert_allclose(far, one, rtol=2e-3)
    close = solve_pin_loads([[0.5, 0.5]], [0.0, 1.2], [0.0, 0.0], 0.5, DEFAULT)[0]
    assert close[0] == pytest.approx(close[1], rel=1e-12) and close.sum() < 0.8 * 2 * one


def test_a_pin_pressed_less_than_its_neighbours_deflection_carries_nothing():
    x, y = [0.0, 1.5], [0.0, 0.0]
    c = pin_compliance(x, y, 0.5, DEFAULT)
    p0 = solve_pin_loads([[0.5, 0.0]], x, y, 0.5, DEFAULT)[0, 0]
    w = c[1, 0] * p0  # the skin under pin 1, pressed down by pin 0 alone
    loads = solve_pin_loads([[0.5, 0.999 * w], [0.5, 1.001 * w]], x, y, 0.5, DEFAULT)
    assert loads[0, 1] == 0.0 and loads[0, 0] == pytest.approx(p0, rel=1e-12)
    assert 0 < loads[1, 1] < 1e-3 * p0 and loads[1, 0] < p0


def test_grouping_by_contact_pattern_equals_solving_each_sample_alone():
    rng = np.random.default_rng(7)
    gx, gy = np.meshgrid(np.arange(4) * 1.3, np.arange(4) * 1.3)
    x, y = gx.ravel(), gy.ravel()
    base = np.clip(rng.normal(0.2, 0.3, (12, 16)), 0, None)
    depth = np.repeat(base, 5, axis=0) * rng.uniform(0.5, 1.5, (60, 1))  # shared patterns, distinct depths
    together = solve_pin_loads(depth, x, y, 0.5, DEFAULT)
    alone = np.vstack([solve_pin_loads(row[None], x, y, 0.5, DEFAULT) for row in depth])
    assert (together == 0).sum() > (depth == 0).sum()  # some pins were dropped on the way
    np.testing.assert_allclose(together, alone, rtol=0, atol=1e-12 * together.max())


def _letter_scan_contact(duration_s):
    """(depth, compliance) of "A" scanned pressed by its base (every pin touching, a few hundred in contact)."""
    pins, depth, _ = scan_depths(letters("A"), duration_s=duration_s, contact_mm=0.8, window_mm=(6.0, 6.0),
                                 pitch_mm=0.25)
    a = effective_radius(pins.x_mm, pins.y_mm, pins.radius_mm, DEFAULT)
    return depth, pin_compliance(pins.x_mm, pins.y_mm, a, DEFAULT)


def test_a_scan_updating_its_contact_set_gives_the_loads_solved_afresh(monkeypatch):
    depth, c = _letter_scan_contact(0.3)
    updated = kernels.contact_loads(depth, c)
    monkeypatch.setattr(kernels, "_REBUILD_AFTER", 0)  # every change of the set: a new inverse
    fresh = kernels.contact_loads(depth, c)
    in_contact = updated > 0
    assert (depth > 0).all() and (in_contact[1:] != in_contact[:-1]).sum() > 1000  # every pin touches, many pull free
    np.testing.assert_allclose(updated, fresh, rtol=0, atol=1e-13 * fresh.max())  # no drift over the updates
    assert np.all(updated >= 0) and np.all(updated @ c >= depth - 1e-12)  # no pin out of contact sinks


def test_an_inverse_gone_wrong_is_computed_afresh(monkeypatch):
    # Updates let rounding errors grow; fault injection: every pin added leaves the inverse 1% off.
    depth, c = _letter_scan_contact(0.05)
    exact = kernels.contact_loads(depth, c)
    add = kernels._ContactInverse._add

    def drifting_add(self, join):
        add(self, join)
        self.inverse *= 1.01

    monkeypatch.setattr(kernels._ContactInverse, "_add", drifting_add)
    np.testing.assert_allclose(kernels.contact_loads(depth, c), exact, rtol=0, atol=1e-13 * exact.max())


def test_a_sample_that_does_not_settle_is_solved_by_dropping_pins(monkeypatch):
    depth, c = _letter_scan_contact(0.02)
    settled = kernels.contact_loads(depth, c)
    monkeypatch.setattr(kernels, "_MAX_ROUNDS", 0)
    np.testing.assert_allclose(kernels.contact_loads(depth, c), settled, rtol=0, atol=1e-13 * settled.max())


def test_a_pin_dropped_on_the_way_comes_back_when_the_skin_would_rise_through_it():
    # Dropping the pins that pull, alone, ends here with pin 1 below the skin (0.11 mm): pin 0's load alone
    # leaves the skin above pin 1 once pin 2 is dropped.  Shared by _SHARED samples, then a sample alone.
    c = np.array([[1.0, 0.44, 0.87], [0.44, 1.0, 0.26], [0.87, 0.26, 1.0]])
    depth = np.repeat([[0.75, 0.44, 0.21]], kernels._SHARED, axis=0)
    for rows in (depth, depth[:1]):
        loads = kernels.contact_loads(rows, c)
        np.testing.assert_allclose(loads[0], [0.68998016, 0.13640873, 0.0], rtol=1e-7)
        assert np.all(loads @ c >= rows - 1e-12) and np.all(loads == loads[0])


def test_box_average_holds_a_constant_and_zeroes_each_multiple_of_its_inverse_length():
    fs, length = 5000.0, 1.0 / 160.0  # 31.25 samples: a fractional window
    t = np.arange(5000) / fs
    assert np.allclose(kernels.box_average(np.full((50, 2), 3.0), fs, length), 3.0, rtol=0, atol=1e-12)
    for f, gain in [(160.0, 0.0), (320.0, 0.0), (40.0, np.sinc(0.25)), (80.0, np.sinc(0.5))]:
        out = kernels.box_average(np.sin(2 * np.pi * f * t)[:, None], fs, length)[500:-500, 0]
        assert np.abs(out).max() == pytest.approx(gain, abs=2e-4, rel=5e-3)  # the samples joined by lines: ~0.2% less
    values = np.arange(6.0)[:, None]
    np.testing.assert_array_equal(kernels.box_average(values, fs, 0.5 / fs), values)  # under one sample: as it was
    wide = np.random.default_rng(0).normal(size=(300, 2 * kernels._BOX_COLUMNS + 3))  # three blocks of columns
    apart = kernels.box_average(wide, fs, length)
    np.testing.assert_array_equal(kernels.box_average(wide, fs, length, out=wide), apart)  # in place, block by block


@settings(max_examples=40, deadline=None)
@given(seed=st.integers(0, 2 ** 32 - 1), spacing=st.floats(1.0, 2.5), n_samples=st.integers(2, 30))
def test_a_sequence_solved_in_turn_equals_each_sample_solved_alone(seed, spacing, n_samples):
    # A random walk of depths on a 4 x 4 grid: sets of pins in contact change from sample to sample and are
    # too few to share, so every sample after the first starts from the one before's and updates its inverse.
    rng = np.random.default_rng(seed)
    gx, gy = np.meshgrid(np.arange(4) * spacing, np.arange(4) * spacing)
    x, y = gx.ravel(), gy.ravel()
    depth = np.clip(0.3 + np.cumsum(rng.normal(0.0, 0.08, (n_samples, 16)), axis=0), 0.0, None)
    together = solve_pin_loads(depth, x, y, 0.5, DEFAULT)
    alone = np.vstack([solve_pin_loads(row[None], x, y, 0.5, DEFAULT) for row in depth])
    np.testing.assert_allclose(together, alone, rtol=0, atol=1e-12 * max(alone.max(), 1e-300))
    assert np.all(together >= 0) and np.all(together @ pin_compliance(x, y, 0.5, DEFAULT) >= depth - 1e-12)


_GRID = np.stack(np.meshgrid(np.arange(3.0), np.arange(3.0)), axis=-1).reshape(-1, 2)


@given(spacing=st.floats(1.0, 4.0), depths=st.lists(st.floats(0.0, 1.0), min_size=9, max_size=9),
       lift=st.floats(1e-3, 0.5), touchsim=st.booleans())
def test_loads_are_never_negative_and_grow_with_a_uniform_push(spacing, depths, lift, touchsim):
    skin, (x, y) = TOUCHSIM if touchsim else DEFAULT, (_GRID * spacing).T
    depth = np.array([depths, np.array(depths) + lift])
    loads = solve_pin_loads(depth, x, y, 0.5, skin)
    assert np.all(loads >= 0) and np.all(loads[1] >= loads[0] - 1e-12)
    deflection = loads @ pin_compliance(x, y, 0.5, skin)  # no pin sinks below the skin's surface
    assert np.all(deflection >= depth - 1e-12)


@SKINS
def test_pin_radius_is_capped_by_touchsim_and_kept_by_default(skin):
    x, y = [0.0, 1.0, 5.0], [0.0, 0.0, 0.0]
    if skin.cap_pin_radius:
        assert effective_radius(x, y, 0.8, skin) == 0.5 and effective_radius(x, y, 0.3, skin) == 0.3
    else:
        assert effective_radius(x, y, 0.5, skin) == 0.5  # touching pins are allowed
        with pytest.raises(ValueError, match=r"pins 0 and 1 overlap: centres 1.0 mm apart, less than 2 \* radius_mm"):
            effective_radius(x, y, 0.8, skin)
    assert effective_radius([2.0], [3.0], 7.0, skin) == 7.0


# TouchSim's transduction (github.com/hsaal/touchsim, commit 4ec9f5c), run on this machine: three pins at
# (0, 0), (1.5, 0), (0, 2) mm, radius 0.9 mm (capped to 0.75), these depths (mm) at 1 kHz, receptors at (0.5, 0.5),
# (2, 1), (-1, 3) mm at depths 0.3, 1.6, 2.0 mm.  Loads in N, static stress in MPa, its dynamic term in N/(mm^3 s).
_TS_DEPTH = [[0.5, 0.3, 0.0], [0.6, 0.3, 0.05], [0.7, 0.35, 0.1], [0.6, 0.4, 0.2], [0.5, 0.1, 0.3]]
_TS_LOADS = [[0.040178571429, 0.013392857143, 0.0], [0.050223214286, 0.010044642857, 0.0],
             [0.05859375, 0.01171875, 0.0], [0.046330390671, 0.019749309158, 0.002688580421],
             [0.040514204555, 0.0, 0.016871297447]]
_TS_STATIC = [[0.015162527336, 0.001515479205, 0.000265259451], [0.018723062348, 0.001428661904, 0.00031443154],
              [0.021843572739, 0.001666772221, 0.000366836797], [0.01764010387, 0.002086042746, 0.000434964378],
              [0.014875720318, 0.000834254615, 0.000973797697]]
_TS_DYNAMIC = [[65.30186185782, 0.420081501507, 0.216770625856], [65.30186185782, 0.420081501507, 0.216770625856],
               [5.540685642937, 0.557380613416, 0.129776423078],
               [-67.618884909913, -0.74854516558, 0.150506045316], [-67.618884909913, -0.74854516558, 0.150506045316]]
# One pin (radius 0.5 mm) at 40 kHz, depth 0.3 + 0.1 sin(2 pi 2000 t) mm, receptors at (0.3, 0), (1.5, 0), (2.5, 0),
# (0, 1.64) mm, depths 0.3, 0.3, 2.0, 1.0 mm: the wave reaches them 0, 5, 10 and 5.7 (rounded: 6) samples late.
_TS_WAVE = [[777.493719964, 0.0, 0.0, 0.0], [777.493719964, 0.0, 0.0, 0.0], [661.375661376, 0.0, 0.0, 0.0],
            [480.517544977, 0.0, 0.0, 0.0], [252.623023314, 0.0, 0.0, 0.0], [0.0, 168.208352926, 0.0, 0.0],
            [-252.623023314, 168.208352926, 0.0, 13.801156658], [-480.517544977, 143.086571388, 0.0, 13.801156658],
            [-661.375661376, 103.9584793, 0.0, 11.739965067], [-777.493719964, 54.654206937, 0.0, 8.529583899],
            [-817.505276124, 0.0, 2.242478299, 4.484267629], [-817.505276124, -54.654206937, 2.242478299, 0.0]]


def test_touchsim_skin_reproduces_touchsims_transduction():
    px, py, x, y, z = [0.0, 1.5, 0.0], [0.0, 0.0, 2.0], [0.5, 2.0, -1.0], [0.5, 1.0, 3.0], [0.3, 1.6, 2.0]
    loads = solve_pin_loads(_TS_DEPTH, px, py, 0.9, TOUCHSIM)
    np.testing.assert_allclose(loads, _TS_LOADS, rtol=1e-9, atol=1e-12)
    a = effective_radius(px, py, 0.9, TOUCHSIM)
    np.testing.assert_allclose(normal_stress(loads, px, py, a, x, y, z) * 1e-6, _TS_STATIC, rtol=1e-9)
    dynamic = dynamic_stress(loads, px, py, 0.9, x, y, z, 1000.0, TOUCHSIM) * 1e-6
    np.testing.assert_allclose(dynamic, _TS_DYNAMIC, rtol=1e-9)
    t = np.arange(12) / 40e3
    one = solve_pin_loads((0.3 + 0.1 * np.sin(2 * np.pi * 2000 * t))[:, None], [0.0], [0.0], 0.5, TOUCHSIM)
    wave = dynamic_stress(one, [0.0], [0.0], 0.5, [0.3, 1.5, 2.5, 0], [0, 0, 0, 1.64], [0.3, 0.3, 2.0, 1.0], 40e3,
                          TOUCHSIM)
    np.testing.assert_allclose(wave * 1e-6, _TS_WAVE, rtol=1e-8, atol=1e-8)


def test_derivative_dynamics_is_the_static_stress_rate():
    t = np.arange(50) / 1000.0
    depth = np.c_[0.4 + 0.1 * np.sin(2 * np.pi * 7 * t), 0.3 * t]
    args = ([0.0, 2.0], [0.0, 0.0], 0.5, [0.0, 1.0, 4.0], [0.0, 0.5, 0.0], [0.5, 0.7, 2.0])
    loads = solve_pin_loads(depth, *args[:3], DEFAULT)
    static = normal_stress(loads, *args)
    np.testing.assert_allclose(dynamic_stress(loads, *args, 1000.0, DEFAULT), np.gradient(static, 1e-3, axis=0),
                               rtol=1e-10, atol=1e-10 * np.abs(static).max())
    assert not dynamic_stress(loads[:1], *args, 1000.0, DEFAULT).any()  # one sample has no rate


# --- tangential ------------------------------------------------------------------------------------------------------

def _drag(path_x, normal=0.1, skin=DEFAULT):
    u = np.zeros((len(path_x), 1, 2))
    u[:, 0, 0] = path_x
    p = np.broadcast_to(np.asarray(normal, float).reshape(-1, 1), (len(path_x), 1))
    return tangential_loads(u, p, 0.5, skin)[:, 0]


def test_a_pin_sticks_below_the_friction_limit_then_slips_then_reverses():
    k, limit = DEFAULT.tangential_stiffness(0.5), DEFAULT.friction * 0.1
    assert k == pytest.approx(8 * (0.05 / 3.0) * 0.5 / 1.5)  # 8 G a / (2 - nu), G = E / (2 (1 + nu))
    q = _drag([0.0, 0.5, 1.0, 3.0, 2.5, 0.0])
    np.testing.assert_allclose(q[:3, 0], k * np.array([0.0, 0.5, 1.0]))  # stuck: Q = k_t u
    assert np.hypot(*q[3]) == pytest.approx(limit) and q[3, 1] == 0  # slipped at mu P
    assert q[4, 0] == pytest.approx(limit - k * 0.5)  # reversal: stuck again from the slipped anchor
    assert q[5, 0] == pytest.approx(-limit)  # and slips the other way


def test_a_lifted_pin_carries_nothing_and_resets_its_anchor():
    q = _drag([0.0, 0.5, 1.0, 1.5], normal=[0.1, 0.1, 0.0, 0.1])
    assert q[1, 0] > 0 and not q[2].any() and q[3, 0] == pytest.approx(DEFAULT.tangential_stiffness(0.5) * 0.5)
    frictionless = dataclasses.replace(DEFAULT, friction=0.0)
    assert not _drag([0.0, 0.5, 1.0], skin=frictionless).any()


def test_slip_follows_the_direction_of_travel_in_the_plane():
    u = np.zeros((3, 2, 2))
    u[:, 0] = [[0, 0], [3, 4], [6, 8]]
    u[:, 1] = [[0, 0], [0, -0.01], [0, -0.02]]
    q = tangential_loads(u, np.full((3, 2), 0.2), 0.5, TOUCHSIM)
    np.testing.assert_allclose(q[2, 0], 0.5 * 0.2 * np.array([0.6, 0.8]))
    np.testing.assert_allclose(q[2, 1], [0.0, -TOUCHSIM.tangential_stiffness(0.5) * 0.02])


# --- the skins and the refusals --------------------------------------------------------------------------------------

def test_the_named_skins_hold_their_constants():
    assert set(SKIN_MODELS) == {"touchsim", "default"}
    assert (TOUCHSIM.youngs_modulus_pa, TOUCHSIM.poisson, TOUCHSIM.wave_speed_mm_s) == (50e3, 0.4, 8000.0)
    assert dict(TOUCHSIM.receptor_depth_mm) == {"SAI": 0.3, "RAI": 1.6, "RAII": 2.0, "SAII": 1.0}
    assert DEFAULT.receptor_depth_mm == ()  # the registry's depths
    assert {t: DEFAULT.depth_mm(t) for t in ("SAI", "RAI", "RAII", "SAII")} == {"SAI": 0.5, "RAI": 0.7, "RAII": 2.0,
                                                                               "SAII": 1.0}
    assert (DEFAULT.poisson, DEFAULT.dynamic, DEFAULT.cap_pin_radius) == (0.5, "derivative", False)


def _skin(**change):
    return lambda: dataclasses.replace(DEFAULT, **change)


_P = ([0.0, 2.0], [0.0, 0.0])  # two pins
_PT = ([0.0], [1.0], [0.5])  # one point


@pytest.mark.parametrize("call,error,match", [
    (lambda: solve_pin_loads([[0.1, -0.2]], *_P, 0.5, DEFAULT), ValueError,
     r"depth_mm must be >= 0 mm \(into the skin\); got -0.2 at sample 0, pin 1"),
    (lambda: solve_pin_loads([[0.1, np.nan]], *_P, 0.5, DEFAULT), ValueError, "depth_mm must be finite; got nan"),
    (lambda: solve_pin_loads([[0.1, 0.2, 0.3]], *_P, 0.5, DEFAULT), ValueError,
     r"depth_mm must have one column per pin \(2\), got shape \(1, 3\)"),
    (lambda: solve_pin_loads([0.1, 0.2], *_P, 0.5, DEFAULT), ValueError, "depth_mm must be 2-D"),
    (lambda: solve_pin_loads([[0.1, 0.2]], *_P, 0.0, DEFAULT), ValueError, "radius_mm must be a finite number > 0 mm"),
    (lambda: solve_pin_loads([[0.1, 0.2]], *_P, -1, DEFAULT), ValueError, "radius_mm .* got -1.0"),
    (lambda: solve_pin_loads([[0.1, 0.2]], [0.0, np.inf], [0, 0], 0.5, DEFAULT), ValueError,
     "pin x_mm must be finite; got inf at flat index 1"),
    (lambda: solve_pin_loads([[0.1, 0.2]], [0.0, 2.0], [0.0], 0.5, DEFAULT), ValueError,
     "pin x_mm and y_mm must be non-empty and of equal length; got 2 and 1"),
    (lambda: solve_pin_loads([[0.1, 0.2]], [0.0, 0.8], [0, 0], 0.5, DEFAULT), ValueError,
     r"pins 0 and 1 overlap: centres 0.8 mm apart, less than 2 \* radius_mm = 1.0 mm"),
    (lambda: solve_pin_loads([[0.1, 0.2]], [1.0, 1.0], [2, 2], 0.5, TOUCHSIM), ValueError,
     r"pins 0 and 1 coincide at \(1.0, 2.0\) mm"),
    (lambda: solve_pin_loads([[0.1, 0.2]], *_P, 0.5, "default"), TypeError, "skin must be a SkinMechanics"),
    (lambda: stress_kernel(*_P, 0.5, [0.0, 1.0], [0.0, 0.0], [0.5, 0.0]), ValueError,
     r"depth_mm must be > 0 mm \(a receptor under the surface\); got 0.0 at point 1"),
    (lambda: stress_kernel(*_P, 0.5, [0.0], [0.0], -0.3), ValueError, "depth_mm must be > 0 mm .*got -0.3 at point 0"),
    (lambda: stress_kernel(*_P, 0.5, [0.0, 1.0], [0.0, 0.0], [0.5, 0.5, 0.5]), ValueError,
     r"depth_mm must be one number or one per point \(2\), got shape \(3,\)"),
    (lambda: stress_kernel(*_P, 0.5, [0.0, 1.0], [0.0], 0.5), ValueError,
     "point x_mm and y_mm must be non-empty and of equal length"),
    (lambda: stress_kernel(*_P, 0.0, *_PT), ValueError, "radius_mm must be a finite number > 0 mm, got 0.0"),
    (lambda: normal_stress([[0.1]], *_P, 0.5, *_PT), ValueError, r"loads must have one column per pin \(2\)"),
    (lambda: normal_stress([[0.1, -0.01]], *_P, 0.5, *_PT), ValueError,
     r"loads must be >= 0 N \(a pin cannot pull\); got -0.01 at sample 0, pin 1"),
    (lambda: dynamic_stress([[0.1, 0.1]], *_P, 0.5, *_PT, 0.0, DEFAULT), ValueError, "fs must be a finite number > 0"),
    (lambda: tangential_loads(np.zeros((2, 2, 3)), np.zeros((2, 2)), 0.5, DEFAULT), ValueError,
     r"lateral_mm must have shape \(n_samples, n_pins, 2\) matching loads \(2, 2\), got \(2, 2, 3\)"),
    (lambda: tangential_loads(np.zeros((3, 2, 2)), np.zeros((2, 2)), 0.5, DEFAULT), ValueError,
     "lateral_mm must have shape"),
    (lambda: tangential_loads(np.zeros((2, 2, 2)), -np.ones((2, 2)), 0.5, DEFAULT), ValueError, "loads must be >= 0"),
    (lambda: tangential_loads(np.zeros((2, 2, 2)), np.zeros((2, 2)), 0.0, DEFAULT), ValueError, "radius_mm must be"),
    (_skin(youngs_modulus_pa=0.0), ValueError, "youngs_modulus_pa must be a finite number > 0 Pa, got 0.0"),
    (_skin(youngs_modulus_pa=-5e3), ValueError, "youngs_modulus_pa .* got -5000.0"),
    (_skin(poisson=0.6), ValueError, r"poisson must be in \[0, 0.5\] \(0.5: incompressible skin\), got 0.6"),
    (_skin(poisson=-0.1), ValueError, r"poisson must be in \[0, 0.5\].*got -0.1"),
    (_skin(poisson="0.4"), TypeError, "poisson must be a real number, got str"),
    (_skin(poisson=np.nan), ValueError, "poisson must be a finite number, got nan"),
    (_skin(friction=-0.2), ValueError, "friction must be a finite number >= 0, got -0.2"),
    (_skin(friction=np.inf), ValueError, "friction must be a finite number, got inf"),
    (_skin(cap_pin_radius=1), TypeError, "cap_pin_radius must be a bool, got int"),
    (_skin(receptor_depth_mm=None), ValueError, "receptor_depth_mm must be .type code, depth mm. pairs, got None"),
    (_skin(dynamic="wave"), ValueError, "dynamic='wave' is not allowed; allowed: derivative, surface_wave"),
    (_skin(dynamic="surface_wave"), TypeError, "wave_speed_mm_s must be a real number, got NoneType"),
    (_skin(wave_speed_mm_s=8000.0), ValueError, "wave_speed_mm_s must be None for dynamic='derivative', got 8000.0"),
    (_skin(receptor_depth_mm=(("SAI", 0.0),)), ValueError, r"receptor_depth_mm\['SAI'\] must be a finite number > 0"),
    (_skin(receptor_depth_mm=(("SAI", 1.0), ("SAI", 2.0))), ValueError, "unique codes"),
    (lambda: get_skin_mechanics("soft"), ValueError, "skin='soft' is not allowed; allowed: touchsim, default"),
    (lambda: DEFAULT.depth_mm("PC"), ValueError, "afferent_type='PC' is not an afferent type; allowed: SAI, RAI"),
])
def test_bad_input_is_refused_by_name(call, error, match):
    with pytest.raises(error, match=match):
        call()


def test_no_samples_give_empty_results():
    assert solve_pin_loads(np.zeros((0, 2)), *_P, 0.5, DEFAULT).shape == (0, 2)
    assert tangential_loads(np.zeros((0, 2, 2)), np.zeros((0, 2)), 0.5, DEFAULT).shape == (0, 2, 2)
    assert normal_stress(np.zeros((0, 2)), *_P, 0.5, *_PT).shape == (0, 1)


def test_a_custom_skin_is_a_frozen_dataclass():
    skin = SkinMechanics("stiff", 2e5, 0.45, 1.0, "derivative", None, False, (("SAI", 0.5),))
    with pytest.raises(dataclasses.FrozenInstanceError):
        skin.poisson = 0.3
    assert solve_pin_loads([[0.1]], [0.0], [0.0], 1.0, skin)[0, 0] == pytest.approx(2 * 1.0 * _e_star(skin) * 0.1)
