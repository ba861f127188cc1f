"""The documentation stays true: its code runs, its commands parse, its reference pages match the code.

* Every ```python block of the README and of each ``docs/`` page runs, the
  blocks of one page in order in one namespace (as a reader would type
  them), in a temporary directory; a block that raises fails the suite.
* Every ``ddmm ...`` line of a ```bash block parses with the CLI's own parser
  (the commands themselves are run by their own tests).
* ``docs/cli.md`` and ``docs/api.md`` are what `ddmm.experiments.docs_reference`
  generates.
* Every figure in ``docs/`` exists and names the command that makes it.
"""

import re
import shlex
from pathlib import Path

import pytest

ROOT = Path(__file__).resolve().parent.parent
DOCS = ROOT / "docs"
PAGES = [ROOT / "README.md", *sorted(DOCS.glob("*.md"))]
BLOCK = re.compile(r"^```(python|bash)\n(.*?)^```", re.S | re.M)


def _blocks(page: Path, language: str) -> list:
    return [code for lang, code in BLOCK.findall(page.read_text()) if lang == language]


@pytest.mark.parametrize("page", [p for p in PAGES if _blocks(p, "python")], ids=lambda p: p.name)
def test_python_blocks_run(page, tmp_path, monkeypatch):
    monkeypatch.chdir(tmp_path)
    namespace = {"__name__": "__docs__"}
    for i, code in enumerate(_blocks(page, "python")):
        try:
            exec(compile(code, f"<{page.name} block {i}>", "exec"), namespace)
        except Exception as exc:
            raise AssertionError(f"{page.name}, python block {i} raised {type(exc).__name__}: {exc}") from exc


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
