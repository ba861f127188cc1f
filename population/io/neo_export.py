"""Export a simulation Dataset to a Neo Block (for Elephant and the Neo ecosystem; ``pip install "ddmm[neo]"``).

Layout:

* one ``Segment`` per (condition, trial), condition-major (condition 0's
  trials, then condition 1's), annotated with ``condition`` (scene name),
  ``condition_index``, ``trial``, ``theta_r`` (deg; 0 when ``has_theta_r`` is
  False), ``has_theta_r``, ``duration`` (s) and ``stages`` ({label: [start,
  end]} in s); the stages are also an ``Epoch`` named ``"stages"``;
* in each segment one ``SpikeTrain`` per afferent (in the Dataset's
  afferent order) in s from the trial's start, ``t_start = 0``, ``t_stop`` =
  the condition's duration, annotated with ``afferent_id``,
  ``afferent_type``, ``theta_t``, ``nap``, ``k``, ``gain``, ``sensitivity``, ``x_mm``,
  ``y_mm``, ``region``, ``frame_deg``, ``noise_sigma`` and ``noise_cv``
  (plain floats; their units are in the block's ``afferent_units``
  annotation: deg, mm, ...);
* one ``Group`` per afferent holding its spike trains of every segment;
* with the forces recorded, an ``AnalogSignal`` ``fingertip_force`` (fx, fy,
  fz in N at fs) per segment, and ``site_force`` (channels ``"<site> fx"``
  ...) for multi-site scenes;
* the block is annotated with the Dataset's attrs (engine, dt, method,
  seed, model constants, ddmm version).
"""

from __future__ import annotations

import numpy as np

from ddmm.population.io import _export as ex
from ddmm.utils.extras import require

__all__ = ["to_neo"]


def to_neo(dataset):
    """A `neo.Block` of a simulation Dataset's spike trains and forces (layout in the module docstring).

    Parameters
    ----------
    dataset : xarray.Dataset
        A Dataset of `ddmm.population.simulate` or `load_dataset` with spike events.

    Returns
    -------
    neo.Block

    Raises
    ------
    TypeError, ValueError
        On a bad dataset; ImportError without neo.

    Examples
    --------
    >>> from ddmm.population import birznieks, sample_population, simulate, to_neo
    >>> pop = sample_population("fingertip", rng=0).select(range(20))
    >>> block = to_neo(simulate(pop, birznieks(90.0), engine="direct", trials=2, quiet=True))
    >>> len(block.segments), len(block.segments[0].spiketrains), block.segments[1].annotations["trial"]
    (2, 20, 1)
    """
    ex.check_dataset(dataset, "to_neo")
    neo = require("neo", "to_neo", "neo")
    import quantities as pq  # a dependency of neo

    values = ex.afferent_values(dataset)
    block = neo.Block(name=f"ddmm {dataset.attrs.get('population', '')}".strip(),
                      description="Simulated tactile afferents (ddmm): one segment per (condition, trial)",
                      afferent_units={name: unit for name, unit, _ in ex.AFFERENT_FIELDS})
    block.annotate(**{key: ex.plain(value) for key, value in dataset.attrs.items()})
    block.groups = [neo.Group(name=f"afferent {i}", afferent_id=i, allowed_types=[neo.SpikeTrain])
                    for i in values["afferent_id"]]
    time, k, aff = ex.spike_order(dataset, "trial")
    n_a = dataset.sizes["afferent"]
    cond, trial = ex.trial_grid(dataset)
    bounds = np.searchsorted(k * n_a + aff, np.arange(cond.size * n_a + 1))
    for kk, (c, t) in enumerate(zip(cond, trial)):
        segment = _segment(neo, pq, dataset, c, t, kk)
        t_stop = float(dataset["duration"].values[c])
        for a in range(n_a):
            train = neo.SpikeTrain(time[bounds[kk * n_a + a]: bounds[kk * n_a + a + 1]], units="s", t_start=0.0,
                                   t_stop=t_stop, name=f"afferent {values['afferent_id'][a]}",
                                   **{name: column[a] for name, column in values.items()})
            train.segment = segment
            segment.spiketrains.append(train)
            block.groups[a].add(train)
        block.segments.append(segment)
    block.check_relationships()
    return block


def _segment(neo, pq, ds, c: int, t: int, index: int):
    """The segment of condition ``c``, trial ``t``: annotations, stage epoch and forces (no spikes yet)."""
    stages = ex.stages_of(ds, c)
    segment = neo.Segment(name=f"{ds['condition'].values[c]} trial {t}", index=index,
                          condition=str(ds["condition"].values[c]), condition_index=int(c), trial=int(t),
                          theta_r=float(ds["theta_r"].values[c]), has_theta_r=bool(ds["has_theta_r"].values[c]),
                          duration=float(ds["duration"].values[c]),
                          stages={label: [a, b] for label, a, b in stages})
    if stages:
        segment.epochs.append(neo.Epoch(times=[a for _, a, _ in stages] * pq.s,
                                        durations=[b - a for _, a, b in stages] * pq.s,
                                        labels=np.array([label for label, _, _ in stages]), name="stages"))
    force, site_force = ex.condition_forces(ds, c)
    rate = float(ds.attrs["fs"]) * pq.Hz
    if force is not None:
        segment.analogsignals.append(neo.AnalogSignal(
            force, units="N", sampling_rate=rate, t_start=0.0 * pq.s, name="fingertip_force",
            array_annotations={"channel_names": np.array(["fx", "fy", "fz"])}))
    if site_force is not None:
        segment.analogsignals.append(neo.AnalogSignal(
            site_force.reshape(len(force), -1), units="N", sampling_rate=rate, t_start=0.0 * pq.s,
            name="site_force", array_annotations={"channel_names": np.array(ex.site_labels(ds))}))
    for signal in segment.analogsignals + segment.epochs:
        signal.segment = segment
    return segment
