"""The engine seam: one `integrate` call, on any registered engine (`registry`).

Both engines take input currents for N afferents and return the spikes as
(afferent index, step index) pairs, identical between engines.  Currents are
sampled at ``fs`` and held for ``1 / (fs * dt)`` integration steps, which must
be a whole number: the input is the same piecewise-constant function of time
whatever the step, so changing dt changes only the integration error.
"""

from __future__ import annotations

import math
import warnings
from dataclasses import dataclass

import numpy as np

from ddmm.models.engines.registry import Engine, engine_names, get_engine, register_engine
from ddmm.models.neuron import V_FLOOR, V_PEAK, NeuronParams, neuron_arrays, resting_state
from ddmm.utils.notices import with_cli
from ddmm.utils.validation import as_finite_array, check_choice, check_positive

__all__ = ["ENGINES", "Engine", "get_engine", "register_engine", "engine_names", "METHODS", "MAX_NEGATIVE_DRIVE_MV",
           "NeuronState", "SpikeResult", "NumericalInstabilityError", "SpikeCapWarning", "substeps_for", "prepare",
           "integrate", "run_checked", "check_integration", "check_stability"]

#: Names of the engines registered with the package (`registry`).
ENGINES = engine_names()
#: Largest negative drive per step, dt * (-I) in mV, that the multi-stage methods
#: accept.  Beyond it their intermediate stages overshoot far below -100 mV,
#: where dv/dt = 0.04 v^2 + ... turns large and positive: rk2 then fires false
#: spikes every step and rk4 and the 2003 scheme overflow.  Euler needs no such
#: limit: the v floor protects it.
MAX_NEGATIVE_DRIVE_MV = 50.0
METHODS = ("euler", "rk2", "rk4", "izhikevich2003")


class NumericalInstabilityError(ValueError):
    """The integration left the finite numbers (the method is unstable at this dt and current)."""


class SpikeCapWarning(RuntimeWarning):
    """A neuron spiked on consecutive steps: the one-spike-per-step cap bound, rates are limited by 1/dt."""


@dataclass(frozen=True)
class NeuronState:
    """Membrane state of N neurons: ``v`` in mV, ``u`` in mV/ms, and ``r`` the refractory steps each has left
    (whole numbers as float64; None: none, `ddmm.models.neuron.NeuronParams.t_ref`)."""

    v: np.ndarray
    u: np.ndarray
    r: np.ndarray | None = None

    def __post_init__(self):  # sizes are checked against the currents by `integrate`
        for name in ("v", "u", "r"):
            value = getattr(self, name)
            arr = np.asarray(value)
            if (value is not None or name != "r") and (arr.dtype.kind not in "iuf" or arr.ndim != 1):
                raise TypeError(f"NeuronState {name} must be a 1-D numeric array (one value per neuron), got "
                                f"{type(value).__name__} of dtype {arr.dtype} and shape {arr.shape}")


@dataclass(frozen=True)
class SpikeResult:
    """Spikes of one `integrate` call.

    Attributes
    ----------
    afferent : ndarray of int64
        Column index of the spiking afferent, one entry per spike.
    step : ndarray of int64
        Integration step at whose start the spike is recorded; its time is
        ``step * dt`` seconds.  Sorted by step, then afferent.
    state : NeuronState
        State after the last step (to continue a run).
    dt : float
        Step in seconds.
    n_steps : int
        Steps integrated.
    """

    afferent: np.ndarray
    step: np.ndarray
    state: NeuronState
    dt: float
    n_steps: int

    @property
    def time(self) -> np.ndarray:
        """Spike times in seconds."""
        return self.step * self.dt

    def counts(self, n_afferents: int) -> np.ndarray:
        """Spike count per afferent."""
        return np.bincount(self.afferent, minlength=n_afferents)


def substeps_for(fs: float, dt: float) -> int:
    """Integration steps per input sample, ``1 / (fs * dt)``, checked to be whole.

    Examples
    --------
    >>> substeps_for(1000.0, 1e-4)
    10
    """
    fs = check_positive(fs, "fs", "Hz")
    dt = check_positive(dt, "dt", "s")
    ratio = 1.0 / (fs * dt)
    n = int(round(ratio))
    if n < 1 or abs(ratio - n) > 1e-9 * max(1.0, ratio):
        rates = sorted({1.0 / (k * dt) for k in (max(1, math.floor(ratio)), max(1, math.ceil(ratio)))})
        raise ValueError(
            f"dt={dt:g} s ({dt * 1e3:g} ms) must divide the sample interval 1/fs = {1.0 / fs:g} s "
            f"({1e3 / fs:g} ms) a whole number of times; the nearest rates it divides: "
            f"{' and '.join(f'{r:g} Hz' for r in rates)} (or choose a dt that divides 1/fs)"
        )
    return n


def prepare(engine) -> None:
    """Import an engine's heavy modules now, in the calling (main) thread.

    ``import brian2`` installs a SIGINT handler, which Python allows only in
    the main thread; callers that integrate from worker threads call this
    first.
    """
    get_engine(engine).prepare()


def _initial_state(state, b, n):
    if state is None:
        v, u = resting_state(b)
        return np.array(v, dtype=float), np.array(u, dtype=float), np.zeros(n)
    if not isinstance(state, NeuronState):
        raise TypeError(f"state must be a NeuronState or None, got {type(state).__name__}")
    v = as_finite_array(state.v, "state.v", ndim=1).copy()
    u = as_finite_array(state.u, "state.u", ndim=1).copy()
    r = np.zeros(n) if state.r is None else as_finite_array(state.r, "state.r", ndim=1).copy()
    if v.shape != (n,) or u.shape != (n,) or r.shape != (n,):
        raise ValueError(f"state must hold {n} neurons, got v {v.shape}, u {u.shape} and r {r.shape}")
    if np.any((r < 0) | (r != np.rint(r))):
        bad = float(r[(r < 0) | (r != np.rint(r))][0])
        raise ValueError(f"state.r must hold whole numbers of steps >= 0, got {bad:g}")
    return v, u, r


def integrate(
    current,
    *,
    fs: float,
    dt: float,
    afferent_type,
    engine: str = "brian2",
    method: str = "euler",
    state: NeuronState | None = None,
    neuron_params: dict[str, NeuronParams] | None = None,
) -> SpikeResult:
    """Integrate Izhikevich afferents driven by input currents (eqs 4-6).

    Parameters
    ----------
    current : array_like, shape (n_samples, n_afferents)
        Input current in mV/ms (Izhikevich units), sampled at ``fs``.
    fs : float
        Sample rate of ``current`` in Hz.
    dt : float
        Integration step in seconds; ``1 / (fs * dt)`` must be a whole number.
    afferent_type : str or sequence of str
        ``"SAI"``, ``"RAI"`` or ``"RAII"``, one per column or one for all.
    engine : {"brian2", "direct"} or Engine
        Brian2 C++ standalone (default) or the numba integrator, or any
        registered `Engine`.  Same spikes.
    method : {"euler", "rk2", "rk4", "izhikevich2003"}
        Integration scheme: forward Euler (default), Brian2's midpoint
        "rk2" and classical "rk4", or Izhikevich's 2003 scheme (two
        half-steps of v, then u from the new v).
    state : NeuronState, optional
        Initial state; default: each neuron's resting fixed point.
    neuron_params : dict, optional
        Overrides of `ddmm.models.neuron.NEURON_PARAMS` by type.

    Returns
    -------
    SpikeResult

    Raises
    ------
    NumericalInstabilityError
        If the state becomes non-finite (rk4 and the 2003 scheme can, at
        large dt and current); NaN never leaves this function.

    Warns
    -----
    SpikeCapWarning
        When a neuron spikes on consecutive steps.

    Examples
    --------
    >>> res = integrate(np.full((100, 1), 10.0), fs=1000.0, dt=1e-4,
    ...                 afferent_type="SAI", engine="direct")
    >>> res.counts(1).tolist()
    [3]
    """
    engine = get_engine(engine)
    check_choice(method, "method", METHODS)
    substeps = substeps_for(fs, dt)
    current = as_finite_array(current, "current", ndim=2)
    n = current.shape[1]
    types = np.broadcast_to(np.asarray(afferent_type, dtype=object), (n,))
    params = neuron_arrays(types, neuron_params)
    v, u, r = _initial_state(state, params["b"], n)
    return run_checked(np.ascontiguousarray(current), substeps, dt, params, v, u, engine, method, r)


def run_checked(current, substeps, dt, params, v, u, engine, method, r=None, *, stacklevel=4) -> SpikeResult:
    """`integrate` on inputs already checked: the seam's engines, stability and spike checks.

    ``current`` is a finite, C-contiguous float64 (n_samples, n) array in
    mV/ms; ``params`` as `ddmm.models.neuron.neuron_arrays` gives them; ``v`` and
    ``u`` (mV) and ``r`` (refractory steps left; None: zeros) are updated in
    place to the final state.  For callers that made their inputs themselves
    (`Engine.advance`); ``stacklevel`` of the spike-cap warning counts from
    the check (4: the caller of our caller).
    """
    n = current.shape[1]
    r = np.zeros(n) if r is None else r
    params = params if "t_ref" in params else {**params, "t_ref": np.zeros(n)}
    check_stability(current, dt, method)
    if n == 0 or current.shape[0] == 0:
        neuron = step = np.empty(0, np.int64)
    else:
        neuron, step = get_engine(engine).run(current, substeps, dt, params, v, u, r, method=method, v_peak=V_PEAK,
                                              v_floor=V_FLOOR)
    check_integration(neuron, step, v, u, current, method, dt, stacklevel=stacklevel)  # default: our caller's caller
    return SpikeResult(neuron, step, NeuronState(v, u, r), dt, current.shape[0] * substeps)


def check_stability(current, dt, method) -> None:
    """Refuse negative drives a multi-stage method cannot integrate (see MAX_NEGATIVE_DRIVE_MV)."""
    if method == "euler" or current.size == 0:
        return
    drive = -float(current.min()) * dt * 1e3
    if drive > MAX_NEGATIVE_DRIVE_MV:
        raise NumericalInstabilityError(
            f"method={method!r} is unstable for currents down to {current.min():.3g} mV/ms at dt={dt * 1e3:g} ms "
            f"(a step's negative drive of {drive:.3g} mV exceeds {MAX_NEGATIVE_DRIVE_MV:g} mV); "
            "use method='euler' (protected by the v floor) or a smaller dt"
        )


def check_integration(neuron, step, v, u, current, method, dt, stacklevel=3) -> None:
    """Never hand back NaN (raise); warn when the one-spike-per-step cap bound."""
    if not (np.all(np.isfinite(v)) and np.all(np.isfinite(u))):
        bad = int(np.flatnonzero(~(np.isfinite(v) & np.isfinite(u)))[0])
        raise NumericalInstabilityError(
            f"method={method!r} diverged (non-finite membrane state, neuron {bad}) at dt={dt * 1e3:g} ms with "
            f"currents up to {np.abs(current).max():.3g} mV/ms; use a smaller dt or method='euler'"
        )
    if neuron.size > 1:
        from ddmm.models.engines.direct import cap_scan

        capped, ordered = cap_scan(np.asarray(neuron, np.int64), np.asarray(step, np.int64), int(neuron.max()) + 1)
        if ordered and not capped:  # one pass, no sort: the common case
            return
        order = np.lexsort((step, neuron))
        consecutive = (np.diff(step[order]) == 1) & (np.diff(neuron[order]) == 0)
        if consecutive.any():
            n_capped = np.unique(neuron[order][1:][consecutive]).size
            text = (f"{n_capped} neuron(s) spiked on consecutive steps: the one-spike-per-step cap bound at "
                    f"dt={dt * 1e3:g} ms (rates up to {1.0 / dt:.0f} pulses/s)")
            warnings.warn(with_cli(SpikeCapWarning(f"{text}; use a smaller dt"), f"{text}; use a smaller --dt (ms)"),
                          stacklevel=stacklevel)
