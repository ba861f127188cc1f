"""The one production path from force to spikes: two numba passes over samples (`FusedPipeline`).

`simulate`, the streaming encoder, `compute_currents`, the paper's
reproductions and the calibration all run on it.  The model is described in
`ddmm.models.attenuation` and `ddmm.models.currents`, and computed stage by
stage in the reference oracle (`ddmm.models.reference_pipeline`).
`FusedPipeline` runs the same arithmetic, sample by sample, with every
per-call constant packed once into typed tables
(`ddmm.models._fused_tables.FusedTables`, built from an `AfferentColumns`):

1. **front** (one numba pass): shear magnitude and direction, each
   afferent's profile AF (`attenuation.profile_value`), the no-shear
   reading, F_A (with the presets' shear-magnitude term) or SA-II's stretch drive, then the type's linear stage
   (`_stage_kernels.filter_sections` and `stage_tail`: filter, derivative,
   adaptation, gain, receptor noise);
2. **transducers**: numpy's vectorised log1p/tanh on each type's columns (a
   scalar libm call in numba would differ in the last bit from numpy's SIMD
   ones, and is several times slower);
3. **back** (one numba pass, `_back`): the current's low-pass, the bias and the
   additive noise.

The passes' kernels are in `ddmm.models._fused_passes`.

Then an engine integrates the neurons (`FusedPipeline.advance` hands the
chunk to `ddmm.models.engines.Engine.advance`): the direct engine runs `_back`
and its integrator in one numba call (`ddmm.models.engines.direct_fused`);
an engine that takes currents gets `FusedPipeline.currents`.

The per-sample drive of the front pass (shear, profile AF, F_A or stretch,
site mixing) is in `ddmm.models._fused_drive`.

For the streaming encoder's large populations, the front pass also runs on
afferent ranges in parallel (`_front_parts`): afferents are independent, so
the bits are the same.  A streaming push (`FusedPipeline.push_drive`) runs
the front pass per range with the transducers' first pass, keeps each
range's profile AF from push to push, and leaves the transducers' last pass
to the engine's own parallel region (`ddmm.models._transducer_kernels.TransducerRuns`).

Because the scalar helpers are the very functions the oracle's kernels
call, and every operation keeps their order, the result is bit-identical to
the oracle's (``tests/models/test_reference_pipeline.py``, ``tests/models/test_fused.py``);
``tests/population/test_stream.py`` holds the streaming encoder, which runs
on this chunk by chunk, to the offline `simulate`.  Filter state has one
layout (`ddmm.models._fused_tables.rest_state`), the oracle's too.
"""

from __future__ import annotations

import numpy as np

from ddmm.models._fused_drive import mix_forces, mixing_matrix
from ddmm.models._fused_passes import _back, _front, _front_parts, _front_push, _front_push_parts
from ddmm.models._fused_tables import (
    AfferentColumns,
    _NO_FORCES,
    _NO_SITES,
    _NO_WEIGHTS,
    _SLICE,
    FusedTables,
    NoiseKey,
    afferent_table,
    group_tables,
    rest_state,
    transducer_runs,
    type_runs,
)
from ddmm.models._transducer_kernels import (
    transducer_table,
    transduce_columns,
    transduce_inplace,
    transduce_mid,
)
from ddmm.models.afferent_types import type_mask
from ddmm.models.attenuation import F_TH, NO_SHEAR_READINGS, UNTUNED
from ddmm.models.currents import excitability, initial_phase, type_filter_constants
from ddmm.models.engines import get_engine
from ddmm.models.neuron import neuron_arrays, resting_state
from ddmm.utils.validation import check_choice, check_positive

__all__ = ["AfferentColumns", "FusedPipeline", "mix_forces", "mixing_matrix"]

#: Rows (samples) of a drive from which the transducers run fused (`transduce_columns`): below, its
#: per-call set-up costs more than numpy's few passes save (a streaming push is one row).
_FUSED_ROWS = 64
#: A push updating its state in place, and one with no signed transducer (`FusedPipeline.push_drive`).
_IN_PLACE, _NO_SIGNS = np.zeros((0, 0)), np.zeros((0, 0), np.bool_)


def _with_input(consts, sections):
    """A type's `type_filter_constants` with a front end's ``sections`` run first (None: as they are)."""
    if sections is None:
        return consts
    stage, sos, alpha_adapt, alpha_smooth = consts
    return stage, np.vstack([np.asarray(sections, dtype=float).reshape(-1, 6), sos]), alpha_adapt, alpha_smooth


class FusedPipeline:
    """Tables of the fused pipeline for one population, ordered so that each type's afferents are contiguous.

    Parameters
    ----------
    columns : AfferentColumns
        The afferents' type, NAP, tuning, gain and noise, one value per afferent.
    params : CurrentParams
    fs : float
        Sample rate in Hz.
    no_shear : {"pass", "block", "smooth"}
        The reading of AF at or below the shear threshold (`ddmm.models.attenuation`).
    f_th : float
        Shear threshold in newtons.
    mixing : ndarray, shape (n_sites, n_afferents), optional
        Each afferent's coefficients of the site forces (`mixing_matrix`):
        the pipeline then takes site forces and mixes them in its kernel.
    neuron_params : dict, optional
        `ddmm.models.neuron.NeuronParams` by type code, overriding
        `NEURON_PARAMS` (both engines integrate with them).
    input_sections : dict, optional
        Filter sections (shape (n, 6), as `ddmm.models.current_filters.lowpass_sos`)
        by type code, run before the type's own filters on the attenuated
        force: a stimulus front end's transduction (an indentation's,
        `ddmm.population.stimuli.transduction`); None or a type left out: none.

    Attributes
    ----------
    Columns : type
        `AfferentColumns`, for callers that hold the pipeline class only.
    neuron_params : dict
        The ``neuron_params`` overrides.
    tables : FusedTables
        Every constant of both passes, built once (`ddmm.models._fused_tables`).
    kernel_tables : tuple
        ``tuple(tables)``, as the kernels take it from Python (numba types a
        plain tuple in C, a named one in Python).

    Examples
    --------
    >>> from ddmm.models.currents import CurrentParams
    >>> pipe = FusedPipeline(AfferentColumns.filled(["SAI"]), CurrentParams(), 1000.0)
    >>> pipe.currents(np.array([[0.0, 0.0, 2.0]]), pipe.new_state(), False).shape
    (1, 1)
    """

    def __init__(self, columns: AfferentColumns, params, fs: float, *, no_shear: str = "pass", f_th: float = F_TH,
                 mixing=None, neuron_params=None, input_sections=None):
        if not isinstance(columns, AfferentColumns):
            raise TypeError(f"columns must be an AfferentColumns, got {type(columns).__name__}")
        check_choice(no_shear, "no_shear", NO_SHEAR_READINGS)
        f_th = check_positive(f_th, "f_th", "N")  # the front divides by it (`VECTOR_KERNEL`)
        afferent_type, nap, afferent_id = np.asarray(columns.afferent_type), np.asarray(columns.nap), columns.afferent_id
        self.afferent_type, self._memo, self._neuron_arrays = afferent_type, {}, None
        self.neuron_params = dict(neuron_params or {})  # `NeuronParams` overrides by type (eqs 4-6 otherwise)
        self.mixing = None if mixing is None else np.ascontiguousarray(mixing, dtype=float)
        if self.mixing is not None and (self.mixing.ndim != 2 or self.mixing.shape[1] != afferent_type.size):
            raise ValueError(f"mixing must be (n_sites, {afferent_type.size}), one column per afferent, got shape "
                             f"{self.mixing.shape}")
        self.afferent_id = np.ascontiguousarray(np.arange(afferent_type.size) if afferent_id is None else afferent_id,
                                                dtype=np.int64)
        self.n_afferents, self.fs = afferent_type.size, float(fs)
        spans = type_runs(afferent_type, nap)  # runs of one type, tuned or not
        consts = [_with_input(type_filter_constants(params, str(afferent_type[a]), self.fs),
                              (input_sections or {}).get(str(afferent_type[a]))) for a, _ in spans]
        self.phase = np.zeros(self.n_afferents)  # per afferent: its type's start-phase spread (`TypeParams.phase`)
        for (a, b), (stage, *_) in zip(spans, consts):
            self.phase[a:b] = stage.phase
        noise_cv, noise_sigma = np.asarray(columns.noise_cv, dtype=float), np.asarray(columns.noise_sigma, dtype=float)
        sensitivity = None if columns.sensitivity is None else np.asarray(columns.sensitivity, dtype=float)
        unit = (np.asarray(columns.scale, dtype=float), sensitivity, self.afferent_id, noise_cv, noise_sigma)
        aff_f = afferent_table(nap, columns.theta_t, columns.k, spans, consts, unit, self.fs)
        grp_f, grp_i, sos = group_tables(spans, consts, noise_cv, nap != UNTUNED, self.fs)
        self.rows = 2 * sos.shape[1]
        self.tables = FusedTables(aff_f, grp_f, grp_i, sos, self.fs, no_shear == "smooth",
                                  1.0 if no_shear == "pass" else 0.0, float(f_th),
                                  _NO_WEIGHTS if mixing is None else self.mixing,
                                  mixing is not None, np.flatnonzero(noise_sigma > 0).astype(np.int64))
        self.kernel_tables = tuple(self.tables)  # as the kernels take it from Python
        self.excite_cv = np.zeros(self.n_afferents)  # per afferent: its type's trial excitability CV
        for (a, b) in spans:
            self.excite_cv[a:b] = params.excite_cv(str(afferent_type[a]))
        self.excite_any, self._excite = bool(np.any(self.excite_cv > 0)), (None, None)
        self.transducers, self._plain = transducer_runs(spans, consts)  # numpy's calls cost per call
        self.transducer_runs = transducer_table(self.transducers, self._plain)  # a streaming push's split passes

    def advance(self, forces, state, sample0, key, neuron_state, *, dt, method, engine, parts=1):
        """One chunk through the whole pipeline: (afferent, step within the chunk, `NeuronState` after).

        ``forces`` and ``key`` as `currents`; ``sample0`` is the chunk's first
        sample (0 starts the filters at rest on it); ``neuron_state`` the
        `NeuronState` before (None: at rest, `initial_membrane`).  The engine
        (a name or a `ddmm.models.engines.Engine`) supplies the integrator
        (`Engine.advance`), with the seam's checks; ``parts`` column ranges
        may run in parallel.
        """
        return get_engine(engine).advance(self, forces, state, sample0, key, neuron_state, dt=dt, method=method,
                                          parts=parts)

    def initial_neuron(self, key, b, d, c):
        """Neuron state (v, u) before the first sample: at rest, or with a stream ``key`` each afferent of a
        `AfferentType.phase_spread` type (SA-II) whose `TypeParams.phase` is > 0 at its own phase
        (`ddmm.models.currents.initial_phase`): ``v = c``, ``u = u_rest + phase U d``."""
        v, u = (np.array(x, dtype=float) for x in resting_state(b))
        tonic = type_mask(self.afferent_type, "phase_spread") & (self.phase > 0.0)
        if key is not None and tonic.any():
            cols = np.flatnonzero(tonic)
            v[cols] = np.asarray(c, dtype=float)[cols] if np.ndim(c) else c
            spread = self.phase[cols] * initial_phase(key, self.afferent_id[cols])
            u[cols] = u[cols] + spread * (np.asarray(d)[cols] if np.ndim(d) else d)
        return v, u

    def neuron_arrays(self) -> dict:
        """Per-afferent ``a``, ``b``, ``c``, ``d`` and ``t_ref`` (s) of eqs 4-6, with the `neuron_params`
        overrides (`ddmm.models.neuron.neuron_arrays`), computed once."""
        if self._neuron_arrays is None:
            self._neuron_arrays = neuron_arrays(self.afferent_type, self.neuron_params)
        return self._neuron_arrays

    def initial_membrane(self, neuron_state, key):
        """(v, u, r) to integrate a chunk from: copies of a `NeuronState` ``neuron_state`` (its ``r`` None:
        zeros), or for None the state before the first sample (`initial_neuron` with ``key``; no refractory
        steps)."""
        if neuron_state is None:
            p = self.neuron_arrays()
            v, u = self.initial_neuron(key, p["b"], p["d"], p["c"])
            return v, u, np.zeros(v.size)
        v, u, r = neuron_state.v, neuron_state.u, neuron_state.r
        return v.copy(), u.copy(), np.zeros(v.size) if r is None else r.copy()

    def memo(self, key, make):
        """``make()``, computed once per hashable ``key`` for this pipeline: what an engine derives from it
        (its integrator's tables for a step and method, its column ranges)."""
        if key not in self._memo:
            self._memo[key] = make()
        return self._memo[key]

    def new_state(self) -> np.ndarray:
        """Filter, offset, difference, adaptation, smoothing and dynamic-response state at rest, shape (n_rows, n_afferents)."""
        return rest_state(self.rows // 2, self.n_afferents)

    def noise_key(self, key, sample0) -> NoiseKey:
        """The kernels' `NoiseKey` for a stream ``key`` (None: noise-free) and the chunk's first sample."""
        return NoiseKey(np.uint64(key or 0), key is not None, self.afferent_id, int(sample0))

    def drive(self, forces, state, started, sample0, key, bounds=None, out=None):
        """The front pass and the transducers: the drive of the back pass (`_back`), shape (n_samples, n_afferents).

        Arguments as `currents`; with ``bounds`` (more than one afferent
        range, `ddmm.models.engines.direct.part_bounds`) the front pass runs
        on the ranges in parallel; ``out`` receives the result if given.
        """
        mixed = self.mixing is not None
        if forces.ndim != (3 if mixed else 2):
            raise ValueError(f"forces must be {'(n, n_sites, 3) site forces' if mixed else '(n, 3)'} for this pipeline, "
                             f"got shape {forces.shape}")
        # Plain tuples: numba types them in C at the call, a named tuple in Python (`ddmm.models._fused_tables`).
        args = (self.kernel_tables, state, (_NO_FORCES, forces) if mixed else (forces, _NO_SITES),
                tuple(self.noise_key(key, sample0)), started,
                np.empty((forces.shape[0], self.n_afferents)) if out is None else out)
        # The parallel kernel is called from here, never from a cached kernel
        # (numba's cache does not track a cached caller's parallel callee).
        drive = _front(*args) if bounds is None or bounds.size <= 2 else _front_parts(*args, bounds)
        excite = self.excitability(key) if key is not None and self.excite_any else None
        for cols, stage in self.transducers:  # as the oracle's `current_core`; a push of a few rows: numpy's passes cost least
            if stage.signed or drive.shape[0] < _FUSED_ROWS:
                transduce_inplace(drive[:, cols], stage, None if excite is None else excite[cols])
            else:
                transduce_columns(drive, cols, stage, None if excite is None else excite[cols])
        if excite is not None:
            for cols in self._plain:  # runs without a transducer: the factor alone
                drive[:, cols] *= excite[cols]
        return drive

    def push_work(self, bounds):
        """The work arrays of streaming pushes on the afferent ranges ``bounds`` (`push_drive`), made once:
        `front_scratch`'s arrays but the last, each range's profile direction (n_ranges, 2, n_groups; NaN:
        none yet) and the excitability factor of a trial without one (ones)."""
        def make():
            m = self.n_afferents
            scratch = (np.empty(m), np.empty(m), np.empty(m), np.empty(m), np.empty((3, m)), np.empty(m, np.uint64),
                       np.empty(m))
            return scratch, np.full((bounds.size - 1, 2, self.tables.grp_i.shape[1]), np.nan), np.ones(m)
        return self.memo(("push work", bounds.tobytes()), make)

    def push_drive(self, forces, state, source, started, sample0, key, bounds, noise=None):
        """A streaming push's drive on the afferent ranges ``bounds`` (in parallel when more than one), all
        but the transducers' last pass: (drive, sign mask), shape (n_samples, n_afferents) each.

        The engine finishes each range with `transduce_post` (``* i_max`` and
        the sign mask; its `TransducerRuns` is `transducer_runs`) and
        `_back_range`, in its own parallel region
        (`ddmm.models.engines.direct_fused`): the drive then equals
        `drive`'s, bit for bit.  ``state`` receives the filter state after
        the chunk; the state before is read from ``source`` (left as it is),
        or, when ``source`` is ``state``, ``state`` is updated in place.
        Each range keeps its profile AF from push to push (`push_work`): a
        shear direction held from the last push costs no profile evaluation.
        ``noise`` is ``tuple(noise_key(key, sample0))`` if the caller has it.  Other arguments as `drive`.
        """
        mixed = self.mixing is not None
        if forces.ndim != (3 if mixed else 2):
            raise ValueError(f"forces must be {'(n, n_sites, 3) site forces' if mixed else '(n, 3)'} for this pipeline, "
                             f"got shape {forces.shape}")
        scratch, af_dirs, ones = self.push_work(bounds)
        runs = self.transducer_runs
        out = np.empty((forces.shape[0], self.n_afferents))
        negative = np.empty(out.shape, np.bool_) if runs.signed else _NO_SIGNS
        args = (self.kernel_tables, (state, _IN_PLACE if source is state else source),  # `PushState`
                (_NO_FORCES, forces) if mixed else (forces, _NO_SITES),
                tuple(self.noise_key(key, sample0)) if noise is None else noise, started,
                out, scratch, af_dirs, (runs.runs_i, runs.runs_f, negative))  # `TransducerPass`
        if bounds.size <= 2:
            _front_push(*args)
        else:  # the parallel kernel is called from Python (see `drive`)
            _front_push_parts(*args, bounds)
        for cols in runs.sat:  # numpy's log1p and tanh, as `transduce_inplace` (one call per run of columns)
            np.log1p(out[:, cols], out=out[:, cols])
        transduce_mid(out, runs.runs_i, runs.runs_f, self.excitability(key) if key is not None and self.excite_any
                      else ones)
        for cols in runs.bounded:
            np.tanh(out[:, cols], out=out[:, cols])
        return out, negative

    def excitability(self, key) -> np.ndarray:
        """The trial's excitability factor per afferent (`ddmm.models.currents.excitability`), cached per key."""
        if self._excite[0] != key:
            self._excite = (key, excitability(key, self.afferent_id, self.excite_cv))
        return self._excite[1]

    def currents(self, forces, state, started, sample0=0, key=None):
        """Currents (mV/ms), shape (n_samples, n_afferents), of forces in newtons.

        ``forces`` is (n_samples, 3), felt by every afferent, or for a pipeline
        with a ``mixing`` the site forces (n_samples, n_sites, 3); long inputs
        run in slices of time of `_SLICE` elements, with the same result.
        ``state`` is updated in place; ``started`` is False on the first
        chunk, whose first sample is sample ``sample0`` of the scene.  With
        a stream ``key`` (`ddmm.models.rng.stream_key`), the noise of sample n of
        afferent a is ``ddmm.models.rng.normal(key, a, n)``; None: noise-free.
        """
        n, step = forces.shape[0], max(1, _SLICE // max(1, self.n_afferents))
        if n <= step:
            return self._current_slice(forces, state, started, sample0, key)
        out = np.empty((n, self.n_afferents))
        for t0 in range(0, n, step):  # slices of time, contiguous rows of ``out``: each one's passes stay in cache
            rows = slice(t0, t0 + step)
            self._current_slice(forces[rows], state, started or t0 > 0, sample0 + t0, key, out[rows])
        return out

    def _current_slice(self, forces, state, started, sample0, key, out=None):
        current = self.drive(forces, state, started, sample0, key, out=out)
        _back(self.kernel_tables, state, tuple(self.noise_key(key, sample0)), current, False)  # the engines check
        return current
