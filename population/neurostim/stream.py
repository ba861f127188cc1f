"""Stimulation in closed loop: a streaming `Encoder`'s spikes and forces -> pulses, chunk by chunk.

`StimulationEncoder` wraps an `Encoder`: each push runs the encoder, bins its
spikes into model samples, reads the forces under the fields from the forces
the model consumed (after conditioning), and advances the same `PulseKernel`
`stimulation_pulses` runs offline.  The kernel is causal and keeps its state,
so the pulses of any chunking equal the offline pulses of the same run, bit
for bit.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from ddmm.population.neurostim.encode import _check_reach, as_table
from ddmm.population.neurostim.pulses import PulseKernel, contact_weights, field_weights
from ddmm.population.neurostim.rules import get_rule

__all__ = ["PulseEvents", "StimulationEncoder"]


@dataclass(frozen=True)
class PulseEvents:
    """The pulses of one pushed chunk.

    Attributes
    ----------
    electrode : ndarray of int64
        Position of the electrode in the table.
    time : ndarray of float
        Start of the cathodic phase, s since the first sample.
    amplitude_ua : ndarray of float
        Amplitude, µA.
    phase_width_us : ndarray of float
        Width of each phase, µs (the electrode's).
    spikes : StreamSpikes
        The encoder's spikes of the chunk.
    """

    electrode: np.ndarray
    time: np.ndarray
    amplitude_ua: np.ndarray
    phase_width_us: np.ndarray
    spikes: object


class StimulationEncoder:
    """Pulses for an electrode table from a live force stream.

    Parameters
    ----------
    encoder : Encoder
        The streaming encoder (its sites or contact place the force).
    electrodes : ElectrodeTable, sequence of Electrode, or path
    rule : str or rule object
        As `stimulation_pulses`.

    Raises
    ------
    ValueError
        If no field of the table reaches an afferent the encoder simulates or
        its contact or force sites (as `stimulation_pulses`).

    Examples
    --------
    >>> from ddmm.population import birznieks, make_population
    >>> from ddmm.population.runtime import Encoder
    >>> from ddmm.population.neurostim import Electrode
    >>> enc = Encoder(make_population(["SAI", "RAI"]), 1000.0, seed=0, conditioning=None)
    >>> stim = StimulationEncoder(enc, [Electrode("E1", 20.0, 80.0, 200.0, 300.0, 20.0, x_mm=0.0, y_mm=0.0,
    ...                                           radius_mm=10.0)])
    >>> s = birznieks(90.0)
    >>> out = stim.push(np.column_stack([s.fx, s.fy, s.fz]))
    >>> bool(out.time.size > 0)
    True
    """

    def __init__(self, encoder, electrodes, rule="biomimetic"):
        from ddmm.population.runtime.stream import Encoder

        if not isinstance(encoder, Encoder):
            raise TypeError(f"encoder must be an Encoder (ddmm.population.runtime), got {type(encoder).__name__}")
        self.encoder, self.table, self.rule = encoder, as_table(electrodes), get_rule(rule)
        pop, positions = encoder.population, encoder.positions
        self._slot = np.full(len(pop), -1, np.int64)
        self._slot[positions] = np.arange(positions.size)  # spikes' population positions -> kernel axis
        members = self.table.members(pop.x_mm[positions], pop.y_mm[positions], pop.region[positions])
        self._weights = self._site_weights()
        placed = self.encoder.sites is not None or self.encoder.contact is not None  # else: the whole skin
        _check_reach(self.table, members, np.any(self._weights > 0, axis=1) & placed, str(pop.name))
        self._kernel = PulseKernel(self.table, self.rule, encoder.model_fs, members,
                                   self.rule.type_weights(pop.afferent_type[positions]))
        self._substeps = encoder.substeps
        self._width = self.table.column("phase_width_us")

    def _site_weights(self) -> np.ndarray:
        sites, contact = self.encoder.sites, self.encoder.contact
        if sites is not None:
            return field_weights(self.table, sites.x_mm, sites.y_mm, sites.radius_mm, sites.region)
        if contact is not None:
            return contact_weights(self.table, contact.x_mm, contact.y_mm, contact.radius_mm)[:, None]
        return contact_weights(self.table, 0.0, 0.0, None)[:, None]

    def warm_up(self) -> None:
        """`Encoder.warm_up` and one pass of the pulse kernel, then reset: before the first live sample."""
        self.encoder.warm_up()
        self._kernel.advance(np.ones((2, len(self.table))), np.empty(0, np.int64), np.empty(0, np.int64))
        self._kernel.reset()

    def reset(self) -> None:
        """Back to the start, the encoder too."""
        self.encoder.reset()
        self._kernel.reset()

    def push(self, forces, times=None) -> PulseEvents:
        """Push a chunk of force samples (as `Encoder.push`); return the chunk's pulses and spikes."""
        spikes = self.encoder.push(forces, times)
        model = spikes.forces
        fz = model[..., 2] if model.ndim == 3 else model[:, 2:3]
        under = fz @ self._weights.T
        step = np.round(spikes.time / self.encoder.dt).astype(np.int64)
        order = np.argsort(step // self._substeps, kind="stable")
        (t, e, a), _ = self._kernel.advance(under, (step // self._substeps)[order],
                                            self._slot[spikes.afferent[order]])
        return PulseEvents(e, t, a, self._width[e], spikes)
