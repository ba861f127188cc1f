"""The fused pipeline (`ddmm.models.fused`) against the per-stage functions it fuses: the same bits."""

import dataclasses

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from ddmm.models.attenuation import UNTUNED, attenuation_factor, profile_factor
from ddmm.models.currents import CurrentParams, excitability
from ddmm.models.fused import AfferentColumns, FusedPipeline
from ddmm.models.reference_pipeline import attenuated_force, current_core, shear_drive, stretch_drive
from ddmm.models.rng import normals as keyed_normals
from ddmm.population import load_spec

FS = 1000.0
#: The fingertip's stage with the shear-magnitude term on, so every branch is compared.
PHYSIO = dataclasses.replace(load_spec("fingertip").current, shear_sai=0.5, shear_rai=4.0, shear_raii=1.0,
                             opponent_shear_sai=1.0, opponent_shear_rai=0.5, opponent_shear_raii=0.25, depth_sai=0.5,
                             depth_rai=0.7, transient_sai=1.5, tau_transient_sai_s=0.03)
#: The presets with a half-wave FA-II drive too (their FA-I drive already is: negative_weight_rai < 1).
HALF_WAVE = dataclasses.replace(PHYSIO, negative_weight_raii=0.0)
#: The paper's currents with only the attenuation depth changed (no shear term: F_A alone carries it).
DEPTH_ONLY = dataclasses.replace(CurrentParams(), depth_sai=0.5, depth_rai=0.3, depth_raii=0.7)
#: Afferents in runs of one type (as the encoder orders them), tuned and untuned in each.
TYPES = ["SAI"] * 4 + ["RAI"] * 4 + ["RAII"] * 3 + ["SAII"] * 3
NAPS = ["selective", "broad", "none", "bipolar", "broad", "none", "selective", "bipolar",
        "selective", "none", "broad", "broad", "none", "selective"]


def forces(seed, n=400):
    """Press, shear that rotates and crosses F_TH, release: every branch of the drive."""
    rng = np.random.default_rng(seed)
    t = np.arange(n) / FS
    fz = np.clip(3.0 * np.sin(np.pi * t / t[-1]) + 0.05 * rng.standard_normal(n), 0.0, None)
    shear = np.clip(0.4 * np.sin(2 * np.pi * 3 * t), 0.0, None)
    angle = rng.uniform(0, 2 * np.pi) + 4.0 * t
    return np.column_stack([shear * np.cos(angle), shear * np.sin(angle), fz])


def reference(f, params, no_shear, scale, cv, sigma, theta, k, normals, excite=None, ids=None, sensitivity=None):
    """The stage-by-stage path: AF, F_A or stretch, each type's stage (with the trial ``excite``), additive noise."""
    fx, fy, fz = f.T
    drive = np.empty((f.shape[0], len(TYPES)))
    for j, (kind, nap) in enumerate(zip(TYPES, NAPS)):
        if kind == "SAII":
            af = profile_factor(fx, fy, theta[j], nap, k[j]) if nap != UNTUNED else np.ones((fx.size, 1))
            drive[:, j] = stretch_drive(fx, fy, af, params.opponent_saii, fz, params.normal_saii)[:, 0]
        elif nap == UNTUNED:
            drive[:, j] = fz
        else:
            drive[:, j] = attenuated_force(fz, attenuation_factor(fx, fy, theta[j], nap, k[j], no_shear=no_shear),
                                           params.for_type(kind).depth)[:, 0]
        if kind != "SAII":  # the presets' shear-magnitude term (a no-op at the paper's defaults)
            raw = profile_factor(fx, fy, theta[j], nap, k[j])
            drive[:, [j]] = shear_drive(drive[:, [j]], fx, fy, raw, params.for_type(kind).shear,
                                        params.for_type(kind).opponent_shear)
    current = np.empty_like(drive)
    for kind in dict.fromkeys(TYPES):
        cols = np.flatnonzero(np.array(TYPES) == kind)
        current[:, cols], _ = current_core(drive[:, cols], FS, kind, params, None, scale[cols],
                                           None if normals is None else normals[cols], cv[cols],
                                           None if excite is None else excite[cols],
                                           None if ids is None else ids[cols],
                                           None if sensitivity is None else sensitivity[cols])
    if normals is not None and np.any(sigma > 0):
        current += (normals * (sigma / np.sqrt(1000.0 / FS))[:, None]).T
    return current


@settings(max_examples=12, deadline=None)
@given(seed=st.integers(0, 2**16), no_shear=st.sampled_from(["pass", "block", "smooth"]),
       physio=st.sampled_from([0, 1, 2, 3]), noisy=st.booleans(), cut=st.integers(1, 399))
def test_fused_currents_equal_the_stage_by_stage_path(seed, no_shear, physio, noisy, cut):
    rng = np.random.default_rng(seed)
    params = (CurrentParams(), PHYSIO, HALF_WAVE, DEPTH_ONLY)[physio]
    n = len(TYPES)
    theta, k, scale = rng.uniform(0, 360, n), rng.uniform(2.0, 5.0, n), rng.uniform(0.5, 2.0, n)
    cv = np.where(rng.random(n) < 0.7, rng.uniform(0.1, 1.0, n), 0.0)
    sigma = np.where(np.array(TYPES) == "SAII", 0.5, 0.0)
    f = forces(seed)
    ids = np.arange(100, 100 + n)
    key = seed + 1 if noisy else None
    normals = keyed_normals(key, ids, 0, f.shape[0]) if noisy else None
    excite = excitability(key, ids, [params.excite_cv(t) for t in TYPES]) if noisy else None
    sensitivity = np.exp(rng.normal(0.0, 0.9, n))  # each unit its own gain and dead zone
    expected = reference(f, params, no_shear, scale, cv, sigma, theta, k, normals, excite, ids, sensitivity)
    plan = FusedPipeline(AfferentColumns.filled(TYPES, nap=NAPS, theta_t=theta, k=k, scale=scale, noise_cv=cv,
                                                      noise_sigma=sigma, afferent_id=ids, sensitivity=sensitivity),
                         params, FS, no_shear=no_shear)
    state = plan.new_state()
    parts = [plan.currents(f[a:b], state, a > 0, a, key)
             for a, b in ((0, cut), (cut, f.shape[0]))]  # in two chunks: the state carries over
    np.testing.assert_array_equal(np.concatenate(parts), expected)


@pytest.mark.parametrize("per_slice", [1, 37, 400])
def test_fused_currents_in_time_slices_equal_the_stage_by_stage_path(monkeypatch, per_slice):
    """`FusedPipeline.currents` cuts long inputs into slices of time that fit in cache; the cut changes no bit."""
    import ddmm.models.fused

    monkeypatch.setattr(ddmm.models.fused, "_SLICE", per_slice * len(TYPES))
    rng = np.random.default_rng(11)
    n = len(TYPES)
    theta, k, scale = rng.uniform(0, 360, n), rng.uniform(2.0, 5.0, n), rng.uniform(0.5, 2.0, n)
    cv, sigma = np.full(n, 0.4), np.where(np.array(TYPES) == "SAII", 0.5, 0.0)
    f, ids = forces(5), np.arange(n)
    normals = keyed_normals(9, ids, 0, f.shape[0])
    excite = excitability(9, ids, [PHYSIO.excite_cv(t) for t in TYPES])
    expected = reference(f, PHYSIO, "smooth", scale, cv, sigma, theta, k, normals, excite, ids)
    plan = FusedPipeline(AfferentColumns.filled(TYPES, nap=NAPS, theta_t=theta, k=k, scale=scale, noise_cv=cv,
                                                      noise_sigma=sigma, afferent_id=ids), PHYSIO, FS, no_shear="smooth")
    np.testing.assert_array_equal(plan.currents(f, plan.new_state(), False, 0, 9), expected)


def held_forces(seed, n=400):
    """Shear held in a few directions: above F_TH at A, below it while turning to B, above it at B, back to A.

    The fused path reuses AF while the direction stays the same; this is the
    case where a stale reuse would show (a group that skipped the profile
    below F_TH must not take another group's values at B).
    """
    rng = np.random.default_rng(seed)
    a, b = rng.uniform(0, 2 * np.pi, 2)
    angle = np.repeat([a, b, b, a], n // 4)
    shear = np.repeat([0.3, 0.05, 0.3, 0.3], n // 4)
    fz = np.full(n, 2.0) + 0.01 * rng.standard_normal(n)
    return np.column_stack([shear * np.cos(angle), shear * np.sin(angle), fz])


@pytest.mark.parametrize("no_shear", ["pass", "block", "smooth"])
def test_fused_currents_equal_the_reference_on_held_directions(no_shear):
    rng = np.random.default_rng(7)
    n = len(TYPES)
    theta, k, scale = rng.uniform(0, 360, n), rng.uniform(2.0, 5.0, n), np.ones(n)
    f = held_forces(3)
    expected = reference(f, PHYSIO, no_shear, scale, np.zeros(n), np.zeros(n), theta, k, None, ids=np.arange(n))
    plan = FusedPipeline(AfferentColumns.filled(TYPES, nap=NAPS, theta_t=theta, k=k, scale=scale), PHYSIO, FS,
                         no_shear=no_shear)
    np.testing.assert_array_equal(plan.currents(f, plan.new_state(), False), expected)


def test_fused_plan_needs_no_tuned_afferent():
    plan = FusedPipeline(AfferentColumns.filled(["RAI", "RAI"]), PHYSIO, FS, no_shear="smooth")
    f = forces(1)
    drive = shear_drive(np.column_stack([f[:, 2], f[:, 2]]), f[:, 0], f[:, 1], np.ones((f.shape[0], 2)),
                        PHYSIO.shear_rai, PHYSIO.opponent_shear_rai)  # untuned: AF = 1, every direction
    expected, _ = current_core(drive, FS, "RAI", PHYSIO, None, np.ones(2))
    np.testing.assert_array_equal(plan.currents(f, plan.new_state(), False), expected)


@pytest.mark.parametrize("method", ["euler", "rk4"])
def test_fused_spikes_equal_the_direct_engine(method):
    from ddmm.models.engines import integrate
    from ddmm.models.engines.direct import BLOCK, METHOD_CODES, Membrane, NeuronTable
    from ddmm.models.engines.direct_fused import pipeline_spikes
    from ddmm.models.neuron import V_FLOOR, V_PEAK, neuron_arrays, resting_state

    plan = FusedPipeline(AfferentColumns.filled(TYPES, nap=NAPS, theta_t=np.linspace(0, 330, len(TYPES)), k=3.0,
                                                      scale=2.0), PHYSIO, FS, no_shear="smooth")
    f = forces(2)
    current = plan.currents(f, plan.new_state(), False)
    res = integrate(current, fs=FS, dt=1e-4, afferent_type=np.array(TYPES), engine="direct", method=method)
    p = neuron_arrays(np.array(TYPES))
    v, u = (np.array(x, dtype=float) for x in resting_state(p["b"]))
    neuron = NeuronTable(10, METHOD_CODES[method], 1.0 * 1e-4 / 0.001, (1.0 * (0.5 * 1e-4)) / 0.001, p["a"], p["b"],
                         p["c"], p["d"], np.zeros(len(TYPES)), V_PEAK, V_FLOOR, BLOCK)
    mem = Membrane(v, u, np.zeros(len(TYPES)))
    _, afferent, step, _, finite, capped = pipeline_spikes(plan, f, plan.new_state(), False, 0, None, neuron, mem)
    assert finite and not capped and afferent.size > 10
    order = np.lexsort((afferent, step))
    np.testing.assert_array_equal(afferent[order], res.afferent)
    np.testing.assert_array_equal(step[order], res.step)
    np.testing.assert_array_equal(v, res.state.v)


def test_an_engine_that_only_integrates_currents_advances_a_pipeline_as_the_direct_one():
    """The registry supplies each engine's integrator (`Engine.advance`); an engine with `run` alone gets the
    pipeline's currents through the seam, with the spikes and state of the direct engine's fused pass."""
    from ddmm.models.engines import Engine, get_engine

    class CurrentsOnly(Engine):
        name = "currents-only"

        def run(self, *args, **kwargs):
            return get_engine("direct").run(*args, **kwargs)

    n = len(TYPES)
    plan = FusedPipeline(AfferentColumns.filled(TYPES, nap=NAPS, theta_t=np.linspace(0, 330, n), k=3.0, scale=2.0,
                                                      noise_cv=0.3, noise_sigma=0.2), PHYSIO, FS, no_shear="smooth")
    f, out = forces(3), []
    for engine in (CurrentsOnly(), "direct"):
        state, neuron, afferents, steps = plan.new_state(), None, [], []
        for a, b in ((0, 150), (150, 400)):  # noisy, in two chunks: the state carries over
            afferent, step, neuron = plan.advance(f[a:b], state, a, 5, neuron, dt=1e-4, method="rk2", engine=engine)
            afferents.append(afferent)
            steps.append(step + 10 * a)
        afferent, step = np.concatenate(afferents), np.concatenate(steps)
        order = np.lexsort((afferent, step))
        out.append((afferent[order], step[order], neuron))
    assert out[0][0].size > 10
    for x, y in zip(out[0][:2], out[1][:2]):
        np.testing.assert_array_equal(x, y)
    for name in ("v", "u", "r"):
        np.testing.assert_array_equal(getattr(out[0][2], name), getattr(out[1][2], name))


def test_the_pipeline_takes_a_column_record_and_its_options_by_name():
    """`FusedPipeline(columns, params, fs, *, no_shear, f_th, mixing, neuron_params)` (issue 41): nothing
    positional after ``fs``, the columns as one `AfferentColumns`, each of one value per afferent."""
    columns = AfferentColumns.filled(["SAI", "RAI"])
    with pytest.raises(TypeError):
        FusedPipeline(columns, PHYSIO, FS, "smooth")
    with pytest.raises(TypeError):  # the former column-by-column call
        FusedPipeline(["SAI"], ["none"], [0.0], [1.0], [1.0], [0.0], [0.0], PHYSIO, FS, "pass", 0.1)
    with pytest.raises(TypeError, match="AfferentColumns"):
        FusedPipeline(["SAI", "RAI"], PHYSIO, FS)
    for field in dataclasses.fields(AfferentColumns)[1:]:
        with pytest.raises(ValueError, match=rf"AfferentColumns\.{field.name} must hold one value per afferent \(2\)"):
            dataclasses.replace(columns, **{field.name: np.zeros(3)})
    with pytest.raises(ValueError, match="mixing"):
        FusedPipeline(columns, PHYSIO, FS, mixing=np.ones((2, 3)))
    with pytest.raises(ValueError, match="no_shear"):
        FusedPipeline(columns, PHYSIO, FS, no_shear="smoth")
