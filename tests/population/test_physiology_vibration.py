"""Phase locking to vibration (`ddmm.population.analysis.physiology_vibration`): rows, helpers, the paper's drive."""

import dataclasses

import numpy as np
import pytest

from ddmm.population.data.published import PHYSIOLOGY_REFERENCE
from ddmm.population import sample_population
from ddmm.population.analysis import physiology_vibration as vib
from ddmm.population.analysis.physiology import PROPERTIES, score_physiology

ROWS = ["vs_RAI", "locked_RAI", "vs_2f_ratio_RAI", "vs_RAI_2N", "locked_RAI_2N", "vs_2f_ratio_RAI_2N"]


@pytest.fixture(scope="module")
def fingertip():
    return sample_population("fingertip", rng=0)


def test_rows_are_registered_and_half_are_held_out():
    assert set(ROWS) <= set(PROPERTIES)
    roles = [PHYSIOLOGY_REFERENCE[n].role for n in ROWS]
    assert roles.count("held out") >= len(ROWS) / 2


def test_the_presets_lock_and_the_papers_drive_does_not(fingertip):
    rows, data = score_physiology(fingertip, PHYSIOLOGY_REFERENCE, properties=ROWS, seed=0)
    assert all(r["pass"] for r in rows), [(r["name"], r["value"]) for r in rows]
    assert data["phase_locking"]["RAI"]["phases"].size > 100
    # The paper's |dF_A/dt| with the old smoothing (tau 30 ms, i_max 100) locks to 2f, not to f.
    paper = fingertip.current.with_type("RAI", negative_weight=1.0, tau_s=0.03, i_max=100.0)
    rows, _ = score_physiology(dataclasses.replace(fingertip, current=paper), PHYSIOLOGY_REFERENCE,
                               properties=ROWS, seed=0)
    values = {r["name"]: r["value"] for r in rows}
    assert not any(r["pass"] for r in rows), values
    assert values["vs_RAI"] < 0.5 and values["vs_2f_ratio_RAI"] > 1.0


def test_vector_strength_and_threshold_search():
    assert vib.vector_strength([], 10.0) != vib.vector_strength([], 10.0)  # nan without spikes
    spikes = 0.1 + np.arange(8) / 20.0 + 0.001  # one per cycle of 20 Hz in 0.1-0.5 s
    assert vib.vector_strength(spikes, 20.0) == pytest.approx(1.0)
    assert vib.vector_strength(spikes, 20.0, 2) == pytest.approx(1.0)
    both = np.sort(np.r_[spikes, spikes + 0.025])  # both half-cycles: locked to 2f only
    assert vib.vector_strength(both, 20.0) == pytest.approx(0.0, abs=1e-12)
    assert vib.vector_strength(both, 20.0, 2) == pytest.approx(1.0)


@pytest.mark.parametrize("first", ["ddmm.population.analysis.physiology_vibration",
                                   "ddmm.population.analysis.physiology_fields",
                                   "ddmm.population.analysis.physiology"])
def test_registration_holds_in_either_import_order(first):
    import subprocess
    import sys

    code = (f"import importlib; importlib.import_module({first!r}); "
            "from ddmm.population.analysis import physiology as ph; "
            "print(ph.PROTOCOLS.count('phase_locking'), 'vs_RAI' in ph.PROPERTIES, 'field_growth_RAI' in ph.PROPERTIES)")
    out = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, check=True).stdout
    assert out.split() == ["1", "True", "True"]
