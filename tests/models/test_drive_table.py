"""The drive's rules per afferent (`ddmm.models.drive_table.DriveTable`): each read from the type's registry entry and
parameters, on the package's types and on toy types registered here."""

import numpy as np
import pytest

from ddmm.models import afferent_types as registry
from ddmm.models import variability
from ddmm.models.afferent_types import AfferentType, register_afferent_type
from ddmm.models.current_params import CurrentParams
from ddmm.models.drive_table import DriveTable
from ddmm.models.type_params import TypeParams

TYPES = np.array(["SAI", "RAI", "RAII", "SAII"])  # three pressure types, then the stretch type
PRESSURE, STRETCH, EVERY, NONE = [True] * 3 + [False], [False] * 3 + [True], [True] * 4, [False] * 4


@pytest.mark.parametrize("changes, rule, expected", [
    ({}, "stretch", STRETCH),
    ({"depth": 0.5}, "shallow", PRESSURE),  # a stretch drive takes no depth
    ({"shear": 0.3}, "shear_gained", PRESSURE),  # nor a shear-magnitude term
    ({"bias": 1.0}, "biased", EVERY),
    ({"normal": 0.4}, "normal_driven", STRETCH),  # only a stretch drive reads TypeParams.normal
    ({"excite_cv": 0.1}, "excitable", EVERY),
    ({"phase": 0.5}, "phase_spread", STRETCH),  # only SA-II is AfferentType.phase_spread
])
def test_each_rule_reads_its_field_and_its_mechanism(changes, rule, expected):
    table = DriveTable.of(TYPES, CurrentParams().with_all_types(**changes))
    assert getattr(table, rule).tolist() == expected
    off = DriveTable.of(TYPES, CurrentParams())  # the package's defaults switch every departure off
    assert getattr(off, rule).tolist() == (STRETCH if rule == "stretch" else NONE)
    assert table.type_index.tolist() == [0, 1, 2, 3]


def test_one_type_changed_changes_only_its_afferents():
    table = DriveTable.of(np.array(["RAI", "SAI", "RAI"]), CurrentParams().with_type("RAI", depth=0.2, bias=0.5))
    assert table.shallow.tolist() == table.biased.tolist() == [True, False, True]


def test_the_bias_multiplier_is_each_units_by_its_types_spread():
    params = CurrentParams().with_type("SAI", bias_cv=0.2).with_type("SAII", bias_cv=0.4)
    table = DriveTable.of(TYPES[[0, 1, 3, 0]], params)
    ids = np.array([3, 3, 9, 11])
    m = table.bias_multiplier(ids)
    assert m[1] == 1.0 and table.bias_cv.tolist() == [0.2, 0.0, 0.4, 0.2]
    np.testing.assert_array_equal(m[[0, 3]], variability.bias_multiplier(0.2, ids[[0, 3]]))
    assert m[2] == variability.bias_multiplier(0.4, [9])[0] and m[0] != m[3]  # keyed by the unit's id
    np.testing.assert_array_equal(DriveTable.of(TYPES, CurrentParams()).bias_multiplier(np.arange(4)), np.ones(4))


FACTS = {"max_shear": 0.0, "pressed": True, "loaded": True, "computes_af": True, "af_constant": 1.0}
BLOCKED = {"computes_af": False, "af_constant": 0.0}  # no_shear="block" with the AF stage skipped: AF = 0


@pytest.mark.parametrize("code, changes, scene, given, expected", [
    ("SAI", {}, {}, {}, False),  # pressed: F_A > 0
    ("SAI", {}, {"pressed": False}, {}, True),  # nothing presses: rectified F_A is 0
    ("SAI", {}, {}, {"scale": 0.0}, True),  # out of the field, or no gain
    ("SAI", {}, BLOCKED, {}, True),  # AF = 0 throughout
    ("SAI", {}, BLOCKED, {"tuned": False}, False),  # an untuned afferent's AF is 1
    ("SAI", {"depth": 0.5}, BLOCKED, {}, False),  # half the normal force is not attenuated
    ("SAI", {"shear": 0.3}, {"pressed": False, "max_shear": 1.0}, {}, False),  # the shear term drives it
    ("SAI", {"shear": 0.3}, {"pressed": False}, {}, True),  # ... only with shear
    ("SAI", {}, {"pressed": False}, {"noise_sigma": 0.5}, False),  # additive noise
    ("SAI", {"bias": 0.5}, {"pressed": False}, {}, False),  # a tonic current
    ("SAI", {"excite_cv": 0.3}, {"pressed": False}, {}, True),  # a factor on zero is zero
    ("SAII", {}, {}, {}, True),  # no shear, no stretch
    ("SAII", {}, {"max_shear": 1.0}, {}, False),
    ("SAII", {}, {"max_shear": 1.0}, {"scale": 0.0}, True),
    ("SAII", {"normal": 0.4}, {}, {}, False),  # its drive reads the normal force
    ("SAII", {"normal": 0.4}, {"loaded": False}, {}, True),
    ("SAII", {"bias": 0.5}, {}, {}, False),
    ("SAII", {}, {}, {"noise_sigma": 0.5}, False),
])
def test_quiet_is_the_identically_zero_current(code, changes, scene, given, expected):
    table = DriveTable.of(np.array([code]), CurrentParams().with_type(code, **changes))
    arrays = {"scale": 1.0, "noise_sigma": 0.0, "tuned": True, **given}
    quiet = table.quiet(*(np.array([arrays[k]]) for k in ("scale", "noise_sigma", "tuned")), **{**FACTS, **scene})
    assert quiet.tolist() == [expected]


def test_the_af_is_read_by_tuned_afferents_whose_drive_it_shapes():
    params = CurrentParams().with_type("RAI", shear=0.3)
    table = DriveTable.of(np.array(["SAI", "RAI", "SAII", "SAI"]), params)
    tuned = np.array([True, True, True, False])
    assert table.reads_af(tuned, 0.0, True).tolist() == [True, False, False, False]  # shear drives read no AF
    assert table.reads_af(tuned, 1.0, False).tolist() == [False, True, True, False]  # AF constant for F_A
    assert table.reads_af(tuned, 1.0, True).tolist() == [True, True, True, False]


def test_what_varies_by_trial():
    params = CurrentParams().with_type("RAI", excite_cv=0.2).with_all_types(phase=0.5)
    table = DriveTable.of(np.array(["SAI", "SAI", "SAI", "RAI", "SAII"]), params)
    varies = table.varies_by_trial(np.array([0.0, 0.3, 0.0, 0.0, 0.0]), np.array([0.0, 0.0, 0.1, 0.0, 0.0]))
    assert varies.tolist() == [False, True, True, True, True]  # SA-I's phase is inert: not a phase-spread type


@pytest.fixture
def toys(monkeypatch):
    """Two toy types in a copy of the registry: a stretch drive with a phase spread, and a shallow pressure type."""
    monkeypatch.setattr(registry, "_REGISTRY", dict(registry._REGISTRY))
    monkeypatch.setattr(registry, "_CODE_OF", dict(registry._CODE_OF))
    register_afferent_type(AfferentType("TOYS", "TOY-S", stretch_drive=True, log_compression=False, phase_spread=True,
                                        current=TypeParams(normal=0.5, phase=0.3, bias=0.2, depth=0.5)))
    register_afferent_type(AfferentType("TOYP", "TOY-P", current=TypeParams(depth=0.5, bias_cv=0.1, excite_cv=0.2)))


def test_a_registered_type_brings_its_rules_and_an_unknown_one_is_refused(toys):
    table = DriveTable.of(np.array(["TOYS", "TOYP", "SAI"]), CurrentParams())
    assert table.type_index.tolist() == [4, 5, 0]
    assert table.stretch.tolist() == table.normal_driven.tolist() == table.phase_spread.tolist() \
        == [True, False, False]
    assert table.biased.tolist() == [True, False, False]
    assert table.shallow.tolist() == table.excitable.tolist() == [False, True, False]
    assert table.bias_cv.tolist() == [0.0, 0.1, 0.0]
    with pytest.raises(ValueError, match="'NOPE' is not a registered type"):
        DriveTable.of(np.array(["SAI", "NOPE"]), CurrentParams())


def test_take_keeps_each_afferents_rules_and_the_arrays_are_read_only():
    table = DriveTable.of(TYPES, CurrentParams().with_type("RAII", shear=0.3))
    kept = table.take(np.array([3, 2]))
    assert kept.stretch.tolist() == [True, False] and kept.shear_gained.tolist() == [False, True]
    assert kept.type_index.tolist() == [3, 2]
    with pytest.raises(ValueError, match="read-only"):
        table.stretch[0] = True
    mine = np.zeros(1, dtype=bool)
    DriveTable(*([np.zeros(1, dtype=int)] + [mine] * 7 + [np.zeros(1)]))
    assert mine.flags.writeable  # the caller's array is left as it was
