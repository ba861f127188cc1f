"""Izhikevich neuron parameters per afferent type (paper eqs 4-6).

    dv/dt = 0.04 v^2 + 5 v + 140 - u + I        (eq. 4, t in ms, v in mV)
    du/dt = A (B v - u)                          (eq. 5)
    if v >= 30: v <- C, u <- u + D               (eq. 6)

A = 0.02, C = -65, D = 8 for every type.  B = 0.2 for SAI (regular spiking)
and B = 0.25 for RAI and RAII (low-threshold spiking; the paper's "RAI and
RAI" is a typo for RAI and RAII, docs/model.md §1.7).  SA-II, which the paper
leaves out, is regular spiking like SA-I (B = 0.2): Ruffini afferents fire
regularly and adapt slowly.

Each neuron starts at its resting fixed point for I = 0, not at v = C.
Started elsewhere (e.g. v = -65, u = B v) it relaxes toward rest on the
recovery time scale 1/A = 50 ms: no spike (none in 1 s at dt = 0.01-1 ms),
but a transient in v and u that the input did not cause, and that a run of
zero force should not contain.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from ddmm.utils.validation import as_finite_array, shown

__all__ = [
    "V_PEAK",
    "V_FLOOR",
    "NeuronParams",
    "NEURON_PARAMS",  # noqa: F822 (a view of the registry: the module's __getattr__)
    "resting_state",
    "neuron_arrays",
    "refractory_steps",
    "check_neuron",
]

#: Spike cut-off in mV (eq. 6).
V_PEAK = 30.0
#: Lower bound on v in mV, applied after every step.  It stops a strongly
#: negative current from driving forward Euler into a false oscillation
#: (dt > 2/sqrt(0.64 - 0.16 I) ms for B = 0.2) and 1/(2 dt) spiking.  It is
#: not a no-op: negative currents do occur (noise dips, SA-II stretch against
#: its preferred direction, user currents), and where v reaches the floor the
#: floor changes the trajectory.  Measured on the old preset (additive
#: 1 mV/sqrt(ms) noise), RA-I reached -107 to -132 mV and RA-II -258 mV, and
#: the floor changed one RA-II count in 565.
V_FLOOR = -100.0


@dataclass(frozen=True)
class NeuronParams:
    """Izhikevich parameters of one afferent type (eqs 4-6).

    Attributes
    ----------
    a : float
        Recovery time scale, 1/ms (eq. 5).  Paper: 0.02.
    b : float
        Sensitivity of u to v, dimensionless (eq. 5).  0.2 (RS) or 0.25 (LTS).
    c : float
        Reset potential in mV (eq. 6).  Paper: -65.
    d : float
        Reset increment of u in mV/ms (eq. 6).  Paper: 8.
    t_ref : float
        Absolute refractory period in seconds (not in the paper; 0 there):
        for ``round(t_ref / dt)`` steps after a spike v is held at C while u
        evolves, so no interval is shorter than ``(round(t_ref / dt) + 1) dt``
        (`refractory_steps`).  Without it an Izhikevich neuron at a
        saturating current fires again within 0.5 ms.
    """

    a: float = 0.02
    b: float = 0.2
    c: float = -65.0
    d: float = 8.0
    t_ref: float = 0.0

    def __post_init__(self):
        rules = {"a": (lambda x: x > 0.0, "> 0 (1/ms)"), "b": (lambda x: 0.0 < x <= 0.267, "in (0, 0.267]"),
                 "c": (lambda x: True, "(mV)"), "d": (lambda x: x >= 0.0, ">= 0 (mV/ms)"),
                 "t_ref": (lambda x: 0.0 <= x <= 0.1, "in [0, 0.1] (s)")}  # b: a resting state
        for name, (ok, allowed) in rules.items():
            value = getattr(self, name)
            number = isinstance(value, (int, float)) and not isinstance(value, bool)
            if not (number and np.isfinite(value) and ok(value)):
                shown = f"{float(value):g}" if number else repr(value)
                raise ValueError(f"{name} must be a finite number {allowed}, got {shown}")


def __getattr__(name):
    if name == "NEURON_PARAMS":  # a view of the registry (`AfferentType.neuron`), whatever is registered now
        from ddmm.models.afferent_types import afferent_type_codes, afferent_type_info

        return {code: afferent_type_info(code).neuron for code in afferent_type_codes()}
    raise AttributeError(f"module {__name__!r} has no attribute {name!r}")


def resting_state(b) -> tuple[np.ndarray, np.ndarray]:
    """Resting fixed point (v_rest, u_rest) of eqs 4-5 for I = 0.

    v_rest is the lower root of ``0.04 v^2 + (5 - b) v + 140 = 0`` and
    ``u_rest = b v_rest``.

    Parameters
    ----------
    b : float or array_like
        Parameter B of eq. 5.

    Returns
    -------
    v_rest, u_rest : ndarray
        In mV and mV/ms.

    Examples
    --------
    >>> v, u = resting_state(0.2)
    >>> round(float(v), 6), round(float(u), 6)
    (-70.0, -14.0)
    """
    b = as_finite_array(b, "b")
    disc = (5.0 - b) ** 2 - 4.0 * 0.04 * 140.0
    if np.any(disc < 0.0):
        raise ValueError(f"b={shown(b)} leaves eq. 4-5 without a resting state (b must be <= 0.267)")
    v = (-(5.0 - b) - np.sqrt(disc)) / (2.0 * 0.04)
    return v, b * v


def check_neuron(neuron, name: str = "neuron") -> None:
    """Check a table of `NeuronParams` overrides keyed by type code (``"SAI"``, ``"RAI"``, ...).

    Raises
    ------
    TypeError, ValueError
        Naming the entry and what is allowed.

    Examples
    --------
    >>> check_neuron({"RAII": NeuronParams(a=0.5, b=0.25, d=100.0)})
    """
    from ddmm.models.afferent_types import afferent_type_codes  # the registry imports this module

    if not isinstance(neuron, dict):
        raise TypeError(f"{name} must be a dict of NeuronParams by afferent type, got {type(neuron).__name__}")
    for kind, params in neuron.items():
        if kind not in afferent_type_codes():
            raise ValueError(f"{name}: unknown afferent type {kind!r}; allowed: {', '.join(afferent_type_codes())}")
        if not isinstance(params, NeuronParams):
            raise TypeError(f"{name}.{kind} must be a NeuronParams, got {type(params).__name__}")


def neuron_arrays(afferent_type, params: dict[str, NeuronParams] | None = None):
    """Per-afferent parameter arrays for a sequence of afferent types.

    Parameters
    ----------
    afferent_type : str or sequence of str
        A type code (or accepted spelling) per afferent.
    params : dict, optional
        Overrides of each type's registered neuron (`AfferentType.neuron`), keyed by type code.

    Returns
    -------
    dict
        Arrays ``a``, ``b``, ``c``, ``d`` and ``t_ref`` (float64, one entry
        per afferent).

    Examples
    --------
    >>> neuron_arrays(["SAI", "RAI"])["b"].tolist()
    [0.2, 0.25]
    """
    from ddmm.models.afferent_types import afferent_type_info  # the registry imports this module

    types = np.atleast_1d(np.asarray(afferent_type, dtype=object))
    kinds = {t: afferent_type_info(t) for t in set(types.tolist())}
    table = {t: (params or {}).get(kind.code, kind.neuron) for t, kind in kinds.items()}
    out = {}
    for field in ("a", "b", "c", "d", "t_ref"):
        lookup = {t: getattr(p, field) for t, p in table.items()}
        out[field] = np.array([lookup[t] for t in types.tolist()], dtype=float)
    return out


def refractory_steps(t_ref, dt: float) -> np.ndarray:
    """Steps v is held at C after a spike: ``round(t_ref / dt)``, as float64 (both engines count in floats).

    Parameters
    ----------
    t_ref : array_like
        Absolute refractory periods in seconds (`NeuronParams.t_ref`).
    dt : float
        Integration step in seconds.

    Examples
    --------
    >>> refractory_steps([0.0, 0.002], 1e-4).tolist()
    [0.0, 20.0]
    """
    return np.rint(np.asarray(t_ref, dtype=float) / dt).astype(float)
