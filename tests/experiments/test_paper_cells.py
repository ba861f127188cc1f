"""The paper calibration, cell by cell: Tables II-III, Fig. 8's peaks, Table IV on a recording, the fit."""

import json

import numpy as np
import pytest

from ddmm.experiments.calibration.paper import FIT_CELLS, objective, type_config
from ddmm.experiments.cli import main
from ddmm.experiments.paper.calibrations import CALIBRATIONS, FITTED_CELLS, PAPER_CALIBRATION, PAPER_OBJECTIVES
from ddmm.experiments.paper.cells import cell_keys, reproduce_cells
from ddmm.population import press_push_lift

CELL_FIELDS = {"table", "type", "profile", "row", "paper", "model", "rel_error", "role"}


@pytest.fixture(scope="module")
def paper():
    return reproduce_cells(CALIBRATIONS["paper"], FITTED_CELLS["paper"])


def _cells(result, **match):
    return [c for c in result["cells"] if all(c[k] == v for k, v in match.items())]


def test_every_cell_once_with_its_fields(paper):
    assert len(paper["cells"]) == 3 * len(cell_keys()) == 3 * 16
    assert all(set(c) == CELL_FIELDS for c in paper["cells"])
    assert {(c["type"], c["table"], c["profile"], c["row"]) for c in paper["cells"]} == {
        (t, *k) for t in ("SAI", "RAI", "RAII") for k in cell_keys()}
    assert all(set(p) == {"type", "profile", "peak_theta_t", "off_alignment_deg"} for p in paper["fig8"])


def test_roles(paper):
    """Under the paper calibration every non-symmetric cell is fitted; the rest are reproduced by symmetry."""
    for c in paper["cells"]:
        key = (c["table"], c["profile"], c["row"])
        assert c["role"] == ("fitted" if key in FIT_CELLS else "reproduced"), c
    assert len(FIT_CELLS) == 10 and {k[1] for k in FIT_CELLS if k[2] != "SF (75°)"} == {"selective", "broad"}


def test_symmetric_cells_are_reproduced_exactly(paper):
    for kind in ("SAI", "RAI", "RAII"):
        for profile in ("bipolar", "cmm"):
            assert _cells(paper, type=kind, profile=profile, row="PRSI")[0]["model"] == 0.0
            at = {c["row"]: c["model"] for c in _cells(paper, type=kind, profile=profile, table="III")}
            assert at["SF (75°)"] == at["SF (255°)"] and at["SF Diff"] == 0.0


def test_fig8_peaks_at_alignment_for_every_type_and_profile(paper):
    """A prediction (no fit sees Fig. 8): within 15 deg of theta_R = 90 (bipolar: or 270)."""
    for p in paper["fig8"]:
        if p["profile"] == "cmm":
            assert p["peak_theta_t"] is None
        else:
            assert p["off_alignment_deg"] <= 15.0, p


@pytest.mark.parametrize("kind,bound", [("RAI", 0.15), ("RAII", 0.15)])
def test_ra_cells_near_the_paper(paper, kind, bound):
    """Every non-zero RA cell of Tables II-III within 15% (docs/model.md)."""
    errors = {(c["table"], c["profile"], c["row"]): abs(c["rel_error"]) for c in _cells(paper, type=kind)
              if c["rel_error"] is not None}
    assert max(errors.values()) <= bound, errors


def test_committed_objective_matches_the_fit():
    """The committed configurations give the objectives the fit reported (docs/model.md)."""
    for kind, config in PAPER_CALIBRATION.items():
        value, _ = objective(kind, config)
        assert value == pytest.approx(PAPER_OBJECTIVES[kind], abs=5e-4), kind


def test_type_config_box():
    lo = type_config("RAII", np.zeros(6), "block", "contact_mean")
    hi = type_config("RAII", np.ones(6), "pass", "peak_bin")
    assert (lo.ramp_s, lo.lift_ramp_s, lo.shear_delay_s, lo.no_shear) == (0.1, 0.1, 0.0, "block")
    assert (hi.ramp_s, hi.lift_ramp_s, hi.sf_definition) == (4.0, 5.0, "peak_bin")
    assert hi.shear_delay_s == pytest.approx(0.9 * 4.0) and hi.current_params.type_params("RAII").cutoff_hz == 80.0
    assert type_config("RAI", np.ones(6), "block", "peak_bin").current_params.type_params("RAI").cutoff_hz == 300.0


def test_gains_only_calibration_fits_only_the_cmm_column(capsys):
    code = main(["reproduce", "table3", "--json", "--engine", "direct", "--calibration", "gains-only"])
    cells = json.loads(capsys.readouterr().out)["cells"]
    assert code == 0
    fitted = {(c["type"], c["profile"], c["row"]) for c in cells if c["role"] == "fitted"}
    assert fitted == {(t, "cmm", "SF (75°)") for t in ("SAI", "RAI", "RAII")}
    cmm = {c["type"]: c["model"] for c in cells if c["profile"] == "cmm" and c["row"] == "SF (75°)"}
    assert cmm["SAI"] == pytest.approx(47.5, rel=0.05) and cmm["RAI"] == pytest.approx(15.0, rel=0.05)


def _recording(path, fs=100.0, noise=0.005):
    """A force-plate-like press-push-lift at ``fs`` with shear toward 45 deg (the pilot's), as a CSV."""
    scene = press_push_lift(45.0, ramp_s=1.0)
    step = int(round(scene.fs / fs))
    rng = np.random.default_rng(0)
    forces = np.column_stack([scene.fx, scene.fy, scene.fz])[::step] + rng.normal(0.0, noise, (len(scene.fz[::step]), 3))
    forces[:, 2] = np.maximum(forces[:, 2], 0.0)
    t = np.arange(len(forces)) / fs
    np.savetxt(path, np.column_stack([t, forces]), delimiter=",", header="time,fx,fy,fz", comments="")
    return path


def test_table4_on_a_recording(capsys, tmp_path):
    path = _recording(tmp_path / "pilot.csv")
    code = main(["reproduce", "table4", "--scene", str(path), "--json", "--engine", "direct"])
    captured = capsys.readouterr()
    assert "ddmm: warning: " in captured.err and "100 Hz" in captured.err  # one line, naming --types
    cells = json.loads(captured.out)["cells"]
    assert code == 0 and len(cells) == 3 * 4 * 5 and {c["role"] for c in cells} == {"prediction"}
    sf = {(c["type"], c["profile"], c["row"]): c["model"] for c in cells}
    # shear toward 45 deg: a selective SA-I tuned to 75 deg fires more than one tuned to 225 deg
    assert sf[("SAI", "selective", "SF (75°)")] > sf[("SAI", "selective", "SF (225°)")]
    assert sf[("SAI", "cmm", "SF (75°)")] == sf[("SAI", "cmm", "SF (255°)")] > 0


@pytest.mark.parametrize("argv,match", [
    (["reproduce", "table4"], "ddmm reproduce table4 needs --scene FILE.csv"),
    (["reproduce", "table2", "--scene", "x.csv"], "--scene goes with 'ddmm reproduce table4' only"),
    (["reproduce", "table4", "--scene", "missing.csv"], "missing.csv"),
])
def test_table4_errors_are_one_line(capsys, argv, match):
    code = main(argv + ["--engine", "direct"])
    err = capsys.readouterr().err
    assert code == 2 and match in err and err.count("\n") == 1, err


def test_table4_refuses_a_recording_that_never_reaches_contact(capsys, tmp_path):
    """A light touch that stays at 0.04 N would give a table of zeros: SF is the mean rate in contact."""
    t = np.arange(3000) / 1000.0
    path = tmp_path / "light.csv"
    np.savetxt(path, np.column_stack([t, 0 * t, 0 * t, 0.04 + 0 * t]), delimiter=",", header="time,fx,fy,fz",
               comments="")
    code = main(["reproduce", "table4", "--scene", str(path), "--engine", "direct"])
    captured = capsys.readouterr()
    errors = [line for line in captured.err.splitlines() if line.startswith("ddmm: error: ")]
    assert code == 2 and not captured.out and len(errors) == 1, captured
    assert f"recording '{path}' never reaches contact" in errors[0] and "contact threshold 0.05 N" in errors[0]


@pytest.mark.slow
def test_the_fit_reproduces_the_committed_ra_i_setting():
    """``ddmm calibrate --target paper`` for RA-I (its chosen reading and SF definition) gives the committed values."""
    from ddmm.experiments.calibration.paper import fit_type

    committed = PAPER_CALIBRATION["RAI"]
    fit = fit_type("RAI", committed.no_shear, committed.sf_definition, seed=0)
    assert fit["config"].current_params.gain("RAI") == committed.current_params.gain("RAI")
    assert (fit["config"].ramp_s, fit["config"].lift_ramp_s) == (committed.ramp_s, committed.lift_ramp_s)
    assert (fit["config"].current_params.type_params("RAI").cutoff_hz
            == committed.current_params.type_params("RAI").cutoff_hz)
