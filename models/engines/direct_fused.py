"""The direct engine's integrator for the fused pipeline: the back pass and the neurons in one numba call.

`DirectEngine.advance` runs a chunk here: the pipeline's front pass and
transducers (`ddmm.models.fused.FusedPipeline.drive`), then
`back_and_integrate`: the fused back pass (`ddmm.models.fused._back`:
low-pass, bias, additive noise) and `ddmm.models.engines.direct.integrate_range`
on the currents while they are in cache, with the seam's checks
(`ddmm.models.engines.direct.spike_checks`).  A push that integrates on
several column ranges calls the parallel kernel from Python (numba's cache
does not track a cached caller's parallel callee).

The dependency goes this way only: the pipeline knows no engine.
"""

from __future__ import annotations

import numba as nb
import numpy as np

from ddmm.models._fused_tables import FusedTables, NoiseKey
from ddmm.models.engines import NeuronState, check_integration, check_stability, substeps_for
from ddmm.models.engines.direct import (
    Membrane,
    NeuronTable,
    integrate_parts,
    integrate_range,
    neuron_table,
    part_bounds,
    spike_checks,
)
from ddmm.models.fused import _back

__all__ = ["advance_fused", "back_and_integrate", "pipeline_spikes"]


@nb.njit(cache=True, nogil=True)
def back_and_integrate(tables, state, noise, current, neuron_table, mem, integrate):
    """`ddmm.models.fused._back`, then (if ``integrate``) the direct engine on the current.

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
