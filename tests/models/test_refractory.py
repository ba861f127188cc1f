"""The absolute refractory period (`NeuronParams.t_ref`): analytic intervals, both engines, chunking, bad state."""

import numpy as np
import pytest

from ddmm.models.engines import NeuronState, SpikeCapWarning, integrate
from ddmm.models.neuron import NeuronParams, refractory_steps

FS, DT = 1000.0, 1e-4


def _run(current, t_ref, engine="direct", state=None, method="euler"):
    params = {"RAII": NeuronParams(b=0.25, t_ref=t_ref)}
    return integrate(current, fs=FS, dt=DT, afferent_type="RAII", engine=engine, method=method, state=state,
                     neuron_params=params)


def _intervals(res, n):
    return [np.diff(res.step[res.afferent == j]) for j in range(n)]


def test_a_saturating_current_fires_once_per_period_plus_one_step():
    # 5000 mV/ms crosses threshold within one step of any reset: without the
    # period every step spikes (the cap warns); with it every interval is
    # round(t_ref / dt) held steps plus the step that crosses.
    current = np.full((50, 1), 5000.0)
    with pytest.warns(SpikeCapWarning):
        free = _intervals(_run(current, 0.0), 1)[0]
    held = _intervals(_run(current, 0.002), 1)[0]
    assert set(free.tolist()) == {1}
    assert set(held.tolist()) == {21} and held.size == 499 // 21


def test_the_period_only_lengthens_intervals():
    current = np.full((50, 1), 300.0)
    free = _intervals(_run(current, 0.0), 1)[0]
    held = _intervals(_run(current, 0.002), 1)[0]
    assert free.min() < 8 and held.min() >= 21 and held.size < free.size


def test_period_rounds_to_whole_steps():
    assert refractory_steps([0.0, 0.002, 0.00204, 0.00206], DT).tolist() == [0.0, 20.0, 20.0, 21.0]


@pytest.mark.parametrize("method", ["euler", "rk4"])
def test_both_engines_give_the_same_spikes_and_state(method):
    rng = np.random.default_rng(4)
    t = np.arange(300) / FS
    current = np.clip(np.outer(np.sin(2 * np.pi * 150 * t), rng.uniform(20, 200, 6)), 0, None)
    a, b = _run(current, 0.002, "direct", method=method), _run(current, 0.002, "brian2", method=method)
    assert a.afferent.size > 50
    np.testing.assert_array_equal(a.afferent, b.afferent)
    np.testing.assert_array_equal(a.step, b.step)
    for name in ("v", "u", "r"):
        np.testing.assert_array_equal(getattr(a.state, name), getattr(b.state, name))


@pytest.mark.parametrize("cut", [1, 7, 123])
def test_a_run_cut_anywhere_continues_through_the_period(cut):
    current = np.full((200, 3), 150.0) * np.array([1.0, 2.0, 0.5])
    whole = _run(current, 0.003)
    first = _run(current[:cut], 0.003)
    assert np.any(first.state.r > 0) or cut == 123  # some cuts fall inside a period
    second = _run(current[cut:], 0.003, state=first.state)
    steps = np.r_[first.step, second.step + cut * 10]
    np.testing.assert_array_equal(steps, whole.step)
    np.testing.assert_array_equal(np.r_[first.afferent, second.afferent], whole.afferent)


@pytest.mark.parametrize(("r", "match"), [
    (np.array([-1.0]), "state.r must hold whole numbers of steps >= 0, got -1"),
    (np.array([2.5]), "state.r must hold whole numbers of steps >= 0, got 2.5"),
    (np.array([1.0, 2.0]), r"state must hold 1 neurons"),
])
def test_bad_refractory_state_is_named(r, match):
    state = NeuronState(np.array([-70.0]), np.array([-17.5]), r)
    with pytest.raises(ValueError, match=match):
        _run(np.zeros((5, 1)), 0.002, state=state)


@pytest.mark.parametrize("value", [-1e-3, 0.2, float("nan"), "2 ms"])
def test_bad_period_is_named(value):
    with pytest.raises(ValueError, match="t_ref must be a finite number in"):
        NeuronParams(t_ref=value)
