"""Sampling a population of afferents from a spec.

`sample_population` returns a `Population`: one array per afferent property,
ordered SAI, RAI, RAII, SAII.  With a ``[map]`` each type is placed region by
region of `ddmm.population.anatomy.hand_map` (uniform within a region).  Every afferent carries a stable ``afferent_id``;
per-afferent random streams (the current noise) are derived from it, so
splitting a population into chunks, or keeping only some types, never
changes any afferent's result.
"""

from __future__ import annotations

import os
from dataclasses import dataclass, field

import numpy as np

from ddmm.models.afferent_types import afferent_type_codes, normalize_type
from ddmm.models.attenuation import UNTUNED
from ddmm.models.current_params import CurrentParams
from ddmm.models.nap import PROFILE_NAMES, k_from_selectivity, validate_k
from ddmm.models.neuron import check_neuron
from ddmm.population.anatomy import hand_map
from ddmm.population.anatomy.receptive_fields import check_shape
from ddmm.population.spec import (
    NAP_CHOICES,
    AngleDistribution,
    PopulationSpec,
    SharpnessDistribution,
    TypeSpec,
    load_spec,
)
from ddmm.utils.validation import as_finite_array, check_instance, check_rng

__all__ = ["Population", "sample_population", "make_population"]

_ARRAYS = ("afferent_type", "theta_t", "nap", "k", "gain", "x_mm", "y_mm", "noise_sigma", "noise_cv",
           "afferent_id", "region", "frame_deg", "sensitivity")
#: Spawn-key tag of the per-unit sensitivity streams ("sens" in ASCII): apart from every other draw.
SENSITIVITY_TAG = 0x73656E73


@dataclass(frozen=True, eq=False)
class Population:
    """Afferents as arrays, one entry per afferent.

    Attributes
    ----------
    afferent_type : ndarray of str
        ``"SAI"``, ``"RAI"``, ``"RAII"`` or ``"SAII"``.
    theta_t : ndarray of float
        Tuning angle in degrees, in [0, 360), in the afferent's local digit
        frame (+X radial, +Y distal along its digit).
    nap : ndarray of str
        ``"selective"``, ``"broad"``, ``"bipolar"`` or ``"none"`` (untuned).
    k : ndarray of float
        Sharpness (eq. 12); 0 for untuned afferents, which have no NAP.
    gain : ndarray of float
        Per-afferent multiplier of the current drive (dimensionless).
    x_mm, y_mm : ndarray of float
        Position in mm (+X radial, +Y distal): on the fingertip, or in the
        hand frame for a population drawn from the hand map.
    noise_sigma : ndarray of float
        Additive current-noise intensity in mV/sqrt(ms).
    noise_cv : ndarray of float
        Drive-proportional noise intensity in sqrt(ms) (see `TypeSpec`).
    afferent_id : ndarray of int64
        Stable identity; noise streams derive from it.
    region : ndarray of str
        Hand-map region (`ddmm.population.anatomy.hand_map`), ``""`` when unknown.
    frame_deg : ndarray of float
        Counterclockwise rotation (deg) from the afferent's local digit frame
        to the hand frame (0 for D2, the palm and unknown regions).
    sensitivity : ndarray of float
        Per-afferent sensitivity (dimensionless, > 0; default 1): it
        multiplies the gain and divides the type's dead zone, so the unit's
        stimulus thresholds are its type's over it (`TypeSpec.sensitivity_sd`).
    current : CurrentParams
        Gains and filter of eqs 1-3 shared by the population.
    name : str
        The spec's name.
    receptive_field : {"gaussian", "tailed"}
        Shape of the receptive fields' fall-off beyond a contact
        (`ddmm.population.anatomy.receptive_fields`).
    neuron : dict
        `ddmm.models.neuron.NeuronParams` by type code overriding the
        paper's (eqs 4-6, `NEURON_PARAMS`); empty: the paper's neurons.
    """

    afferent_type: np.ndarray
    theta_t: np.ndarray
    nap: np.ndarray
    k: np.ndarray
    gain: np.ndarray
    x_mm: np.ndarray
    y_mm: np.ndarray
    noise_sigma: np.ndarray
    noise_cv: np.ndarray
    afferent_id: np.ndarray
    region: np.ndarray = None
    frame_deg: np.ndarray = None
    sensitivity: np.ndarray = None
    current: CurrentParams = field(default_factory=CurrentParams)
    name: str = "custom"
    receptive_field: str = "gaussian"
    neuron: dict = field(default_factory=dict)

    def __post_init__(self):
        check_shape(self.receptive_field)
        check_neuron(self.neuron)
        check_instance(self.current, "current", CurrentParams, "a CurrentParams")
        check_instance(self.name, "name", str, "a str")
        n = len(self.afferent_type)
        if self.region is None:
            object.__setattr__(self, "region", np.full(n, "", dtype=object))
        if self.frame_deg is None:
            object.__setattr__(self, "frame_deg", np.zeros(n))
        if self.sensitivity is None:
            object.__setattr__(self, "sensitivity", np.ones(n))
        for name in _ARRAYS:
            arr = np.asarray(getattr(self, name), dtype=object if name == "region" else None)
            if arr.shape != (n,):
                raise ValueError(f"population {name} must have shape ({n},), got {arr.shape}")
            arr = arr.copy()
            arr.setflags(write=False)
            object.__setattr__(self, name, arr)
        _validate_values(self)

    def __len__(self) -> int:
        return len(self.afferent_type)

    def select(self, index) -> "Population":
        """The afferents at ``index`` (indices or a boolean mask); ids are kept.

        The values were validated when this population was made, so only
        the ids' uniqueness is checked again (an index may repeat).
        """
        arrays = {name: getattr(self, name)[index] for name in _ARRAYS}
        if arrays["afferent_id"].ndim != 1:
            raise ValueError(f"index must select a 1-d set of afferents (indices, a slice or a mask), got {index!r}")
        idx = np.asarray(index) if not isinstance(index, slice) else np.empty(0, np.int64)
        if idx.dtype != bool and idx.size and np.bincount(idx.ravel() % len(self), minlength=len(self)).max() > 1:
            raise ValueError("population afferent_id values must be unique: index repeats an afferent")
        sub = object.__new__(Population)  # a simulation selects every block: skip the per-element checks
        for name, arr in arrays.items():
            arr.setflags(write=False)
            object.__setattr__(sub, name, arr)
        object.__setattr__(sub, "current", self.current)
        object.__setattr__(sub, "name", self.name)
        object.__setattr__(sub, "receptive_field", self.receptive_field)
        object.__setattr__(sub, "neuron", self.neuron)
        return sub

    def counts(self) -> dict:
        """Afferents per type."""
        return {t: int(np.sum(self.afferent_type == t)) for t in afferent_type_codes() if np.any(self.afferent_type == t)}


def _validate_values(pop: Population) -> None:
    bad = sorted(set(pop.afferent_type.tolist()) - set(afferent_type_codes()))
    if bad:
        raise ValueError(f"afferent_type={bad[0]!r} is unknown; allowed: {', '.join(afferent_type_codes())}")
    bad = sorted(set(pop.nap.tolist()) - set(NAP_CHOICES))
    if bad:
        raise ValueError(f"nap={bad[0]!r} is unknown; allowed: {', '.join(NAP_CHOICES)}")
    if not all(issubclass(t, str) for t in set(map(type, pop.region.tolist()))):  # per type: C-speed
        bad = next(r for r in pop.region.tolist() if not isinstance(r, str))
        raise ValueError(f"population region must hold strings ('' when unknown), got {bad!r}")
    for name in ("theta_t", "gain", "x_mm", "y_mm", "noise_sigma", "noise_cv", "k", "frame_deg", "sensitivity"):
        arr = np.asarray(getattr(pop, name), dtype=float)
        if not np.all(np.isfinite(arr)):
            raise ValueError(f"population {name} must be finite")
    if np.any(pop.sensitivity <= 0):
        raise ValueError(f"population sensitivity must be > 0, got {float(np.min(pop.sensitivity)):g}")
    if np.any(pop.gain < 0) or np.any(pop.noise_sigma < 0) or np.any(pop.noise_cv < 0):
        raise ValueError("population gain, noise_sigma and noise_cv must be >= 0")
    for profile in PROFILE_NAMES:
        validate_k(pop.k[pop.nap == profile], profile)
    if _repeats(np.asarray(pop.afferent_id)):
        raise ValueError("population afferent_id values must be unique")


def _repeats(ids) -> bool:
    """Whether an id occurs twice: a histogram for the usual small non-negative ids, else a sort."""
    if ids.size and ids.dtype.kind in "iu" and ids.min() >= 0 and ids.max() < 4 * ids.size + 1024:
        return bool(np.bincount(ids).max() > 1)
    return len(np.unique(ids)) != ids.size


def _apportion(fractions: dict, n: int) -> list:
    """Exact counts per key by largest remainder, then listed in key order."""
    keys = list(fractions)
    raw = np.array([fractions[k] * n for k in keys])
    counts = np.floor(raw).astype(int)
    order = np.argsort(-(raw - counts), kind="stable")
    counts[order[: n - counts.sum()]] += 1
    return np.repeat(np.array(keys, dtype=object), counts).tolist()


def _sample_angles(dist: AngleDistribution, n: int, rng) -> np.ndarray:
    if dist.distribution == "uniform":
        theta = rng.uniform(0.0, 360.0, n)
    elif dist.distribution == "fixed":
        theta = np.full(n, dist.value_deg)
    elif dist.distribution == "list":
        theta = np.resize(np.asarray(dist.values_deg, float), n)
    else:
        weights = dist.weights or tuple(np.full(len(dist.mean_deg), 1.0 / len(dist.mean_deg)))
        comp = rng.choice(len(dist.mean_deg), size=n, p=np.asarray(weights) / np.sum(weights))
        means = np.deg2rad(np.asarray(dist.mean_deg))[comp]
        theta = np.rad2deg(rng.vonmises(means, dist.kappa)) if n else np.empty(0)
    return np.mod(theta, 360.0)


def _sample_k(dist: SharpnessDistribution, profile: str, n: int, rng) -> np.ndarray:
    if dist.distribution == "fixed":
        values = np.full(n, dist.value)
    elif dist.distribution == "uniform":
        values = rng.uniform(dist.low, dist.high, n)
    else:
        values = np.resize(np.asarray(dist.values, float), n)
    if n == 0:
        return values
    return np.asarray(k_from_selectivity(values, profile) if dist.of == "theta_a" else validate_k(values, profile))


def _place_in_ellipse(region, n: int, rng) -> dict:
    """Uniform in the spec's ellipse (local frame), labelled with its hand-map name."""
    radius, angle = np.sqrt(rng.uniform(0, 1, n)), rng.uniform(0, 2 * np.pi, n)
    (cx, cy), (a, b) = region.center_mm, region.semi_axes_mm
    return {"x_mm": cx + a * radius * np.cos(angle), "y_mm": cy + b * radius * np.sin(angle),
            "region": np.full(n, region.name, dtype=object), "frame_deg": np.full(n, region.frame_deg)}


def _place_on_map(counts: dict, n: int, rng) -> dict:
    """Region by region (map order), uniform within each, hand frame."""
    sizes = np.array(list(counts.values()), dtype=np.int64)
    if sizes.sum() != n:  # pragma: no cover - counts come from the same map
        raise ValueError(f"map counts sum to {sizes.sum()}, expected {n}")
    pts = [hand_map.sample_in_region(name, c, rng) for name, c in counts.items()]
    xy = np.concatenate(pts) if pts else np.empty((0, 2))
    frames = np.array([hand_map.REGIONS[name].frame_deg for name in counts], float)
    return {"x_mm": xy[:, 0], "y_mm": xy[:, 1], "region": np.repeat(np.array(list(counts), dtype=object), sizes),
            "frame_deg": np.repeat(frames, sizes)}


def _sample_type(kind: str, spec: TypeSpec, n: int, place, rng) -> dict:
    nap = np.array(_apportion(spec.nap, n), dtype=object)
    nap = nap[rng.permutation(n)] if n else nap
    k = np.zeros(n)
    for profile in PROFILE_NAMES:  # a fixed order: draws must not depend on hash seeds
        idx = np.flatnonzero(nap == profile)
        if idx.size == 0:
            continue
        k[idx] = _sample_k(spec.sharpness[profile], profile, idx.size, rng)
    s2 = np.log1p(spec.gain_cv**2)
    gain = rng.lognormal(-s2 / 2.0, np.sqrt(s2), n) if spec.gain_cv > 0 else np.ones(n)
    where = place(n, rng)
    return {
        "afferent_type": np.full(n, kind, dtype=object), "theta_t": _sample_angles(spec.theta_t, n, rng),
        "nap": nap, "k": k, "gain": gain, **where, "noise_sigma": np.full(n, spec.noise_sigma),
        "noise_cv": np.full(n, spec.noise_cv),
    }


def _sample_sensitivity(sd: float, n: int, kind: str, rng) -> np.ndarray:
    """Each unit's sensitivity, lognormal with median 1 and log-SD ``sd``, from its own stream.

    The stream is keyed by the seed's `numpy.random.SeedSequence`, a tag and
    the type, so the other draws of a seed (positions, theta_T, NAP, k, gain)
    are the same with any spread; a generator without a seed sequence gives
    a key drawn from it after every other draw.
    """
    if sd == 0.0 or n == 0:
        return np.ones(n)
    seq = getattr(rng.bit_generator, "seed_seq", None)
    tag = (SENSITIVITY_TAG, afferent_type_codes().index(kind))
    if isinstance(seq, np.random.SeedSequence):
        seq = np.random.SeedSequence(seq.entropy, spawn_key=tuple(seq.spawn_key) + tag, pool_size=seq.pool_size)
    else:
        seq = np.random.SeedSequence(int(rng.integers(2**63)), spawn_key=tag)
    return np.exp(sd * np.random.default_rng(seq).standard_normal(n))


def _placements(spec: PopulationSpec) -> dict:
    """Per type: (count, placement function)."""
    if spec.map is None:
        return {kind: (t.n_afferents(spec.region), lambda n, rng: _place_in_ellipse(spec.region, n, rng))
                for kind, t in spec.types.items()}
    by_region = spec.map.counts(spec.types)
    out = {}
    for kind in spec.types:
        counts = {name: c[kind] for name, c in by_region.items()}
        out[kind] = (sum(counts.values()), lambda n, rng, counts=counts: _place_on_map(counts, n, rng))
    return out


def sample_population(spec, rng=None) -> Population:
    """Draw a population from a spec.

    Parameters
    ----------
    spec : PopulationSpec, str or path
        A spec, a preset name (``"fingertip"``, ``"hand"``) or a TOML path.
    rng : numpy.random.Generator, int or None
        Randomness; the same seed gives the same population.

    Returns
    -------
    Population

    Examples
    --------
    >>> pop = sample_population("fingertip", rng=1)
    >>> len(pop), pop.counts()
    (991, {'SAI': 282, 'RAI': 573, 'RAII': 100, 'SAII': 36})
    """
    check_instance(spec, "spec", (PopulationSpec, str, os.PathLike),
                   "a PopulationSpec, a preset name ('fingertip', 'hand') or a .toml path")
    spec = load_spec(spec)
    rng = check_rng(rng)
    placements = _placements(spec)
    parts = [_sample_type(kind, tspec, *placements[kind], rng) for kind, tspec in spec.types.items()]
    arrays = {name: np.concatenate([p[name] for p in parts]) for name in parts[0]}
    n = len(arrays["theta_t"])
    arrays["sensitivity"] = np.concatenate([_sample_sensitivity(tspec.sensitivity_sd, len(p["theta_t"]), kind, rng)
                                            for p, (kind, tspec) in zip(parts, spec.types.items())])
    return Population(**arrays, afferent_id=np.arange(n, dtype=np.int64), current=spec.current, name=spec.name,
                      receptive_field=spec.receptive_field, neuron=dict(spec.neuron))


def make_population(afferent_type, theta_t=0.0, nap=UNTUNED, k=3.0, *, gain=1.0, x_mm=0.0, y_mm=0.0,
                    noise_sigma=0.0, noise_cv=0.0, region="", frame_deg=0.0, sensitivity=1.0,
                    current: CurrentParams = CurrentParams(), name="custom",
                    receptive_field: str = "gaussian") -> Population:
    """Build a population from explicit per-afferent values (scalars broadcast).

    Examples
    --------
    >>> pop = make_population(["SAI", "SAI"], theta_t=[90.0, 270.0], nap="selective")
    >>> pop.k.tolist()
    [3.0, 3.0]
    """
    types = np.array([normalize_type(t) for t in np.atleast_1d(np.asarray(afferent_type, dtype=object)).tolist()],
                     dtype=object)
    n = types.size
    if n == 0:
        raise ValueError("afferent_type must name at least one afferent, got 0")
    nap = _per_afferent(nap, "nap", n, object)
    k = np.where(nap == UNTUNED, 0.0, _per_afferent(k, "k", n))
    arrays = {name: _per_afferent(v, name, n)
              for name, v in (("theta_t", theta_t), ("gain", gain), ("x_mm", x_mm), ("y_mm", y_mm),
                              ("noise_sigma", noise_sigma), ("noise_cv", noise_cv), ("frame_deg", frame_deg),
                              ("sensitivity", sensitivity))}
    region = _per_afferent(region, "region", n, object)
    return Population(afferent_type=types, nap=np.array(nap), k=k, afferent_id=np.arange(n, dtype=np.int64),
                      region=region, current=current, name=name, receptive_field=receptive_field, **arrays)


def _per_afferent(value, name: str, n: int, dtype=float) -> np.ndarray:
    """``value`` (one for all, or one per afferent) as an array of ``n``; errors name ``name``."""
    arr = as_finite_array(value, name) if dtype is float else np.asarray(value, dtype=object)
    try:
        return np.broadcast_to(arr, (n,)).copy()
    except ValueError:
        raise ValueError(f"{name} must be one value or one per afferent ({n}), got shape {arr.shape}") from None
