"""The package as a user installs it: one import name, a layout that shows the architecture.

* ``ddmm`` is the only top-level name: a script and ``ddmm simulate`` run
  from a folder holding its own ``models``, ``population`` and
  ``experiments`` packages (common in ML projects) still work.
* ``ddmm --version`` answers; the installed packages are the folders.
* No exported name equals a submodule's name (importing the submodule would
  replace the name on its package); no caller compares engine names.
* No tracked file points outside the repository.
"""

import ast
import importlib
import os
import subprocess
import sys
import tomllib
from pathlib import Path

import pytest

import ddmm

ROOT = Path(__file__).resolve().parent.parent
SOURCE_DIRS = ("models", "population", "experiments")


def _env_for_subprocess() -> dict:
    """The environment a user's process gets: ``ddmm`` importable as this test imports it, nothing else."""
    where = Path(ddmm.__file__).resolve().parent.parent  # site-packages, or a source checkout's root
    env = dict(os.environ, PYTHONPATH=str(where))
    env.pop("PYTHONSAFEPATH", None)
    return env


@pytest.fixture
def crowded_cwd(tmp_path):
    """A working directory with the user's own ``models/``, ``population/``, ``experiments/`` and ``models.py``."""
    for name in SOURCE_DIRS:
        (tmp_path / name).mkdir()
        (tmp_path / name / "__init__.py").write_text("raise ImportError('the user\\'s own package was imported')\n")
    (tmp_path / "helpers").mkdir()
    (tmp_path / "helpers" / "models.py").write_text("raise ImportError('the user\\'s models.py was imported')\n")
    return tmp_path


def test_script_runs_beside_the_users_own_models_package(crowded_cwd):
    script = crowded_cwd / "run.py"
    script.write_text(
        "import ddmm\n"
        "from ddmm.population import birznieks, sample_population, simulate\n"
        "pop = sample_population('fingertip', rng=0).select(range(30))\n"
        "ds = simulate(pop, birznieks(90.0), engine='direct', seed=0, quiet=True)\n"
        "print(int(ds.sizes['afferent']), ddmm.__version__ != '')\n")
    out = subprocess.run([sys.executable, str(script)], cwd=crowded_cwd, env=_env_for_subprocess(),
                         capture_output=True, text=True, timeout=300)
    assert out.returncode == 0, out.stderr
    assert out.stdout.split() == ["30", "True"]


def test_cli_simulate_runs_beside_the_users_own_packages(crowded_cwd):
    out = subprocess.run([sys.executable, "-m", "ddmm", "simulate", "--population", "fingertip", "--engine", "direct",
                          "--quiet", "--out", "run.nc"], cwd=crowded_cwd, env=_env_for_subprocess(),
                         capture_output=True, text=True, timeout=300)
    assert out.returncode == 0, out.stderr
    assert (crowded_cwd / "run.nc").stat().st_size > 0


def test_version(capsys):
    from ddmm.experiments.cli import main

    with pytest.raises(SystemExit) as stop:
        main(["--version"])
    assert stop.value.code == 0
    assert capsys.readouterr().out.strip() == f"ddmm {ddmm.__version__}"


def _source_packages() -> set:
    found = {"ddmm"}
    for top in SOURCE_DIRS:
        for init in (ROOT / top).rglob("__init__.py"):
            found.add("ddmm." + ".".join(init.parent.relative_to(ROOT).parts))
    return found


def test_pyproject_installs_every_source_package():
    config = tomllib.loads((ROOT / "pyproject.toml").read_text())["tool"]["setuptools"]
    assert set(config["packages"]) == _source_packages()
    assert config["package-dir"] == {"ddmm": "ddmm", **{f"ddmm.{d}": d for d in SOURCE_DIRS}}


@pytest.mark.parametrize("package", sorted(p for p in _source_packages()))
def test_exported_names_never_equal_submodule_names(package):
    pkg = importlib.import_module(package)
    submodules = {p.stem for p in Path(pkg.__file__).parent.glob("*.py")} | \
                 {p.parent.name for p in Path(pkg.__file__).parent.glob("*/__init__.py")}
    clash = set(getattr(pkg, "__all__", ())) & (submodules - {"__init__"})
    assert not clash, f"{package} exports names that are also its submodules: {sorted(clash)}"
    for name in getattr(pkg, "__all__", ()):
        getattr(pkg, name)  # every exported name resolves


def test_no_caller_compares_engine_names():
    """Engines are registered objects (`ddmm.models.engines.registry`): the library never compares a name to pick one.

    (Benchmarks and figures in ``experiments/`` may label results by engine name.)
    """
    offenders = []
    for path in [*(ROOT / "models").rglob("*.py"), *(ROOT / "population").rglob("*.py")]:
        for node in ast.walk(ast.parse(path.read_text())):
            if isinstance(node, ast.Compare):
                for side in (node.left, *node.comparators):
                    if isinstance(side, ast.Constant) and side.value in ("direct", "brian2"):
                        offenders.append(f"{path.relative_to(ROOT)}:{node.lineno}")
    assert not offenders, offenders


def test_no_tracked_file_points_outside_the_repository():
    files = subprocess.run(["git", "ls-files"], cwd=ROOT, capture_output=True, text=True).stdout.split()
    if not files:
        pytest.skip("not a git checkout")
    outside = ("../" + "shared", "DDMM-" + "NOTES", "PHYSIOLOGY" + ".md")  # spelled so this file is no hit
    offenders = []
    for name in files:
        path = ROOT / name
        if path.suffix in {".png", ".nc", ".npz", ".h5"} or not path.is_file():
            continue
        text = path.read_text(errors="replace")
        if any(token in text for token in outside):
            offenders.append(name)
    assert not offenders, offenders
