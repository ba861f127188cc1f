"""A streaming encoder: live fingertip force in, spikes out, with bounded latency.

`Encoder` keeps the whole pipeline's state between calls: the derivative
filters, every neuron's (v, u), and each afferent's noise stream.  Because
the filter is causal and every stage carries its state, the concatenated
spikes of *any* chunking equal the offline `simulate` run of the whole
signal with the same seed (condition 0, trial 0), bit for bit.

Each chunk runs through `models.fused.FusedPlan`: two numba passes (force
to linear drive, then current to spikes) around numpy's transducers, with
the same arithmetic as the offline stage-by-stage path.

Noise is drawn ahead in blocks (``noise_block`` samples per afferent) from
the same per-afferent streams as offline, on a background thread while the
previous block is consumed, so a chunk only slices a ready block and drawing
(hundreds of ms for a whole hand) never stalls the stream.
"""

from __future__ import annotations

from collections import deque
from concurrent.futures import ThreadPoolExecutor
from dataclasses import dataclass

import numpy as np

from models._validation import as_finite_array, check_choice, check_positive
from models.attenuation import F_TH, NO_SHEAR_READINGS
from models.currents import check_fs
from models.direct import _BLOCK, _METHOD_CODES
from models.engines import (ENGINES, METHODS, NeuronState, check_integration, check_stability, integrate, prepare,
                            substeps_for)
from models.fused import FusedPlan, mix_forces
from models.neuron import V_FLOOR, V_PEAK, neuron_arrays, resting_state

from .noise import draw_noise, noise_streams, root_seed
from .sampling import Population
from .scenes import Contact, Sites
from .simulate import _grouped
from .spatial import frame_theta, local_mixing, receptive_field_weight, site_coverage

__all__ = ["StreamSpikes", "Encoder"]

_PREFETCH = ThreadPoolExecutor(max_workers=1, thread_name_prefix="ddmm-noise-prefetch")


@dataclass(frozen=True)
class StreamSpikes:
    """Spikes of one pushed chunk.

    Attributes
    ----------
    afferent : ndarray of int64
        Position of the spiking afferent in the encoder's population.
    time : ndarray of float
        Spike time in seconds since the first sample (``step * dt``).
    """

    afferent: np.ndarray
    time: np.ndarray


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
        (`population.spatial`), as `simulate` does for `Scene.from_sites`.
    noise_block : int
        Noise samples drawn ahead per afferent.

    Examples
    --------
    >>> from population import make_population
    >>> enc = Encoder(make_population(["SAI"]), fs=1000.0, engine="direct", seed=1)
    >>> out = enc.push(np.column_stack([np.zeros(300), np.zeros(300), np.full(300, 4.0)]))
    >>> bool(out.afferent.size > 0)
    True
    """

    def __init__(self, population, fs: float, *, dt: float = 1e-4, engine: str = "direct", method: str = "euler",
                 seed=None, no_shear: str = "smooth", contact: Contact | None = None, sites: Sites | None = None,
                 noise_block: int = 1000):
        if not isinstance(population, Population):
            raise TypeError(f"population must be a Population, got {type(population).__name__}")
        self.fs = check_positive(fs, "fs", "Hz")
        self.substeps = substeps_for(self.fs, dt)
        self.dt, self.engine = float(dt), check_choice(engine, "engine", ENGINES)
        self.method = check_choice(method, "method", METHODS)
        self.no_shear = check_choice(no_shear, "no_shear", NO_SHEAR_READINGS)
        if contact is not None and not isinstance(contact, Contact):
            raise TypeError(f"contact must be a Contact or None, got {type(contact).__name__}")
        if sites is not None and (not isinstance(sites, Sites) or contact is not None):
            raise TypeError("sites must be a Sites (and then no contact is given), got "
                            f"{type(sites).__name__} with contact={contact!r}")
        self.seed, self.contact, self.noise_block = root_seed(seed), contact, int(noise_block)
        self.sites = sites
        check_fs(self.fs, population.current, tuple(np.unique(population.afferent_type)))
        idx = np.arange(len(population))
        self._order = _grouped(population, idx, idx)  # contiguous (type, NAP) groups, as offline
        self._pop = population.select(self._order)
        self._precompute()
        prepare(engine)
        self.reset()

    def _precompute(self) -> None:
        """The fused plan's tables (the same values the offline path uses) and the integrator's constants."""
        pop = self._pop
        scale, self._mixing = pop.gain, None
        if self.contact is not None:
            scale = pop.gain * receptive_field_weight(pop.x_mm, pop.y_mm, pop.afferent_type, self.contact)
        elif self.sites is not None:
            scale = pop.gain * site_coverage(pop, self.sites)
            self._mixing = local_mixing(pop.x_mm, pop.y_mm, pop.afferent_type, self.sites)[:3]
        theta = pop.theta_t if self.sites is None else frame_theta(pop)
        self._plan = FusedPlan(pop.afferent_type, pop.nap, theta, pop.k, scale, pop.noise_cv, pop.noise_sigma,
                               pop.current, self.fs, self.no_shear, F_TH)
        p = neuron_arrays(pop.afferent_type)
        h, half = 1.0 * self.dt / 0.001, (1.0 * (0.5 * self.dt)) / 0.001  # as run_direct computes them
        self._neuron_args = (self.substeps, _METHOD_CODES[self.method], h, half, p["a"], p["b"], p["c"], p["d"],
                             V_PEAK, V_FLOOR, _BLOCK)
        self._b = p["b"]

    def reset(self) -> None:
        """Back to the start: filters unset, neurons at rest, noise streams rewound."""
        if getattr(self, "_pending", None) is not None:
            self._pending.result()  # let an in-flight draw finish before its streams are dropped
        self._pending = None
        self._state, self._neuron, self._samples, self._last_time = self._plan.new_state(), None, 0, None
        noisy = np.any(self._pop.noise_sigma > 0) or np.any(self._pop.noise_cv > 0)
        self._streams = noise_streams(self.seed, 0, 0, self._pop.afferent_id) if noisy else None
        self._blocks = deque()  # noise drawn ahead, oldest first; rows before _noise_pos are used
        self._noise_pos = 0
        if self._streams is not None:
            self._prefetch(self.noise_block)  # the first block is drawn before the first chunk arrives

    def wait_ready(self) -> None:
        """Block until the noise drawn ahead is ready (call before a real-time loop starts)."""
        if self._pending is not None:
            self._blocks.append(self._pending.result())
            self._pending = None

    @property
    def n_samples(self) -> int:
        """Samples consumed since the start (or the last reset)."""
        return self._samples

    def _peek_noise(self, n: int) -> np.ndarray:
        """The next ``n`` noise rows, drawing ahead as needed but consuming nothing.

        Draws advance the generators, so drawn rows are kept until used: a
        push that fails later leaves the noise sequence exactly where it was.
        Blocks are queued, never concatenated (a hand's block is 100 MB).
        """
        while sum(b.shape[0] for b in self._blocks) - self._noise_pos < n:
            if self._pending is None:
                self._prefetch(max(self.noise_block, n))
            self._blocks.append(self._pending.result())
            self._pending = None
        parts, start, need = [], self._noise_pos, n
        for block in self._blocks:
            take = min(need, block.shape[0] - start)
            parts.append(block[start:start + take])
            need, start = need - take, 0
            if need == 0:
                break
        ahead = sum(b.shape[0] for b in self._blocks) - self._noise_pos - n
        if self._pending is None and ahead < self.noise_block:
            self._prefetch(self.noise_block)  # keep a whole block drawn ahead of the one in use
        return parts[0] if len(parts) == 1 else np.concatenate(parts)

    def _consume_noise(self, n: int) -> None:
        self._noise_pos += n
        while self._blocks and self._noise_pos >= self._blocks[0].shape[0]:
            self._noise_pos -= self._blocks.popleft().shape[0]

    def _prefetch(self, rows: int) -> None:
        """Start drawing the next ``rows`` noise samples on the background thread (one draw at a time)."""
        self._pending = _PREFETCH.submit(lambda: draw_noise(self._streams, rows).T)

    def _validate(self, forces, times):
        forces = as_finite_array(forces, "forces")
        if self.sites is not None:
            if forces.ndim != 3 or forces.shape[1:] != (len(self.sites), 3):
                raise ValueError(f"forces must have shape (n, n_sites, 3) = (n, {len(self.sites)}, 3) for the "
                                 f"encoder's sites, got {forces.shape}")
        elif forces.ndim != 2 or forces.shape[1] != 3:
            raise ValueError(f"forces must have shape (n, 3) for (fx, fy, fz), got {forces.shape}")
        if np.any(forces[..., 2] < 0):
            raise ValueError("forces: the normal force fz must be >= 0 N")
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
            F_X, F_Y, F_Z in newtons, one row per sample at ``fs``.
        times : array_like, shape (n,), optional
            Sample times in seconds, checked to increase strictly across
            chunks (the encoder's clock is the sample count, not these).

        Raises
        ------
        ValueError
            For non-finite values, a negative normal force, a wrong shape or
            time going backwards; the encoder's state is left untouched.
        """
        forces, times = self._validate(forces, times)
        n = forces.shape[0]
        if n == 0:
            return StreamSpikes(np.empty(0, np.int64), np.empty(0))
        state = self._state.copy()  # committed only if the whole chunk succeeds
        if self._mixing is not None:
            forces = mix_forces(forces, *self._mixing)  # each afferent's own force, (n, n_afferents, 3)
        normals = None if self._streams is None else self._peek_noise(n).T
        afferent, step, v, u = self._run(forces, normals, state)
        step0 = self._samples * self.substeps
        self._state, self._neuron = state, NeuronState(v, u)
        if self._streams is not None:
            self._consume_noise(n)
        self._samples += n
        if times is not None:
            self._last_time = float(times[-1])
        afferent, step = self._order[afferent], step + step0
        if afferent.size > 1:
            order = np.lexsort((afferent, step))
            afferent, step = afferent[order], step[order]
        return StreamSpikes(afferent, step * self.dt)

    def _run(self, forces, normals, state):
        """The fused plan on a chunk: spikes and the neurons' new state (the seam's checks, without its set-up)."""
        started = self._samples > 0
        if self._neuron is None:
            v, u = (np.array(x, dtype=float) for x in resting_state(self._b))
        else:
            v, u = self._neuron.v.copy(), self._neuron.u.copy()
        if self.engine != "direct":
            current = self._plan.currents(forces, normals, state, started)
            res = integrate(current, fs=self.fs, dt=self.dt, afferent_type=self._pop.afferent_type,
                            engine=self.engine, method=self.method, state=NeuronState(v, u))
            return res.afferent, res.step, res.state.v, res.state.u
        current, afferent, step, lowest, finite = self._plan.spikes(forces, normals, state, started,
                                                                    self._neuron_args, v, u)
        if self.method != "euler":
            check_stability(np.array([lowest]), self.dt, self.method)
        if not finite or afferent.size > 1:
            check_integration(afferent, step, v, u, current, self.method, self.dt)
        return afferent, step, v, u
