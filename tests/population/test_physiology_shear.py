"""The shear protocol module (`ddmm.population.analysis.physiology_shear`) in the scorecard."""

from dataclasses import replace

import pytest

from ddmm.population.data.published import PHYSIOLOGY_REFERENCE
from ddmm.population import sample_population
from ddmm.population.analysis import physiology, physiology_shear

NAMES = list(physiology_shear.PROPERTIES)


def test_rows_are_registered_with_references_half_held_out():
    assert set(NAMES) <= set(physiology.PROPERTIES)
    assert set(physiology_shear.PROTOCOLS) <= set(physiology.PROTOCOLS)
    roles = [PHYSIOLOGY_REFERENCE[n].role for n in NAMES]
    assert roles.count("held out") >= len(roles) / 2


@pytest.fixture(scope="module")
def fingertip():
    return sample_population("fingertip", rng=0)


#: The term's candidate gains (the presets keep it off: docs/model.md, "What changed in the model").
ON = {"SAI": {"shear": 0.5, "opponent_shear": 1.0}, "RAI": {"shear": 4.0, "opponent_shear": 1.0},
      "RAII": {"shear": 1.0, "opponent_shear": 1.0}}


def _with(params, changes):
    """``params`` with ``changes`` (type -> `TypeParams` fields) applied."""
    for kind, fields in changes.items():
        params = params.with_type(kind, **fields)
    return params


def test_shear_term_passes_and_the_paper_form_fails(fingertip):
    on = replace(fingertip, current=_with(fingertip.current, ON))
    rows, _ = physiology.score_physiology(on, PHYSIOLOGY_REFERENCE, properties=NAMES, seed=0)
    assert all(r["pass"] for r in rows), [r["name"] for r in rows if not r["pass"]]
    paper = replace(fingertip, current=_with(fingertip.current, {kind: {"shear": 0.0} for kind in ON}))
    rows, _ = physiology.score_physiology(paper, PHYSIOLOGY_REFERENCE, properties=NAMES, seed=0)
    failing = {r["name"] for r in rows if not r["pass"]}
    assert {"shear_pref_SAI", "shear_ramp_RAI", "shear_dir_RAI"} <= failing


def test_sa_rows_compare_each_unit_with_its_own_normal_only_rate():
    """The median of per-unit ratios over units that fire under the normal load alone, not a ratio of medians."""
    import numpy as np

    # conditions: normal only, preferred 0.25 / 0.5 / 1 N, opposite 0.25 / 0.5 / 1 N; units: 10, 40, silent
    values = np.array([[10.0, 40.0, 0.0], [12, 40, 5], [14, 44, 5], [20, 44, 5], [8, 30, 0], [5, 20, 0], [0, 10, 0]])
    pref, opp = physiology_shear._relative(values, np.ones(3, bool))
    np.testing.assert_allclose(pref, [1.0, 1.1, 1.25, 1.55])  # medians of (1.2, 1), (1.4, 1.1), (2, 1.1)
    np.testing.assert_allclose(opp, [1.0, 0.775, 0.5, 0.125])
