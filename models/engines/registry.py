"""Engines as registered objects (as Brian2 registers its devices).

An `Engine` knows everything a caller would otherwise decide by comparing
engine names: how it integrates a block of neurons (`Engine.run`) and a
chunk of the whole pipeline (`Engine.advance`: the direct engine fuses the
pipeline's back pass with its integrator), how many afferents a block should
hold, how wide a streaming push runs, and what to import before worker
threads start.
Callers look an engine up with `get_engine` (a name or an `Engine`) and ask
it; they never compare names.

Two engines are registered: ``"brian2"`` (Brian2's C++ standalone device, the
default of `ddmm.population.simulate`) and ``"direct"`` (the numba integrator,
its cross-check).  Both give the same spikes for the same input.
"""

from __future__ import annotations

__all__ = ["Engine", "DirectEngine", "Brian2Engine", "register_engine", "get_engine", "engine_names"]

_REGISTRY: dict = {}


class Engine:
    """What every engine provides; subclasses set the attributes and implement `run`.

    Attributes
    ----------
    name : str
        The registered name (``engine=`` in the API and ``--engine`` in the CLI).
    block_size : int
        Afferents per block in process (``chunk_size`` when not given).
    task_block_size : int
        Afferents per block when the blocks are Dask tasks.
    part_size : int or None
        A block larger than this runs in parts of this size (None: whole).
    summary : str
        One line on what the engine is, for help texts (``ddmm --engine``).
    """

    name: str = ""
    summary: str = ""
    block_size: int = 4096
    task_block_size: int = 4096
    part_size: int | None = None

    def chunk_size(self, scheduler=None) -> int:
        """Afferents per block: `block_size` in process, `task_block_size` on a scheduler."""
        return self.block_size if scheduler is None else self.task_block_size

    def prepare(self) -> None:
        """Import the engine's heavy modules now, in the calling (main) thread."""

    def stream_parts(self, n_afferents: int, threads: int | None = None) -> int:
        """Column ranges a streaming push integrates in parallel (1: serial); ``threads`` caps them (None: the
        engine's default)."""
        return 1

    def run(self, current, substeps, dt, params, v, u, r, *, method, v_peak, v_floor):
        """Integrate checked inputs; return (neuron, step) int64 arrays, ``v``/``u``/``r`` updated in place.

        ``params`` holds per-neuron ``a``, ``b``, ``c``, ``d`` and ``t_ref``
        (s); ``r`` the refractory steps each neuron has left
        (`ddmm.models.neuron.refractory_steps`).
        """
        raise NotImplementedError

    def advance(self, pipeline, forces, state, sample0, key, neuron_state, *, dt, method, parts=1):
        """One chunk of a `ddmm.models.fused.FusedPipeline` on this engine: (afferent, step, `NeuronState` after).

        Parameters
        ----------
        pipeline : ddmm.models.fused.FusedPipeline
        forces, state, sample0, key
            As `FusedPipeline.advance` takes them (``state`` updated in place).
        neuron_state : NeuronState or None
            The state before the chunk (None: `FusedPipeline.initial_membrane`).
        dt : float
            Step in seconds.
        method : str
            Integration scheme.
        parts : int
            Column ranges the engine may integrate in parallel.

        Returns
        -------
        afferent, step : ndarray of int64
            The chunk's spikes (step counted from the chunk's start).
        state : NeuronState

        Notes
        -----
        This default computes the pipeline's currents and integrates them
        with `run` through the seam's checks (`ddmm.models.engines.run_checked`);
        an engine with an integrator of its own overrides it.
        """
        from ddmm.models.engines import run_checked, substeps_for  # the package imports this module

        substeps, params = substeps_for(pipeline.fs, dt), pipeline.neuron_arrays()
        v, u, r = pipeline.initial_membrane(neuron_state, key)
        current = pipeline.currents(forces, state, sample0 > 0, sample0, key)
        res = run_checked(current, substeps, dt, params, v, u, self, method, r, stacklevel=5)
        return res.afferent, res.step, res.state

    def push(self, pipeline, forces, before, after, sample0, key, neuron_state, *, dt, method, parts=1, spare=None):
        """One chunk of a streaming push: `advance`, with the filter state before read from ``before`` (left
        as it is) and the state after written to ``after`` (an array of its shape; ``before`` itself: in
        place), so a caller commits a chunk only when it succeeds without copying its state first.

        ``spare`` is a `NeuronState` whose arrays an engine may overwrite
        with the state after (the one returned); ``neuron_state`` is left
        as it is.  This default copies ``before`` into ``after`` and calls
        `advance`; the direct engine reads and writes in its kernels
        (`ddmm.models.engines.direct_fused.push_fused`).
        """
        if after is not before:
            after[...] = before
        return self.advance(pipeline, forces, after, sample0, key, neuron_state, dt=dt, method=method, parts=parts)

    def __repr__(self) -> str:
        return f"<ddmm engine {self.name!r}>"


class DirectEngine(Engine):
    """The numba integrator: small blocks that stay in cache, fused with the pipeline's back pass, threaded pushes."""

    name = "direct"
    summary = "the numba integrator: the same spikes bit for bit, no C++ compile, usually faster"
    #: A block's filter and neuron state stay in L2 and both threads stay busy to
    #: the end (the hand x 1 s: 0.18 s with 4096, 0.155-0.165 s with 512).
    block_size = 512
    #: A Dask task's block runs in parts of this size (as one part, the 100k case
    #: on 2 workers took 1.6 s against 0.93 s in process).
    part_size = 512
    #: Afferents from which a streaming push integrates on every core: below, one core is faster.
    parallel_min_afferents = 4096

    def prepare(self) -> None:
        from . import direct  # noqa: F401 - loads numba and the kernels

    def stream_parts(self, n_afferents: int, threads: int | None = None) -> int:
        from .direct import default_threads

        threads = default_threads() if threads is None else threads
        return threads if n_afferents >= self.parallel_min_afferents else 1

    def run(self, current, substeps, dt, params, v, u, r, *, method, v_peak, v_floor):
        from .direct import run_direct

        return run_direct(current, substeps, dt, params, v, u, r, method=method, v_peak=v_peak, v_floor=v_floor)

    def advance(self, pipeline, forces, state, sample0, key, neuron_state, *, dt, method, parts=1):
        """The pipeline's back pass and the neurons in one numba call (`ddmm.models.engines.direct_fused`),
        ``parts`` column ranges in parallel."""
        from .direct_fused import advance_fused

        return advance_fused(pipeline, forces, state, sample0, key, neuron_state, dt=dt, method=method, parts=parts)

    def push(self, pipeline, forces, before, after, sample0, key, neuron_state, *, dt, method, parts=1, spare=None):
        """A streaming chunk in two parallel regions that copy no state (`ddmm.models.engines.direct_fused.push_fused`)."""
        from .direct_fused import push_fused

        return push_fused(pipeline, forces, before, after, sample0, key, neuron_state, dt=dt, method=method,
                          parts=parts, spare=spare)


class Brian2Engine(Engine):
    """Brian2's C++ standalone device: large blocks, each a run of a compiled binary; a pipeline's chunk
    integrates its currents (`Engine.advance`)."""

    name = "brian2"
    summary = "Brian2's C++ standalone device, compiled once per shape"

    def prepare(self) -> None:
        # ``import brian2`` installs a SIGINT handler, which Python allows only in the main thread.
        from .brian2.engine import import_brian2

        import_brian2()

    def run(self, current, substeps, dt, params, v, u, r, *, method, v_peak, v_floor):
        from .brian2.engine import run_brian2

        return run_brian2(current, substeps, dt, params, v, u, r, method=method, v_peak=v_peak, v_floor=v_floor)


def register_engine(engine: Engine) -> Engine:
    """Add an engine to the registry under ``engine.name``; returns it.

    Examples
    --------
    >>> get_engine("direct") is register_engine(get_engine("direct"))
    True
    """
    if not isinstance(engine, Engine) or not engine.name:
        raise TypeError(f"engine must be a named Engine instance, got {engine!r}")
    _REGISTRY[engine.name] = engine
    return engine


def get_engine(engine) -> Engine:
    """The registered `Engine` for a name (or the `Engine` itself).

    Raises
    ------
    ValueError
        For a name that is not registered (the message lists the names).
    TypeError
        For anything that is neither a string nor an `Engine`.

    Examples
    --------
    >>> get_engine("direct").chunk_size(), get_engine("brian2").chunk_size()
    (512, 4096)
    """
    if isinstance(engine, Engine):
        return engine
    if not isinstance(engine, str):
        raise TypeError(f"engine must be one of {engine_names()} or an Engine, got {type(engine).__name__}")
    try:
        return _REGISTRY[engine]
    except KeyError:
        raise ValueError(f"engine must be one of {engine_names()}, got {engine!r}") from None


def engine_names() -> tuple:
    """Names of the registered engines, in registration order."""
    return tuple(_REGISTRY)


register_engine(Brian2Engine())
register_engine(DirectEngine())
