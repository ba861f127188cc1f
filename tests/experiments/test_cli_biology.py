"""ddmm tuning / decode / calibrate: JSON shapes, figures, targets."""

import json

import numpy as np
import pytest

from ddmm.experiments.calibration.presets import spec_to_toml
from ddmm.experiments.cli import main
from ddmm.experiments.validation.decoding import run_decoding, summarise
from ddmm.population import load_spec, spec_from_dict


def run(capsys, *argv):
    code = main([str(a) for a in argv])
    out = capsys.readouterr()
    return code, out.out, out.err


def test_tuning_json_and_figures(capsys, tmp_path):
    code, out, _ = run(capsys, "tuning", "--population", "fingertip", "--seed", "2", "--json", "--out", tmp_path)
    assert code == 0
    result = json.loads(out)
    assert set(result["tuned_fraction"]) == {"all", "recorded", "SAI", "RAI", "RAII", "SAII"}
    assert set(result["dsi"]["SAI"]) == {"mean", "sd"} and "reference" in result
    assert {"tuning.json", "dsi_histograms.png", "preferred_directions.png"} <= {p.name for p in tmp_path.iterdir()}


def test_tuning_prints_its_table(capsys):
    """The text path (a strict type label once broke it on the pooled rows)."""
    code, out, err = run(capsys, "tuning", "--population", "fingertip", "--seed", "2", "--trials", "3")
    assert code == 0, err
    assert "| SA-I + SA-II + FA-I | " in out and "| all four types | " in out and "| FA-II | " in out


def test_decode_json_shape(capsys, tmp_path):
    code, out, _ = run(capsys, "decode", "--seed", "1", "--train", "40", "--test", "20", "--subsets", "1",
                       "--json", "--out", tmp_path)
    assert code == 0
    result = json.loads(out)
    assert set(result["errors"]) == {"population_vector", "maximum_likelihood", "first_spike_latency"}
    by_window = result["errors"]["maximum_likelihood"]
    assert list(by_window) == ["25", "50", "100", "125", "250"]
    assert list(by_window["125"]) == ["10", "30", "100", "300", "991"]
    assert set(by_window["125"]["991"]) == {"median_deg", "p90_deg"} and "reference" in result
    assert (tmp_path / "neurometric.png").stat().st_size > 10_000


def test_full_fingertip_decodes_within_human_threshold_in_125_ms():
    summary = summarise(run_decoding("fingertip", seed=5, n_train=120, n_test=60, windows_ms=(125,), sizes=(None,)))
    best = min(d["125"]["991"]["median_deg"] for d in summary["errors"].values())
    assert best <= 7.1


def test_bad_decode_options(capsys):
    code, _, err = run(capsys, "decode", "--train", "0")
    assert code == 2 and "--train" in err


@pytest.mark.parametrize("name", ["fingertip", "hand"])
def test_calibrated_spec_round_trips_through_toml(name):
    spec = load_spec(name)
    import tomllib
    again = spec_from_dict(tomllib.loads(spec_to_toml(spec)))
    assert again.current == spec.current and again.n_afferents() == spec.n_afferents()
    assert again.map == spec.map and again.region == spec.region
    assert again.receptive_field == spec.receptive_field  # a calibrated preset once lost its tailed fields
    assert again.neuron == spec.neuron
    for kind in spec.types:
        assert again.types[kind].nap == pytest.approx(spec.types[kind].nap)


@pytest.mark.slow
def test_calibration_reproduces_the_committed_preset():
    from ddmm.experiments.calibration.presets import calibrate

    spec, report = calibrate()
    committed = load_spec("fingertip")
    assert spec.current.type_params("SAI").i_sat == pytest.approx(committed.current.type_params("SAI").i_sat, rel=0.02)
    assert spec.types["RAI"].nap["none"] == pytest.approx(committed.types["RAI"].nap["none"], abs=0.01)
    assert np.isclose(report["validation"]["mean_sd"]["tuned_fraction.recorded"][0], 0.86, atol=0.03)
    assert all(v["all_pass"] for v in report["validation"]["scorecard_all_pass"].values())


def test_decode_torque_json_shape_and_the_100_ms_claim(capsys):
    code = main(["decode", "--task", "torque", "--trials", "6", "--subsets", "1", "--json"])
    out = capsys.readouterr().out
    assert code == 0
    result = json.loads(out)
    assert result["task"] == "torque" and result["role"] == "prediction"
    row = next(r for r in result["results"] if r["window_ms"] == 100 and len(r["types"]) == 4
               and r["n_afferents"] == 991)
    assert set(row) >= {"window_ms", "n_afferents", "types", "accuracy"} and row["accuracy"] >= 0.95


def test_decode_slip_json_reports_latency_and_false_alarms(capsys):
    code = main(["decode", "--task", "slip", "--trials", "4", "--subsets", "1", "--population", "fingertip",
                 "--json"])
    result = json.loads(capsys.readouterr().out)
    assert code == 0 and result["task"] == "slip"
    assert all({"latency_ms", "false_alarms_per_s", "accuracy"} <= set(r) for r in result["results"])
    full = [r for r in result["results"] if len(r["types"]) == 4 and r["n_afferents"] == 991]
    assert all(r["latency_ms"] is not None and r["latency_ms"] < 74.0 for r in full)


def test_decode_task_bad_input(capsys):
    assert main(["decode", "--task", "torque", "--trials", "1"]) == 2
    assert "--trials must be >= 2" in capsys.readouterr().err
    with pytest.raises(SystemExit) as exc:
        main(["decode", "--task", "spin"])
    assert exc.value.code == 2
