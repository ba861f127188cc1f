"""Transduction of an indentation: from the stress at a receptor's depth to the drive the DDMM reads.

The skin's mechanics (`ddmm.population.stimuli.contact`) give the compressive
stress at each afferent's receptor depth; times the force path's reference
area it is the force the DDMM's stages take (`indentation.ContactSpread`).
The force path's constants were fitted to fingertip forces, not to stress, so
each type's receptor gets a front end of its own between the two, with three
named parameters (`Transduction`):

- ``gain``: the stress-to-drive gain (dimensionless, on the equivalent force);
- ``zero_hz`` and ``pole_hz``: a first-order lead-lag on the equivalent force,
  ``(1 + s / w_z) / (1 + s / w_p)``, unit gain at 0 Hz
  (`ddmm.models.current_filters.lead_lag_sos`).  A zero below the pole is a
  lead: the receptor follows the stress and its rate (SA-I and FA-I); a zero
  above the pole a lag: the high frequencies are cut relative to the low ones
  (FA-II, whose force-path band-pass falls faster below 200 Hz than a
  Pacinian corpuscle's threshold rises).

The force path is untouched: only indentation scenes carry a transduction.
Named sets (`TRANSDUCTIONS`): ``"fitted"`` (the default: SA-I, FA-I and FA-II
fitted to TouchSim's responses on part of a named list of stimuli; SA-II,
which TouchSim does not model, unit gain and no filter) and ``"none"`` (unit
gain and no filter for every type: the mechanics straight into the force
path).  The fit, its split and what it holds out: docs/model.md,
"Transduction of displacement", and `ddmm.experiments.calibration.displacement`.
"""

from __future__ import annotations

import math
import numbers
from dataclasses import dataclass
from types import MappingProxyType

from ddmm.models.afferent_types import normalize_type
from ddmm.models.current_filters import lead_lag_sos
from ddmm.utils.validation import shown

__all__ = ["TRANSDUCTIONS", "Transduction", "get_transduction"]


@dataclass(frozen=True)
class Transduction:
    """One type's front end from the stress at its receptor depth to its drive.

    Attributes
    ----------
    gain : float
        Stress-to-drive gain (dimensionless, > 0): it multiplies the equivalent
        force (the stress times the reference area) the force path reads.
    zero_hz, pole_hz : float or None
        Corners in Hz (> 0) of the lead-lag ``(1 + s / w_z) / (1 + s / w_p)``
        on the equivalent force; both None: no filter.

    Examples
    --------
    >>> Transduction(gain=0.2, zero_hz=2.0, pole_hz=1000.0).lead
    True
    """

    gain: float = 1.0
    zero_hz: float | None = None
    pole_hz: float | None = None

    def __post_init__(self):
        object.__setattr__(self, "gain", _positive(self.gain, "gain", "a finite number > 0"))
        if (self.zero_hz is None) != (self.pole_hz is None):
            raise ValueError(f"zero_hz and pole_hz must both be given or both None, got {shown(self.zero_hz)} and "
                             f"{shown(self.pole_hz)}")
        for name in ("zero_hz", "pole_hz"):
            if getattr(self, name) is not None:
                object.__setattr__(self, name, _positive(getattr(self, name), name,
                                                         "a finite frequency > 0 in Hz or None"))

    @property
    def lead(self) -> bool:
        """True if the filter raises the high frequencies (zero below pole)."""
        return self.zero_hz is not None and self.zero_hz < self.pole_hz

    def sections(self, fs: float):
        """The filter's section at ``fs`` Hz (shape (1, 6)), or None without a filter.

        A corner at or above ``fs / 2`` is not refused: the bilinear map (`lead_lag_sos`) compresses it
        towards the Nyquist frequency.  The fitted set's largest corner, 1000 Hz, sits there at 2 kHz, a
        rate indentation scenes run at (5 kHz, `ddmm.population.stimuli.waveforms.INDENT_FS`, by default).
        """
        if self.zero_hz is None or self.zero_hz == self.pole_hz:
            return None
        return lead_lag_sos(self.zero_hz, self.pole_hz, fs)


def _positive(value, name: str, allowed: str) -> float:
    """``value`` as a plain float if it is a finite real number > 0 (a numpy scalar too; not a bool)."""
    if isinstance(value, bool) or not isinstance(value, numbers.Real) or not (math.isfinite(value) and value > 0):
        raise ValueError(f"{name} must be {allowed}, got {shown(value)}")
    return float(value)


#: Named transduction sets, by type code (a type left out: unit gain, no filter).  ``"fitted"``: the values
#: `ddmm.experiments.calibration.displacement` found (fitted; docs/model.md gives the fit's split and score).
TRANSDUCTIONS = MappingProxyType({
    "fitted": MappingProxyType({
        "SAI": Transduction(gain=0.2501, zero_hz=1.327, pole_hz=1000.0),
        "RAI": Transduction(gain=0.04201, zero_hz=12.14, pole_hz=169.4),
        "RAII": Transduction(gain=22.15, zero_hz=589.1, pole_hz=10.22),
    }),
    "none": MappingProxyType({}),
})


def get_transduction(transduction="fitted") -> tuple:
    """A transduction set as sorted ``(type code, Transduction)`` pairs (hashable, for a frozen spread).

    Parameters
    ----------
    transduction : str or mapping
        A name of `TRANSDUCTIONS` (``"fitted"``, ``"none"``), or a mapping of
        type (any spelling of a registered type) to `Transduction`.

    Examples
    --------
    >>> dict(get_transduction("fitted"))["SAI"].gain > 0
    True
    >>> get_transduction("none")
    ()
    """
    if isinstance(transduction, str):
        if transduction not in TRANSDUCTIONS:
            raise ValueError(f"transduction must be one of {sorted(TRANSDUCTIONS)} or a mapping of type to "
                             f"Transduction, got {transduction!r}")
        transduction = TRANSDUCTIONS[transduction]
    if not hasattr(transduction, "items"):
        raise TypeError(f"transduction must be a name or a mapping of type to Transduction, got "
                        f"{type(transduction).__name__}")
    pairs = {}
    for kind, value in transduction.items():
        code = normalize_type(kind, "transduction's type")
        if not isinstance(value, Transduction):
            raise TypeError(f"transduction[{kind!r}] must be a Transduction, got {type(value).__name__}")
        pairs[code] = value
    return tuple(sorted(pairs.items()))
