"""A simulation Dataset's spikes as the input layer of a Brian2 network: a ``SpikeGeneratorGroup``.

Layout of the group `to_brian2` returns:

* one generator neuron per afferent, index ``i`` = the afferent's position
  on the Dataset's ``afferent`` dim; its spikes are those of one
  (condition, trial), or of every (condition, trial) one after another;
* spike times on the group's clock: a spike at ``t`` s goes to the step of
  ``dt`` that contains it, ``floor(t / dt)`` (a time within 1e-6 of a step
  below a step boundary counts as on it, so that ``n * dt`` rounded by floats
  stays in step ``n``), and is emitted at that step's start;
* numeric afferent metadata as read-only Brian2 variables, usable in
  ``Synapses.connect(condition=...)`` (with ``_pre``), in
  ``Synapses(on_pre=...)`` and as ``group.x_mm[:]``: ``afferent_id``,
  ``x_mm``, ``y_mm`` (mm), ``theta_t`` (deg), ``k``, ``gain`` and
  ``sensitivity`` (dimensionless; 1 for a Dataset older than it), stored as plain numbers;
* text metadata as read-only numpy arrays on the group (Brian2 variables
  are numeric): ``afferent_type``, ``nap`` and ``region``, to select
  presynaptic indices, e.g. ``i=np.flatnonzero(group.afferent_type ==
  "SAI")``;
* ``group.pairs`` (n, 2): the (condition, trial) positions it holds, and
  ``group.offsets`` (n,): where each starts on the group's clock, in s.

The group itself is returned (not a wrapper), so Brian2's ``run()`` finds
it in the caller's namespace as it finds any group the caller made.
"""

from __future__ import annotations

import numbers

import numpy as np

from ddmm.population.io import _export as ex
from ddmm.utils.validation import check_positive

__all__ = ["to_brian2"]

_TOL = 1e-6  # fraction of a step: a time this close below a step boundary counts as on it
_VARIABLES = (("afferent_id", "afferent", np.int64), ("x_mm", "x_mm", np.float64), ("y_mm", "y_mm", np.float64),
              ("theta_t", "theta_t", np.float64), ("k", "k", np.float64), ("gain", "gain", np.float64),
              ("sensitivity", "sensitivity", np.float64))  # (Brian2 variable, Dataset coord, dtype)
_LABELS = ("afferent_type", "nap", "region")


def to_brian2(dataset, condition=0, trial=0, *, dt=None, join_trials=False, merge=False, gap_s=0.0,
              name="afferents"):
    """A `brian2.SpikeGeneratorGroup` emitting a Dataset's spikes, one neuron per afferent (layout in the module
    docstring).

    Parameters
    ----------
    dataset : xarray.Dataset
        A Dataset of `ddmm.population.simulate` or `load_dataset` with spike events.
    condition : int or str, optional
        The condition, by position or by scene name.
    trial : int, optional
        The trial, by position.
    dt : float or brian2 Quantity, optional
        The target network's time step in s (default: the simulation's,
        ``dataset.attrs["dt"]``); also the group's clock.  Exact (every spike
        at its own time) when the simulation's dt is a whole multiple of it:
        equal, or finer by an integer factor.  Otherwise spikes move earlier,
        by less than ``dt``, to the start of their step.
    join_trials : bool, optional
        Every (condition, trial) of the Dataset, condition-major (condition
        0's trials, then condition 1's), on one clock: each starts where the
        one before ended (its condition's duration) plus ``gap_s``, rounded
        up to a whole step.  ``condition`` and ``trial`` must then stay 0.
    merge : bool, optional
        At a ``dt`` coarser than the simulation's one afferent may spike twice
        in one step, which Brian2 cannot emit: an error, unless ``merge``,
        which keeps the first of them and drops the others.
    gap_s : float, optional
        Silence between joined trials, in s (>= 0).
    name : str, optional
        The group's Brian2 name (unique within a network; end it with ``*``
        to let Brian2 number it).

    Returns
    -------
    brian2.SpikeGeneratorGroup

    Raises
    ------
    TypeError, ValueError
        On a bad dataset or argument, or two spikes of one afferent in one
        step without ``merge``.

    Examples
    --------
    >>> from ddmm.population import birznieks, make_population, simulate, to_brian2
    >>> ds = simulate(make_population(["SAI", "RAI"]), birznieks(90.0), engine="direct", quiet=True)
    >>> group = to_brian2(ds)  # condition 0, trial 0, at the simulation's dt
    >>> group.N, len(group.spike_time) == int(ds.spike_count.sum()), group.afferent_type.tolist()
    (2, True, ['SAI', 'RAI'])
    >>> import numpy as np
    >>> sa1 = np.flatnonzero(group.afferent_type == "SAI")  # e.g. Synapses(group, ...).connect(i=sa1, j=0)
    >>> sa1.tolist(), group.x_mm[:].tolist(), group.offsets.tolist()
    ([0], [0.0, 0.0], [0.0])
    """
    ex.check_dataset(dataset, "to_brian2")
    brian2 = _import_brian2()
    dt = _target_dt(dataset, dt, brian2)
    pairs = _pairs(dataset, condition, trial, join_trials)
    gap_s = _flags(merge, gap_s, name)
    index, step, offsets = _events(dataset, pairs, dt, gap_s)
    index, step = _one_per_step(dataset, index, step, dt, merge)
    group = brian2.SpikeGeneratorGroup(dataset.sizes["afferent"], index, (step * dt) * brian2.second,
                                       dt=dt * brian2.second, sorted=True, name=name)
    _attach(group, dataset, pairs, offsets * dt)
    return group


def _import_brian2():
    """Brian2, imported the engine's way (it does not take over the process's warnings and logging)."""
    from ddmm.models.engines.brian2 import import_brian2

    return import_brian2()


def _target_dt(dataset, dt, brian2) -> float:
    """The target dt in s: a positive finite number or Brian2 time; the simulation's when None."""
    if "dt" not in dataset.attrs:
        raise ValueError("to_brian2: dataset attrs lack 'dt' (the simulation's step); allowed: a Dataset from "
                         "ddmm.population.simulate or load_dataset")
    if dt is None:
        dt = dataset.attrs["dt"]
    if isinstance(dt, brian2.Quantity):
        if not brian2.have_same_dimensions(dt, brian2.second) or dt.size != 1:
            raise TypeError(f"to_brian2: dt must be a time (s), got {dt!r}")
        dt = float(np.asarray(dt / brian2.second).item())
    return check_positive(dt, "to_brian2: dt", "s")


def _position(value, name: str, size: int, labels=None) -> int:
    """``value`` as a position in 0..size-1 (or, with ``labels``, a label's position)."""
    if labels is not None and isinstance(value, str):
        if value not in labels:
            raise ValueError(f"to_brian2: {name}={value!r} is not in the Dataset; allowed: {', '.join(labels)} "
                             f"or a position 0..{size - 1}")
        return labels.index(value)
    if isinstance(value, bool) or not isinstance(value, numbers.Integral):
        kinds = "an int or a str" if labels is not None else "an int"
        raise TypeError(f"to_brian2: {name} must be {kinds}, got {type(value).__name__}")
    if not 0 <= value < size:
        raise ValueError(f"to_brian2: {name} must be in 0..{size - 1}, got {int(value)}")
    return int(value)


def _pairs(dataset, condition, trial, join_trials) -> np.ndarray:
    """The (condition, trial) positions to emit, (n, 2), in order."""
    if not isinstance(join_trials, bool):
        raise TypeError(f"to_brian2: join_trials must be a bool, got {type(join_trials).__name__}")
    if dataset.sizes["afferent"] == 0:
        raise ValueError("to_brian2: dataset has no afferents")
    labels = [str(c) for c in dataset["condition"].values]
    c = _position(condition, "condition", dataset.sizes["condition"], labels)
    t = _position(trial, "trial", dataset.sizes["trial"])
    if not join_trials:
        return np.array([[c, t]], dtype=np.int64)
    if (c, t) != (0, 0):
        raise ValueError(f"to_brian2: join_trials=True joins every (condition, trial); leave condition and trial "
                         f"at 0, got condition={condition!r}, trial={trial!r}")
    return np.stack(ex.trial_grid(dataset), axis=1).astype(np.int64)


def _flags(merge, gap_s, name) -> float:
    """Check ``merge`` and ``name``; ``gap_s`` as a float >= 0."""
    if not isinstance(merge, bool):
        raise TypeError(f"to_brian2: merge must be a bool, got {type(merge).__name__}")
    if not isinstance(name, str):
        raise TypeError(f"to_brian2: name must be a str, got {type(name).__name__}")
    if isinstance(gap_s, bool) or not isinstance(gap_s, numbers.Real):
        raise TypeError(f"to_brian2: gap_s must be a real number (s), got {type(gap_s).__name__}")
    if not (np.isfinite(gap_s) and gap_s >= 0):
        raise ValueError(f"to_brian2: gap_s must be a finite number >= 0 s, got {float(gap_s)}")
    return float(gap_s)


def _events(dataset, pairs, dt: float, gap_s: float):
    """Afferent position and step (on the joined clock) of every event of ``pairs``, and each pair's first step."""
    n_t = dataset.sizes["trial"]
    order = np.full(dataset.sizes["condition"] * n_t, -1, np.int64)
    order[pairs[:, 0] * n_t + pairs[:, 1]] = np.arange(len(pairs))
    which = order[dataset["spike_condition"].values.astype(np.int64) * n_t + dataset["spike_trial"].values]
    keep = which >= 0
    length = np.ceil((dataset["duration"].values[pairs[:, 0]] + gap_s) / dt - _TOL).astype(np.int64)
    offsets = np.concatenate([[0], np.cumsum(length)[:-1]]).astype(np.int64)
    local = np.floor(dataset["spike_time"].values[keep] / dt + _TOL).astype(np.int64)
    return dataset["spike_afferent"].values[keep].astype(np.int64), offsets[which[keep]] + local, offsets


def _one_per_step(dataset, index, step, dt: float, merge: bool):
    """The events sorted by (step, afferent) with at most one per afferent and step (else raise, or keep the first)."""
    order = np.lexsort((index, step))  # stable: equal (step, afferent) keep the Dataset's order (by time)
    index, step = index[order], step[order]
    twice = np.flatnonzero((np.diff(step) == 0) & (np.diff(index) == 0))
    if twice.size and not merge:
        a, s = int(index[twice[0]]), int(step[twice[0]])
        raise ValueError(f"to_brian2: afferent {int(dataset['afferent'].values[a])} (position {a}) spikes more than "
                         f"once in step {s} (t = {s * dt:.12g} s) at dt={dt} s; pass merge=True to keep one spike per "
                         f"step, or a dt <= {float(dataset.attrs['dt'])} s (the simulation's)")
    if twice.size:
        keep = np.ones(index.size, bool)
        keep[twice + 1] = False
        index, step = index[keep], step[keep]
    if step.size and step[-1] > np.iinfo(np.int32).max:
        raise ValueError(f"to_brian2: the last spike falls in step {int(step[-1])} at dt={dt} s, beyond Brian2's "
                         f"{np.iinfo(np.int32).max}; use a coarser dt or fewer joined trials")
    return index, step


def _attach(group, dataset, pairs, offsets_s) -> None:
    """Afferent metadata (read-only Brian2 variables and numpy attributes), ``pairs`` and ``offsets`` on ``group``."""
    n = group.N
    for variable, coord, dtype in _VARIABLES:
        values = dataset[coord].values if coord in dataset.variables else np.full(n, ex.OPTIONAL_FIELDS[coord])
        group.variables.add_array(variable, size=n, values=np.asarray(values, dtype), dtype=dtype,
                                  constant=True, read_only=True)
    arrays = {label: np.asarray(dataset[label].values).astype(str) for label in _LABELS}
    arrays.update(pairs=pairs, offsets=np.asarray(offsets_s, np.float64))
    for attribute, values in arrays.items():
        values.setflags(write=False)
        group.add_attribute(attribute)
        setattr(group, attribute, values)
