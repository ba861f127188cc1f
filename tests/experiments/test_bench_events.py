"""``ddmm bench --cases events``: latency from the event (contact, release, shear), on a few afferents at 1 kHz."""

import json
import math
import os
import sys

import numpy as np
import pytest

from ddmm.experiments.bench import events
from ddmm.experiments.bench.cases import EVENT_CASES, GROUPS
from ddmm.experiments.cli import main


@pytest.fixture(scope="module")
def case():
    """The 1 kHz case on 30 afferents of each type, one press (10 N/s to 3 N), no shear step."""
    from ddmm.population import sample_population

    pop = sample_population("fingertip", rng=0)
    few = np.concatenate([np.flatnonzero(pop.afferent_type == t)[:30] for t in ("SAI", "RAI", "RAII", "SAII")])
    return events.event_case("events_1khz", pop=pop.select(few), presses=((10.0, 3.0),), shear=False)


def test_events_of_an_analytic_ramp():
    # 4 N/s from 0.1 s: F_Z(k) = 4 (k / fs - 0.1) reaches 30 mN at 0.1075 s, between samples
    f = events.press_release(1000.0, 4.0, 1.0, pre_s=0.1, hold_s=0.5, post_s=0.1)
    assert events.contact_events(f[:, 2]) == (108, 1093)  # down from 0.85 s: below 30 mN after 1.0925 s
    assert events.fall_sample(f[:, 2]) == 1088  # F_Z <= 0.05 N for good from 1.0875 s
    slow = events.press_release(100.0, 4.0, 1.0, pre_s=0.1, hold_s=0.5, post_s=0.1)
    assert events.contact_events(slow[:, 2])[0] == 11
    assert events.contact_events([0.0, 0.02, 0.03, 0.5, 0.03, 0.029]) == (2, 5)  # >= 30 mN is contact
    shear, start = events.shear_step(1000.0)
    assert start == 1000 and events.shear_event(shear, start) == 1001  # 100 N/s from 1.0 s: 30 mN at 1.0003 s
    step = np.array([[0.5, 0.0, 2.0], [0.5, 0.0, 2.0], [0.0, 0.625, 2.0], [0.0, 0.75, 2.0]])  # |F_T| 0.5 N held
    assert events.shear_event(step, 1, threshold_n=0.25) == 3  # the magnitude, and a change of exactly the threshold


def test_the_off_path_reads_the_samples_as_a_recording_with_no_conditioning():
    from ddmm.population.stimuli import resample_unconditioned
    x = np.column_stack([np.zeros(12), np.zeros(12), np.arange(12.0)])
    np.testing.assert_allclose(resample_unconditioned(x[:3], 100.0, 1000.0)[:, 2], np.arange(21) / 10.0)
    np.testing.assert_array_equal(resample_unconditioned(x, 5000.0, 1000.0)[:, 2], [0.0, 5.0, 10.0])
    np.testing.assert_array_equal(resample_unconditioned(x, 1000.0, 1000.0), x)


def test_bad_settings_are_refused_by_name():
    with pytest.raises(ValueError, match="rate_n_per_s"):
        events.press_release(1000.0, -2.0, 1.0)
    with pytest.raises(ValueError, match="fs_hz"):
        events.bound_ms(0.0)
    with pytest.raises(ValueError, match="name must be one of"):
        events.event_case("events_2khz")
    assert events.bound_ms(100.0) == 12.0 and events.bound_ms(1000.0) == events.bound_ms(5000.0) == 5.0


def test_first_spikes_are_each_afferents_first_within_the_window():
    got = events.first_spikes([0, 0, 1, 2, 1], [0.09, 0.105, 0.103, 0.3, 0.101], np.array(["SAI", "RAI", "RAI"]),
                              event_s=0.1)
    assert got["SA-I"] == {"median_ms": 5.0, "n": 1}  # 0.09 s is before the event
    assert got["FA-I"] == {"median_ms": 1.0, "n": 1}  # afferent 2 fired 200 ms after: outside the window
    assert got["FA-II"] == {"median_ms": None, "n": 0}


def test_the_off_path_fires_at_contact_after_the_event(case):
    contact = next(e for e in case["events"] if e["event"] == "contact")
    for label in ("SA-I", "FA-I"):
        first = contact["paths"]["off"]["first_spike"][label]
        assert first["n"] > 0 and 0.0 < first["median_ms"] < events.WINDOW_S * 1e3 and math.isfinite(first["median_ms"])
    assert contact["paths"]["off"]["detected_ms"] == 0.0  # at 1 kHz the model sees the event's own sample


def test_the_case_json_shape(case):
    back = json.loads(json.dumps(case))
    assert back["label"] == events.LABEL and back["bound_ms"] == 5.0 and back["n_afferents"] == 120
    assert [e["event"] for e in back["events"]] == ["contact", "release"]
    for e in back["events"]:
        assert set(e) >= {"profile", "event", "event_sample", "event_s", "paths", "difference_ms", "within_bound"}
        for path in ("default", "off"):
            p = e["paths"][path]
            assert set(p) == {"detected_ms", "first_spike", "pulse_ms"}
            assert set(p["first_spike"]) == {"SA-I", "FA-I", "FA-II", "SA-II"}
        assert set(e["within_bound"]) >= {"detected_ms", "FA-I"}
    assert "last_pulse" in back["events"][1]["within_bound"]
    text = "\n".join(events.format_event_case(case))
    assert events.LABEL in text and "bound 5 ms" in text and "| press 10 N/s to 3 N | contact | default |" in text


def test_the_group_is_one_registry_entry(monkeypatch):
    from ddmm.experiments.bench import runner

    assert GROUPS["events"] == EVENT_CASES and set(EVENT_CASES) == {*events.RATES, "events_lsl"}
    ran = []
    monkeypatch.setattr(runner, "_subprocess_case", lambda name: ran.append(name) or {"name": name})
    runner.run_bench(["events"])
    assert ran == list(EVENT_CASES)


def test_cli_takes_the_group_and_refuses_an_unknown_name_in_one_line(monkeypatch, capsys, case):
    from ddmm.experiments.bench import runner

    asked = []
    monkeypatch.setattr(runner, "run_bench", lambda cases: asked.append(cases) or
                        {"cases": [case, {"name": "events_lsl", "skipped": "no pylsl"}], "ratios": {}, "one_time": {}})
    assert main(["bench", "--cases", "events"]) == 0 and asked == [["events"]]
    out = capsys.readouterr().out
    assert out.startswith("events_1khz: input 1000 Hz") and "events_lsl: skipped: no pylsl" in out
    assert main(["bench", "--cases", "events", "--json"]) == 0
    assert json.loads(capsys.readouterr().out)["cases"][0]["name"] == "events_1khz"
    assert main(["bench", "--cases", "events,nope"]) == 2
    err = capsys.readouterr().err
    assert "'nope' is unknown" in err and "events" in err and err.count("\n") == 1


def test_the_lsl_case_says_it_was_skipped_without_pylsl(monkeypatch):
    monkeypatch.setitem(sys.modules, "pylsl", None)
    monkeypatch.delenv("LSLAPICFG", raising=False)
    got = events.lsl_event_case()
    assert got["name"] == "events_lsl" and "pylsl / liblsl not importable" in got["skipped"]
    assert "LSLAPICFG" not in os.environ  # the loopback config is the case's own
    monkeypatch.setenv("LSLAPICFG", "/elsewhere.cfg")
    assert "skipped" in events.lsl_event_case() and os.environ["LSLAPICFG"] == "/elsewhere.cfg"
    assert events.format_event_case(got)[0].startswith("events_lsl: skipped: pylsl / liblsl not importable")
