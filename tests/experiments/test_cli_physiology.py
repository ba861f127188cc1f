"""``ddmm physiology``: JSON shape, figures, one-line errors."""

import json

from ddmm.experiments.cli import main


def run(capsys, *argv):
    code = main([str(a) for a in argv])
    out = capsys.readouterr()
    return code, out.out, out.err


def test_json_shape_and_figures(capsys, tmp_path):
    code, out, _ = run(capsys, "physiology", "--properties", "rest_rate_RAI,best_frequency_RAII,continuity",
                       "--json", "--out", tmp_path)
    assert code == 0
    result = json.loads(out)
    assert set(result) == {"properties", "all_pass"}
    assert [p["name"] for p in result["properties"]] == ["rest_rate_RAI", "best_frequency_RAII", "continuity"]
    assert {"name", "type", "value", "low", "high", "source", "role", "pass"} <= set(result["properties"][0])
    assert result["all_pass"] is True
    assert {"scorecard.json", "rest.png", "frequency_tuning.png"} <= {p.name for p in tmp_path.iterdir()}


def test_table_marks_roles(capsys):
    code, out, _ = run(capsys, "physiology", "--properties", "rest_rate_SAII,force_coding_SAI")
    assert code == 0
    assert "| rest_rate_SAII | SA-II | rest |" in out and "constrained" in out and "held out" in out
    assert out.strip().splitlines()[-1].startswith("physiology: 2/2 properties pass")


def test_bad_input_is_one_line_and_exit_2(capsys, tmp_path):
    code, _, err = run(capsys, "physiology", "--properties", "resting")
    assert code == 2 and err.count("\n") == 1 and "unknown property 'resting'" in err
    spec = tmp_path / "sa_only.toml"
    spec.write_text('[types.SAI]\ncount = 5\n')
    code, _, err = run(capsys, "physiology", "--population", spec, "--properties", "best_frequency_RAII")
    assert code == 2 and err.count("\n") == 1 and "needs RAII afferents" in err
