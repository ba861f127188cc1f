"""The streaming encoder: any chunking equals the offline run; bad chunks leave no trace."""

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from ddmm.population import Scene, press_push_lift, sample_population, simulate
from ddmm.population.runtime.stream import Encoder
from tests.conftest import ENGINES

N = 3000


@pytest.fixture(scope="module")
def setup():
    pop = sample_population("fingertip", rng=0).select(np.arange(0, 991, 7))
    ppl = press_push_lift(90.0)
    scene = Scene(ppl.fx[4000:4000 + N], ppl.fy[4000:4000 + N], ppl.fz[4000:4000 + N], 1000.0, "x")
    forces = np.column_stack([scene.fx, scene.fy, scene.fz])
    offline = {e: simulate(pop, scene, engine=e, seed=3, quiet=True) for e in ENGINES}
    return pop, forces, offline


def concat(outs):
    return np.concatenate([o.afferent for o in outs]), np.concatenate([o.time for o in outs])


@settings(max_examples=12, deadline=None)
@given(cuts=st.lists(st.integers(1, N - 1), max_size=25, unique=True), engine=st.sampled_from(["direct"] * 3 + ["brian2"]))
def test_any_chunking_equals_offline(setup, cuts, engine):
    pop, forces, offline = setup
    enc = Encoder(pop, 1000.0, engine=engine, seed=3, conditioning=None)
    edges = [0] + sorted(cuts) + [N]
    aff, t = concat([enc.push(forces[a:b]) for a, b in zip(edges[:-1], edges[1:])])
    np.testing.assert_array_equal(aff, offline[engine].spike_afferent.values)
    np.testing.assert_array_equal(t, offline[engine].spike_time.values)


@pytest.mark.parametrize("threads", ["2", "3"])
def test_parallel_push_equals_offline(setup, monkeypatch, threads):
    """A large population's pushes integrate on several numba threads: the spikes stay the offline ones."""
    from ddmm.models.engines import get_engine

    monkeypatch.setattr(get_engine("direct"), "parallel_min_afferents", 1)
    monkeypatch.setenv("DDMM_NUM_THREADS", threads)
    pop, forces, offline = setup
    enc = Encoder(pop, 1000.0, engine="direct", seed=3, conditioning=None)
    aff, t = concat([enc.push(forces[a:a + 7]) for a in range(0, N, 7)])
    np.testing.assert_array_equal(aff, offline["direct"].spike_afferent.values)
    np.testing.assert_array_equal(t, offline["direct"].spike_time.values)


def test_the_threads_argument_caps_a_push_and_changes_no_spike(setup, monkeypatch):
    """Encoder(threads=1) pushes in one part whatever DDMM_NUM_THREADS says, threads=2 in two: the same
    spikes; a count below 1 or not an integer is refused."""
    from ddmm.models.engines import get_engine

    monkeypatch.setattr(get_engine("direct"), "parallel_min_afferents", 1)
    monkeypatch.setenv("DDMM_NUM_THREADS", "3")
    pop, forces, offline = setup
    for threads in (1, 2):
        enc = Encoder(pop, 1000.0, engine="direct", seed=3, conditioning=None, threads=threads)
        assert enc._parts == threads
        aff, t = concat([enc.push(forces[a:a + 7]) for a in range(0, N, 7)])
        np.testing.assert_array_equal(aff, offline["direct"].spike_afferent.values)
        np.testing.assert_array_equal(t, offline["direct"].spike_time.values)
    with pytest.raises(ValueError, match="threads must be an integer >= 1, got 0"):
        Encoder(pop, 1000.0, threads=0)
    with pytest.raises(TypeError, match="threads must be an integer, got float 1.5"):
        Encoder(pop, 1000.0, threads=1.5)


def test_bad_chunks_do_not_corrupt_the_state(setup):
    pop, forces, offline = setup
    enc = Encoder(pop, 1000.0, engine="direct", seed=3, conditioning=None)
    times = np.arange(N) / 1000.0
    outs = [enc.push(forces[:1000], times=times[:1000])]
    bad = forces[1000:1100].copy()
    bad[50, 1] = np.nan
    with pytest.raises(ValueError, match="finite"):
        enc.push(bad, times=times[1000:1100])
    with pytest.raises(ValueError, match="increase strictly"):
        enc.push(forces[1000:1100], times=times[900:1000])
    with pytest.raises(ValueError, match="shape"):
        enc.push(forces[1000:1100, :2])
    outs.append(enc.push(forces[1000:], times=times[1000:]))
    aff, t = concat(outs)
    np.testing.assert_array_equal(t, offline["direct"].spike_time.values)
    np.testing.assert_array_equal(aff, offline["direct"].spike_afferent.values)


def test_reset_starts_over(setup):
    pop, forces, _ = setup
    enc = Encoder(pop, 1000.0, engine="direct", seed=3, conditioning=None)
    first = enc.push(forces[:800])
    enc.reset()
    again = enc.push(forces[:800])
    np.testing.assert_array_equal(first.time, again.time)
    assert enc.n_samples == 800


def test_encoder_bad_arguments(setup):
    pop, _, _ = setup
    with pytest.raises(TypeError, match="population"):
        Encoder("fingertip", 1000.0)
    with pytest.raises(ValueError, match="dt"):
        Encoder(pop, 1000.0, dt=3e-4)
    with pytest.raises(ValueError, match="engine"):
        Encoder(pop, 1000.0, engine="nest")


def test_cli_stream(capsys, monkeypatch):
    import io

    from ddmm.experiments.cli import main
    t = np.arange(0, 0.3, 0.001)
    fz = np.interp(t, [0, 0.1, 0.3], [0, 4, 4])
    lines = ["t,fx,fy,fz"] + [f"{a:.3f},0,{0.3 * b:.4f},{b:.4f}" for a, b in zip(t, fz)] + ["0.1,0,0,1", "x"]
    monkeypatch.setattr("sys.stdin", io.StringIO("\n".join(lines) + "\n"))
    assert main(["stream", "--fs", "1000", "--seed", "2"]) == 0
    out, err = capsys.readouterr()
    rows = [r.split(",") for r in out.strip().splitlines()]
    assert len(rows) > 50 and {r[2] for r in rows} <= {"SAI", "RAI", "RAII", "SAII"}
    assert "line 302 skipped" in err and "line 303 skipped" in err


def test_the_spike_cap_warning_survives_the_fused_path():
    """A drive far past the step rate warns offline and when streamed (the fused kernel flags it)."""
    import warnings

    from ddmm.models.engines import SpikeCapWarning
    from ddmm.population import birznieks, make_population

    pop = make_population(["SAI"] * 3, gain=1e4)
    scene = birznieks(90.0)
    with pytest.warns(SpikeCapWarning, match="consecutive steps"):
        simulate(pop, scene, engine="direct", quiet=True)
    enc = Encoder(pop, scene.fs, seed=0, conditioning=None)
    with pytest.warns(SpikeCapWarning):
        enc.push(np.column_stack([scene.fx, scene.fy, scene.fz])[:200])
    with warnings.catch_warnings():
        warnings.simplefilter("error", SpikeCapWarning)
        Encoder(make_population(["SAI"]), scene.fs, seed=0).push(np.column_stack([scene.fx, scene.fy, scene.fz]))


@settings(max_examples=6, deadline=None)
@given(cuts=st.lists(st.integers(1, 299), max_size=12, unique=True))
def test_a_100_hz_sensor_streams_and_equals_the_offline_file_in_the_causal_mode(tmp_path_factory, cuts):
    """Raw 100 Hz samples with sensor noise: the encoder's causal conditioning and types equal `from_csv`
    (same conditioning) and `simulate(afferent_types=...)`, bit for bit, for any chunking."""
    from ddmm.population import from_csv
    from ddmm.population.stimuli.conditioning import Conditioning

    rng = np.random.default_rng(5)
    t = np.arange(300) / 100.0
    f = np.column_stack([rng.normal(0, 0.02, 300), np.interp(t, [0, 1, 2, 3], [0, 0, 1, 1]),
                         np.interp(t, [0, 0.5, 1, 3], [0, 0, 3, 3])]) + [0, 0, 1] * rng.normal(0, 0.02, (300, 3))
    path = tmp_path_factory.mktemp("plate") / "plate.csv"
    path.write_text("Time,Fx,Fy,Fz\n" + "".join(f"{a:.2f},{float(b)!r},{float(c)!r},{float(d)!r}\n" for a, (b, c, d) in zip(t, f)))
    pop = sample_population("fingertip", rng=0).select(np.arange(0, 991, 9))
    types = ("SAI", "RAI", "SAII")
    with pytest.warns(UserWarning, match="FA-II's band"):
        scene = from_csv(path)
    offline = simulate(pop, scene, engine="direct", seed=3, afferent_types=types, quiet=True)
    enc = Encoder(pop, 100.0, seed=3, afferent_types=types, conditioning=Conditioning(), model_fs=1000.0)
    edges = [0] + sorted(cuts) + [300]
    aff, times = concat([enc.push(f[a:b]) for a, b in zip(edges[:-1], edges[1:])])
    ids = offline.afferent.values[offline.spike_afferent.values]
    np.testing.assert_array_equal(pop.afferent_id[aff], ids)
    np.testing.assert_array_equal(times, offline.spike_time.values)
    assert aff.size > 100 and set(pop.afferent_type[aff]) <= set(types)


def test_cli_stream_at_100_hz_with_types_and_a_gap(capsys, monkeypatch):
    import io

    from ddmm.experiments.cli import main
    t = np.r_[np.arange(0, 1.0, 0.01), np.arange(1.2, 2.0, 0.01)]
    fz = -np.interp(t, [0, 0.3, 2], [0, 3, 3])  # a plate that reports pressing as negative
    lines = ["Time,Fx,Fy,Fz"] + [f"{a:.3f},0,0,{b:.4f}" for a, b in zip(t, fz)]
    monkeypatch.setattr("sys.stdin", io.StringIO("\n".join(lines) + "\n"))
    assert main(["stream", "--fs", "100", "--types", "SAI,RAI", "--fz-sign", "-1", "--seed", "2"]) == 0
    out, err = capsys.readouterr()
    rows = [r.split(",") for r in out.strip().splitlines()]
    assert len(rows) > 50 and {r[2] for r in rows} == {"SAI", "RAI"}
    assert "line 102: a gap of 0.21 s at t = 0.99 s" in err and "skipped" not in err


def test_warm_up_changes_no_spike_and_refuses_once_samples_were_pushed(setup):
    pop, forces, offline = setup
    enc = Encoder(pop, 1000.0, seed=3, conditioning=None)
    enc.warm_up()
    out = enc.push(forces)
    np.testing.assert_array_equal(out.afferent, offline["direct"].spike_afferent.values)
    np.testing.assert_array_equal(out.time, offline["direct"].spike_time.values)
    with pytest.raises(ValueError, match="warm_up\\(\\) goes before the first push; 3000 samples"):
        enc.warm_up()


def test_stdout_times_are_on_the_input_clock_in_both_modes(capsys, monkeypatch):
    """The same stamped samples, with a gap, give the same stdout lines from stdin and through the LSL bridge.

    Both are on the input's clock (the bridge's own stamps carry the host's clock offset), and both move the
    spike times on by the gap, so a spike stays beside the samples that caused it.
    """
    import io

    from ddmm.experiments.cli import main
    from ddmm.experiments.cli.stream import csv_sink
    from ddmm.population.runtime.lsl import ForceStream
    from ddmm.population.runtime.lsl_bridge import Bridge

    t = 5.0 + np.r_[np.arange(0, 0.4, 0.001), np.arange(0.45, 0.8, 0.001)]  # a 50 ms gap at 5.4 s
    f = np.column_stack([0 * t, 0.3 * np.interp(t, [5.0, 5.1, 6], [0, 3, 3]), np.interp(t, [5.0, 5.1, 6], [0, 3, 3])])
    lines = ["t,fx,fy,fz"] + [",".join(map(repr, map(float, row))) for row in np.column_stack([t, f])]
    monkeypatch.setattr("sys.stdin", io.StringIO("\n".join(lines) + "\n"))
    assert main(["stream", "--fs", "1000", "--seed", "2", "--conditioning", "off", "--types", "SAI,RAI"]) == 0
    from_stdin, err = capsys.readouterr()
    assert "a gap of 0.051 s at t = 5.399 s" in err

    pop = sample_population("fingertip", rng=2)
    enc = Encoder(pop, 1000.0, seed=2, afferent_types=("SAI", "RAI"), conditioning=None)
    force = ForceStream("fake", "fake-id", "host", 1000.0, 1, "N", 1, 123.25, inlet=None)
    out = io.StringIO()
    Bridge(enc, force, csv_sink(enc, out, force)).consume(f, t)
    assert out.getvalue() == from_stdin
    times = np.array([float(r.split(",")[0]) for r in from_stdin.splitlines()])
    assert times.min() > 5.0 and (times > 5.45).any() and not ((times > 5.4) & (times < 5.45)).any()


def test_a_chunk_refused_after_it_ran_loses_an_euler_encoder_until_reset():
    """Euler's pushes write the state in place: a chunk refused once it ran (here a SpikeCapWarning made an
    error) leaves no usable state, so every later push says so until `reset`; after it, the spikes are a
    fresh encoder's."""
    import warnings

    from ddmm.models.engines import SpikeCapWarning
    from ddmm.population import birznieks, make_population

    pop, scene = make_population(["SAI"] * 3, gain=1e4), birznieks(90.0)
    forces = np.column_stack([scene.fx, scene.fy, scene.fz])
    enc = Encoder(pop, scene.fs, seed=0, conditioning=None)
    with warnings.catch_warnings():
        warnings.simplefilter("error", SpikeCapWarning)
        with pytest.raises(SpikeCapWarning):
            enc.push(forces[:200])
    with pytest.raises(ValueError, match=r"changed the encoder's state \(SpikeCapWarning.*reset\(\) first"):
        enc.push(forces[200:201])
    enc.reset()
    with warnings.catch_warnings():
        warnings.simplefilter("ignore", SpikeCapWarning)
        got, want = enc.push(forces[:300]), Encoder(pop, scene.fs, seed=0, conditioning=None).push(forces[:300])
    assert got.afferent.size > 10
    np.testing.assert_array_equal(got.afferent, want.afferent)
    np.testing.assert_array_equal(got.time, want.time)


@pytest.mark.parametrize("method", ["rk4", "rk2"])
def test_a_chunk_an_explicit_method_refuses_leaves_the_state_untouched(method):
    """The explicit methods' stability check refuses a chunk after it ran; their pushes write spare buffers,
    so the encoder goes on as if the chunk had never come (the same spikes as one that never saw it)."""
    from ddmm.models.currents import CurrentParams
    from ddmm.models.engines import NumericalInstabilityError
    from ddmm.population import make_population

    # SA-II stretched against its preferred direction: -30 mV/ms, refused at dt = 2 ms (as offline).
    pop = make_population(["SAII"] * 4, theta_t=0.0, nap="selective",
                          current=CurrentParams().with_type("SAII", opponent=1.0, gain=10.0))
    good = np.column_stack([np.linspace(0.0, 2.0, 400), np.zeros(400), np.full(400, 1.0)])  # stretch: it fires
    bad = np.column_stack([np.full(30, -5.0), np.zeros(30), np.full(30, 1.0)])
    enc, ref = (Encoder(pop, 500.0, dt=2e-3, method=method, seed=0, conditioning=None) for _ in range(2))
    outs = [enc.push(good[:150])]
    with pytest.raises(NumericalInstabilityError, match="unstable"):
        enc.push(bad)
    assert enc.n_samples == 150
    outs.append(enc.push(good[150:]))
    want = ref.push(good)
    assert want.afferent.size > 10
    np.testing.assert_array_equal(np.concatenate([o.afferent for o in outs]), want.afferent)
    np.testing.assert_array_equal(np.concatenate([o.time for o in outs]), want.time)


@pytest.mark.parametrize("threads", ["1", "2"])
def test_pushes_keep_the_profile_of_a_held_shear_direction_and_turn_with_it(monkeypatch, threads):
    """Each push range keeps its profile AF while the shear direction holds, from push to push: turning,
    holding and reversing the shear, one sample a push, gives the offline spikes, on one range or two."""
    from ddmm.models.engines import get_engine

    monkeypatch.setattr(get_engine("direct"), "parallel_min_afferents", 1)
    monkeypatch.setenv("DDMM_NUM_THREADS", threads)
    pop = sample_population("fingertip", rng=0)
    n = 600
    angle = np.r_[np.full(200, 0.3), np.linspace(0.3, 2.0, 200), np.full(200, 2.0 + np.pi)]
    mag = np.interp(np.arange(n), [0, 50, 600], [0.0, 0.6, 0.6])
    scene = Scene(mag * np.cos(angle), mag * np.sin(angle), np.interp(np.arange(n), [0, 50, 600], [0, 2, 2]),
                  1000.0, "turn")
    offline = simulate(pop, scene, engine="direct", seed=4, quiet=True)
    forces = np.column_stack([scene.fx, scene.fy, scene.fz])
    enc = Encoder(pop, 1000.0, seed=4, conditioning=None)
    aff, t = concat([enc.push(forces[k:k + 1]) for k in range(n)])
    assert aff.size > 100
    np.testing.assert_array_equal(aff, offline.spike_afferent.values)
    np.testing.assert_array_equal(t, offline.spike_time.values)


def test_a_pin_is_checked_on_the_whole_populations_skin_as_simulate_checks_it():
    """With one type selected, a probe on the fingertip's skin but farther from every FA-II than their own
    spacing allows is taken by the encoder as by `simulate`; a probe off the fingertip is refused by both."""
    from scipy.spatial import cKDTree

    from ddmm.population.stimuli.indentation import indent, probe, skin_gap_mm

    pop = sample_population("fingertip", rng=0)
    fa2 = pop.select(np.flatnonzero(pop.afferent_type == "RAII"))
    d, _ = cKDTree(np.column_stack([fa2.x_mm, fa2.y_mm])).query(np.column_stack([pop.x_mm, pop.y_mm]))
    k = int(np.argmax(d))
    assert d[k] > skin_gap_mm(fa2)  # off the FA-II's own skin, on the fingertip's
    press = np.linspace(0.0, 0.3, 200)
    on = indent(probe(float(pop.x_mm[k]), float(pop.y_mm[k])), press, fs=5000.0)
    offline = simulate(pop, on, engine="direct", afferent_types=["RAII"], seed=2, quiet=True)
    enc = Encoder(pop, 5000.0, afferent_types=["RAII"], sites=on.sites, conditioning=None, seed=2)
    out = enc.push(on.site_forces)
    np.testing.assert_array_equal(pop.afferent_id[out.afferent], offline.afferent.values[offline.spike_afferent.values])
    off = indent(probe(40.0, 40.0), press, fs=5000.0)
    for run in (lambda: simulate(pop, off, engine="direct", afferent_types=["RAII"], quiet=True),
                lambda: Encoder(pop, 5000.0, afferent_types=["RAII"], sites=off.sites, conditioning=None)):
        with pytest.raises(ValueError, match="is off the skin of population 'fingertip'"):
            run()
