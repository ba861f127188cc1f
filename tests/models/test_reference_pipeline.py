"""The reference oracle (`ddmm.models.reference_pipeline`) against the one production path: the same bits,
the same state, and no production caller."""

import subprocess
import sys
import warnings

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from ddmm.models import reference_pipeline
from ddmm.models.afferent_types import afferent_type_codes
from ddmm.models.fused import AfferentColumns, FusedPipeline
from ddmm.models.pipeline import compute_currents
from ddmm.models.reference_pipeline import afferent_current, reference_currents, shear_drive, stretch_drive
from ddmm.population import load_spec

FS = 1000.0
PHYSIO = load_spec("fingertip").current.with_all_types(bias_cv=0.0)  # ids key the tonic spread: none here
THETA, K = np.array([0.0, 45.0, 90.0, 200.0, 300.0]), np.array([2.0, 3.0, 5.0, 2.0, 8.0])
MIXED = ["SAII", "SAI", "RAII", "RAI", "SAI"]


def _forces(seed, n=400):
    """A press with a wandering shear that crosses F_TH both ways (N)."""
    rng = np.random.default_rng(seed)
    t = np.arange(n) / FS
    fz = np.maximum(np.interp(t, [0, 0.08, 0.3, 0.38], [0, 3, 3, 0]) + 0.02 * rng.standard_normal(n).cumsum(), 0.0)
    fx = 0.3 * np.sin(2 * np.pi * 3 * t + rng.uniform(0, 6)) * (fz > 0)
    fy = 0.2 * np.cos(2 * np.pi * 5 * t) + 0.01 * rng.standard_normal(n)
    return fx, fy, fz


@pytest.mark.parametrize("profile", ["selective", "broad", "bipolar", "none"])
@pytest.mark.parametrize("no_shear", ["pass", "block", "smooth"])
@pytest.mark.parametrize("params", [None, PHYSIO], ids=["paper", "fingertip"])
def test_production_currents_equal_the_oracle(profile, no_shear, params):
    kwargs = dict(fs=FS, afferent_type=MIXED, profile=profile, theta_t=THETA, k=K, no_shear=no_shear)
    if params is not None:
        kwargs["current_params"] = params
    fx, fy, fz = _forces(0)
    np.testing.assert_array_equal(compute_currents(fx, fy, fz, **kwargs), reference_currents(fx, fy, fz, **kwargs))


@settings(max_examples=15, deadline=None)
@given(seed=st.integers(0, 2**16), kind=st.sampled_from(["SAI", "RAI", "RAII", "SAII"]),
       theta=st.floats(0.0, 359.0))
def test_production_equals_the_oracle_on_any_press(seed, kind, theta):
    fx, fy, fz = _forces(seed, 250)
    kwargs = dict(fs=FS, afferent_type=kind, profile="selective", theta_t=[theta], current_params=PHYSIO,
                  no_shear="smooth")
    np.testing.assert_array_equal(compute_currents(fx, fy, fz, **kwargs), reference_currents(fx, fy, fz, **kwargs))


@pytest.mark.parametrize("kind", afferent_type_codes(lambda t: t.code in ("SAI", "RAI", "RAII", "SAII")))
def test_one_state_format(kind):
    """After the same chunk, the oracle's filter state and a one-type pipeline's hold the same numbers."""
    fx, fy, fz = _forces(3, 300)
    stage = PHYSIO.for_type(kind)
    pipe = FusedPipeline(AfferentColumns.filled([kind, kind]), PHYSIO, FS)
    state = pipe.new_state()
    current = pipe.currents(np.column_stack([fx, fy, fz]), state, False)
    untuned = np.ones((fz.size, 2))
    drive = (stretch_drive(fx, fy, untuned, stage.opponent, fz, stage.normal) if stage.signed
             else shear_drive(np.column_stack([fz, fz]), fx, fy, untuned, stage.shear, stage.opponent_shear))
    expected, oracle_state = afferent_current(drive, FS, kind, PHYSIO)
    np.testing.assert_array_equal(current, expected)
    assert oracle_state.shape == state.shape
    np.testing.assert_array_equal(oracle_state, state)


@pytest.mark.parametrize(("module", "name"), [("attenuation", "attenuated_force"), ("attenuation", "shear_drive"),
                                              ("attenuation", "stretch_drive"), ("currents", "afferent_current"),
                                              ("currents", "current_core"), ("current_filters", "filter_force"),
                                              ("current_filters", "initial_filter_state")])
def test_old_homes_warn_and_lead_to_the_oracle(module, name):
    import importlib

    old = importlib.import_module(f"ddmm.models.{module}")
    with warnings.catch_warnings(record=True) as caught:
        warnings.simplefilter("always")
        found = getattr(old, name)
    assert found is getattr(reference_pipeline, name)
    assert [w.category for w in caught] == [DeprecationWarning]
    assert "ddmm.models.reference_pipeline" in str(caught[0].message)


def test_filter_state_record_is_gone_with_a_pointer():
    from ddmm.models import current_filters

    with pytest.raises(AttributeError, match="rest_state"):
        current_filters.FilterState  # noqa: B018


def test_no_production_path_imports_the_oracle():
    """`simulate`, `compute_currents` and the paper's reproductions run without loading the oracle."""
    code = (
        "import sys, numpy as np\n"
        "from ddmm.population import birznieks, sample_population, simulate\n"
        "from ddmm.models import compute_currents\n"
        "from ddmm.experiments.paper.reproduce import ReproConfig, reproduce_all\n"
        "pop = sample_population('fingertip', rng=0).select(range(0, 991, 50))\n"
        "simulate(pop, birznieks(90.0), engine='direct', seed=0, quiet=True)\n"
        "compute_currents(np.zeros(50), np.zeros(50), np.ones(50), fs=1000.0, afferent_type='RAI')\n"
        "print('ddmm.models.reference_pipeline' in sys.modules)\n"
    )
    out = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, check=True)
    assert out.stdout.strip() == "False"
