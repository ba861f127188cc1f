"""Every public example in a numpydoc docstring runs and prints what it shows."""

import doctest
import importlib
import pkgutil

import pytest

PACKAGES = ("ddmm.utils", "ddmm.models", "ddmm.population", "ddmm.experiments")


def _modules():
    yield "ddmm"
    for name in PACKAGES:
        pkg = importlib.import_module(name)
        yield name
        for info in pkgutil.walk_packages(pkg.__path__, prefix=f"{name}."):
            if not info.name.endswith("__main__"):
                yield info.name


@pytest.mark.parametrize("module_name", sorted(_modules()))
def test_docstring_examples(module_name):
    module = importlib.import_module(module_name)
    finder = doctest.DocTestFinder(exclude_empty=True)
    runner = doctest.DocTestRunner(optionflags=doctest.ELLIPSIS | doctest.NORMALIZE_WHITESPACE)
    for test in finder.find(module, module_name, extraglobs={"np": __import__("numpy")}):
        runner.run(test)
    result = runner.summarize(verbose=False)
    assert result.failed == 0, f"{result.failed} docstring example(s) failed in {module_name}"


def test_packages_import_lazily_and_keep_their_names():
    """``import ddmm.population`` loads no xarray, scipy.signal, Brian2, pynwb or neo; ``simulate`` stays the function."""
    import subprocess
    import sys

    code = ("import sys, ddmm, ddmm.population; heavy = [m for m in ('xarray', 'scipy.signal', 'brian2', 'dask', 'pynwb', 'neo')"
            " if m in sys.modules];"
            "import ddmm.population.simulation; from ddmm.population import simulate, to_neo, to_nwb;"
            "print(heavy, callable(simulate) and simulate.__name__ == 'simulate',"
            " [m for m in ('pynwb', 'neo') if m in sys.modules])")  # the exporters import theirs when called
    out = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, check=True).stdout.strip()
    assert out == "[] True []"
