"""A run's peak memory, estimated before it starts, and the refusal of a run that cannot fit.

The peak of a run is what the process holds now plus what the run adds:

* the code the run loads (the dataset's kernels; the engine's are loaded by
  the pilot below): `OVERHEAD_BYTES`;
* the blocks in flight (two in this process, one per core with a
  scheduler), each ``chunk_size x min(time_chunk, samples)`` elements of
  `BYTES_PER_ELEMENT`;
* the spike counts, `BYTES_PER_COUNT` per (condition, trial, afferent), and
  the recorded forces;
* the spike events, `BYTES_PER_EVENT` each: the blocks' results, the
  concatenated and sorted copies `build_dataset` makes and the Dataset's own
  arrays are alive together at the peak, so an event costs far more than
  its 20 bytes in the file.

Events are not known before the run.  They are counted by a *pilot*: per
condition and afferent type, the active afferents (those the plan does not
skip as silent) are sorted by a proxy of their drive (gain x sensitivity x
receptive-field weight, x the peak force their sites deliver in a
multi-site scene) and cut into up to `PILOT_PICKS` strata of equal size;
the middle afferent of each is simulated over the scene with the direct
engine (trial 0, noise on), and its spikes count for every afferent of its
stratum and every trial.  A scene too long for `PILOT_STEPS` is piloted
over its start and scaled by its length (one whose single sample takes
more, sampled below about 7 Hz, gets the bound below).  On the bench's
cases, fingertip x 100-1,000 trials and hand x 10 trials x 1-4 s of
vibration the estimate was 0.75-1.2x the measured peak (docs/user-guide.md).

`check_run_memory` first tries a ceiling that needs no pilot: every
afferent firing at `CEILING_RATE_HZ` (or once a step, if that is fewer)
throughout.  Only when the ceiling does not fit is the pilot run, so
everyday runs pay nothing for the check.
"""

from __future__ import annotations

import os
from dataclasses import dataclass, replace

import numpy as np

from ddmm.population.runtime.plan import _BYTES_PER_ELEMENT as _PLAN_BYTES_PER_ELEMENT
from ddmm.utils.resources import available_bytes, check_memory, format_bytes, resident_bytes

__all__ = ["BYTES_PER_COUNT", "BYTES_PER_ELEMENT", "BYTES_PER_EVENT", "CEILING_RATE_HZ", "OVERHEAD_BYTES",
           "PILOT_PICKS", "PILOT_STEPS", "MemoryEstimate", "check_run_memory", "estimate_memory"]

#: Bytes per element of a block in flight (the plan's figure: F_A, current, noise, AF and a temporary, float64).
BYTES_PER_ELEMENT = _PLAN_BYTES_PER_ELEMENT
#: Bytes per spike event at a run's peak: measured 112 (simulate) to 130 (simulate, then save_dataset).
BYTES_PER_EVENT = 128
#: Bytes per spike count: the int64 histogram and the int32 variable.
BYTES_PER_COUNT = 16
#: Bytes a first run loads beyond the engine: the dataset's kernels and imports (measured 18 MiB).
OVERHEAD_BYTES = 24 << 20
#: The rate (imp/s) the pilot-free ceiling gives every afferent over a whole run: no afferent of the presets
#: sustains it (FA-II entrained by vibration fire at a few hundred), and a drive that does trips the
#: one-spike-per-step warning.  A 30 s press of the fingertip then needs no pilot on a machine of a few GiB.
CEILING_RATE_HZ = 1000.0
#: Afferents per type and condition the pilot simulates.
PILOT_PICKS = 32
#: Integration steps (afferents x steps) the pilot may take per condition; a longer scene is piloted over its start.
PILOT_STEPS = 200_000_000


@dataclass(frozen=True)
class MemoryEstimate:
    """A run's estimated peak memory, in bytes (module docstring).

    Attributes
    ----------
    resident : float
        What the process holds before the run.
    overhead, working, counts, forces : float
        Code loaded, blocks in flight, spike counts, recorded forces.
    events : float
        Spike events expected.
    piloted : int
        Afferents the pilot simulated (0: ``events`` is the ceiling of
        `CEILING_RATE_HZ` per afferent).
    """

    resident: float
    overhead: float
    working: float
    counts: float
    forces: float
    events: float
    piloted: int

    @property
    def added(self) -> float:
        """Bytes the run adds to the process: what must fit in `available_bytes`."""
        return self.overhead + self.working + self.counts + self.forces + self.events * BYTES_PER_EVENT

    @property
    def peak(self) -> float:
        """The process's estimated peak resident memory."""
        return self.resident + self.added

    @property
    def source(self) -> str:
        """Where `events` comes from, as messages say it."""
        return (f"a pilot of {self.piloted} afferents" if self.piloted
                else f"a ceiling of {CEILING_RATE_HZ:,.0f} imp/s per afferent")

    def describe(self) -> str:
        """One line for ``ddmm plan``: the peak, its parts, and whether `simulate` would refuse the run."""
        room = available_bytes()
        return (f"memory: about {format_bytes(self.peak)} at peak ({format_bytes(self.added)} more than the "
                f"{format_bytes(self.resident)} held now: {format_bytes(self.working)} of blocks in flight, "
                f"{self.events:,.0f} spike events at {BYTES_PER_EVENT} B from {self.source}); this process may use "
                f"{format_bytes(room)} more" + ("; simulate would refuse this run" if self.added > room else ""))


def _ceiling(scene, dt: float) -> float:
    """Spike events one afferent can reach over ``scene``: `CEILING_RATE_HZ`, and at most one a step."""
    from ddmm.models.engines import substeps_for

    return min(scene.n_samples * substeps_for(scene.fs, dt), scene.n_samples / scene.fs * CEILING_RATE_HZ)


def _active(cond, plan) -> np.ndarray:
    """Kept positions (within ``plan.selected``) the plan simulates: every one but the provably silent."""
    return plan.keep[cond.member_unit[plan.keep] != -2]


def _drive(population, scene, cond, plan, active) -> np.ndarray:
    """A proxy of each active afferent's drive: the pilot's strata are cut along it."""
    idx = plan.selected[active]
    drive = population.gain[idx] * population.sensitivity[idx]
    if cond.weights is not None:
        drive = drive * cond.weights[active]
    if scene.sites is not None:  # the force its sites deliver: a pressed taxel's neighbours, not the array's
        from ddmm.population.anatomy.receptive_fields import local_mixing

        indptr, sites, coeff, _ = local_mixing(population.x_mm[idx], population.y_mm[idx],
                                               population.afferent_type[idx], scene.sites, population.receptive_field)
        rows = np.repeat(np.arange(idx.size), np.diff(indptr))
        drive = drive * np.bincount(rows, weights=coeff * _site_peaks(scene)[sites], minlength=idx.size)
    return drive


def _site_peaks(scene) -> np.ndarray:
    """The largest force (N, magnitude) at each site, a block of samples at a time (no copy of the scene)."""
    peak = np.zeros(scene.n_sites)
    for lo in range(0, scene.n_samples, 1 << 16):
        block = scene.site_forces[lo:lo + (1 << 16)]
        np.maximum(peak, np.sqrt(np.einsum("tsi,tsi->ts", block, block).max(axis=0)), out=peak)
    return peak


def _strata(population, scene, cond, plan) -> tuple:
    """(picked positions, afferents each stands for): up to `PILOT_PICKS` strata per type along `_drive`."""
    active = _active(cond, plan)
    types = population.afferent_type[plan.selected[active]]
    drive = _drive(population, scene, cond, plan, active)
    picks, sizes = [], []
    for t in np.unique(types):
        group = active[types == t][np.argsort(drive[types == t], kind="stable")]
        for stratum in np.array_split(group, min(PILOT_PICKS, group.size)):
            picks.append(stratum[stratum.size // 2])
            sizes.append(stratum.size)
    return np.asarray(picks, np.int64), np.asarray(sizes, float)


def _pilot(population, scene, c, cond, plan, config) -> tuple:
    """(spike events per trial of condition ``c``, afferents simulated) from the strata's picks over the scene,
    or None when one sample of them takes more than `PILOT_STEPS` (a scene sampled slower than about 7 Hz)."""
    from ddmm.models.engines import substeps_for
    from ddmm.population.simulation import ChunkJob, _grouped, run_chunk

    picks, sizes = _strata(population, scene, cond, plan)
    if picks.size == 0:
        return 0.0, 0
    order = _grouped(population, plan.selected[picks], np.arange(picks.size))  # the pipeline wants types contiguous
    picks, sizes = picks[order], sizes[order]
    n = min(scene.n_samples, PILOT_STEPS // (picks.size * substeps_for(scene.fs, config.dt)))
    if n == 0:
        return None
    if n < scene.n_samples:  # the scene's start: its stages may lie beyond it
        scene = replace(scene, fx=scene.fx[:n], fy=scene.fy[:n], fz=scene.fz[:n], stages=(),
                        site_forces=None if scene.sites is None else scene.site_forces[:n])
    weights = None if cond.weights is None else cond.weights[picks]
    job = ChunkJob(scene, population.select(plan.selected[picks]), c, (0,), True, weights)
    afferent = run_chunk(job, config)[1]
    counts = np.bincount(afferent, minlength=picks.size)
    return float(counts @ sizes) * cond.n_samples / n, int(picks.size)


def _fixed(scenes, plan, scheduler) -> dict:
    """The parts of `MemoryEstimate` that do not depend on the spikes."""
    in_flight = 2 if scheduler is None else max(2, os.cpu_count() or 1)  # `simulation._PIPELINE`, or the workers
    n_time = max(s.n_samples for s in scenes)
    block = min(plan.chunk_size, plan.selected.size) * min(plan.time_chunk, n_time)
    forces = 0.0
    if "forces" in plan.record:  # the Dataset's fx, fy, fz (and per site) over (condition, time), and the file's copy
        per_sample = 3 * (1 + (scenes[0].n_sites if scenes[0].sites is not None else 0))
        forces = 2.0 * 8 * per_sample * len(scenes) * n_time
    return {"overhead": float(OVERHEAD_BYTES), "working": float(in_flight * block * BYTES_PER_ELEMENT),
            "counts": float(BYTES_PER_COUNT * len(scenes) * plan.trials * plan.keep.size), "forces": forces}


def _checked(population, scenes, plan, dt, method, no_shear) -> list:
    """`estimate_memory`'s arguments checked at the boundary: the scenes as a list."""
    from ddmm.models.attenuation import NO_SHEAR_READINGS
    from ddmm.models.engines import METHODS
    from ddmm.population.runtime.plan import Plan
    from ddmm.population.sampling import Population
    from ddmm.population.stimuli.scenes import as_scenes
    from ddmm.utils.validation import check_choice, check_positive

    if not isinstance(population, Population):
        raise TypeError(f"population must be a Population (see sample_population), got {type(population).__name__}")
    scenes = as_scenes(scenes)
    if not isinstance(plan, Plan):
        raise TypeError(f"plan must be a Plan (see plan_run), got {type(plan).__name__}")
    if len(plan.conditions) != len(scenes):
        raise ValueError(f"plan has {len(plan.conditions)} condition(s) for {len(scenes)} scene(s): make it from "
                         "these scenes (plan_run)")
    check_positive(dt, "dt", "s")
    check_choice(method, "method", METHODS)
    check_choice(no_shear, "no_shear", NO_SHEAR_READINGS)
    return scenes


def estimate_memory(population, scenes, plan, *, dt: float = 1e-4, method: str = "euler", no_shear: str = "smooth",
                    seed=0, scheduler=None, pilot: bool = True, quiet: bool = False) -> MemoryEstimate:
    """Estimate the peak memory of ``simulate(population, scenes)`` following ``plan`` (module docstring).

    Parameters
    ----------
    population : Population
    scenes : sequence of Scene
    plan : Plan
        From `ddmm.population.simulation.plan_run`.
    dt, method, no_shear, seed
        As `simulate` (the pilot integrates as the run will).
    scheduler : None or str
        As `simulate`: with a scheduler, a block per core is in flight.
    pilot : bool
        False: count the ceiling of `CEILING_RATE_HZ` per afferent (no simulation).
    quiet : bool
        No notice when the pilot compiles the numba kernels (as `simulate`).

    Returns
    -------
    MemoryEstimate

    Examples
    --------
    >>> from ddmm.population import birznieks, plan_run, sample_population
    >>> pop, scene = sample_population("fingertip", rng=0), birznieks(90.0)
    >>> est = estimate_memory(pop, [scene], plan_run(pop, scene, trials=100, engine="direct"))
    >>> 1e6 < est.events < 4e6, est.piloted
    (True, 128)
    """
    from ddmm.population.runtime.noise import root_seed
    from ddmm.population.simulation import SimConfig, _compile_notice

    scenes = _checked(population, scenes, plan, dt, method, no_shear)
    if pilot:
        _compile_notice(quiet)  # the first pilot in a fresh install compiles the kernels (about 20 s)
    config = SimConfig("direct", float(dt), method, no_shear, root_seed(seed), plan.time_chunk)
    events, piloted = 0.0, 0
    for c, (scene, cond) in enumerate(zip(scenes, plan.conditions)):
        piloting = _pilot(population, scene, c, cond, plan, config) if pilot else None
        if piloting is None:  # the ceiling
            events += float(_active(cond, plan).size) * plan.trials * _ceiling(scene, dt)
        else:
            events, piloted = events + piloting[0] * plan.trials, piloted + piloting[1]
    return MemoryEstimate(float(resident_bytes()), events=events, piloted=piloted,
                          **_fixed(scenes, plan, scheduler))


def check_run_memory(population, scenes, plan, config, scheduler=None) -> None:
    """Refuse, before the run, one whose estimated memory exceeds what this process may use.

    The ceiling of `CEILING_RATE_HZ` per afferent is tried first; the pilot
    runs only when that does not fit.

    Raises
    ------
    ValueError
        Naming the run, the estimate and the limit (`ddmm.utils.resources.check_memory`).
    """
    kwargs = {"dt": config.dt, "method": config.method, "no_shear": config.no_shear, "seed": config.seed,
              "scheduler": scheduler, "quiet": True}  # `simulate` gave the compile notice
    if estimate_memory(population, scenes, plan, pilot=False, **kwargs).added <= available_bytes():
        return
    est = estimate_memory(population, scenes, plan, **kwargs)
    what = (f"a run of {len(scenes)} condition(s) x {plan.trials:,} trial(s) x {plan.keep.size:,} afferents "
            f"(about {est.events:,.0f} spike events, from {est.source})")
    check_memory(est.added, what, "use fewer trials, afferents, conditions or seconds, or split the run")
