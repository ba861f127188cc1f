"""The Brian2 build cache under faults: concurrent first builds, a damaged binary, an unsafe directory."""

import os
import subprocess
import sys

import numpy as np
import pytest

from ddmm.models import integrate
from ddmm.utils.cache import private_dir
from ddmm.models.engines.brian2 import engine

_RUN = """
import numpy as np
from ddmm.models import integrate
current = np.tile(np.linspace(0.0, 30.0, 7), (300, 1))
r = integrate(current, fs=1000.0, dt=1e-4, afferent_type="SAI", engine="brian2")
print(r.step.tolist(), r.afferent.tolist())
"""


def _current():
    return np.tile(np.linspace(0.0, 30.0, 7), (300, 1))


@pytest.mark.slow  # builds Brian2 projects in fresh processes: run by `pytest -m slow`
def test_two_processes_building_into_one_empty_cache_both_succeed(tmp_path):
    cache = tmp_path / "cache"
    env = dict(os.environ, DDMM_CACHE_DIR=str(cache))
    procs = [subprocess.Popen([sys.executable, "-c", _RUN], env=env, stdout=subprocess.PIPE, stderr=subprocess.PIPE,
                              text=True) for _ in range(2)]
    outs = [p.communicate(timeout=600) for p in procs]
    assert [p.returncode for p in procs] == [0, 0], [err[-2000:] for _, err in outs]
    assert outs[0][0] == outs[1][0] and outs[0][0].strip()
    direct = integrate(_current(), fs=1000.0, dt=1e-4, afferent_type="SAI", engine="direct")
    assert outs[0][0].strip() == f"{direct.step.tolist()} {direct.afferent.tolist()}"
    builds = [p for p in (cache / "brian2").iterdir() if p.is_dir() and p.name.startswith("n")]
    assert len(builds) == 1 and (builds[0] / "main.sha256").is_file()


@pytest.mark.slow  # builds Brian2 projects in fresh processes: run by `pytest -m slow`
@pytest.mark.parametrize("damage", ["truncate", "empty"])
def test_a_damaged_binary_is_rebuilt_with_a_notice(capsys, monkeypatch, damage, tmp_path):
    # A cache of its own: damaging the shared one raced another test worker running that binary
    # ("Exec format error: './main'").
    monkeypatch.setenv("DDMM_CACHE_DIR", str(tmp_path / "cache"))
    monkeypatch.setattr(engine, "_BUILDS", {})
    used = []
    activate = engine._activate
    monkeypatch.setattr(engine, "_activate", lambda key: used.append(activate(key)) or used[-1])
    first = integrate(_current(), fs=1000.0, dt=1e-4, afferent_type="SAI", engine="brian2")
    build = used[-1]
    main = build.directory / "main"
    data = main.read_bytes()
    main.write_bytes(data[: len(data) // 2] if damage == "truncate" else b"")
    capsys.readouterr()
    again = integrate(_current(), fs=1000.0, dt=1e-4, afferent_type="SAI", engine="brian2")
    err = capsys.readouterr().err
    assert "does not match its recorded digest (damaged or replaced): rebuilding it" in err
    np.testing.assert_array_equal(first.step, again.step)
    assert engine._verified(build.directory)


def test_an_unsafe_cache_directory_is_refused(tmp_path):
    shared = tmp_path / "shared"
    shared.mkdir()
    shared.chmod(0o777)
    with pytest.raises(ValueError, match="is writable by other users .*chmod go-w"):
        private_dir(shared)
    link = tmp_path / "link"
    link.symlink_to(private_dir(tmp_path / "real"))
    with pytest.raises(ValueError, match="must be a directory, not a symlink"):
        private_dir(link)
    assert oct(os.stat(private_dir(tmp_path / "new" / "deep")).st_mode & 0o777) == "0o700"


@pytest.mark.slow  # builds Brian2 projects in fresh processes: run by `pytest -m slow`
def test_a_build_killed_midway_leaves_nothing_where_the_cache_looks(tmp_path, monkeypatch):
    """Builds go to a temporary directory installed by rename: a failure midway leaves no project at the key,
    the next build sweeps what a killed one left, and installs a verified binary."""
    monkeypatch.setenv("DDMM_CACHE_DIR", str(tmp_path / "cache"))
    monkeypatch.setattr(engine, "_BUILDS", {})
    key = (8, 300, 10, 1e-4, "euler")
    directory = engine._key_dir(key)
    generate = engine._generate

    def killed(key, where, shown=None):
        (where / "half_written.o").write_bytes(b"\0" * 10)
        raise KeyboardInterrupt  # as a signal would, midway
    monkeypatch.setattr(engine, "_generate", killed)
    with pytest.raises(KeyboardInterrupt):
        engine._build(key)
    assert not directory.exists() and not list(directory.parent.glob(f".{directory.name}.build-*"))
    (directory.parent / f".{directory.name}.build-left").mkdir()  # what a SIGKILL would leave
    monkeypatch.setattr(engine, "_generate", generate)
    build = engine._build(key)
    assert build.directory == directory and engine._verified(directory)
    assert not list(directory.parent.glob(f".{directory.name}.build-*"))
    first = integrate(_current(), fs=1000.0, dt=1e-4, afferent_type="SAI", engine="brian2")
    direct = integrate(_current(), fs=1000.0, dt=1e-4, afferent_type="SAI", engine="direct")
    np.testing.assert_array_equal(first.step, direct.step)


@pytest.mark.slow  # builds Brian2 projects in fresh processes: run by `pytest -m slow`
def test_an_installed_binary_is_never_rewritten_in_place(monkeypatch, tmp_path):
    """A process whose generated project differs relinks a copy and installs it whole, with its digest: another
    process may be running the installed binary, and a binary changed in place no longer matches its digest."""
    monkeypatch.setenv("DDMM_CACHE_DIR", str(tmp_path / "cache"))
    monkeypatch.setattr(engine, "_BUILDS", {})
    first = integrate(_current(), fs=1000.0, dt=1e-4, afferent_type="SAI", engine="brian2")
    (build,) = [p for p in (tmp_path / "cache" / "brian2").iterdir() if p.is_dir() and p.name.startswith("n")]
    before = (build / "main").stat().st_ino
    generate = engine._generate

    def relinking(key, directory, shown=None):  # as make does when this process's project differs
        made = generate(key, directory, shown)
        with open(directory / "main", "ab") as f:
            f.write(b"\0")
        return made

    monkeypatch.setattr(engine, "_generate", relinking)
    monkeypatch.setattr(engine, "_BUILDS", {})
    again = integrate(_current(), fs=1000.0, dt=1e-4, afferent_type="SAI", engine="brian2")
    np.testing.assert_array_equal(first.step, again.step)
    assert engine._verified(build) and (build / "main").stat().st_ino != before


@pytest.mark.slow  # builds Brian2 projects in fresh processes: run by `pytest -m slow`
def test_fresh_processes_generate_the_same_project(tmp_path):
    """Brian2 sets the clocks' start values in a set's order; the engine's device sorts them, so a cached
    build stays as it is from process to process (it was relinked in every other process)."""
    env = dict(os.environ, DDMM_CACHE_DIR=str(tmp_path / "cache"))
    sources = []
    for _ in range(4):
        out = subprocess.run([sys.executable, "-c", _RUN], env=env, capture_output=True, text=True, timeout=600)
        assert out.returncode == 0, out.stderr[-2000:]
        (build,) = [p for p in (tmp_path / "cache" / "brian2").iterdir() if p.is_dir() and p.name.startswith("n")]
        sources.append((build / "main.cpp").read_text())
        assert "does not match its recorded digest" not in out.stderr
    assert all(s == sources[0] for s in sources)
