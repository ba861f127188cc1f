"""The ``"touchsim"`` skin against TouchSim's own figures (`tests/population/data/touchsim_mechanics.json`).

The figures were recorded by running TouchSim (Saal et al. 2017; public repository, commit 4ec9f5c) on this
machine with `experiments/validation/touchsim_reference.py`, on TouchSim's standard stimuli: a ramp on one
pin, a sinusoid on one pin, a two-pin indentation and a 2 x 2 array whose radius TouchSim caps and one of
whose pins loses contact.  Each stimulus is rebuilt here from its recorded description; the pin loads, the
static stress and the dynamic component at SA1, RA and PC depths must match within 2%.
"""

import json
from pathlib import Path

import numpy as np
import pytest

from ddmm.population.stimuli.contact import (
    dynamic_stress,
    effective_radius,
    get_skin_mechanics,
    normal_stress,
    solve_pin_loads,
)

FIXTURE = json.loads((Path(__file__).parent / "data" / "touchsim_mechanics.json").read_text())
SKIN = get_skin_mechanics("touchsim")
CLASSES = {"SA1": 0.3, "RA": 1.6, "PC": 2.0}  # TouchSim's receptor depths (mm), as its classes name them


def _ramped(n: int, k: int) -> np.ndarray:
    """TouchSim's linear on and off ramps of k samples over n samples (its stimulus definition)."""
    env = np.ones(n)
    env[:k] *= np.linspace(0.0, 1.0, k)
    env[n - k:] *= np.linspace(1.0, 0.0, k)
    return env


def _trace(name: str) -> np.ndarray:
    """(n_samples, n_pins) depths in mm of the recorded stimulus ``name``, rebuilt from its description."""
    stim = FIXTURE["stimuli"][name]
    n = stim["n_samples"]
    if name == "ramp":
        return (0.5 * _ramped(n, 500))[:, None]
    if name == "sine":
        wave = 0.1 * np.sin(np.linspace(0.0, 2.0 * np.pi * 50.0 * 0.2, n)) * _ramped(n, 250)
        return (wave + 0.3)[:, None]
    i = np.arange(n)
    shape = np.where(i < 500, i / 499.0, 1.0)
    return shape[:, None] * np.asarray(stim["stimulus"]["depths_mm"])[None, :]


def _close(got, expected, what):
    got, expected = np.asarray(got, dtype=float), np.asarray(expected, dtype=float)
    scale = np.abs(expected).max()
    bad = np.abs(got - expected) > 0.02 * np.abs(expected) + 1e-9 * scale
    assert not bad.any(), f"{what}: {got[bad][:3]} against TouchSim's {expected[bad][:3]}"


@pytest.mark.parametrize("name", ["ramp", "sine", "two_pins", "four_pins"])
def test_the_touchsim_skin_gives_touchsims_loads_and_stresses(name):
    stim = FIXTURE["stimuli"][name]
    pins = np.asarray(stim["pin_locations_mm"], dtype=float)
    depth, idx, fs = _trace(name), np.asarray(stim["samples"]["indices"]), stim["fs"]
    np.testing.assert_allclose(depth[idx].T, stim["trace_mm"], rtol=1e-12, atol=1e-15)  # the same stimulus
    radius = effective_radius(pins[:, 0], pins[:, 1], 0.5, SKIN)
    assert radius == stim["pin_radius_used_mm"]
    loads = solve_pin_loads(depth, pins[:, 0], pins[:, 1], 0.5, SKIN)
    _close(loads[idx].T, stim["profile_N"], f"{name} pin loads (N)")
    x = np.asarray(FIXTURE["afferents"]["x_mm"], dtype=float)
    for cls, z in CLASSES.items():
        static = normal_stress(loads, pins[:, 0], pins[:, 1], radius, x, np.zeros_like(x), z)
        _close(static[idx].T * 1e-6, stim["stat_comp"][cls], f"{name} {cls} static stress (MPa)")
        dyn = dynamic_stress(loads, pins[:, 0], pins[:, 1], 0.5, x, np.zeros_like(x), z, fs, SKIN)
        _close(dyn[idx].T * 1e-6, stim["dyn_comp"][cls], f"{name} {cls} dynamic component")


def test_the_fixture_names_touchsims_commit_and_constants():
    assert FIXTURE["touchsim"]["commit"].startswith("4ec9f5c")
    assert (SKIN.modulus_n_mm2, SKIN.poisson) == (FIXTURE["touchsim"]["E"], FIXTURE["touchsim"]["nu"])
