"""Simulating a population on a set of scenes, into an xarray Dataset.

The work is cut into *chunks*: a block of afferents (``chunk_size``) over a
block of samples (``time_chunk``).  Filter state, neuron state and noise
streams carry from one time block to the next, so peak memory is bounded by
the chunk, not by the scene's length, and no engine call comes near Brian2's
32-bit index limit.  Each afferent block is a self-contained `ChunkJob`
whose result depends only on its own afferents: chunk size never changes a
spike.
"""

from __future__ import annotations

import os
import sys
from dataclasses import dataclass, replace
from pathlib import Path

import numpy as np

from ddmm.models.attenuation import NO_SHEAR_READINGS
from ddmm.models.current_filters import check_fs
from ddmm.models.engines import METHODS, get_engine, prepare, substeps_for
from ddmm.models.fused import AfferentColumns, FusedPipeline, mixing_matrix
from ddmm.population.anatomy.receptive_fields import frame_theta, input_sections, local_mixing
from ddmm.population.runtime.memory import check_run_memory
from ddmm.population.runtime.noise import noise_key, root_seed
from ddmm.population.runtime.plan import RECORD_CHOICES, make_plan
from ddmm.population.sampling import Population
from ddmm.population.stimuli.scenes import Scene, as_scenes
from ddmm.utils.deprecation import renamed_keyword
from ddmm.utils.executors import shared_executor
from ddmm.utils.extras import require
from ddmm.utils.validation import check_choice, check_positive, shown

__all__ = ["SimConfig", "ChunkJob", "run_chunk", "simulate", "plan_run", "population_currents", "block_pipeline",
           "chunk_forces", "default_chunk_size"]

_PIPELINE = 2  # afferent blocks in flight at once
#: The integration step `simulate` takes when given none, s (a scene's sample interval must be a whole number of it).
DEFAULT_DT = 1e-4


def default_chunk_size(engine, scheduler=None) -> int:
    """Afferents per block when ``chunk_size`` is not given: the engine's `Engine.chunk_size`.

    Examples
    --------
    >>> default_chunk_size("direct"), default_chunk_size("brian2"), default_chunk_size("direct", "processes")
    (512, 4096, 4096)
    """
    return get_engine(engine).chunk_size(scheduler)


@dataclass(frozen=True)
class SimConfig:
    """Settings shared by every chunk of a run.

    Attributes
    ----------
    engine : {"brian2", "direct"}
    dt : float
        Integration step in seconds.
    method : str
        Integration scheme.
    no_shear : {"pass", "block", "smooth"}
        Reading of eq. 17 ("smooth": the continuous transition, the default).
    seed : int
        Root seed of the noise streams.
    time_chunk : int
        Samples per time block.
    """

    engine: str = "brian2"
    dt: float = DEFAULT_DT
    method: str = "euler"
    no_shear: str = "smooth"
    seed: int = 0
    time_chunk: int = 2000


@dataclass(frozen=True, eq=False)
class ChunkJob:
    """One block of afferents on one condition.

    Attributes
    ----------
    scene : Scene
    population : Population
        The block's afferents (ids preserved for the noise streams).
    condition : int
        Condition index (part of the noise-stream key).
    trials : tuple of int
        Trials to run; deterministic blocks run trial 0 only.
    noisy : bool
        Whether to add current noise.
    weights : ndarray or None
        Receptive-field weights of the block's afferents.
    """

    scene: Scene
    population: Population
    condition: int
    trials: tuple
    noisy: bool
    weights: np.ndarray | None


def block_pipeline(population, fs: float, sites, scale, no_shear: str):
    """The fused pipeline of a block of afferents (grouped by type) at sample rate ``fs`` (Hz), with the
    mixing of ``sites`` (a multi-site scene's `Sites`, or None).

    A multi-site scene's forces are in the population's frame, so its AF
    uses ``theta_T + frame_deg`` (`spatial.frame_theta`).
    """
    pop = population
    theta, mixing, sections = pop.theta_t, None, None
    if sites is not None:
        theta = frame_theta(pop)
        indptr, indices, coeff, _ = local_mixing(pop.x_mm, pop.y_mm, pop.afferent_type, sites, pop.receptive_field)
        mixing = mixing_matrix(indptr, indices, coeff, len(sites))
        sections = input_sections(sites, fs)
    columns = AfferentColumns(afferent_type=pop.afferent_type, nap=pop.nap, theta_t=theta, k=pop.k, scale=scale,
                              noise_cv=pop.noise_cv, noise_sigma=pop.noise_sigma, afferent_id=pop.afferent_id,
                              sensitivity=pop.sensitivity)
    return FusedPipeline(columns, pop.current, fs, no_shear=no_shear, mixing=mixing, neuron_params=pop.neuron,
                         input_sections=sections)


def chunk_forces(scene, sl: slice) -> np.ndarray:
    """Forces of samples ``sl``: (n, 3) felt by all, or a multi-site scene's (n, n_sites, 3)."""
    if scene.sites is None:
        return np.column_stack([scene.fx[sl], scene.fy[sl], scene.fz[sl]])
    return scene.site_forces[sl]


def _run_trial(job: ChunkJob, pipeline, trial: int, config: SimConfig, progress=None):
    pop, scene = job.population, job.scene
    key = noise_key(config.seed, job.condition, trial) if job.noisy else None
    substeps = substeps_for(scene.fs, config.dt)
    state, neuron_state, afferents, steps = pipeline.new_state(), None, [], []
    for start in range(0, scene.n_samples, config.time_chunk):
        sl = slice(start, min(scene.n_samples, start + config.time_chunk))
        afferent, step, neuron_state = pipeline.advance(chunk_forces(scene, sl), state, start, key, neuron_state,
                                                        dt=config.dt, method=config.method, engine=config.engine)
        afferents.append(afferent)
        steps.append(step + start * substeps)
        if progress is not None:
            progress((sl.stop - sl.start) * len(pop))
    return np.concatenate(afferents), np.concatenate(steps)


def population_currents(population, scene, *, no_shear: str = "smooth") -> np.ndarray:
    """Noise-free input currents (mV/ms) of every afferent, shape (n_samples, n_afferents).

    The same computation `simulate` runs (AF, receptive fields, gains, filter),
    for inspection and for the reference solver; noise is not added.
    """
    check_choice(no_shear, "no_shear", NO_SHEAR_READINGS)
    from ddmm.population.anatomy.receptive_fields import population_weight, site_coverage

    weights = None
    if scene.contact is not None:
        weights = population_weight(population, scene.contact)
    elif scene.sites is not None:
        weights = site_coverage(population, scene.sites)
    scale = population.gain if weights is None else population.gain * weights
    order = _grouped(population, np.arange(len(population)), np.arange(len(population)))
    pipeline = block_pipeline(population.select(order), scene.fs, scene.sites, scale[order], no_shear)
    current = pipeline.currents(chunk_forces(scene, slice(None)), pipeline.new_state(), False)
    out = np.empty_like(current)
    out[:, order] = current
    return out


def run_chunk(job: ChunkJob, config: SimConfig, progress=None):
    """Simulate one block; returns (trial, afferent index within the block, step) arrays.

    An engine with a `Engine.part_size` takes a large block (a Dask task's)
    in parts of that size, whose state stays in cache.
    """
    n, size = len(job.population), get_engine(config.engine).part_size
    if size is None or n <= size:
        return _run_block(job, config, progress)
    out = [[], [], []]
    for lo in range(0, n, size):
        sl = slice(lo, min(n, lo + size))
        part = replace(job, population=job.population.select(sl),
                       weights=None if job.weights is None else job.weights[sl])
        trial, afferent, step = _run_block(part, config, progress)
        for col, arr in zip(out, (trial, afferent + lo, step)):
            col.append(arr)
    return tuple(np.concatenate(col) for col in out)


def _run_block(job: ChunkJob, config: SimConfig, progress=None):
    pop, scene = job.population, job.scene
    scale = pop.gain if job.weights is None else pop.gain * job.weights
    pipeline = block_pipeline(pop, scene.fs, scene.sites, scale, config.no_shear)  # once for every trial
    trials, afferents, steps = [], [], []
    for trial in job.trials:
        aff, stp = _run_trial(job, pipeline, trial, config, progress)
        trials.append(np.full(aff.size, trial, np.int64))
        afferents.append(aff)
        steps.append(stp)
    return np.concatenate(trials), np.concatenate(afferents), np.concatenate(steps)


def _check_sites(scenes) -> None:
    """Multi-site scenes of one run share their sites (the dataset's ``site`` dimension)."""
    multi = [s for s in scenes if s.sites is not None]
    if not multi:
        return
    if len(multi) != len(scenes):
        raise ValueError(f"scenes mix one-site and multi-site conditions ({[s.name for s in scenes]}); "
                         "simulate them in separate runs")
    first = multi[0].sites
    for s in multi[1:]:
        same = len(s.sites) == len(first) and all(
            np.array_equal(getattr(s.sites, f), getattr(first, f)) for f in ("x_mm", "y_mm", "radius_mm", "site_id"))
        if not same:
            raise ValueError(f"scene {s.name!r} has other sites than scene {multi[0].name!r}; the scenes of one "
                             "run must share their sites")


def _validate(population, scenes, engine, dt, method, trials, no_shear, chunk_size, time_chunk):
    if not isinstance(population, Population):
        raise TypeError(f"population must be a Population (see sample_population), got {type(population).__name__}")
    scenes = as_scenes(scenes)
    if len({s.fs for s in scenes}) != 1:
        raise ValueError(f"all scenes must share one sample rate, got {sorted({s.fs for s in scenes})} Hz")
    names = [s.name for s in scenes]
    if len(set(names)) != len(names):
        raise ValueError(f"scene names must be unique (they label conditions), got {names}")
    _check_sites(scenes)
    get_engine(engine)
    check_choice(method, "method", METHODS)
    check_choice(no_shear, "no_shear", NO_SHEAR_READINGS)
    if check_positive(dt, "dt", "s") < MIN_DT:
        raise ValueError(f"dt must be >= {MIN_DT:g} s (1 us; Euler's error at 0.1 ms is already 0.8%), got {dt:g}")
    substeps_for(scenes[0].fs, dt)
    for name, value in (("trials", trials), ("chunk_size", chunk_size), ("time_chunk", time_chunk)):
        if name == "chunk_size" and value is None:
            continue  # the engine's default
        if isinstance(value, bool) or not isinstance(value, (int, np.integer)) or value < 1:
            raise ValueError(f"{name} must be a whole number >= 1, got {shown(value)}")
    return scenes


@renamed_keyword("types", "afferent_types")
def plan_run(population, scenes, *, trials=1, record=RECORD_CHOICES, no_shear="smooth", afferent_types=None,
             chunk_size=None, time_chunk=2000, plan=True, engine="brian2", scheduler=None):
    """The `Plan` that `simulate` would follow (print it with ``plan.describe``)."""
    scenes = as_scenes(scenes)
    chunk_size = default_chunk_size(engine, scheduler) if chunk_size is None else chunk_size
    return make_plan(population, scenes, afferent_types=afferent_types, trials=trials, record=record, no_shear=no_shear,
                     chunk_size=chunk_size, time_chunk=time_chunk, enabled=plan)


def _grouped(population, sel, positions):
    """Positions ordered by (type, NAP), so each group is a contiguous column slice."""
    idx = sel[positions]
    order = np.lexsort((_sort_codes(population.nap[idx]), _sort_codes(population.afferent_type[idx])))
    return positions[order]


def _sort_codes(labels) -> np.ndarray:
    """Integer codes of string ``labels`` that sort as the strings do (hashing, not comparing strings:
    a lexsort of the strings themselves cost a hand run 2-3 ms)."""
    import pandas as pd

    codes, uniques = pd.factorize(np.asarray(labels, dtype=object))
    rank = np.empty(len(uniques), np.int64)
    rank[np.argsort(np.asarray(uniques, dtype=str), kind="stable")] = np.arange(len(uniques))
    return rank[codes]


def _equal_blocks(positions, chunk_size: int) -> list:
    """At most ``chunk_size`` per block, sizes within one of each other, in a multiple of `_PIPELINE` blocks.

    Equal blocks share one padded engine shape, so Brian2 builds once per run.
    An even count lets the blocks in flight end together: 25 blocks left one
    core idle for the last block's 8-10 ms of the hand's 0.15 s.
    """
    if positions.size == 0:
        return []
    n_blocks = -(-positions.size // chunk_size)
    if n_blocks > 1:
        n_blocks = min(positions.size, -(-n_blocks // _PIPELINE) * _PIPELINE)
    return np.array_split(positions, n_blocks)


def _jobs(population, scenes, the_plan):
    """Yield (condition index, ChunkJob, selected positions of the block, deterministic?)."""
    sel = the_plan.selected
    for c, (scene, cond) in enumerate(zip(scenes, the_plan.conditions)):
        for positions, deterministic in ((cond.units, True), (cond.noisy, False)):
            positions = _grouped(population, sel, positions)
            for block in _equal_blocks(positions, the_plan.chunk_size):
                weights = None if cond.weights is None else cond.weights[block]
                trials = (0,) if deterministic else tuple(range(the_plan.trials))
                job = ChunkJob(scene, population.select(sel[block]), c, trials, not deterministic, weights)
                yield c, job, block, deterministic


def _unit_members(cond):
    """Selected positions grouped by deterministic unit: (order, starts)."""
    det = np.flatnonzero(cond.member_unit >= 0)
    order = det[np.argsort(cond.member_unit[det], kind="stable")]
    counts = np.bincount(cond.member_unit[det], minlength=cond.units.size)
    return order, np.concatenate([[0], np.cumsum(counts)])


def _expand(cond, members, the_plan, block, deterministic, result):
    """Map a block's spikes to (trial, selected position, step), replicating units."""
    trial, local, step = result
    if not deterministic:
        return trial, block[local], step
    order, starts = members
    unit = cond.member_unit[block][local]  # the unit each spike belongs to
    count = starts[unit + 1] - starts[unit]
    source = np.repeat(np.arange(step.size), count)
    offset = np.arange(source.size) - np.repeat(np.cumsum(count) - count, count)
    pos = order[starts[unit][source] + offset]
    n_trials = the_plan.trials
    return (np.repeat(np.arange(n_trials, dtype=np.int64), pos.size), np.tile(pos, n_trials),
            np.tile(step[source], n_trials))


@renamed_keyword("types", "afferent_types")
def simulate(population, scenes, *, engine="brian2", dt=None, method=None, tolerance=None, trials=1, seed=None,
             record=RECORD_CHOICES, no_shear="smooth", afferent_types=None, plan=True, chunk_size=None,
             time_chunk=2000, scheduler=None, quiet=False):
    """Simulate a population on one or more scenes.

    Parameters
    ----------
    population : Population
        From `sample_population` or `make_population`.
    scenes : Scene or sequence of Scene
        One condition per scene; all share one sample rate.
    engine : {"brian2", "direct"}
        Simulation engine; both give identical spikes.
    dt : float, optional
        Integration step in seconds (default 0.1 ms).
    method : str, optional
        Integration scheme (default ``"euler"``).
    tolerance : float, optional
        Instead of ``dt`` and ``method``: the largest acceptable mean SF
        error in pulses/s; the cheapest measured (dt, method) within it is
        used (`ddmm.population.runtime.step_choice.choose_setting`) and stated in the attrs.
    trials : int
        Trials per condition (noise differs between trials).
    seed : int, numpy Generator or None
        Root of every noise stream; recorded in the dataset's attrs.
    record : sequence of str
        Optional variables: ``"spikes"`` (events) and ``"forces"``.
    no_shear : {"pass", "block", "smooth"}
        Reading of eq. 17: the continuous transition ("smooth", default), or
        the paper's two (`ddmm.models.attenuation`).
    afferent_types : sequence of str, optional
        Afferent types to simulate (default: all).
    plan : bool
        Skip what provably does not matter (default); False runs everything.
    chunk_size, time_chunk : int
        Afferents and samples per chunk (results do not depend on them).
        ``chunk_size`` defaults to `default_chunk_size` (512 for the direct
        engine in process, 4096 for Brian2 or Dask).
    scheduler : None, "processes", distributed.Client or str
        Where the afferent blocks run: in this process (default), a local
        pool of worker processes, a Dask client, or a scheduler address
        (`ddmm.population.runtime.distributed`).  The Dataset is bit-identical either way.
    quiet : bool
        Hide the progress bar.  Otherwise it is shown on stderr for runs over
        about a second when stderr is a terminal (tqdm's convention);
        ``DDMM_PROGRESS=0`` hides it and ``DDMM_PROGRESS=1`` shows it always.

    Returns
    -------
    xarray.Dataset
        See `ddmm.population.dataset.build_dataset` for the schema.

    Raises
    ------
    ValueError
        Before any work, when the run's estimated peak memory, spike events
        included (`ddmm.population.runtime.memory`), exceeds what this
        process may use (`ddmm.utils.resources.available_bytes`).

    Examples
    --------
    >>> from ddmm.population import sample_population, birznieks
    >>> pop = sample_population("fingertip", rng=0)
    >>> ds = simulate(pop, [birznieks(90.0)], engine="direct", seed=1, quiet=True)
    >>> ds.spike_count.dims
    ('condition', 'trial', 'afferent')
    """
    from tqdm import tqdm

    from ddmm.population.dataset import build_dataset

    scenes = as_scenes(scenes)
    dt, method, choice = _resolve_step(dt, method, tolerance, scenes)
    scenes = _validate(population, scenes, engine, dt, method, trials, no_shear, chunk_size, time_chunk)
    config = SimConfig(engine, float(dt), method, no_shear, root_seed(seed), int(time_chunk))
    the_plan = plan_run(population, scenes, trials=trials, record=record, no_shear=no_shear,
                        afferent_types=afferent_types, chunk_size=chunk_size, time_chunk=time_chunk, plan=plan, engine=engine,
                        scheduler=scheduler)
    check_fs(scenes[0].fs, population.current, tuple(sorted(set(population.afferent_type[the_plan.selected].tolist()))))
    _compile_notice(quiet)  # before the memory check, whose pilot may be what compiles them
    check_run_memory(population, scenes, the_plan, config, scheduler)
    spikes = [[] for _ in scenes]
    members = [_unit_members(cond) for cond in the_plan.conditions]
    work = list(_jobs(population, scenes, the_plan))
    with tqdm(total=the_plan.work(), unit="aff-sample", unit_scale=True, delay=1.0, file=sys.stderr,
              disable=_progress_disabled(quiet), leave=False) as bar:
        results = _run_jobs([job for _, job, _, _ in work], config, scheduler, bar.update)
    for (c, _, block, det), result in zip(work, results):
        spikes[c].append(_expand(the_plan.conditions[c], members[c], the_plan, block, det, result))
    ds = build_dataset(population, scenes, the_plan, spikes, config)
    ds.attrs.update(choice)
    return ds


#: The smallest integration step accepted, s.
MIN_DT = 1e-6


def _progress_disabled(quiet: bool):
    """tqdm's ``disable`` for a run: True when ``quiet``; ``DDMM_PROGRESS`` 0 / 1 forces off / on; else None
    (tqdm then shows the bar only when stderr is a terminal)."""
    setting = os.environ.get("DDMM_PROGRESS", "").strip()
    if setting not in ("", "0", "1"):
        raise ValueError(f"the environment variable DDMM_PROGRESS must be 0 or 1, got {setting!r}")
    if quiet or setting == "0":
        return True
    return False if setting == "1" else None


_NOTICED: list = []  # the compile notice is printed once per process


def _compile_notice(quiet: bool) -> None:
    """One line on stderr before numba compiles the kernels into an empty cache (the first run, ~20 s)."""
    if quiet or _NOTICED:
        return
    _NOTICED.append(True)
    import ddmm.models.fused as fused

    where = os.environ.get("NUMBA_CACHE_DIR")
    cache = Path(where) if where else Path(fused.__file__).parent / "__pycache__"
    if not any(cache.rglob("_fused_passes.*.nbi")):  # the fused pipeline's kernels, beside fused.py
        print(f"ddmm: compiling the numba kernels (first run only, about 20 s; cached in {cache})",
              file=sys.stderr, flush=True)


def _run_jobs(jobs, config, scheduler, progress) -> list:
    """Results of every job, in order: in this process, or as Dask tasks."""
    if scheduler is not None:
        require("distributed", f"scheduler={scheduler!r}", "dask")  # the one-line error of a missing extra
        from ddmm.population.runtime.distributed import dask_client, run_distributed

        with dask_client(scheduler) as client:
            return run_distributed(client, jobs, config, run_chunk, progress)
    prepare(config.engine)  # engine imports that must happen in the main thread
    # Two blocks in flight: one block's currents and noise (numpy) are
    # computed while the other integrates (numba threads, or the Brian2
    # binary in its own process).  Blocks are independent, so the order
    # of completion cannot change a spike.  The pool lives for the process.
    # Submitted last block first: blocks are grouped by type name, so the
    # fast-adapting RA-I, cheapest to integrate (no tonic firing), come last
    # and the two threads end nearly together (SA-I and SA-II last left one
    # idle for 5-13 ms of a hand run's 0.15 s).
    pool = shared_executor("blocks", _PIPELINE)
    futures = [pool.submit(run_chunk, job, config, progress) for job in reversed(jobs)][::-1]
    try:
        return [f.result() for f in futures]
    finally:  # a failed block: the rest are not started
        for f in futures:
            f.cancel()


def _resolve_step(dt, method, tolerance, scenes):
    """(dt, method, attrs) from explicit values, a tolerance, or the defaults."""
    if tolerance is None:
        return (DEFAULT_DT if dt is None else dt), ("euler" if method is None else method), {"tolerance": "none"}
    if dt is not None or method is not None:
        raise ValueError("give tolerance or dt/method, not both: tolerance chooses dt and method")
    if not scenes or not isinstance(scenes[0], Scene):
        raise TypeError("scenes must be a Scene or a non-empty sequence of Scenes")
    from ddmm.population.runtime.step_choice import choose_setting

    row = choose_setting(tolerance, scenes[0].fs)
    attrs = {"tolerance": float(tolerance),
             "tolerance_choice": f"dt={row['dt_ms']:g} ms, method={row['method']}: cheapest measured setting with "
                                 f"mean SF error {row['sf_err_mean']:.3g} <= {tolerance:g} pulses/s"}
    return row["dt_ms"] * 1e-3, row["method"], attrs
