"""The documentation stays true: its code runs, its commands parse, its reference pages match the code.

* Each page is followed as a reader would, in a fresh directory: every
  ```python block runs **on its own** in a new interpreter (no namespace is
  shared, so each block carries its imports and data), and must print what
  it claims; every ```bash block runs as written with the installed ``ddmm``
  on the PATH, after the quick start.  A block preceded by
  ``<!-- file: NAME -->`` is written to NAME first (a table the page shows
  and the commands after it read).
* A block that cannot run here is marked before its fence and still parsed:
  ``<!-- not run: REASON -->`` (it needs a second process, stdin, a live
  device or data the project cannot ship), ``<!-- two processes -->`` (run
  by its own test, tests/experiments/test_cli_lsl.py) and ``<!-- slow -->``
  (run by ``pytest -m slow``).
* Every ``ddmm ...`` line of a ```bash block parses with the CLI's own parser.
* ``docs/cli.md`` and ``docs/api.md`` are what `ddmm.experiments.docs_reference`
  generates.
* Every figure in ``docs/`` exists and names the command that makes it.
"""

import ast
import os
import re
import shlex
import subprocess
import sys
from dataclasses import dataclass
from pathlib import Path

import pytest

ROOT = Path(__file__).resolve().parent.parent
DOCS = ROOT / "docs"
PAGES = [ROOT / "README.md", *sorted(DOCS.glob("*.md"))]
FENCE = re.compile(r"^(?:<!-- (?P<mark>[^\n]*?) -->\n)?```(?P<lang>\w*)\n(?P<code>.*?)^```", re.S | re.M)
SKIP_MARKS = ("not run: ", "two processes")
NOT_RUN_REASONS = ("a second process", "stdin", "a live device", "data the project cannot ship", "the quick start")


@dataclass(frozen=True)
class Block:
    lang: str
    mark: str
    code: str


def _fenced(page: Path) -> list:
    return [Block(m["lang"], m["mark"] or "", m["code"]) for m in FENCE.finditer(page.read_text())]


def _blocks(page: Path, language: str) -> list:
    return [b.code for b in _fenced(page) if b.lang == language]


def _runs(block: Block, slow: bool) -> bool:
    if block.lang not in ("python", "bash") or block.mark.startswith(SKIP_MARKS):
        return False
    return (block.mark == "slow") == slow


def _env() -> dict:
    bin_dir = str(Path(sys.executable).parent)  # `ddmm` and `python` as after the quick start
    return {**os.environ, "PATH": f"{bin_dir}{os.pathsep}{os.environ['PATH']}", "MPLBACKEND": "Agg",
            "DDMM_PROGRESS": "0"}


def _run_block(page: Path, i: int, block: Block, cwd: Path) -> None:
    where = f"{page.name}, {block.lang} block {i}"
    if block.lang == "python":
        script = cwd / f"block_{i}.py"
        script.write_text(block.code)
        argv = [sys.executable, script.name]
    else:
        argv = ["bash", "-euo", "pipefail", "-c", block.code]
    done = subprocess.run(argv, cwd=cwd, env=_env(), capture_output=True, text=True, timeout=1800)
    assert done.returncode == 0, f"{where} failed (exit {done.returncode}):\n{done.stderr[-3000:]}"
    if block.lang == "python":
        assert done.stdout.strip(), f"{where} prints nothing: a block shows what it claims"
        claims = re.findall(r"#\s*(True|False)\s*$", block.code, re.M)  # a line that says what it prints
        assert claims == re.findall(r"\b(True|False)\b", done.stdout)[:len(claims)], (where, done.stdout)


def _follow(page: Path, cwd: Path, slow: bool) -> None:
    for i, block in enumerate(_fenced(page)):
        name = re.fullmatch(r"file: (\S+)", block.mark)
        if name:
            (cwd / name.group(1)).write_text(block.code)
        elif _runs(block, slow):
            _run_block(page, i, block, cwd)


@pytest.mark.parametrize("page", [p for p in PAGES if any(_runs(b, False) for b in _fenced(p))],
                         ids=lambda p: p.name)
def test_each_block_runs_as_written(page, tmp_path):
    _follow(page, tmp_path, slow=False)


@pytest.mark.slow
@pytest.mark.parametrize("page", [p for p in PAGES if any(_runs(b, True) for b in _fenced(p))],
                         ids=lambda p: p.name)
def test_slow_blocks_run_as_written(page, tmp_path):
    _follow(page, tmp_path, slow=True)


def test_blocks_not_run_are_marked_with_a_reason_and_parse():
    marked = [(p, b) for p in PAGES for b in _fenced(p) if b.lang in ("python", "bash") and b.mark]
    assert marked, "no marked block: the marks' parser broke"
    for page, block in marked:
        assert block.mark in ("slow", "two processes") or block.mark.startswith("not run: "), (page.name, block.mark)
        if block.mark.startswith("not run: "):
            assert block.mark[len("not run: "):].startswith(NOT_RUN_REASONS), (page.name, block.mark)
        if block.lang == "python":
            ast.parse(block.code)
        else:
            done = subprocess.run(["bash", "-n", "-c", block.code], capture_output=True, text=True)
            assert done.returncode == 0, (page.name, done.stderr)


def _ddmm_commands(page: Path) -> list:
    """The ``ddmm`` invocations of a page's bash blocks, each cut at a pipe, redirection or comment."""
    commands = []
    for code in _blocks(page, "bash"):
        for line in code.splitlines():
            for part in line.split("&&"):
                words = shlex.split(re.split(r"\s[|<>#&]|^#", part)[0].strip())
                if words and Path(words[0]).name == "ddmm":
                    commands.append(words[1:])
    return commands


@pytest.mark.parametrize("page", [p for p in PAGES if _ddmm_commands(p)], ids=lambda p: p.name)
def test_ddmm_commands_parse(page):
    from ddmm.experiments.cli import build_parser

    parser = build_parser()
    for argv in _ddmm_commands(page):
        try:
            parser.parse_args(argv)
        except SystemExit as exc:
            raise AssertionError(f"{page.name}: `ddmm {shlex.join(argv)}` does not parse") from exc


def test_the_docs_have_code():
    assert sum(len(_blocks(p, "python")) for p in PAGES) >= 8
    assert any(_ddmm_commands(p) for p in PAGES)


@pytest.mark.parametrize("name", ["cli.md", "api.md"])
def test_reference_pages_match_the_code(name):
    from ddmm.experiments.docs_reference import api_reference, cli_reference

    generated = {"cli.md": cli_reference, "api.md": api_reference}[name]()
    assert (DOCS / name).read_text() == generated, (
        f"docs/{name} is stale: run `python -m ddmm.experiments.docs_reference`")


def test_module_map_matches_the_code():
    from ddmm.experiments.docs_reference import with_module_map

    page = (DOCS / "development.md").read_text()
    assert with_module_map(page) == page, "docs/development.md's module map is stale: run " \
                                          "`python -m ddmm.experiments.docs_reference`"


def _dotted(path: Path) -> str:
    parts = path.relative_to(ROOT).with_suffix("").parts
    parts = parts[1:] if parts[0] == "ddmm" else parts
    return ".".join(("ddmm", *(p for p in parts if p != "__init__")))


def test_module_map_names_every_module():
    """Independently of the generator: every source file but a deprecated alias or a ``__main__`` is on the map."""
    page = (DOCS / "development.md").read_text()
    files = [f for top in ("ddmm/utils", "models", "population", "experiments") for f in (ROOT / top).rglob("*.py")
             if f.name != "__main__.py" and not f.read_text().lstrip().startswith('"""Deprecated alias')]
    missing = sorted(_dotted(f) for f in files if f"`{_dotted(f)}`" not in page)
    assert len(files) > 100 and not missing, missing


def test_figures_exist_and_name_their_command():
    for page in [ROOT / "README.md", *DOCS.glob("*.md")]:
        lines = page.read_text().splitlines()
        for i, line in enumerate(lines):
            for figure in re.findall(r"!\[[^\]]*\]\(([^)]+\.png)\)", line):
                assert (page.parent / figure).exists(), f"{page.name}: {figure} is missing"
                caption = " ".join(lines[i + 1:i + 4])
                assert re.search(r"made by `ddmm [^`]*--out", caption), (
                    f"{page.name}: {figure} does not name the `ddmm ... --out` command that makes it")


def test_readme_stays_short():
    assert len((ROOT / "README.md").read_text().splitlines()) <= 250


def test_ci_runs_the_readme_test_line_no_more_and_no_less():
    quick_start = _blocks(ROOT / "README.md", "bash")[0].strip().splitlines()
    ci = (ROOT / ".ci" / "run").read_text().strip().splitlines()
    assert ci[-1] == quick_start[1] and "pytest -m slow" in ci[-1]
