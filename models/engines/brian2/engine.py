"""The Brian2 engine: eqs 4-6 in Brian2's C++ standalone mode, compiled once per shape.

Design (measured on this machine kind, see docs/user-guide.md, "Engines"):

* **Standalone, built once per shape.**  A project is generated for a padded
  shape ``(n_neurons, n_samples)`` plus dt, substeps and method, compiled
  once and cached on disk (``$DDMM_CACHE_DIR/brian2/<key>``, default
  ``~/.cache/ddmm``).  Calls that change only input values re-run the same
  binary: the initial v, u and r and the per-neuron a, b, c, d, n_ref with Brian2's
  ``run_args``, and the current table (a file the binary maps, named in
  its environment), so nothing recompiles.  A one-line notice is printed
  whenever a shape is compiled.
* **Inputs at the force rate.**  The current is sampled at ``fs`` and held
  for ``substeps`` steps: a ``run_regularly`` operation at ``1/fs`` copies
  the table's row into ``I_in``, which the state update reads.  The table
  is read by ``ddmm_input`` (`ddmm.models.engines.brian2.device.input_function`), a
  Brian2 function with a C++ body that memory-maps the lane's file, where
  a `TimedArray` would copy it into fresh memory on every run.
* **Same arithmetic as the direct engine.**  The project is compiled without
  ``-ffast-math`` and with ``-ffp-contract=off`` (no fused multiply-adds),
  and `ddmm.models.engines.direct` mirrors the generated expressions.
* **Padding is exact.**  Extra neurons get zero current and are dropped;
  extra samples come after the end and their spikes are dropped.  The state
  at the true end is captured in ``v_end, u_end, r_end`` by the same operation when
  ``t`` reaches ``t_end`` (a run argument), before the padded steps run.
* **Lanes: runs in parallel.**  The binary is run directly (as Brian2's
  ``device.run`` does, but without changing the process's working
  directory), each concurrent caller in its own *lane* (`ddmm.models.engines.brian2.lanes`):
  its own input files and ``--results_dir``, kept and rewritten in place
  from run to run.  Two blocks in flight then integrate on two cores; only
  generating and compiling a project is serialised, across processes too
  (a file lock beside the project).
* **A cache that can be trusted.**  The key includes the CPU the binary is
  compiled for (``-march=native``); the binary's SHA-256 is recorded when it
  is built and checked before every run (a mismatch is rebuilt, with one
  line saying so); the cache directory must be private (`ddmm.utils.cache.private_dir`).
* **Bounded tables.**  Runs are cut into time chunks of at most 2**25
  table elements (256 MB).
"""

from __future__ import annotations

import dataclasses
import gc
import hashlib
import logging
import os
import platform
import shutil
import subprocess
import sys
import tempfile
import threading
import warnings
from contextlib import contextmanager
from dataclasses import dataclass
from pathlib import Path

import numpy as np

from ddmm.models.engines.brian2.lanes import lane, write_table
from ddmm.models.neuron import V_FLOOR, refractory_steps
from ddmm.utils.cache import cache_root, private_dir

__all__ = ["run_brian2", "cache_dir", "import_brian2", "Brian2Warning"]

_COMPILE_ARGS = ["-w", "-O3", "-ffp-contract=off", "-march=native", "-std=c++11"]
_TEMPLATE_VERSION = "5"  # bump when the generated network changes
_NEURON_QUANTUM = 32  # neuron padding granularity
_SAMPLE_QUANTUM = 250  # sample padding granularity
_MAX_ELEMENTS = 1 << 25  # current table elements per run: 256 MB

_ODE = """
dv/dt = (0.04*v**2 + 5*v + 140 - u + I_in)/ms : 1
du/dt = a*(b*v - u)/ms : 1
"""
# Izhikevich (2003) is not a Brian2 state updater: v and u are plain variables
# updated by explicit code, two half-steps of v, then u from the new v.
_STATE = """
v : 1
u : 1
"""
_IZHIKEVICH_2003 = """v = v + 0.5*(dt/ms)*(0.04*v**2 + 5*v + 140 - u + I_in)
v = v + 0.5*(dt/ms)*(0.04*v**2 + 5*v + 140 - u + I_in)
u = u + (dt/ms)*(a*(b*v - u))"""
# Forward Euler with the floor in the same pass (one loop over the neurons
# instead of Brian2's state updater and then a floor operation).  Written so
# that Brian2 generates the very expressions of its "euler" updater (the
# order of the terms matters): the arithmetic, and the spikes, are the same.
_EULER_FLOORED = """_u_next = dt*(a*(b*v - u))/ms + u
v = clip(dt*(I_in + 0.04*v**2 + 5*v + 140 - u)/ms + v, {floor!r}, inf)
u = _u_next"""
_VARIABLES = """
I_in : 1
v_end : 1
u_end : 1
r_end : 1
t_end : second (shared)
a : 1
b : 1
c : 1
d : 1
r : 1
n_ref : 1
"""
# The absolute refractory period (`NeuronParams.t_ref`): after the update and
# the floor, a neuron with steps left keeps v at c and counts down.  The
# selection by products with 0 and 1 is exact for finite values, so v is the
# direct engine's (which branches) bit for bit.
_REFRACTORY = """_free = int(r < 0.5)
v = _free*v + (1 - _free)*c
r = clip(r - 1, 0, inf)"""


def cache_dir() -> Path:
    """Root of the on-disk Brian2 build cache (``$DDMM_CACHE_DIR`` or ``~/.cache/ddmm``)."""
    return cache_root() / "brian2"


def _cpu_identity() -> str:
    """What ``-march=native`` compiles for: the machine, the CPU model and a digest of its feature flags."""
    identity = platform.machine()
    try:
        lines = Path("/proc/cpuinfo").read_text().splitlines()
    except OSError:
        return identity + " " + platform.processor()
    field = {k.strip(): v.strip() for k, _, v in (line.partition(":") for line in lines) if k.strip()
             in ("model name", "flags")}
    return f"{identity} {field.get('model name', '')} {hashlib.sha256(field.get('flags', '').encode()).hexdigest()[:12]}"


def _digest(path: Path) -> str:
    return hashlib.sha256(path.read_bytes()).hexdigest()


def _verified(directory: Path) -> bool:
    """Whether the compiled binary is there and matches the digest recorded when it was built."""
    main, recorded = directory / "main", directory / "main.sha256"
    try:
        return recorded.read_text().strip() == _digest(main)
    except OSError:
        return False


@contextmanager
def _build_lock(directory: Path):
    """An exclusive lock on ``directory``'s build, across processes (a file lock beside it)."""
    import fcntl

    fd = os.open(directory.parent / f"{directory.name}.lock", os.O_RDWR | os.O_CREAT | getattr(os, "O_NOFOLLOW", 0),
                 0o600)
    try:
        fcntl.flock(fd, fcntl.LOCK_EX)
        yield
    finally:
        os.close(fd)  # releases the lock


def _record_digest(directory: Path) -> None:
    tmp = directory / f".main.sha256.{os.getpid()}"
    tmp.write_text(_digest(directory / "main") + "\n")
    os.replace(tmp, directory / "main.sha256")


@dataclass(frozen=True)
class _Build:
    """A generated and compiled standalone project: where it is and what its files are called."""

    key: tuple
    directory: Path
    n_neurons: int
    n_samples: int
    results: dict  # result name ("i", "t", "v", "u", "v_end", "u_end") -> file name in a results dir


_BUILDS: dict = {}  # key -> _Build, for this process
_LOCK = threading.RLock()  # Brian2's device is process-global: one build at a time
_DEVICE: list = []  # the EngineDevice, made on the first build


def _pad(n: int, quantum: int) -> int:
    return max(quantum, -(-n // quantum) * quantum)


def _key_dir(key: tuple) -> Path:
    brian2 = import_brian2()

    from ddmm.models.engines.brian2 import device

    # What the project is generated from: our templates and C++ (not the module's prose).
    ours = [p.read_bytes() for p in sorted((Path(__file__).parent / "templates").glob("*.cpp"))]
    ours += [device._INPUT_CPP, device._PER_STEP, device._AFTER_LOOP, device._ONCE]
    text = repr((key, brian2.__version__, _COMPILE_ARGS, _cpu_identity(), _TEMPLATE_VERSION, _ODE, _VARIABLES,
                 _IZHIKEVICH_2003, _EULER_FLOORED, _REFRACTORY, ours))
    digest = hashlib.sha256(text.encode()).hexdigest()[:16]
    n_neurons, n_samples, substeps, dt, method = key
    return private_dir(cache_dir()) / f"n{n_neurons}_t{n_samples}_s{substeps}_{method}_{digest}"


class Brian2Warning(RuntimeWarning):
    """A warning Brian2 logged while building or running the engine."""


class _LogToWarnings(logging.Handler):
    """Re-issue Brian2's logged warnings as Python warnings (filterable, testable)."""

    def emit(self, record):
        warnings.warn(Brian2Warning(f"Brian2 ({record.name}): {record.getMessage()}"), stacklevel=2)


_QUIETED = False


def import_brian2():
    """Import Brian2 without letting it take over the process's warnings and logging.

    On import Brian2 calls ``logging.captureWarnings(True)``, which reroutes
    every Python warning of the process into its log (a user's
    ``catch_warnings`` and our own `SpikeCapWarning` would vanish); that is
    undone here.  Brian2's own warnings become `Brian2Warning`s instead of
    console lines, and its error banner and script copies are switched off.
    """
    global _QUIETED
    import brian2

    if not _QUIETED:
        from brian2.utils.logger import BrianLogger

        logging.captureWarnings(False)
        brian2.prefs["logging.display_brian_error_message"] = False
        brian2.prefs["logging.save_script"] = False
        if BrianLogger.console_handler is not None:
            BrianLogger.console_handler.setLevel(logging.ERROR)
        logging.getLogger("brian2").addHandler(_LogToWarnings(level=logging.WARNING))
        _QUIETED = True
    return brian2


@contextmanager
def _brian2_prefs():
    """Set the preferences the build needs, restoring the user's afterwards."""
    brian2 = import_brian2()

    saved = {
        "codegen.cpp.extra_compile_args_gcc": list(brian2.prefs["codegen.cpp.extra_compile_args_gcc"]),
        "devices.cpp_standalone.openmp_threads": brian2.prefs["devices.cpp_standalone.openmp_threads"],
    }
    brian2.prefs["codegen.cpp.extra_compile_args_gcc"] = list(_COMPILE_ARGS)
    brian2.prefs["devices.cpp_standalone.openmp_threads"] = 0
    try:
        yield brian2
    finally:
        for name, value in saved.items():
            brian2.prefs[name] = value


def _device():
    """The process's `ddmm.models.engines.brian2.device.EngineDevice` (Brian2's standalone device, two loops cheaper)."""
    if not _DEVICE:
        from ddmm.models.engines.brian2.device import EngineDevice

        _DEVICE.append(EngineDevice())
    return _DEVICE[0]


def _build(key: tuple) -> _Build:
    """Generate (and if needed compile) the standalone project for ``key``, one process at a time.

    A cached binary whose digest does not match the one recorded when it was
    built (truncated, emptied, replaced) is removed and rebuilt, with one line
    saying so.
    """
    directory = _key_dir(key)
    with _build_lock(directory):
        for stale in directory.parent.glob(f".{directory.name}.build-*"):  # a killed build's leftovers
            shutil.rmtree(stale, ignore_errors=True)
        if _verified(directory):
            return _regenerate(key, directory)
        if (directory / "main").exists():
            print(f"ddmm: the cached Brian2 binary {directory / 'main'} does not match its recorded digest "
                  "(damaged or replaced): rebuilding it", file=sys.stderr, flush=True)
        return _install(key, directory)


def _regenerate(key: tuple, directory: Path) -> _Build:
    """This process's project for an installed, intact build, generated into a copy of it.

    Usually ``make`` finds nothing to do and the copy is dropped.  When this
    process's project differs (Brian2 named an object apart because another
    of that name is alive here), ``make`` relinks ``main``: the copy is then
    installed by an atomic rename with its digest, so an installed binary is
    never rewritten in place (another process may be running it, and its
    recorded digest would no longer match).
    """
    tmp = Path(tempfile.mkdtemp(prefix=f".{directory.name}.build-", dir=directory.parent))
    try:
        shutil.copytree(directory, tmp / "project", symlinks=True)  # copy2 keeps the times make compares
        build = _generate(key, tmp / "project", shown=directory)
        if _digest(tmp / "project" / "main") == _digest(directory / "main"):
            return dataclasses.replace(build, directory=directory)
        _record_digest(tmp / "project")
        aside = Path(tempfile.mkdtemp(prefix=f".{directory.name}.build-", dir=directory.parent))
        os.replace(directory, aside / "old")
        os.replace(tmp / "project", directory)
        shutil.rmtree(aside, ignore_errors=True)
        return dataclasses.replace(build, directory=directory)
    finally:
        shutil.rmtree(tmp, ignore_errors=True)


def _install(key: tuple, directory: Path) -> _Build:
    """Build into a fresh temporary directory and install it by an atomic rename: a build killed midway
    leaves no half-built project where the cache looks (only a temporary directory the next build sweeps)."""
    tmp = Path(tempfile.mkdtemp(prefix=f".{directory.name}.build-", dir=directory.parent))
    try:
        build = _generate(key, tmp, shown=directory)
        _record_digest(tmp)
        if directory.exists():  # damaged, or an older layout: move it aside first (rename is atomic)
            aside = Path(tempfile.mkdtemp(prefix=f".{directory.name}.build-", dir=directory.parent))
            os.replace(directory, aside / "old")
            shutil.rmtree(aside, ignore_errors=True)
        os.replace(tmp, directory)
    except BaseException:
        shutil.rmtree(tmp, ignore_errors=True)
        raise
    return dataclasses.replace(build, directory=directory)


def _generate(key: tuple, directory: Path, shown: Path | None = None) -> _Build:
    """Generate the project into ``directory`` and compile what is missing (``make`` skips what is current).

    ``shown``: the directory the notice names (where the build is installed), default ``directory``.
    """
    n_neurons, n_samples, substeps, dt, method = key
    compiled = (directory / "main").exists()
    if not compiled:
        print(
            f"ddmm: compiling the Brian2 engine for {n_neurons} neurons x {n_samples} samples "
            f"(dt={dt * 1e3:g} ms, {method}); once per shape, cached in {shown or directory} (--engine direct gives the "
            f"same spikes with no compile)",
            file=sys.stderr,
            flush=True,
        )
    with _brian2_prefs() as b2:
        from ddmm.models.engines.brian2.device import input_function

        standalone = _device()
        standalone.reinit()  # forget the previously built project, if any
        # Brian2 names objects uniquely among those alive; once the previous
        # build is gone, this build reuses the cached project's exact names
        # (a stale name would become "..._1" and force a full recompile).
        gc.collect()
        b2.set_device(standalone, directory=str(directory), build_on_run=False)
        fs = 1.0 / (dt * substeps)
        ddmm_input = input_function(n_samples, n_neurons, fs)
        explicit = method in ("izhikevich2003", "euler")
        group = b2.NeuronGroup(
            n_neurons, (_STATE if explicit else _ODE) + _VARIABLES, threshold="v >= 30", reset="v = c; u += d; r = n_ref",
            method=None if explicit else method, dt=dt * b2.second, name="afferents", namespace={"ms": b2.ms},
        )
        if method == "euler":
            group.run_regularly(_EULER_FLOORED.format(floor=V_FLOOR), when="groups", name="afferents_euler")
        else:
            if explicit:
                group.run_regularly(_IZHIKEVICH_2003, when="groups", name="afferents_izhikevich2003")
            group.run_regularly(f"v = clip(v, {V_FLOOR!r}, inf)", when="before_thresholds", name="afferents_floor")
        group.run_regularly(_REFRACTORY, when="before_thresholds", order=1, name="afferents_refractory")
        # Hold the current for one sample; when t reaches t_end (the end of the
        # real input) copy the state, which later padded steps then overwrite.
        code = (
            "I_in = ddmm_input(t, i)\n"
            f"at_end = int(abs(t - t_end) < {0.5 / fs!r}*second)\n"
            "v_end = at_end*v + (1 - at_end)*v_end\n"
            "u_end = at_end*u + (1 - at_end)*u_end\n"
            "r_end = at_end*r + (1 - at_end)*r_end"
        )
        group.run_regularly(code, dt=(1.0 / fs) * b2.second, when="start")
        for var, value in (("a", 0.02), ("b", 0.2), ("c", -65.0), ("d", 8.0), ("v", -70.0),
                           ("u", -14.0), ("v_end", -70.0), ("u_end", -14.0), ("r", 0.0), ("n_ref", 0.0),
                           ("r_end", 0.0)):
            setattr(group, var, value)
        group.t_end = n_samples * substeps * dt * b2.second
        monitor = b2.SpikeMonitor(group, name="spikes")
        net = b2.Network(group, monitor)
        net.run(n_samples * substeps * dt * b2.second, namespace={"ddmm_input": ddmm_input, "ms": b2.ms})
        standalone.build(directory=str(directory), run=False, with_output=False)
        b2.set_device("runtime")  # leave the user's Brian2 in its default mode
        results = {name: standalone.get_array_filename(owner.variables[name])
                   for owner, names in ((group, ("v", "u", "r", "v_end", "u_end", "r_end")), (monitor, ("i", "t")))
                   for name in names}
    return _Build(key, directory, n_neurons, n_samples, results)


def _activate(key: tuple) -> _Build:
    """The build of ``key``: a `_Build` holds only paths and names, so every shape met stays ready."""
    with _LOCK:
        build = _BUILDS.get(key)
        if build is None or not _verified(build.directory):  # checked before every run: ~0.1 ms for ~90 kB
            build = _BUILDS[key] = _build(key)
        return build


def _run_binary(build: _Build, lane: Path, table: Path, run_args: list) -> Path:
    """Run the compiled binary in ``lane`` on the current ``table``; return its results directory."""
    from ddmm.models.engines.brian2.device import TABLE_ENV

    results = lane / "results"
    env = dict(os.environ, LD_BIND_NOW="1", **{TABLE_ENV: str(table)})  # LD_BIND_NOW: Brian2's run environment
    proc = subprocess.run(["./main", "--results_dir", f"{results}{os.sep}", *run_args], cwd=build.directory,
                          env=env, stdout=subprocess.DEVNULL, stderr=subprocess.PIPE, text=True, check=False)
    # Brian2 reports a run argument's file of the wrong size only on stderr (exit 0, defaults used).
    if proc.returncode or "Error" in proc.stderr:
        raise RuntimeError(f"the Brian2 binary failed (exit {proc.returncode}) in {build.directory}: "
                           f"{proc.stderr.strip()[-500:]}")
    return results


def _run_chunk(build: _Build, lane: Path, current, params, v, u, r):
    """Run the compiled binary once on a padded chunk; return spikes and final state."""
    n_real = current.shape[1]
    files = {}
    n_ref = refractory_steps(params["t_ref"], build.key[3])
    for name, arr, fill in (("v", v, -70.0), ("u", u, -14.0), ("r", r, 0.0), ("a", params["a"], 0.02),
                            ("b", params["b"], 0.2), ("c", params["c"], -65.0), ("d", params["d"], 8.0),
                            ("n_ref", n_ref, 0.0)):
        full = np.full(build.n_neurons, fill)
        full[:n_real] = arr
        files[f"afferents.{name}"] = full
    t_end = current.shape[0] * build.key[2] * build.key[3]  # samples * substeps * dt, in s
    run_args = [f"afferents.t_end={t_end!r}"]
    table = lane / "ddmm_current.dat"
    write_table(table, current, build.n_samples, build.n_neurons)
    for target, arr in files.items():  # absolute paths: Brian2 reads a value where one starts with a digit
        path = lane / f"{target}.dat"
        arr.tofile(path)
        run_args.append(f"{target}={path}")
    results = _run_binary(build, lane, table, run_args)
    read = {name: np.fromfile(results / fname, dtype=np.int32 if name == "i" else np.float64)
            for name, fname in build.results.items()}
    neuron = read["i"].astype(np.int64)
    step = np.rint(read["t"] / build.key[3]).astype(np.int64)
    keep = neuron < n_real
    padded_tail = current.shape[0] < build.n_samples
    names = ("v_end", "u_end", "r_end") if padded_tail else ("v", "u", "r")
    return (neuron[keep], step[keep], *(read[name][:n_real] for name in names))


def run_brian2(current, substeps, dt, params, v, u, r=None, method="euler", v_peak=30.0, v_floor=V_FLOOR):
    """Integrate eqs 4-6 for N neurons with Brian2 (same contract as `run_direct`).

    ``v``, ``u`` and ``r`` (refractory steps left; None: zeros) are updated
    in place to the final state.  Returns ``(neuron, step)`` int64 arrays
    sorted by step then neuron.
    """
    if v_peak != 30.0 or v_floor != V_FLOOR:
        raise ValueError(f"the Brian2 engine is built for v_peak = 30 and v_floor = {V_FLOOR} mV")
    r = np.zeros(current.shape[1]) if r is None else r
    params = params if "t_ref" in params else {**params, "t_ref": np.zeros(current.shape[1])}
    with lane() as path:
        return _run_lanes(path, current, substeps, dt, params, v, u, r, method)


def _run_lanes(lane, current, substeps, dt, params, v, u, r, method):
    n_samples_total, n_neurons = current.shape
    n_pad = _pad(n_neurons, _NEURON_QUANTUM)
    chunk = max(_SAMPLE_QUANTUM, (_MAX_ELEMENTS // n_pad) // _SAMPLE_QUANTUM * _SAMPLE_QUANTUM)
    t_pad = min(_pad(n_samples_total, _SAMPLE_QUANTUM), chunk)
    build = _activate((n_pad, t_pad, int(substeps), float(dt), method))
    neurons, steps = [], []
    for start in range(0, n_samples_total, t_pad):
        part = current[start : start + t_pad]
        nrn, stp, v_new, u_new, r_new = _run_chunk(build, lane, part, params, v, u, r)
        n_valid = part.shape[0] * substeps
        keep = stp < n_valid  # spikes in the zero padding after the end are not real
        neurons.append(nrn[keep])
        steps.append(stp[keep] + start * substeps)
        v[:], u[:], r[:] = v_new, u_new, r_new
    neuron = np.concatenate(neurons)
    step = np.concatenate(steps)
    key = step * (n_neurons + 1) + neuron
    if key.size > 1 and np.any(key[1:] < key[:-1]):  # the monitor records by step, then neuron: rarely needed
        order = np.lexsort((neuron, step))
        neuron, step = neuron[order], step[order]
    return neuron, step

