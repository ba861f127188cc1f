"""The engine seam: both engines give identical spikes, and zero input stays silent."""

import re
import warnings

import numpy as np
import pytest
from hypothesis import given
from hypothesis import strategies as st
from hypothesis.extra import numpy as hnp

from ddmm.models.engines import NeuronState, SpikeCapWarning, integrate, substeps_for
from ddmm.models.pipeline import simulate_afferents
from tests.conftest import ENGINES

TYPES = ("SAI", "RAI", "RAII")


def spikes(res):
    return list(zip(res.afferent.tolist(), res.step.tolist()))


@given(current=hnp.arrays(np.float64, st.tuples(st.integers(1, 200), st.integers(1, 30)),
                          elements=st.floats(-20.0, 250.0, allow_subnormal=False)),
       seed=st.integers(0, 2**16), method=st.sampled_from(["euler", "rk2", "rk4", "izhikevich2003"]))
def test_engines_identical_on_random_currents(current, seed, method):
    types = np.random.default_rng(seed).choice(TYPES, current.shape[1])
    with warnings.catch_warnings():
        warnings.simplefilter("ignore", SpikeCapWarning)
        a = integrate(current, fs=1000.0, dt=1e-4, afferent_type=types, engine="direct", method=method)
        b = integrate(current, fs=1000.0, dt=1e-4, afferent_type=types, engine="brian2", method=method)
    assert spikes(a) == spikes(b)
    np.testing.assert_array_equal(a.state.v, b.state.v)
    np.testing.assert_array_equal(a.state.u, b.state.u)


@pytest.mark.parametrize("engine", ENGINES)
def test_continuing_from_state_equals_one_run(engine):
    rng = np.random.default_rng(3)
    current = rng.uniform(0, 40, (600, 5))
    whole = integrate(current, fs=1000.0, dt=1e-4, afferent_type="RAI", engine=engine)
    first = integrate(current[:230], fs=1000.0, dt=1e-4, afferent_type="RAI", engine=engine)
    second = integrate(current[230:], fs=1000.0, dt=1e-4, afferent_type="RAI", engine=engine,
                       state=first.state)
    joined = spikes(first) + [(a, s + 2300) for a, s in spikes(second)]
    assert joined == spikes(whole)
    np.testing.assert_array_equal(second.state.v, whole.state.v)


@pytest.mark.parametrize("engine", ENGINES)
def test_ten_seconds_of_zero_force_give_no_spikes(engine):
    n = 10_000
    zeros = np.zeros(n)
    for profile in ("selective", "broad", "bipolar", "none"):
        res = simulate_afferents(zeros, zeros, zeros, fs=1000.0, afferent_type=list(TYPES), profile=profile,
                       theta_t=[0.0, 90.0, 180.0], engine=engine)
        assert res.afferent.size == 0
        assert res.n_steps == n * 10


@pytest.mark.parametrize("engine", ENGINES)
def test_neurons_start_at_rest(engine):
    res = integrate(np.zeros((300, 3)), fs=1000.0, dt=1e-4, afferent_type=list(TYPES), engine=engine)
    np.testing.assert_allclose(res.state.v, [-70.0, -64.41391, -64.41391], atol=1e-4)


def test_brian2_compiles_once_per_shape(capsys):
    rng = np.random.default_rng(0)
    for _ in range(3):  # same shape, new values: no compile notice after the first
        integrate(rng.uniform(0, 20, (90, 7)), fs=1000.0, dt=1e-4, afferent_type="SAI", engine="brian2")
    first = capsys.readouterr().err
    integrate(rng.uniform(0, 20, (90, 7)), fs=1000.0, dt=1e-4, afferent_type="SAI", engine="brian2")
    assert "compiling" not in capsys.readouterr().err
    assert first.count("compiling") <= 1


def test_substeps_must_be_whole():
    assert substeps_for(1000.0, 1e-5) == 100
    with pytest.raises(ValueError, match="dt"):
        substeps_for(1000.0, 3e-4)
    with pytest.raises(ValueError, match=r"\(0.3125 ms\) a whole number of times; the nearest rates it divides: "
                                         r"2500 Hz and 3333.33 Hz \(or choose a dt that divides 1/fs\)$"):
        substeps_for(3200.0, 1e-4)
    with pytest.raises(ValueError, match=r"the nearest rates it divides: 10000 Hz \("):
        substeps_for(20000.0, 1e-4)


@pytest.mark.parametrize("kwargs,exc,match", [
    (dict(fs=0.0), ValueError, "fs"),
    (dict(dt=-1e-4), ValueError, "dt"),
    (dict(dt=0.0), ValueError, "dt"),
    (dict(engine="neuron"), ValueError, "engine"),
    (dict(method="rk9"), ValueError, "method"),
    (dict(method="rk45"), ValueError, "method"),
    (dict(afferent_type="SAIII"), ValueError, "afferent_type"),
    (dict(state=(1, 2)), TypeError, "state"),
    (dict(state=NeuronState(np.zeros(2), np.zeros(2))), ValueError, "state"),
])
def test_bad_input(kwargs, exc, match):
    args = dict(fs=1000.0, dt=1e-4, afferent_type="SAI", engine="direct")
    args.update(kwargs)
    with pytest.raises(exc, match=match):
        integrate(np.zeros((10, 3)), **args)
    with pytest.raises(ValueError, match="current"):
        integrate(np.full((10, 3), np.nan), fs=1000.0, dt=1e-4, afferent_type="SAI", engine="direct")


@pytest.mark.parametrize("kwargs,match", [
    (dict(fx=[0.0, np.nan]), "fx"), (dict(fz=[0.0, np.inf]), "fz"),
    (dict(fy=[0.0]), "equal length"), (dict(fz=[0.0, -1.0]), "fz"),
    (dict(profile="oval"), "profile"), (dict(k=0.0), "k="), (dict(profile="broad", k=1.5), "k="),
])
def test_pipeline_bad_input(kwargs, match):
    args = dict(fx=[0.0, 0.0], fy=[0.0, 0.0], fz=[0.0, 1.0], fs=1000.0, afferent_type="SAI",
                profile="selective", k=3.0, engine="direct")
    args.update(kwargs)
    with pytest.raises(ValueError, match=match):
        simulate_afferents(args.pop("fx"), args.pop("fy"), args.pop("fz"), **args)


def test_engines_identical_across_thresholder_blocks():
    """The Brian2 engine's thresholder scans 64 neurons at a time (`models/engines/brian2/templates/threshold.cpp`).

    150 neurons (160 with padding: blocks of 64, 64 and 32) spiking at
    different steps, including the first and last neuron of every block.
    """
    rng = np.random.default_rng(5)
    current = rng.uniform(0.0, 30.0, (120, 150)) * np.linspace(0.2, 1.5, 150)
    a = integrate(current, fs=1000.0, dt=1e-4, afferent_type="RAI", engine="direct")
    b = integrate(current, fs=1000.0, dt=1e-4, afferent_type="RAI", engine="brian2")
    assert {0, 63, 64, 127, 128, 149} <= set(a.afferent.tolist())
    assert spikes(a) == spikes(b)


def test_brian2_network_loop_reads_the_clock_once():
    """Brian2's network loop reads the process CPU clock (a system call) after every step; the engine's, once."""
    from ddmm.models.engines.brian2.device import EngineCodeObject, drop_per_step_clock

    def loop(source):
        start = source.index("while(clock")
        return source[start:source.index("Network::_globally_running = false;", start)]

    source = EngineCodeObject.templater.network(None, None, maximum_run_time=None).cpp_file
    assert loop(source).count("std::clock()") == 2  # Brian2's loop: if this fails, the patch no longer applies
    patched = drop_per_step_clock(source)
    assert loop(patched).count("std::clock()") == 1  # the report's read, made only when a report is asked for
    assert "elapsed_realtime = (double)(std::clock() - start)" in patched


def test_brian2_refuses_an_input_file_it_could_not_read(monkeypatch):
    """Brian2's binary only prints an error for a run argument's file of the wrong size, and exits 0."""
    import ddmm.models.engines.brian2.engine as engine

    def short_table(path, current, n_samples, n_neurons):
        np.zeros(7).tofile(path)

    monkeypatch.setattr(engine, "write_table", short_table)
    with pytest.raises(RuntimeError, match="Error reading the current table"):
        integrate(np.full((90, 7), 20.0), fs=1000.0, dt=1e-4, afferent_type="SAI", engine="brian2")


def test_brian2_lanes_live_as_long_as_their_process():
    """A lane's files are kept between runs, removed at exit, and swept once their process is gone."""
    import subprocess
    import sys
    from pathlib import Path

    from ddmm.models.engines.brian2.lanes import _root

    stale = _root() / "4194305_0"  # above Linux's largest pid: a process that cannot be alive
    (stale / "results").mkdir(parents=True, exist_ok=True)
    code = ("import os, numpy as np; from ddmm.models.engines import integrate; from ddmm.models.engines.brian2.lanes import _root\n"
            "for _ in range(2):\n"
            "    integrate(np.full((90, 7), 20.0), fs=1000.0, dt=1e-4, afferent_type='SAI', engine='brian2')\n"
            "mine = sorted(p.name for p in _root().iterdir() if p.name.startswith(f'{os.getpid()}_'))\n"
            "print(os.getpid(), mine, sorted(p.name for p in (_root() / mine[0]).iterdir()))")
    out = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, check=True,
                         cwd=Path(__file__).parents[2]).stdout.split(maxsplit=1)
    assert not stale.exists()
    assert re.match(rf"\['{out[0]}_0_\w+'\] ", out[1]), out  # one lane (private, unpredictable name), both runs
    assert "'ddmm_current.dat'" in out[1] and "'results'" in out[1]
    assert not any(p.name.startswith(f"{out[0]}_") for p in _root().iterdir())


def test_brian2_table_is_padded_with_zeros_whatever_the_lane_held(tmp_path):
    """The lane's table file is rewritten in place: padding must not keep an earlier run's values."""
    from ddmm.models.engines.brian2.lanes import write_table

    path = tmp_path / "table.dat"
    write_table(path, np.full((8, 4), 7.0), 8, 4)
    write_table(path, np.arange(6.0).reshape(2, 3), 8, 4)  # fewer samples and neurons than the table
    table = np.fromfile(path).reshape(8, 4)
    np.testing.assert_array_equal(table[:2, :3], np.arange(6.0).reshape(2, 3))
    assert not table[:2, 3:].any() and not table[2:].any()
    write_table(path, np.ones((3, 2)), 5, 2)  # another shape: the file is cut to it
    np.testing.assert_array_equal(np.fromfile(path).reshape(5, 2), np.r_[np.ones((3, 2)), np.zeros((2, 2))])


def test_brian2_lanes_hold_only_small_tables_mapped(tmp_path, monkeypatch):
    """Between runs a lane keeps a small table mapped (cheap to rewrite) but not a long run's."""
    import ddmm.models.engines.brian2.lanes as lanes

    monkeypatch.setattr(lanes, "_KEEP_MAPPED", 20)
    small, large = tmp_path / "small.dat", tmp_path / "large.dat"
    lanes.write_table(small, np.ones((4, 5)), 4, 5)
    lanes.write_table(large, np.ones((4, 6)), 4, 6)
    assert small in lanes._MAPS and large not in lanes._MAPS
    np.testing.assert_array_equal(np.fromfile(large), np.ones(24))
