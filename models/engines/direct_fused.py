"""The direct engine's integrator for the fused pipeline: the back pass and the neurons in one numba call.

`DirectEngine.advance` runs a chunk here: the pipeline's front pass and
transducers (`ddmm.models.fused.FusedPipeline.drive`), then
`back_and_integrate`: the fused back pass (`ddmm.models._fused_passes._back`:
low-pass, bias, additive noise) and `ddmm.models.engines.direct.integrate_range`
on the currents while they are in cache, with the seam's checks
(`ddmm.models.engines.direct.spike_checks`).  A push that integrates on
several column ranges calls the parallel kernel from Python (numba's cache
does not track a cached caller's parallel callee).

The dependency goes this way only: the pipeline knows no engine.
"""

from __future__ import annotations

import math

import numba as nb
import numpy as np

from ddmm.models._fused_tables import FusedTables, NoiseKey
from ddmm.models._transducer_kernels import TransducerPass, transduce_post
from ddmm.models.engines import NeuronState, check_integration, check_stability, substeps_for
from ddmm.models.engines.direct import (
    PUSH_BLOCK,
    Membrane,
    NeuronTable,
    _concatenate,
    integrate_parts,
    integrate_range,
    integrate_span,
    neuron_table,
    part_bounds,
    spike_checks,
)
from ddmm.models._fused_passes import _back, _back_range

__all__ = ["advance_fused", "back_and_integrate", "pipeline_spikes", "push_fused"]


@nb.njit(cache=True, nogil=True)
def back_and_integrate(tables, state, noise, current, neuron_table, mem, integrate):
    """`ddmm.models._fused_passes._back`, then (if ``integrate``) the direct engine on the current.

    ``tables``, ``state`` and ``noise`` as `_back` takes them; ``neuron_table``
    is the `NeuronTable` and ``mem`` the `Membrane` (updated in place), all as
    plain tuples from Python (`ddmm.models._fused_tables`).
    Returns spikes, the smallest current (inf for Euler, whose check does
    not read it), whether the state stayed finite and whether a neuron spiked
    on consecutive steps (the one-spike-per-step cap bound): the seam's
    checks need the full spike lists only then.
    """
    tables, noise = FusedTables(*tables), NoiseKey(*noise)  # plain tuples from Python, named again
    table, mem = NeuronTable(*neuron_table), Membrane(*mem)
    lowest = _back(tables, state, noise, current, table.method != 0)
    if not integrate:
        return np.empty(0, np.int64), np.empty(0, np.int64), lowest, True, False
    idx, stp = integrate_range(current, table, mem, 0, mem.v.size)
    finite, capped, _ = spike_checks(idx, stp, mem.v, mem.u)
    return idx, stp, lowest, finite, capped


def pipeline_spikes(pipeline, forces, state, started, sample0, key, neuron_table, mem, parts=1):
    """Currents, then the direct engine: (current, afferent, step, smallest current, finite, capped).

    Parameters
    ----------
    pipeline : ddmm.models.fused.FusedPipeline
    forces, state, started, sample0, key
        As `FusedPipeline.currents` takes them (``state`` updated in place).
    neuron_table : NeuronTable
        The integrator's constants (`ddmm.models.engines.direct.neuron_table`).
    mem : Membrane
        ``v``, ``u`` and ``r`` (refractory steps left), updated in place.
    parts : int
        Column ranges integrated in parallel (the spikes are the same,
        ordered range by range).

    Returns
    -------
    tuple
        (current, afferent, step, smallest current, finite, capped).
    """
    bounds = pipeline.memo(("direct parts", parts), lambda: part_bounds(pipeline.n_afferents, parts))
    current = pipeline.drive(forces, state, started, sample0, key, bounds)
    serial, table, mem = bounds.size <= 2, tuple(neuron_table), tuple(mem)  # plain tuples: numba types them in C
    out = back_and_integrate(pipeline.kernel_tables, state, tuple(pipeline.noise_key(key, sample0)), current, table,
                             mem, serial)
    if not serial:  # from Python, as the front's parallel kernel
        idx, stp = integrate_parts(current, table, mem, bounds)
        out = (idx, stp, out[2], *spike_checks(idx, stp, mem[0], mem[1])[:2])
    return (current, *out)


def advance_fused(pipeline, forces, state, sample0, key, neuron_state, *, dt, method, parts=1):
    """`ddmm.models.engines.registry.DirectEngine.advance`: one chunk of ``pipeline`` with the seam's checks.

    Arguments as `FusedPipeline.advance`; returns (afferent, step within
    the chunk, `NeuronState` after).
    """
    table = pipeline.memo(("direct", float(dt), method),
                          lambda: neuron_table(pipeline.neuron_arrays(), substeps_for(pipeline.fs, dt), dt, method))
    mem = Membrane(*pipeline.initial_membrane(neuron_state, key))
    current, afferent, step, lowest, finite, capped = pipeline_spikes(pipeline, forces, state, sample0 > 0, sample0,
                                                                      key, table, mem, parts)
    if method != "euler":
        check_stability(np.array([lowest]), dt, method)
    if not finite or capped:  # the warning names the caller of `FusedPipeline.advance`
        check_integration(afferent, step, mem.v, mem.u, current, method, dt, stacklevel=5)
    return afferent, step, NeuronState(mem.v, mem.u, mem.r)


@nb.njit(cache=True, nogil=True)
def _back_part(tables, state, noise, current, trans, table, source, mem, a0, a1):
    """A streaming push's afferents ``a0..a1`` after `FusedPipeline.push_drive`: the transducers' last pass
    (`transduce_post`; ``trans`` is the `TransducerPass`), the back pass (`_back_range`), then the neurons
    from ``source`` into ``mem`` (`integrate_span`), with the seam's checks on these neurons.

    Returns (afferent, step, smallest current, finite, capped) as
    `back_and_integrate`; ``capped`` here says a neuron spiked on
    consecutive steps (a range's spikes come neuron by neuron in time order).
    """
    transduce_post(current, trans.runs_i, trans.runs_f, trans.negative, a0, a1)
    lowest = _back_range(tables, state, noise, current, table.method != 0, a0, a1)
    idx, stp = integrate_span(current, table, source, mem, a0, a1)
    finite = True
    for j in range(a0, a1):
        if not (math.isfinite(mem.v[j]) and math.isfinite(mem.u[j])):
            finite = False
    last, capped = np.full(a1 - a0, -2, np.int64), False
    for k in range(idx.size):
        j = idx[k] - a0
        if stp[k] == last[j] + 1:
            capped = True
        last[j] = stp[k]
    return idx, stp, lowest, finite, capped


@nb.njit(cache=True, nogil=True)
def _back_push(tables, state, noise, current, trans, table, source, mem):
    """`_back_part` on every afferent (plain tuples from Python, named again here)."""
    tables, noise, table = FusedTables(*tables), NoiseKey(*noise), NeuronTable(*table)
    trans = TransducerPass(*trans)
    return _back_part(tables, state, noise, current, trans, table, Membrane(*source), Membrane(*mem), 0,
                      current.shape[1])


@nb.njit(cache=True, nogil=True, parallel=True)
def _back_push_parts(tables, state, noise, current, trans, table, source, mem, bounds):
    """`_back_part` on the afferent ranges ``bounds[p]..bounds[p+1]`` in parallel; the spikes range by range."""
    # Three names an assignment at most: a longer unpacking builds a tuple, which hides the named tuples'
    # definitions from numba's parallel lowering.
    tables, noise, table = FusedTables(*tables), NoiseKey(*noise), NeuronTable(*table)
    source, mem, trans = Membrane(*source), Membrane(*mem), TransducerPass(*trans)
    n_parts = bounds.size - 1
    idx_parts = [np.empty(0, np.int64) for _ in range(n_parts)]
    stp_parts = [np.empty(0, np.int64) for _ in range(n_parts)]
    lowest, finite, capped = np.empty(n_parts), np.empty(n_parts, np.bool_), np.empty(n_parts, np.bool_)
    for p in nb.prange(n_parts):
        idx_parts[p], stp_parts[p], lowest[p], finite[p], capped[p] = _back_part(
            tables, state, noise, current, trans, table, source, mem, bounds[p], bounds[p + 1])
    return _concatenate(idx_parts), _concatenate(stp_parts), lowest.min(), finite.all(), capped.any()


def push_fused(pipeline, forces, before, after, sample0, key, neuron_state, *, dt, method, parts=1, spare=None):
    """`ddmm.models.engines.registry.DirectEngine.push`: one streaming chunk in two parallel regions.

    The front pass (`FusedPipeline.push_drive`: ``before`` read, ``after``
    written, ranges in parallel), numpy's log1p and tanh, then per range the
    transducers' last pass, the back pass and the neurons (`_back_part`), so
    that a push copies no state: the neurons are read from ``neuron_state``
    (None: `FusedPipeline.initial_membrane`) and written to ``spare`` (a
    `NeuronState` whose arrays are overwritten; None: new arrays).  With
    ``after`` being ``before`` the filter state is updated in place.
    Returns (afferent, step within the chunk, `NeuronState` after), the
    spikes range by range; they equal `advance_fused`'s, bit for bit.
    """
    table = pipeline.memo(("direct push", float(dt), method), lambda: tuple(
        neuron_table(pipeline.neuron_arrays(), substeps_for(pipeline.fs, dt), dt, method)._replace(block=PUSH_BLOCK)))
    bounds = pipeline.memo(("direct parts", parts), lambda: part_bounds(pipeline.n_afferents, parts))
    if neuron_state is None:
        source = pipeline.initial_membrane(None, key)
    else:
        r = neuron_state.r if neuron_state.r is not None else np.zeros(neuron_state.v.size)
        source = (neuron_state.v, neuron_state.u, r)
    n, reuse = pipeline.n_afferents, spare is not None and spare.r is not None and spare.v.size == pipeline.n_afferents
    mem = (spare.v, spare.u, spare.r) if reuse else (np.empty(n), np.empty(n), np.empty(n))
    noise, runs = tuple(pipeline.noise_key(key, sample0)), pipeline.transducer_runs
    current, negative = pipeline.push_drive(forces, after, before, sample0 > 0, sample0, key, bounds, noise=noise)
    trans = (runs.runs_i, runs.runs_f, negative)  # a `TransducerPass`, as a plain tuple
    args = (pipeline.kernel_tables, after, noise, current, trans, table, source, mem)
    if bounds.size <= 2:
        afferent, step, lowest, finite, capped = _back_push(*args)
    else:  # from Python, as the front's parallel kernel
        afferent, step, lowest, finite, capped = _back_push_parts(*args, bounds)
    if method != "euler":
        check_stability(np.array([lowest]), dt, method)
    if not finite or capped:  # the warning names the caller of `Engine.push`
        check_integration(afferent, step, mem[0], mem[1], current, method, dt, stacklevel=5)
    return afferent, step, spare if reuse else NeuronState(*mem)
