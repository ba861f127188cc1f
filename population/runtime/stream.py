"""A streaming encoder: live fingertip force in, spikes out, with bounded latency.

`Encoder` keeps the whole pipeline's state between calls: the filters and
every neuron's (v, u).  Each chunk runs through `ddmm.models.fused.FusedPipeline`,
the very plan `simulate` runs offline, and the noise of sample n of
afferent a is a pure function of (seed, condition 0, trial 0, a, n)
(`ddmm.population.runtime.noise`), drawn on demand inside the kernel.  So the
concatenated spikes of *any* chunking equal the offline run of the whole
signal with the same seed, bit for bit, with no noise drawn ahead, no
background thread and no queue.  An engine may integrate a push in
parallel (`Engine.stream_parts`): the direct engine, from
``DirectEngine.parallel_min_afferents`` afferents, runs a push on every core (``DDMM_NUM_THREADS``) in two
numba parallel regions (the front pass, then the back pass and the neurons, around numpy's log1p and tanh;
`Engine.push`); afferents are independent, so no spike changes.  A push copies no state: with forward Euler it
updates the state in place, otherwise it writes spare buffers that a success swaps in.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numba as nb
import numpy as np

from ddmm.models.attenuation import NO_SHEAR_READINGS
from ddmm.models.current_filters import check_fs
from ddmm.models.engines import METHODS, NeuronState, get_engine, substeps_for
from ddmm.population.anatomy.receptive_fields import population_weight, site_coverage
from ddmm.population.runtime.noise import noise_key, root_seed
from ddmm.population.sampling import Population
from ddmm.population.simulation import _grouped, block_pipeline
from ddmm.population.stimuli.conditioning import Conditioner, Conditioning, noise_allowance
from ddmm.population.stimuli.recordings import MAX_FORCE_N, RECORDED, check_force_bound
from ddmm.population.stimuli.scenes import DEFAULT_FS, MAX_FS, Contact, Sites
from ddmm.utils.deprecation import renamed_keyword
from ddmm.utils.validation import as_finite_array, check_choice, check_count, check_positive

__all__ = ["StreamSpikes", "Encoder"]


@dataclass(frozen=True)
class StreamSpikes:
    """Spikes of one pushed chunk.

    Attributes
    ----------
    afferent : ndarray of int64
        Position of the spiking afferent in the encoder's population.
    time : ndarray of float
        Spike time in seconds since the first sample (``step * dt``).
    forces : ndarray, shape (m, 3) or (m, n_sites, 3), or None
        The forces the model consumed in this chunk, N, at ``model_fs``
        (after the conditioning stage): what a stimulation encoder reads.
    """

    afferent: np.ndarray
    time: np.ndarray
    forces: np.ndarray | None = None


class Encoder:
    """Turn streamed force samples into spikes, chunk by chunk.

    Parameters
    ----------
    population : Population
        The afferents.
    fs : float
        Sample rate of the force stream in Hz.
    dt : float
        Integration step in seconds (must divide ``1/fs``).
    engine : {"direct", "brian2"}
        Simulation engine (direct by default: it is the low-latency one).
    method : str
        Integration scheme.
    seed : int, Generator or None
        Root of the noise streams (as in `simulate`).
    no_shear : {"pass", "block", "smooth"}
        Reading of eq. 17 (default "smooth", as `simulate`).
    contact : Contact, optional
        Fixed contact geometry, for receptive-field weighting.
    sites : Sites, optional
        The force sites of a sensor array or multi-digit hand: chunks are
        then (n, n_sites, 3), and each afferent feels its own local force
        (`ddmm.population.anatomy.receptive_fields`), as `simulate` does for `Scene.from_sites`.
    afferent_types : sequence of str, optional
        Afferent types to simulate (as `simulate`'s ``types``); the others
        never spike.  A sensor too slow for FA-II leaves them out this way.
    conditioning : Conditioning or None
        The causal conditioning stage for a live sensor
        (`ddmm.population.stimuli.conditioning`; default on, `RECORDED`, as
        for recorded files): pushed samples (at ``fs``) are conditioned and
        brought to ``model_fs``, and the spikes equal an offline `from_csv`
        of the same samples with the same conditioning, bit for bit.  None:
        forces are taken as they are, as `simulate` takes a `Scene` (for
        noise-free forces, e.g. a simulated robot; it also saves the stage's
        ~0.17 ms a push).
    model_fs : float, optional
        The model's sample rate with ``conditioning`` (default 1000 Hz, the
        rate `from_csv` gives); without it the model runs at ``fs``.
    max_force_n : float
        The largest force (N, magnitude) a pushed sample may carry at a site,
        1 kN by default: a chunk beyond it is refused (a unit slip).
    threads : int, optional
        The most threads a push runs on (None: ``DDMM_NUM_THREADS``, else
        every core).  One keeps a push off the cores a live sender and its
        consumers need (`ddmm stream --lsl-in` on a 2-core host).

    Notes
    -----
    From ``DirectEngine.parallel_min_afferents`` afferents, the direct engine's pushes run
    on ``threads`` numba threads, read when the encoder is made; no spike changes with it.

    Examples
    --------
    >>> from ddmm.population import make_population
    >>> enc = Encoder(make_population(["SAI"]), fs=1000.0, engine="direct", seed=1)  # conditioned
    >>> out = enc.push(np.column_stack([np.zeros(300), np.zeros(300), np.full(300, 4.0)]))
    >>> bool(out.afferent.size > 0)
    True
    """

    @renamed_keyword("types", "afferent_types")
    def __init__(self, population, fs: float, *, dt: float = 1e-4, engine: str = "direct", method: str = "euler",
                 seed=None, no_shear: str = "smooth", contact: Contact | None = None, sites: Sites | None = None,
                 afferent_types=None, conditioning: Conditioning | None = RECORDED, model_fs: float | None = None,
                 max_force_n: float = MAX_FORCE_N, threads: int | None = None):
        if not isinstance(population, Population):
            raise TypeError(f"population must be a Population, got {type(population).__name__}")
        self.fs = check_positive(fs, "fs", "Hz")
        if self.fs > MAX_FS:
            raise ValueError(f"fs = {self.fs:g} Hz is beyond any force sensor (at most {MAX_FS:g} Hz)")
        self.max_force_n = check_positive(max_force_n, "max_force_n", "N")
        self._threads = None if threads is None else check_count(threads, "threads")
        self.conditioning = conditioning
        self.model_fs = self._model_fs(conditioning, model_fs)
        self.substeps = substeps_for(self.model_fs, dt)
        self.dt, self._engine = float(dt), get_engine(engine)
        self.engine = self._engine.name
        self.method = check_choice(method, "method", METHODS)
        self.no_shear = check_choice(no_shear, "no_shear", NO_SHEAR_READINGS)
        if contact is not None and not isinstance(contact, Contact):
            raise TypeError(f"contact must be a Contact or None, got {type(contact).__name__}")
        if sites is not None and (not isinstance(sites, Sites) or contact is not None):
            raise TypeError("sites must be a Sites (and then no contact is given), got "
                            f"{type(sites).__name__} with contact={contact!r}")
        self.seed, self.contact = root_seed(seed), contact
        self.sites = sites
        self._shape = (3,) if sites is None else (len(sites), 3)  # a sample's shape
        self._allowance = 0.0 if conditioning is None else noise_allowance(conditioning)
        idx = _type_positions(population, afferent_types)
        check_fs(self.model_fs, population.current, tuple(np.unique(population.afferent_type[idx])))
        self._order = idx[_grouped(population, idx, np.arange(idx.size))]  # contiguous (type, NAP) groups, as offline
        self.population, self._positions = population, len(population)
        self._pop = population.select(self._order)
        self._precompute()
        self._engine.prepare()
        self.reset()

    def _precompute(self) -> None:
        """The fused pipeline (the one `simulate` builds for these afferents, with its site mixing)."""
        pop = self._pop
        scale = pop.gain
        if self.contact is not None:
            scale = pop.gain * population_weight(pop, self.contact)
        elif self.sites is not None:  # checked on the whole population's skin, as `simulate` checks it
            scale = pop.gain * site_coverage(self.population, self.sites)[self._order]
        self._pipeline = block_pipeline(pop, self.model_fs, self.sites, scale, self.no_shear)
        # Forward Euler refuses no chunk it was given (no stability check; the v floor and the bounded drive keep
        # it finite), so its pushes write the state in place: a copy of the state costs more than the kernels'
        # own sweep of it (the hand: ~1.5 MB a push, out of cache).  The other methods' stability check may
        # refuse a chunk after it ran: theirs write spare buffers, committed when the chunk succeeds.
        self._in_place = self.method == "euler"
        # Read once: a push is latency-bound, and the thread count is fixed for the encoder's life.
        self._parts = self._engine.stream_parts(len(pop), self._threads)
        noisy = np.any(pop.noise_sigma > 0) or np.any(pop.noise_cv > 0) or self._pipeline.excite_any
        self._key = noise_key(self.seed, 0, 0) if noisy else None
        # The neurons before the first sample (SA-II's phases drawn): made once, copied at each reset.
        self._initial = self._pipeline.initial_membrane(None, self._key)

    def reset(self) -> None:
        """Back to the start: filters at rest on the next sample, neurons at rest, noise from sample 0."""
        self._state, self._samples, self._last_time = self._pipeline.new_state(), 0, None
        self._neuron_state = NeuronState(*(x.copy() for x in self._initial))
        # What the next push writes, swapped in when it succeeds (a push in place writes the state itself).
        self._spare, self._lost = (None, None) if self._in_place else (np.empty_like(self._state), None), None
        self._conditioner = None if self.conditioning is None else Conditioner(
            self.conditioning, self.fs, self.model_fs, None if self.sites is None else len(self.sites))

    def _model_fs(self, conditioning, model_fs) -> float:
        if conditioning is None:
            if model_fs is not None:
                raise ValueError("model_fs goes with a conditioning: without one the model runs at fs")
            return self.fs
        if not isinstance(conditioning, Conditioning) or conditioning.mode != "causal":
            raise ValueError(f"conditioning must be a causal Conditioning (a stream cannot look ahead), "
                             f"got {conditioning!r}")
        return DEFAULT_FS if model_fs is None else check_positive(model_fs, "model_fs", "Hz")

    def warm_up(self) -> None:
        """Run every path of a push once, then reset: call it before the first sample of a live stream.

        A synthetic press with shear goes through in one chunk and then sample by sample (some kernels
        specialise on a one-sample chunk), so the first real samples meet loaded kernels; measured, the
        first push after a reset otherwise takes ~14 ms instead of ~0.3 ms (fingertip).  Raises
        `ValueError` once samples have been pushed (it would throw their state away).
        """
        if self._samples:
            raise ValueError(f"warm_up() goes before the first push; {self._samples} samples have been pushed "
                             "(reset() first to start over)")
        n = max(int(self.fs * 0.05), 2)
        press = np.zeros((2 * n, 3))
        press[:, 0], press[:, 2] = np.linspace(0.0, 0.3, 2 * n), np.linspace(0.0, 1.0, 2 * n)
        if self.sites is not None:
            press = np.repeat(press[:, None, :], len(self.sites), axis=1)
        self.push(press[:n])
        for row in press[n:]:
            self.push(row[None])
        self.reset()

    def wait_ready(self) -> None:
        """Nothing to prepare: noise is drawn on demand (kept so real-time loops written for it still run)."""

    @property
    def positions(self) -> np.ndarray:
        """Positions in ``population`` of the afferents the encoder simulates (its ``types``), in its order."""
        return self._order.copy()

    @property
    def n_samples(self) -> int:
        """Model samples (at ``model_fs``) consumed since the start (or the last reset)."""
        return self._samples

    def _validate(self, forces, times):
        if times is None and type(forces) is np.ndarray and forces.dtype == np.float64 and forces.flags.c_contiguous \
                and forces.shape[1:] == self._shape and forces.shape[0]:  # a live push: one pass checks it all
            finite, peak, fz_min = _summary(forces.reshape(-1, 3))
            if finite and peak * math.sqrt(3.0) <= self.max_force_n and fz_min >= -self._allowance:
                return forces, None  # else the checks below say what is wrong
        forces = as_finite_array(forces, "forces")
        if self.sites is not None:
            if forces.ndim != 3 or forces.shape[1:] != (len(self.sites), 3):
                raise ValueError(f"forces must have shape (n, n_sites, 3) = (n, {len(self.sites)}, 3) for the "
                                 f"encoder's sites, got {forces.shape}")
        elif forces.ndim != 2 or forces.shape[1] != 3:
            raise ValueError(f"forces must have shape (n, 3) for (fx, fy, fz), got {forces.shape}")
        check_force_bound(forces, self.max_force_n, "forces")
        allowance = 0.0 if self.conditioning is None else noise_allowance(self.conditioning)
        if forces.size and float(forces[..., 2].min()) < -allowance:
            raise ValueError(f"forces: the normal force fz must be >= {-allowance:g} N, got "
                             f"{float(forces[..., 2].min()):g}" + (" (a live sensor's noise and offset: give the "
                             "encoder a conditioning)" if self.conditioning is None else " (check the sign convention)"))
        if times is not None:
            times = as_finite_array(times, "times", ndim=1)
            if times.size != forces.shape[0]:
                raise ValueError(f"times must have one entry per sample; got {times.size} for {forces.shape[0]}")
            previous = np.r_[self._last_time if self._last_time is not None else -np.inf, times]
            if np.any(np.diff(previous) <= 0):
                raise ValueError("times must increase strictly, continuing from the previous chunk")
        return forces, times

    def push(self, forces, times=None) -> StreamSpikes:
        """Consume a chunk of samples; return the spikes that fell inside it.

        Parameters
        ----------
        forces : array_like, shape (n, 3)
            F_X, F_Y, F_Z in newtons, one row per sample at ``fs`` (with a
            conditioning, the sensor's raw samples).
        times : array_like, shape (n,), optional
            Sample times in seconds, checked to increase strictly across
            chunks (the encoder's clock is the sample count, not these).

        Raises
        ------
        ValueError
            For non-finite values, a negative normal force, a force beyond
            ``max_force_n``, a wrong shape or time going backwards; the
            encoder's state is left untouched.
        NumericalInstabilityError
            When the integration refuses the chunk (an explicit method's
            stability check, or a non-finite state): with ``method="euler"``,
            whose pushes update the state in place, the state is then lost
            and every later push raises until `reset`; with the other
            methods it is left untouched.
        """
        forces, times = self._validate(forces, times)
        if self._conditioner is not None:
            forces, _ = self._conditioner.push(forces)  # may hold back nothing: it is causal, sample by sample
        n = forces.shape[0]
        if n == 0:
            return StreamSpikes(np.empty(0, np.int64), np.empty(0), forces)
        if self._lost is not None:
            raise ValueError(f"a push failed after it had changed the encoder's state ({self._lost}): reset() first")
        # The engine reads the state and writes the spare buffers, swapped in if the whole chunk succeeds; or, in
        # place, writes the state itself (a failure then loses it).
        state, spare = (self._state, self._neuron_state) if self._in_place else self._spare
        try:
            afferent, step, neuron_state = self._engine.push(self._pipeline, forces, self._state, state,
                                                             self._samples, self._key, self._neuron_state, dt=self.dt,
                                                             method=self.method, parts=self._parts, spare=spare)
        except BaseException as exc:
            if self._in_place:
                self._lost = f"{type(exc).__name__}: {exc}"
            raise
        step0 = self._samples * self.substeps
        if not self._in_place:
            self._spare = (self._state, self._neuron_state)
        self._state, self._neuron_state = state, neuron_state
        self._samples += n
        if times is not None:
            self._last_time = float(times[-1])
        afferent, time = _in_order(afferent, step, self._order, self._positions, step0, self.dt)
        return StreamSpikes(afferent, time, forces)


@nb.njit(cache=True, nogil=True)
def _summary(forces):
    """(all finite, largest |component|, smallest F_Z) of samples (n, 3), in one pass."""
    finite, peak, fz_min = True, 0.0, np.inf
    for i in range(forces.shape[0]):
        for k in range(3):
            x = forces[i, k]
            finite &= math.isfinite(x)
            peak = max(peak, abs(x))
        fz_min = min(fz_min, forces[i, 2])
    return finite, peak, fz_min


@nb.njit(cache=True, nogil=True)
def _in_order(idx, stp, order, n, step0, dt):
    """Spikes (columns ``idx``, steps ``stp`` within the chunk) as (position in the population, time in s),
    sorted by time, then position: ``order[idx]`` and ``(stp + step0) dt``.

    A neuron spikes at most once a step, so the keys ``(step - first) n +
    position`` (``n`` positions) are distinct and their order is the one
    wanted: a push spans a few steps, so they fit a few 11-bit digits, sorted
    digit by digit (an LSD radix sort, a pass over the spikes each);
    a chunk of many steps sorts them at once.
    """
    m = idx.size
    positions, time = np.empty(m, np.int64), np.empty(m)
    if m == 0:
        return positions, time
    lo = stp.min()
    keys = np.empty(m, np.int64)
    for k in range(m):
        keys[k] = (stp[k] - lo) * n + order[idx[k]]
    top, passes = keys.max(), 0
    while top > 0:
        top >>= 11
        passes += 1
    if passes > 3:
        keys = keys[np.argsort(keys)]
    else:
        other, count = np.empty(m, np.int64), np.empty(2049, np.int64)
        for p in range(passes):
            shift = 11 * p
            count[:] = 0
            for k in range(m):
                count[((keys[k] >> shift) & 2047) + 1] += 1
            for d in range(1, 2049):
                count[d] += count[d - 1]
            for k in range(m):
                d = (keys[k] >> shift) & 2047
                other[count[d]] = keys[k]
                count[d] += 1
            keys, other = other, keys
    for k in range(m):
        step = keys[k] // n
        positions[k] = keys[k] - step * n
        time[k] = (step + lo + step0) * dt
    return positions, time


def _type_positions(population, afferent_types) -> np.ndarray:
    """Positions of the afferents of ``afferent_types`` (all when None), checked as `simulate` checks them."""
    if afferent_types is None:
        return np.arange(len(population))
    from ddmm.models.afferent_types import normalize_type

    codes = {normalize_type(t) for t in ([afferent_types] if isinstance(afferent_types, str) else afferent_types)}
    idx = np.flatnonzero(np.isin(population.afferent_type, sorted(codes)))
    if idx.size == 0:
        raise ValueError(f"afferent_types={sorted(codes)} selects no afferent of this population")
    return idx
