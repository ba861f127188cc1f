"""Accuracy against cost: error falls with dt, the tolerance choice holds on unseen workloads."""

import dataclasses
import json
import warnings

import numpy as np
import pytest

from ddmm.experiments.validation.accuracy import _compare, _run_times, measure, reference_times, workload
from ddmm.experiments.cli import main
from ddmm.models.engines import SpikeCapWarning
from ddmm.population import rotating_shear, simulate
from ddmm.population.runtime.step_choice import choose_setting, load_table

ROW_KEYS = {"dt_ms", "method", "engine", "wall_s_per_afferent_s", "sf_err_mean", "sf_err_max", "spike_time_err_ms",
            "count_mismatch", "prsi_err", "decode_err_delta_deg"}


@pytest.fixture(scope="module")
def small():
    pop, scenes = workload("fingertip", seed=0)
    pop = pop.select(np.arange(0, len(pop), 16))  # 60 afferents, 8 directions
    return pop, scenes, reference_times(pop, scenes)


@pytest.mark.parametrize("method", ["euler", "rk2"])
def test_error_falls_as_dt_shrinks(small, method):
    pop, scenes, ref = small
    with warnings.catch_warnings():
        warnings.simplefilter("ignore", SpikeCapWarning)
        rows = [measure(pop, scenes, ref, dt, method, "direct") for dt in (1.0, 0.25, 0.1, 0.025)]
    assert ROW_KEYS <= set(rows[0])
    errors = [r["sf_err_mean"] for r in rows]
    assert all(a > b for a, b in zip(errors, errors[1:])), errors
    if method == "euler":
        assert errors[2] <= 1.0  # Euler at 0.1 ms


def test_shipped_table_properties():
    rows = load_table()
    for method in ("euler", "rk2", "rk4", "izhikevich2003"):
        errs = [r["sf_err_mean"] for r in sorted((r for r in rows if r["method"] == method), key=lambda r: -r["dt_ms"])]
        assert all(a >= b for a, b in zip(errs, errs[1:])), method
    euler = {r["dt_ms"]: r for r in rows if r["method"] == "euler"}
    assert euler[0.1]["sf_err_mean"] <= 1.0


@pytest.mark.parametrize("tolerance", [0.5, 1.0, 3.0])
def test_tolerance_choice_holds_on_a_workload_it_was_not_measured_on(tolerance):
    pop, scenes = workload("fingertip", seed=3, directions=(30.0, 200.0),
                           scene=lambda d: dataclasses.replace(rotating_shear(start_deg=d), name=f"rot{d:g}"))
    pop = pop.select(np.arange(0, len(pop), 12))
    ref = reference_times(pop, scenes)
    ds = simulate(pop, scenes, engine="direct", tolerance=tolerance, seed=0, quiet=True, record=("spikes",))
    assert ds.attrs["tolerance"] == tolerance and "method=" in ds.attrs["tolerance_choice"]
    assert _compare(_run_times(ds, len(pop)), ref, pop, scenes)["sf_err_mean"] <= tolerance


def test_tolerance_bad_input(small):
    pop, scenes, _ = small
    with pytest.raises(ValueError, match="not both"):
        simulate(pop, scenes[:1], engine="direct", dt=1e-4, tolerance=1.0)
    with pytest.raises(ValueError, match="no measured setting"):
        choose_setting(1e-4, 1000.0)
    with pytest.raises(ValueError, match="tolerance"):
        choose_setting(-1.0, 1000.0)


@pytest.mark.slow  # minutes: run by `pytest -m slow`
def test_cli_accuracy_json(capsys, tmp_path):
    code = main(["accuracy", "--engines", "direct", "--dts", "0.5,0.1", "--methods", "euler", "--json",
                 "--out", str(tmp_path)])
    result = json.loads(capsys.readouterr().out)
    assert code == 0 and len(result["rows"]) == 2 and set(result["rows"][0]) == ROW_KEYS
    assert (tmp_path / "pareto.png").exists()
