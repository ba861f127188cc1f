"""Scans and the pin lattice (`ddmm.experiments.validation.pin_lattice`): the averaged lattice silences the FA-II
that the fixed one drives, and the script's output."""

import pytest

from ddmm.experiments.validation import pin_lattice


def test_averaging_the_lattice_leaves_fa2_nothing_to_answer_on_a_shallow_cosine():
    # Every pin touches; the fixed lattice's pins under the troughs leave contact column by column at 160 Hz.
    rows = pin_lattice.lattice_responses(1, ("cosine",), (0.25,), (0.0,))
    by_lattice = {r[3]: r[4] for r in rows}
    assert by_lattice[False]["RAII"][0] > 20.0 and by_lattice[True]["RAII"][0] < 2.0
    for kind in ("SAI", "RAI"):  # the slow types barely move
        assert by_lattice[True][kind][0] == pytest.approx(by_lattice[False][kind][0], abs=3.0)
        assert by_lattice[True][kind][1] > 0.7


def test_the_script_prints_its_table_labelled_held_out(capsys):
    assert pin_lattice.main(["--surfaces", "cosine", "--pitches", "0.5", "--directions", "0"]) == 0
    out = capsys.readouterr().out.splitlines()
    assert "held out" in out[0] and len(out) == 3
    assert out[1].split()[:6] == ["cosine", "0", "deg", "pitch", "0.50", "mm"] and "fixed" in out[1]
    assert "averaged" in out[2]


def test_a_bad_pitch_exits_2_with_one_line(capsys):
    with pytest.raises(SystemExit) as info:
        pin_lattice.main(["--surfaces", "cosine", "--pitches", "-0.2", "--directions", "0"])
    assert info.value.code == 2
    err = capsys.readouterr().err
    assert err.count("\n") == 1 and "pitch_mm" in err
