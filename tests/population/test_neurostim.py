"""Stimulation pulses: electrode tables, limits held over random inputs, the rules' trends, offline = streaming."""

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from ddmm.models.metrics import CONTACT_THRESHOLD
from ddmm.population import Contact, Scene, Sites, sample_population, simulate
from ddmm.population.runtime import Encoder
from ddmm.population.neurostim import (Biomimetic, Electrode, ElectrodeTable, LinearAmplitude, LinearFrequency,
                                         PulseKernel, StimulationEncoder, check_pulses, load_pulses, read_electrodes,
                                         save_pulses, stimulation_pulses)
from ddmm.population.neurostim.pulses import disc_overlap

RULES = ("biomimetic", "linear-amplitude", "linear-frequency")


def _electrode(name="E1", **field):
    field = field or {"x_mm": 0.0, "y_mm": 0.0, "radius_mm": 4.0}
    return Electrode(name, 20.0, 80.0, 200.0, 300.0, 20.0, **field)


@pytest.fixture(scope="module")
def presses():
    """Presses of 0.5-4 N on a 5 mm contact at the fingertip's centre, two trials each."""
    fs, t = 1000.0, np.arange(1500) / 1000.0
    scenes = []
    for force in (0.5, 1.0, 2.0, 4.0):
        fz, zero = np.interp(t, [0, 0.2, 1.2, 1.4], [0, force, force, 0]), np.zeros_like(t)
        scenes.append(Scene(zero, zero, fz, fs, f"press_{force:g}N", contact=Contact(0.0, 0.0, 5.0)))
    return simulate(sample_population("fingertip", rng=0), scenes, engine="direct", seed=2, trials=2, quiet=True)


# ---- electrode tables --------------------------------------------------------------------------------------

@pytest.mark.parametrize("kwargs, message", [
    ({"amplitude_max_ua": 200.0}, "16|40 nC exceeds charge_limit_nc = 20: lower amplitude_max_ua to <= 100"),
    ({"phase_width_us": 2000.0, "amplitude_max_ua": 10.0, "amplitude_min_ua": 5.0},
     "a pulse lasts 4000 us .* not shorter than 1 / max_rate_hz = 3333.33 us"),
    ({"amplitude_min_ua": 90.0}, "amplitude_min_ua = 90 exceeds amplitude_max_ua = 80"),
    ({"max_rate_hz": 0.0}, "max_rate_hz must be a finite number > 0, got 0"),
    ({"max_rate_hz": float("nan")}, "max_rate_hz must be a finite number > 0, got nan"),
    ({"amplitude_max_ua": 5e4, "charge_limit_nc": 1e4}, "amplitude_max_ua = 50000 is beyond 20000"),
    ({"region": "D2d"}, "a disc field .* or a region, not both"),
    ({"radius_mm": None}, "a field needs x_mm, y_mm and radius_mm"),
])
def test_an_electrode_whose_limits_contradict_is_refused(kwargs, message):
    base = {"id": "E1", "amplitude_min_ua": 20.0, "amplitude_max_ua": 80.0, "phase_width_us": 200.0,
            "max_rate_hz": 300.0, "charge_limit_nc": 20.0, "x_mm": 0.0, "y_mm": 0.0, "radius_mm": 4.0}
    with pytest.raises(ValueError, match=f"electrode 'E1': .*({message})"):
        Electrode(**{**base, **kwargs})


def test_tables_read_from_csv_and_toml_and_errors_name_file_line_and_field(tmp_path):
    header = "id,x_mm,y_mm,radius_mm,region,amplitude_min_ua,amplitude_max_ua,phase_width_us,max_rate_hz,charge_limit_nc\n"
    good = tmp_path / "e.csv"
    good.write_text(header + "E1,0,0,4,,20,80,200,300,20\nE2,,,,D2,10,60,100,200,10\n")
    table = read_electrodes(good)
    assert table.ids == ["E1", "E2"] and table.electrodes[1].region == "D2"
    toml = tmp_path / "e.toml"
    toml.write_text('[[electrode]]\nid = "T1"\nregion = "D1d"\namplitude_min_ua = 20\namplitude_max_ua = 80\n'
                    'phase_width_us = 200\nmax_rate_hz = 300\ncharge_limit_nc = 20\n')
    assert read_electrodes(toml).ids == ["T1"]
    for body, message in ((header + "E1,0,0,4,,20,80,200,abc,20\n", "line 2: field 'max_rate_hz': 'abc' is not a number"),
                          (header + "E1,0,0,4,,20,200,200,300,20\n", "line 2: electrode 'E1': amplitude_max_ua"),
                          (header + "E1,0,0,4,,20,80,200,300\n", "line 2: 9 fields, the header has 10"),
                          (header + "E1,0,0,4,,20,80,200,300,20\nE1,0,0,4,,20,80,200,300,20\n", "'E1' appears 2 times"),
                          ("id,foo\nE1,1\n", "line 2: field 'amplitude_min_ua' is missing")):
        bad = tmp_path / "bad.csv"
        bad.write_text(body)
        with pytest.raises(ValueError, match=f"electrode table '{bad}'.*{message}"):
            read_electrodes(bad)


HEADER = "id,x_mm,y_mm,radius_mm,region,amplitude_min_ua,amplitude_max_ua,phase_width_us,max_rate_hz,charge_limit_nc"
ROW = "E1,0,0,4,,20,80,200,300,20"
TOML = ('[[electrode]]\nregion = "D1d"\namplitude_min_ua = 20\namplitude_max_ua = 80\nphase_width_us = 200\n'
        'max_rate_hz = 300\ncharge_limit_nc = 20\n')


@pytest.mark.parametrize("name, body, message", [
    ("e.csv", f"{HEADER},amplitude_max_ua\n{ROW},90\n",
     "line 1: field 'amplitude_max_ua' is given twice \\(column 7 'amplitude_max_ua' and column 11"),
    ("e.csv", f"{HEADER},ID\n{ROW},E2\n", "line 1: field 'id' is given twice \\(column 1 'id' and column 11 'ID'"),
    ("e.toml", TOML + 'id = "T1"\nID = "T2"\n', "electrode 1: field 'id' is given twice \\('id' and 'ID'"),
])
def test_a_field_given_twice_in_any_case_is_refused_not_merged(tmp_path, name, body, message):
    path = tmp_path / name
    path.write_text(body)
    with pytest.raises(ValueError, match=f"electrode table '{path}', {message}"):
        read_electrodes(path)


@pytest.mark.parametrize("name, body, message", [
    ("e.csv", f'{HEADER}\n"E1\nE2: 999 pulses",0,0,4,,20,80,200,300,20\n', r"id 'E1\\nE2: 999 pulses' holds .* U\+000A"),
    ("e.csv", f"{HEADER}\nE1\x1b[2K,0,0,4,,20,80,200,300,20\n", r"U\+001B"),
    ("e.csv", f"{HEADER}\nE1\u202e,0,0,4,,20,80,200,300,20\n", r"U\+202E"),
    ("e.csv", f"{HEADER}\n{'E' * 65},0,0,4,,20,80,200,300,20\n", "id must be at most 64 characters, got 65"),
    ("e.csv", f'{HEADER}\nE1,,,,"D2\nE9",20,80,200,300,20\n', r"electrode 'E1': region 'D2\\nE9' holds .* U\+000A"),
    ("e.toml", TOML + 'id = "T1\\nT2"\n', r"electrode 1: electrode id 'T1\\nT2' holds .* U\+000A"),
    ("e.toml", TOML.replace("D1d", "D1\\u2028d") + 'id = "T1"\n', r"region 'D1\\u2028d' holds .* U\+2028"),
])
def test_ids_and_regions_that_cannot_print_on_one_line_are_refused(tmp_path, name, body, message):
    path = tmp_path / name
    path.write_text(body)
    with pytest.raises(ValueError, match=f"electrode table '{path}', .*{message}"):
        read_electrodes(path)


def test_a_64_character_id_prints_and_is_taken():
    assert _electrode("E" * 64).id == "E" * 64
    with pytest.raises(ValueError, match=r"electrode id must be at most 64 characters, got 1,000,000 \('EEE"):
        _electrode("E" * 1_000_000)


def test_oversized_tables_are_refused_naming_the_file_before_they_are_read(tmp_path):
    cases = {"id.csv": f"{HEADER}\n{'E' * 1_000_000},0,0,4,,20,80,200,300,20\n",  # a 1 MB id
             "open.csv": f'{HEADER}\n"E1,' + ("x" * 4000 + "\n") * 40}  # a quote left open over 160 kB
    for name, body in cases.items():
        (tmp_path / name).write_text(body)
    with open(tmp_path / "sparse.csv", "wb") as f:
        f.truncate(1 << 30)  # 1 GiB of holes: nothing to read, everything to refuse
    for name, message in (("id.csv", ", line 2: 1,000,024 characters, more than the 4,096 a table's line may hold"),
                          ("open.csv", r", line 2: not valid CSV \(field larger than field limit \(131072\): is a quote"),
                          ("sparse.csv", ": larger than the 1,048,576 bytes an electrode table may hold")):
        with pytest.raises(ValueError, match=f"electrode table '{tmp_path / name}'{message}"):
            read_electrodes(tmp_path / name)


def test_disc_overlap_is_the_area_fraction():
    assert disc_overlap(0.0, 4.0, 2.0) == 1.0 and disc_overlap(10.0, 4.0, 2.0) == 0.0
    assert disc_overlap(0.0, 2.0, 4.0) == pytest.approx(0.25)
    lens = 2 * 4 * np.arccos(0.5) - 1.0 * np.sqrt(16 - 4)  # two radius-2 discs 2 mm apart
    assert disc_overlap(2.0, 2.0, 2.0) == pytest.approx(lens / (4 * np.pi), rel=1e-9)


# ---- limits hold over random inputs ------------------------------------------------------------------------

@st.composite
def _tables(draw):
    electrodes = []
    for i in range(draw(st.integers(1, 4))):
        width = draw(st.floats(20.0, 500.0))
        rate = draw(st.floats(5.0, min(1000.0, 0.9e6 / (2 * width))))
        a_min = draw(st.floats(1.0, 100.0))
        a_max = draw(st.floats(a_min, a_min * 5))
        electrodes.append(Electrode(f"E{i}", a_min, a_max, width, rate, a_max * width * 1e-3 * draw(st.floats(1, 2)),
                                    x_mm=0.0, y_mm=0.0, radius_mm=5.0))
    return ElectrodeTable(electrodes)


def _violations(table, fs, force, times, elec, amps):
    """Every limit, checked independently of the kernel."""
    bad = []
    for e, el in enumerate(table):
        t, a = times[elec == e], amps[elec == e]
        if np.any(np.diff(t) < 1.0 / el.max_rate_hz) or np.any(np.diff(t) < el.pulse_s):
            bad.append("interval")
        if np.any(a < el.amplitude_min_ua) or np.any(a > el.amplitude_max_ua):
            bad.append("amplitude")
        if np.any(a * el.phase_width_us * 1e-3 > el.charge_limit_nc):
            bad.append("charge")
        near = [np.clip(np.floor(t * fs + d).astype(int), 0, force.shape[0] - 1) for d in (-1e-9, 1e-9)]
        if np.any((force[near[0], e] <= CONTACT_THRESHOLD) & (force[near[1], e] <= CONTACT_THRESHOLD)):
            bad.append("contact")
    return bad


@settings(max_examples=60, deadline=None)
@given(table=_tables(), rule=st.sampled_from(RULES), seed=st.integers(0, 2**32 - 1),
       fs=st.sampled_from([100.0, 1000.0, 2000.0]))
def test_every_limit_holds_for_random_tables_spikes_and_forces(table, rule, seed, fs):
    rng = np.random.default_rng(seed)
    n, n_aff = int(fs * 0.5), 40
    force = np.clip(rng.normal(0.5, 1.5, (n, 1)).cumsum(0) * 0.05, 0, None) * rng.uniform(0, 3, (1, len(table)))
    force[rng.uniform(size=n) < 0.1] = 0.0  # contact lost now and then
    samples = np.sort(rng.integers(0, n, rng.integers(0, 4000)))
    members = [np.flatnonzero(rng.uniform(size=n_aff) < 0.6) for _ in table]
    kernel = PulseKernel(table, Biomimetic(rate_sat_hz=rng.uniform(1, 50)) if rule == "biomimetic" else
                         __import__("ddmm").population.neurostim.get_rule(rule), fs, members, np.ones(n_aff))
    (t, e, a), traces = kernel.advance(force, samples, rng.integers(0, n_aff, samples.size))
    assert _violations(table, fs, force, t, e, a) == []
    assert np.all(traces[0] <= table.column("max_rate_hz")) and np.all(traces[0] >= 0)  # the commands, too


@pytest.mark.parametrize("code", [0, 1, 2])
def test_a_full_amplitude_command_never_rounds_over_the_electrode_maximum(code):
    """17.009 + (171.592 - 17.009) x 1 is 171.59200000000004 in floating point: the command must be 171.592.
    (Found by the random multi-site test: 161.667 uA reported outside [33.025, 161.667].)"""
    from ddmm.population.neurostim.pulses import _commands

    limits = np.array([[17.009, 171.592, 200.0, 100.0]])
    params = np.array([0.0, 1.0, 0.0, 0.5, 50.0, 1.0, 1.0])  # saturating rate, active fraction and force
    _, amplitude = _commands(code, 0, 5.0, 10.0, 1.0, limits, params, CONTACT_THRESHOLD)
    assert amplitude == 171.592


def test_the_last_check_drops_a_pulse_closer_than_the_rate_limit_allows():
    """Even a command over the limit (which no rule gives) cannot place two pulses too close."""
    from ddmm.population.neurostim.pulses import _KernelState, _PulseBuffers, _pulses

    out = _PulseBuffers(np.empty(100), np.empty(100, np.int64), np.empty(100), np.zeros((3, 1, 1)))
    state = _KernelState(np.zeros(1), np.zeros(1), np.full(1, -np.inf), np.zeros(1, np.int64))
    count = _pulses(0, 0.0, 0.1, 1000.0, 50.0, 1.0 / 300.0, state, out, 0)
    assert count > 10 and np.all(np.diff(out.time[:count]) >= 1.0 / 300.0)


# ---- what the rules do -------------------------------------------------------------------------------------

@pytest.mark.parametrize("rule", RULES)
def test_rate_and_amplitude_rise_with_force_and_a_field_without_contact_is_silent(presses, rule):
    table = [_electrode("centre"), _electrode("far", x_mm=0.0, y_mm=-9.0, radius_mm=2.0)]  # afferents, no contact
    pulses = stimulation_pulses(presses, table, rule)
    assert check_pulses(pulses) == [] and not np.any(pulses.pulse_electrode.values == 1)
    hold = (pulses.pulse_electrode == 0) & (pulses.pulse_time > 0.4) & (pulses.pulse_time < 1.2)
    rates, amps = [], []
    for c in range(4):
        mine = (hold & (pulses.pulse_condition == c)).values
        rates.append(mine.sum() / 0.8 / 2)
        amps.append(pulses.pulse_amplitude.values[mine].mean())
    assert rates[0] > 0 and amps[0] > 0
    assert np.all(np.diff(rates) > 0) or rule == "linear-amplitude"
    assert np.all(np.diff(amps) > 0) or rule == "linear-frequency"


@pytest.mark.parametrize("make, message", [
    (lambda: Biomimetic(tau_s=1e12), r"biomimetic: tau_s must be a finite number in \(0, 1\] s, got 1e\+12"),
    (lambda: Biomimetic(active_window_s=5.0), r"active_window_s must be a finite number in \(0, 1\] s, got 5"),
    (lambda: Biomimetic(rate_sat_hz=1e9), r"rate_sat_hz must be a finite number in \(0, 1000\] spikes/s, got 1e\+09"),
    (lambda: Biomimetic(weights=tuple((t, 0.0) for t in ("SAI", "RAI", "RAII", "SAII"))), "not all 0"),
    (lambda: Biomimetic(weights=(("SA3", 1.0),)), "SA3"),
    (lambda: Biomimetic(weights=(("SAI", -1.0),)), ">= 0"),
    (lambda: LinearAmplitude(rate_hz=0.001), r"linear-amplitude: rate_hz must be a finite number in \[1, 2000\] Hz"),
    (lambda: LinearAmplitude(force_sat_n=0.05), r"force_sat_n must be a finite number in \(0.05, 500\] N, got 0.05"),
    (lambda: LinearFrequency(force_sat_n=1e15), r"force_sat_n must be a finite number in \(0.05, 500\] N, got 1e\+15"),
])
def test_rule_settings_outside_their_physical_range_are_refused_with_it(make, message):
    with pytest.raises(ValueError, match=message):
        make()


def test_the_ends_of_each_range_are_taken():
    Biomimetic(tau_s=1.0, active_window_s=1.0, rate_sat_hz=1000.0, active_sat=1.0)
    LinearAmplitude(rate_hz=1.0, force_sat_n=500.0), LinearAmplitude(rate_hz=2000.0, force_sat_n=0.051)


@pytest.mark.parametrize("fields, named", [
    ([{"x_mm": 1000.0, "y_mm": 1000.0, "radius_mm": 5.0}], r"'E0' \(disc \(1000, 1000\) mm r 5\);"),
    ([{"region": "D9"}, {"x_mm": 0.0, "y_mm": -30.0, "radius_mm": 2.0}],
     r"'E0' \(region 'D9'\), 'E1' \(disc \(0, -30\) mm r 2\);"),
])
def test_a_table_no_field_of_which_reaches_an_afferent_or_a_site_is_refused(presses, fields, named):
    table = [_electrode(f"E{i}", **f) for i, f in enumerate(fields)]
    with pytest.raises(ValueError, match=f"no electrode of the table reaches an afferent of population "
                                         f"'fingertip' or a force site: {named} .* so no pulse could start"):
        stimulation_pulses(presses, table)
    enc = Encoder(sample_population("fingertip", rng=0), 1000.0, seed=2, conditioning=None,
                  contact=Contact(0.0, 0.0, 5.0))
    with pytest.raises(ValueError, match="no electrode of the table reaches an afferent"):
        StimulationEncoder(enc, table)


def test_one_field_off_the_skin_beside_others_warns_and_reports_no_pulse(presses):
    table = [_electrode("centre"), _electrode("off", x_mm=1000.0, y_mm=1000.0, radius_mm=5.0)]
    with pytest.warns(UserWarning, match=r"electrode\(s\) 'off' \(disc \(1000, 1000\) mm r 5\) reach no afferent"):
        pulses = stimulation_pulses(presses, table, "linear-frequency")
    assert not np.any(pulses.pulse_electrode.values == 1) and np.any(pulses.pulse_electrode.values == 0)


@settings(max_examples=6, deadline=None)
@given(cuts=st.lists(st.integers(1, 1499), max_size=15, unique=True), rule=st.sampled_from(RULES))
def test_streaming_pulses_equal_the_offline_pulses_for_any_chunking(presses, cuts, rule):
    from ddmm.population import Contact as C

    pop = sample_population("fingertip", rng=0)
    table = [_electrode("centre"), _electrode("edge", x_mm=3.0, y_mm=2.0, radius_mm=3.0)]
    fz = presses.fz.values[2]
    scene = Scene(np.zeros_like(fz), np.zeros_like(fz), fz, 1000.0, "press", contact=C(0.0, 0.0, 5.0))
    offline = stimulation_pulses(simulate(pop, scene, engine="direct", seed=2, quiet=True), table, rule)
    enc = Encoder(pop, 1000.0, seed=2, conditioning=None, contact=C(0.0, 0.0, 5.0))
    stim = StimulationEncoder(enc, table, rule)
    forces = np.column_stack([np.zeros_like(fz), np.zeros_like(fz), fz])
    edges = [0] + sorted(cuts) + [fz.size]
    outs = [stim.push(forces[a:b]) for a, b in zip(edges[:-1], edges[1:])]
    t, e = np.concatenate([o.time for o in outs]), np.concatenate([o.electrode for o in outs])
    a = np.concatenate([o.amplitude_ua for o in outs])
    order = np.lexsort((e, t))
    np.testing.assert_array_equal(t[order], offline.pulse_time.values)
    np.testing.assert_array_equal(e[order], offline.pulse_electrode.values)
    np.testing.assert_array_equal(a[order], offline.pulse_amplitude.values)


def test_trials_of_one_condition_are_encoded_apart(presses):
    """Trial 1 does not inherit trial 0's state: without trial 0's spikes its pulses are the same."""
    table = [_electrode()]
    both = stimulation_pulses(presses, table)
    alone = stimulation_pulses(presses.isel(spike=presses.spike_trial.values == 1), table)
    one = both.pulse_trial.values == 1
    np.testing.assert_array_equal(both.pulse_time.values[one], alone.pulse_time.values[alone.pulse_trial.values == 1])
    assert one.sum() > 50 and not np.any(alone.pulse_trial.values == 0)


def test_sites_place_the_force_under_each_field():
    fs, t = 1000.0, np.arange(600) / 1000.0
    press = np.interp(t, [0, 0.1, 0.6], [0, 2, 2])
    forces = np.zeros((t.size, 2, 3))
    forces[:, 0, 2] = press  # only the first site is pressed
    scene = Scene.from_sites(forces, Sites([0.0, 6.0], [0.0, 0.0], 1.5), fs, "two_sites")
    ds = simulate(sample_population("fingertip", rng=0), scene, engine="direct", seed=0, quiet=True)
    table = [_electrode("on", x_mm=0.0, y_mm=0.0, radius_mm=2.0), _electrode("off", x_mm=6.0, y_mm=0.0, radius_mm=2.0)]
    pulses = stimulation_pulses(ds, table, "linear-frequency")
    assert pulses.field_force.values[0, -1, 0] == pytest.approx(2.0) and pulses.field_force.values[0, -1, 1] == 0.0
    assert set(pulses.pulse_electrode.values.tolist()) == {0}


# ---- the file is checked --------------------------------------------------------------------------------------

def test_check_pulses_finds_tampering_and_save_refuses_it(presses, tmp_path):
    pulses = stimulation_pulses(presses, [_electrode()], "linear-amplitude")
    path = save_pulses(pulses, tmp_path / "p.nc")
    assert check_pulses(load_pulses(path)) == []
    bad = pulses.copy(deep=True)
    bad["pulse_amplitude"].values[3] = 81.0
    bad["pulse_time"].values[5] = bad["pulse_time"].values[4] + 1e-4
    bad["pulse_time"].values[0] = 1.45  # after the press ended
    problems = check_pulses(bad)
    assert any("amplitude 81" in p for p in problems) and any("under 3.33333 ms" in p for p in problems)
    assert any("no contact" in p for p in problems)
    with pytest.raises(ValueError, match="refusing to write pulses that break their limits"):
        save_pulses(bad, tmp_path / "bad.nc")
    assert not (tmp_path / "bad.nc").exists()


@settings(max_examples=8, deadline=None)
@given(table=_tables(), rule=st.sampled_from(RULES), seed=st.integers(0, 2**32 - 1))
def test_every_limit_holds_on_random_multi_site_scenes(table, rule, seed):
    """Random presses and slides on four taxels, simulated, then encoded: `check_pulses` finds nothing."""
    rng = np.random.default_rng(seed)
    n, knots = 400, np.linspace(0.0, 0.4, 6)
    t = np.arange(n) / 1000.0
    forces = np.zeros((n, 4, 3))
    for s in range(4):
        forces[:, s, 2] = np.interp(t, knots, rng.uniform(0, 2, 6) * (rng.uniform(size=6) > 0.3))
        forces[:, s, :2] = np.interp(t, knots, rng.uniform(-0.3, 0.3, 6))[:, None] * (forces[:, s, 2:3] > 0)
    forces *= ((t > 0.05) & (t < 0.3))[:, None, None]  # no contact at the start and the end
    sites = Sites(rng.uniform(-4, 4, 4), rng.uniform(-4, 4, 4), 1.5)
    pop = sample_population("fingertip", rng=0).select(np.arange(0, 991, 4))
    ds = simulate(pop, Scene.from_sites(forces, sites, 1000.0, "random"), engine="direct", seed=seed % 1000,
                  quiet=True)
    pulses = stimulation_pulses(ds, table, rule)
    assert check_pulses(pulses) == []


def test_biomimetic_weights_name_types_by_any_spelling_and_the_rest_weigh_one():
    rule = Biomimetic(weights=(("FA-II", 3.0), ("SA-I", 0.0)))
    assert rule.type_weights(["SAI", "RAI", "RAII", "SAII", "RAII"]).tolist() == [0.0, 1.0, 3.0, 1.0, 3.0]
    assert Biomimetic().type_weights(["SAI", "SAII"]).tolist() == [1.0, 1.0]


def test_a_registered_fifth_type_weighs_one_by_default(monkeypatch):
    from ddmm.models import afferent_types as registry
    from ddmm.models.afferent_types import AfferentType, register_afferent_type

    monkeypatch.setattr(registry, "_REGISTRY", dict(registry._REGISTRY))
    monkeypatch.setattr(registry, "_CODE_OF", dict(registry._CODE_OF))
    register_afferent_type(AfferentType("TOY", "TOY-I"))
    assert Biomimetic().type_weights(["TOY", "SAI"]).tolist() == [1.0, 1.0]
    assert Biomimetic(weights=(("TOY", 2.0),)).type_weights(["TOY"]).tolist() == [2.0]
