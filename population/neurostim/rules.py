"""Encoding rules: from afferent activity or force under a field to a pulse rate and amplitude.

Each rule sets, at every model sample (1 / fs), a **commanded pulse rate**
and a **commanded amplitude** per electrode; `ddmm.population.neurostim.pulses`
turns the commands into pulses within the electrode's limits.  Every rule
emits nothing while the force under the field is at or below the contact
threshold (0.05 N, `ddmm.models.metrics.CONTACT_THRESHOLD`).

**biomimetic** (`Biomimetic`), after the biomimetic encoders of Okorokova et
al. (2018), Valle et al. (2018) and George et al. (2019) (Okorokova's abstract read,
the others recalled: docs/references.md).  The pulse rate follows the aggregate firing rate of the
afferents in the electrode's projected field, and the amplitude follows how
many of them are active, so that stimulation recruits more fibres when more
afferents would fire:

* aggregate rate ``r`` (spikes/s per field afferent): the weighted spike count
  of the field's afferents per sample, divided by their number, smoothed by a
  causal exponential of time constant ``tau_s``.  Okorokova et al. (2018;
  abstract read) drive stimulation by the time-varying *population* firing
  rate, so by default every spike counts once (``weights`` 1 for each type):
  the FA-I and FA-II bursts at contact onset and offset are the transients,
  as they are in the nerve.  ``weights`` can stress them further;
* rate command ``max_rate_hz x min(r / rate_sat_hz, 1)``;
* active fraction ``a``: field afferents that fired in the last
  ``active_window_s``, over their number; amplitude command
  ``amplitude_min_ua + (amplitude_max_ua - amplitude_min_ua) x min(a / active_sat, 1)``.

**linear-amplitude** (`LinearAmplitude`): a fixed rate ``rate_hz`` (at most the
electrode's limit), amplitude rising linearly from ``amplitude_min_ua`` at the
contact threshold to ``amplitude_max_ua`` at ``force_sat_n`` under the field.

**linear-frequency** (`LinearFrequency`): a fixed amplitude (``amplitude_fraction``
of the way from the minimum to the maximum), rate rising linearly from 0 at the
contact threshold to ``max_rate_hz`` at ``force_sat_n``.

Settings outside their physical range are refused, with the range (`RANGES`):
``tau_s`` and ``active_window_s`` in (0, 1] s (a smoothing or window longer
than a touch could not follow one); ``rate_sat_hz`` in (0, 1000] spikes/s
(no afferent sustains 1 kHz, so a higher saturation is never reached);
``rate_hz`` in [1, 2000] Hz (below 1 Hz no pulse in a second of touch; 2 kHz
the electrodes' own bound, `MAX_RATE_HZ`); ``force_sat_n`` in (0.05, 500] N
(above the contact threshold, where the ramp starts; 500 N about the
strongest human grip).  Weights must not all be 0.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from ddmm.models.afferent_types import afferent_type_codes, normalize_type
from ddmm.models.metrics import CONTACT_THRESHOLD
from ddmm.population.neurostim.electrodes import MAX_RATE_HZ
from ddmm.utils.validation import shown

__all__ = ["Biomimetic", "LinearAmplitude", "LinearFrequency", "RULES", "RANGES", "get_rule", "check_setting"]

#: Physical range of each setting: (low, high, whether low itself is allowed); high is always allowed.
RANGES = {"tau_s": (0.0, 1.0, False), "active_window_s": (0.0, 1.0, False), "active_sat": (0.0, 1.0, False),
          "rate_sat_hz": (0.0, 1000.0, False), "rate_hz": (1.0, MAX_RATE_HZ, True),
          "force_sat_n": (CONTACT_THRESHOLD, 500.0, False)}
_UNITS = {"tau_s": "s", "active_window_s": "s", "active_sat": "", "rate_sat_hz": "spikes/s", "rate_hz": "Hz",
          "force_sat_n": "N"}


def check_setting(label: str, name: str, value, scale: float = 1.0, unit: str | None = None) -> None:
    """Refuse a rule setting outside its range (`RANGES`), as the user wrote it.

    ``value x scale`` is the setting in the rule's units; ``label`` and ``unit``
    name it as the user wrote it (``"--tau"``, ``"ms"`` for ``tau_s``, scale
    1e-3; the unit defaults to the rule's own).

    Examples
    --------
    >>> check_setting("--tau", "tau_s", 1e15, 1e-3, "ms")
    Traceback (most recent call last):
    ...
    ValueError: --tau must be a finite number in (0, 1000] ms, got 1e+15
    """
    low, high, closed = RANGES[name]
    unit = _UNITS[name] if unit is None else unit
    number = isinstance(value, (int, float, np.integer, np.floating)) and not isinstance(value, bool)
    if number and math.isfinite(value) and (low <= value * scale if closed else low < value * scale) \
            and value * scale <= high:
        return
    bounds = f"{'[' if closed else '('}{low / scale:g}, {high / scale:g}]{f' {unit}' if unit else ''}"
    raise ValueError(f"{label} must be a finite number in {bounds}, got {f'{float(value):g}' if number else repr(value)}")


@dataclass(frozen=True)
class Biomimetic:
    """The biomimetic rule (module docstring).

    Attributes
    ----------
    tau_s : float
        Time constant of the aggregate rate's smoothing, s, in (0, 1].
    rate_sat_hz : float
        Aggregate rate (spikes/s per field afferent) at which the pulse rate
        reaches the electrode's limit, in (0, 1000].
    active_window_s : float
        An afferent is active for this long after each of its spikes, s, in (0, 1].
    active_sat : float
        Active fraction at which the amplitude reaches its maximum (0-1].
    weights : tuple of (str, float)
        Weight of each named type's spikes in the aggregate rate (>= 0; any
        spelling of a registered type); a type not named weighs 1, and the
        registered types' weights may not all be 0.

    Examples
    --------
    >>> Biomimetic().code
    0
    """

    tau_s: float = 0.02
    rate_sat_hz: float = 100.0
    active_window_s: float = 0.02
    active_sat: float = 0.5
    weights: tuple = ()
    name = "biomimetic"
    code = 0

    def __post_init__(self):
        for field in ("tau_s", "rate_sat_hz", "active_window_s", "active_sat"):
            check_setting(f"{self.name}: {field}", field, getattr(self, field))
        weights = self._named_weights()
        if any(not (isinstance(w, (int, float)) and not isinstance(w, bool) and math.isfinite(w) and w >= 0)
               for w in weights.values()) or not any(weights.get(t, 1.0) for t in afferent_type_codes()):
            raise ValueError(f"{self.name}: weights must be finite and >= 0, not all 0 over "
                             f"{', '.join(afferent_type_codes())} (no spike would count), got {self.weights!r}")

    def _named_weights(self) -> dict:
        """The weights by registered type code (a type not named: absent)."""
        try:
            pairs = dict(self.weights)
        except (TypeError, ValueError):
            raise TypeError(f"{self.name}: weights must be (type, weight) pairs, got {self.weights!r}") from None
        return {normalize_type(t, f"{self.name}: weights"): w for t, w in pairs.items()}

    def type_weights(self, afferent_type) -> np.ndarray:
        """The weight of each afferent's spikes (1 for a type ``weights`` does not name)."""
        weights, afferent_type = self._named_weights(), np.asarray(afferent_type).astype(str)
        out = np.ones(afferent_type.shape)
        for code, w in weights.items():  # one comparison a named type
            out[afferent_type == code] = w
        return out

    def params(self) -> np.ndarray:
        """The kernel's parameter vector (`ddmm.population.neurostim.pulses`)."""
        return np.array([self.tau_s, self.rate_sat_hz, self.active_window_s, self.active_sat, 0.0, 0.0, 0.0])


@dataclass(frozen=True)
class LinearAmplitude:
    """The linear-amplitude baseline: fixed rate, amplitude linear in the force under the field.

    Attributes
    ----------
    rate_hz : float
        Pulse rate in contact, Hz, in [1, 2000] (each electrode's limit caps it).
    force_sat_n : float
        Force under the field at which the amplitude reaches its maximum, N,
        in (0.05, 500] (above the contact threshold).

    Examples
    --------
    >>> LinearAmplitude(rate_hz=50.0).name
    'linear-amplitude'
    """

    rate_hz: float = 100.0
    force_sat_n: float = 5.0
    name = "linear-amplitude"
    code = 1

    def __post_init__(self):
        check_setting(f"{self.name}: rate_hz", "rate_hz", self.rate_hz)
        check_setting(f"{self.name}: force_sat_n", "force_sat_n", self.force_sat_n)

    def type_weights(self, afferent_type) -> np.ndarray:
        """Unused by this rule (no afferent activity): ones."""
        return np.ones(len(afferent_type))

    def params(self) -> np.ndarray:
        """The kernel's parameter vector."""
        return np.array([1.0, 1.0, 1.0, 1.0, self.rate_hz, self.force_sat_n, 0.0])


@dataclass(frozen=True)
class LinearFrequency:
    """The linear-frequency baseline: fixed amplitude, rate linear in the force under the field.

    Attributes
    ----------
    amplitude_fraction : float
        Where the fixed amplitude sits between the electrode's minimum (0) and maximum (1).
    force_sat_n : float
        Force under the field at which the rate reaches the electrode's limit,
        N, in (0.05, 500] (above the contact threshold).

    Examples
    --------
    >>> LinearFrequency().amplitude_fraction
    0.5
    """

    amplitude_fraction: float = 0.5
    force_sat_n: float = 5.0
    name = "linear-frequency"
    code = 2

    def __post_init__(self):
        number = isinstance(self.amplitude_fraction, (int, float)) and not isinstance(self.amplitude_fraction, bool)
        if not number or not 0.0 <= self.amplitude_fraction <= 1.0:
            raise ValueError(f"{self.name}: amplitude_fraction must be in [0, 1], got {shown(self.amplitude_fraction)}")
        check_setting(f"{self.name}: force_sat_n", "force_sat_n", self.force_sat_n)

    def type_weights(self, afferent_type) -> np.ndarray:
        """Unused by this rule (no afferent activity): ones."""
        return np.ones(len(afferent_type))

    def params(self) -> np.ndarray:
        """The kernel's parameter vector."""
        return np.array([1.0, 1.0, 1.0, 1.0, 0.0, self.force_sat_n, self.amplitude_fraction])


#: The rules by name, each with its default settings.
RULES = {rule.name: rule for rule in (Biomimetic, LinearAmplitude, LinearFrequency)}


def get_rule(rule):
    """A rule object from a rule or its name.

    Examples
    --------
    >>> get_rule("linear-frequency").name
    'linear-frequency'
    """
    if isinstance(rule, (Biomimetic, LinearAmplitude, LinearFrequency)):
        return rule
    if isinstance(rule, str) and rule in RULES:
        return RULES[rule]()
    raise ValueError(f"rule={rule!r} is unknown; allowed: {', '.join(RULES)} or a rule object")
