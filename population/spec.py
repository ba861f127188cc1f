"""Population specs: per afferent type, how many, where, how tuned, how noisy.

A spec is a TOML file or the matching frozen dataclasses.  Unknown keys,
negative counts, NAP fractions that do not sum to 1 and unknown distributions
are rejected with a `ValueError` naming the key.  Three presets ship inside the
package: ``fingertip`` (TouchSim's index-fingertip pad, region ``D2d`` of the
hand map), ``hand`` (the glabrous hand of `ddmm.population.anatomy.hand_map`)
and ``fingertip_vibration`` (the fingertip with faster FA-I and SA-I currents,
which follow vibration to 150 Hz; docs/model.md).  A spec may start from a
preset: ``extends = "fingertip"`` takes the preset's tables and lays the
file's own keys on them.

Frame: +X radial, +Y distal (mm, fingertip frame), so theta = 0 deg is radial,
90 deg distal, 180 deg ulnar and 270 deg proximal.  With a ``[map]`` the
positions are in the hand frame and theta_T in each afferent's local digit
frame (`ddmm.population.anatomy.hand_map`).

TOML layout (every table optional unless marked)::

    name = "fingertip"
    # extends = "fingertip"        # optional: start from a preset; the tables below change it
    [region]                       # ellipse in mm
    center_mm = [0.0, 0.0]
    semi_axes_mm = [7.0, 9.0]      # radial, distal
    name = "D2d"                   # optional: the hand-map region it stands for
    # or, instead of [region] and of every count / density_per_cm2:
    # [map]
    # name = "hand"                # counts from the map's densities (row 16)
    # regions = ["D2d", "D2m"]     # optional subset (default: every region)
    [current]                      # overrides of ddmm.models.CurrentParams: shared fields,
    cutoff_hz = 20.0               #   then a table of ddmm.models.TypeParams fields per type
    [current.SAI]
    gain = 5.367
    [types.SAI]                    # one table per type present
    count = 282                    # or density_per_cm2 = 70.0
    noise_sigma = 1.0              # mV/sqrt(ms), additive
    noise_cv = 0.3                 # sqrt(ms), proportional to the drive
    gain_cv = 0.2                  # per-afferent gain spread (lognormal CV)
    theta_t = { distribution = "von_mises", mean_deg = 90.0, kappa = 0.6 }
    nap = { selective = 0.4, broad = 0.3, bipolar = 0.1, none = 0.2 }
    [types.SAI.sharpness.selective]
    distribution = "uniform"       # fixed | uniform | list
    of = "theta_a"                 # theta_a (deg) or k
    low = 20.0
    high = 50.0
"""

from __future__ import annotations

import copy
import dataclasses
import functools
import math
import os
import tomllib
import warnings
from dataclasses import dataclass, field
from importlib import resources
from pathlib import Path

from ddmm.models.afferent_types import afferent_type_codes, afferent_type_info, normalize_type
from ddmm.models.attenuation import UNTUNED
from ddmm.models.current_params import LEGACY_FIELDS, CurrentParams
from ddmm.models.nap import PROFILE_NAMES
from ddmm.models.neuron import NeuronParams, check_neuron
from ddmm.models.type_params import TypeParams
from ddmm.population.anatomy.receptive_fields import check_shape
from ddmm.population.spec_parts import (
    DEFAULT_SHARPNESS,
    MAPS,
    AngleDistribution,
    MapSpec,
    Region,
    SharpnessDistribution,
)
from ddmm.population.spec_parts import fail as _fail
from ddmm.population.spec_parts import merge_tables
from ddmm.population.spec_parts import finite as _finite
from ddmm.utils.deprecation import warn_renamed
from ddmm.utils.validation import check_instance, shown

__all__ = [
    "NAP_CHOICES",
    "AngleDistribution",
    "SharpnessDistribution",
    "Region",
    "MapSpec",
    "MAPS",
    "TypeSpec",
    "PopulationSpec",
    "PRESETS",
    "load_spec",
    "spec_from_dict",
]

#: NAP choices of a population: the three profiles and "none" (untuned, CMM).
NAP_CHOICES = PROFILE_NAMES + (UNTUNED,)
PRESETS = ("fingertip", "hand", "fingertip_vibration")
#: Bounds of a type's afferent count and density: far above the human hand (about 17,000; fingertip
#: about 241 per cm^2) and below what a process can sample.
MAX_COUNT = 1_000_000
MAX_DENSITY_PER_CM2 = 10_000.0
#: Largest ``sensitivity_sd``: a q90/q10 threshold ratio of about 600, beyond any reported spread.
MAX_SENSITIVITY_SD = 2.5


@dataclass(frozen=True)
class TypeSpec:
    """How the afferents of one type are drawn.

    Attributes
    ----------
    count : int or None
        Number of afferents; give this or ``density_per_cm2`` (neither with a
        ``[map]``, which sets the counts).
    density_per_cm2 : float or None
        Afferents per cm^2 over the spec's region.
    theta_t : AngleDistribution
        Tuning-angle distribution.
    nap : dict
        Fractions of ``selective``, ``broad``, ``bipolar`` and ``none`` (sum 1).
    sharpness : dict
        `SharpnessDistribution` per profile (default: k = 3).
    gain_cv : float
        Coefficient of variation of the per-afferent gain (lognormal, mean 1).
    sensitivity_sd : float
        Spread of the per-afferent sensitivity: the SD of its natural log
        (lognormal, median 1; 0: every unit 1, the paper).  A unit's
        sensitivity multiplies its gain and divides its type's dead zone, so
        its stimulus thresholds are its type's divided by it; the q90/q10
        ratio of thresholds is ``exp(2.563 sensitivity_sd)`` (docs/model.md,
        "Units that differ").  Drawn from a stream keyed by the seed and the
        type, apart from every other draw.
    noise_sigma : float
        Additive white current-noise intensity in mV/sqrt(ms): each current
        sample of length h ms gets ``noise_sigma * N(0, 1) / sqrt(h)``, so the
        voltage noise over any interval is independent of the sampling.  It
        acts at rest too: on low-threshold (RA) neurons it causes firing
        without any force.
    noise_cv : float
        Drive-proportional (receptor) noise intensity in sqrt(ms): a sample
        of current I gets ``noise_cv * |I| * N(0, 1) / sqrt(h)`` more, so an
        afferent with no drive stays silent while a driven one varies from
        trial to trial.  At 1 kHz (h = 1 ms) its SD is ``noise_cv * |I|``.
    """

    count: int | None = None
    density_per_cm2: float | None = None
    theta_t: AngleDistribution = AngleDistribution()
    nap: dict = field(default_factory=lambda: {UNTUNED: 1.0})
    sharpness: dict = field(default_factory=lambda: dict(DEFAULT_SHARPNESS))
    gain_cv: float = 0.0
    sensitivity_sd: float = 0.0
    noise_sigma: float = 0.0
    noise_cv: float = 0.0

    def __post_init__(self):
        if self.count is not None and self.density_per_cm2 is not None:
            _fail("count", "give exactly one of count and density_per_cm2")
        if self.count is not None and (isinstance(self.count, bool) or not isinstance(self.count, int)
                                       or not 0 <= self.count <= MAX_COUNT):
            _fail("count", f"must be a whole number in [0, {MAX_COUNT:,}] (a hand has about 17,000 afferents), "
                           f"got {shown(self.count)}")
        if self.density_per_cm2 is not None:
            _finite("density_per_cm2", self.density_per_cm2, nonneg=True)
            if self.density_per_cm2 > MAX_DENSITY_PER_CM2:
                _fail("density_per_cm2", f"must be <= {MAX_DENSITY_PER_CM2:g} per cm^2 (the human fingertip has "
                                         f"about 241), got {self.density_per_cm2:g}")
        for name in self.nap:
            if name not in NAP_CHOICES:
                _fail(f"nap.{name}", f"unknown NAP; allowed: {', '.join(NAP_CHOICES)}")
        fracs = {k: _finite(f"nap.{k}", v, nonneg=True) for k, v in self.nap.items()}
        if not math.isclose(sum(fracs.values()), 1.0, abs_tol=1e-6):
            _fail("nap", f"fractions must sum to 1, got {shown(sum(fracs.values()))}")
        object.__setattr__(self, "nap", fracs)
        sharp = dict(DEFAULT_SHARPNESS, **self.sharpness)
        for name in sharp:
            if name not in PROFILE_NAMES:
                _fail(f"sharpness.{name}", f"unknown profile; allowed: {', '.join(PROFILE_NAMES)}")
        object.__setattr__(self, "sharpness", sharp)
        _finite("gain_cv", self.gain_cv, nonneg=True)
        _finite("sensitivity_sd", self.sensitivity_sd, nonneg=True)
        if self.sensitivity_sd > MAX_SENSITIVITY_SD:
            _fail("sensitivity_sd", f"must be <= {MAX_SENSITIVITY_SD:g} (thresholds spread over a factor of "
                                    f"{math.exp(2.563 * MAX_SENSITIVITY_SD):,.0f} from q10 to q90), "
                                    f"got {self.sensitivity_sd:g}")
        _finite("noise_sigma", self.noise_sigma, nonneg=True)
        _finite("noise_cv", self.noise_cv, nonneg=True)

    def n_afferents(self, region: Region) -> int:
        """Count, or density times the region's area, rounded."""
        if self.count is not None:
            return self.count
        if self.density_per_cm2 is None:
            _fail("count", "give exactly one of count and density_per_cm2 (or a [map])")
        return int(round(self.density_per_cm2 * region.area_cm2))


@dataclass(frozen=True)
class PopulationSpec:
    """A population: types, region, current parameters.

    Attributes
    ----------
    name : str
        Label stored in datasets.
    types : dict
        `TypeSpec` per afferent type (``"SAI"``, ``"RAI"``, ``"RAII"``, ``"SAII"``).
    region : Region
        Where afferents are placed (uniformly), in mm, when there is no map.
    current : CurrentParams
        Gains and derivative filter of eqs 1-3.
    description : str
        Free text.
    map : MapSpec or None
        When given, afferents are placed region by region of the hand map at
        its densities, and no type gives a count or density.
    receptive_field : {"gaussian", "tailed"}
        Fall-off of the receptive fields beyond a contact's edge
        (`ddmm.population.anatomy.receptive_fields`): the Gaussian with a hard
        support (default) or the tailed shape whose fields grow with force.
    neuron : dict
        `ddmm.models.neuron.NeuronParams` by type code overriding the paper's
        neurons (eqs 4-6); TOML ``[neuron.RAII]`` with keys ``a``, ``b``,
        ``c``, ``d`` (missing keys keep the type's paper values).
    """

    name: str = "custom"
    types: dict = field(default_factory=dict)
    region: Region = Region()
    current: CurrentParams = CurrentParams()
    description: str = ""
    map: MapSpec | None = None
    receptive_field: str = "gaussian"
    neuron: dict = field(default_factory=dict)

    def __post_init__(self):
        check_instance(self.name, "name", str, "a str")
        check_instance(self.types, "types", dict, "a dict of afferent type -> TypeSpec")
        check_instance(self.current, "current", CurrentParams, "a CurrentParams")
        check_shape(self.receptive_field)  # one message for a spec, a population and a weight call
        check_neuron(self.neuron)
        for kind in self.types:
            if kind not in afferent_type_codes():
                _fail(f"types.{kind}", f"unknown afferent type; allowed: {', '.join(afferent_type_codes())}")
        ordered = {k: self.types[k] for k in afferent_type_codes() if k in self.types}
        object.__setattr__(self, "types", ordered)
        if self.map is not None and not isinstance(self.map, MapSpec):
            raise TypeError(f"map must be a MapSpec or None, got {type(self.map).__name__}")
        for kind, t in ordered.items():
            given = t.count is not None or t.density_per_cm2 is not None
            if self.map is not None and given:
                _fail(f"types.{kind}.count", "a spec with a [map] takes its counts from the map; "
                      "remove count and density_per_cm2")
            if self.map is None and not given:
                _fail(f"types.{kind}.count", "give exactly one of count and density_per_cm2 (or a [map])")

    def n_afferents(self) -> dict:
        """Afferents per type."""
        if self.map is not None:
            counts = self.map.counts(self.types).values()
            return {k: sum(c[k] for c in counts) for k in self.types}
        return {k: t.n_afferents(self.region) for k, t in self.types.items()}

    def replace(self, **changes) -> "PopulationSpec":
        """A copy with fields replaced (see `dataclasses.replace`)."""
        return dataclasses.replace(self, **changes)


def _build(cls, data: dict, key: str, nested=None):
    """Build dataclass ``cls`` from ``data``, naming any unknown key."""
    if not isinstance(data, dict):
        _fail(key, f"must be a table, got {type(data).__name__}")
    allowed = {f.name for f in dataclasses.fields(cls)}
    for name in data:
        if name not in allowed:
            _fail(f"{key}.{name}" if key else name, f"unknown key; allowed: {', '.join(sorted(allowed))}")
    kwargs = dict(data)
    for name, builder in (nested or {}).items():
        if name in kwargs:
            kwargs[name] = builder(kwargs[name], f"{key}.{name}" if key else name)
    for name, value in kwargs.items():
        if isinstance(value, list):
            kwargs[name] = tuple(value)
    try:
        return cls(**kwargs)
    except ValueError as exc:
        raise ValueError(f"{key}.{exc}" if key and not str(exc).startswith(key) else str(exc)) from None


def _type_spec(data, key):
    def sharpness(d, k):
        if not isinstance(d, dict):
            _fail(k, "must be a table of profiles")
        return {name: _build(SharpnessDistribution, v, f"{k}.{name}") for name, v in d.items()}

    return _build(TypeSpec, data, key, {
        "theta_t": lambda d, k: _build(AngleDistribution, d, k),
        "sharpness": sharpness,
    })


def spec_from_dict(data: dict, *, default_name: str = "custom") -> PopulationSpec:
    """Build a `PopulationSpec` from the TOML structure (a dict).

    Raises
    ------
    ValueError
        Naming the first unknown key or invalid value.

    Examples
    --------
    >>> spec = spec_from_dict({"types": {"SAI": {"count": 10}}})
    >>> spec.n_afferents()
    {'SAI': 10}
    """
    check_instance(data, "data", dict, "a dict (the TOML structure)")
    check_instance(default_name, "default_name", str, "a str")
    data = _resolve_extends(data, ())
    data.setdefault("name", default_name)
    allowed = {f.name for f in dataclasses.fields(PopulationSpec)}
    for name in data:
        if name not in allowed:
            _fail(name, f"unknown key; allowed: {', '.join(sorted(allowed | {'extends'}))}")
    types = data.get("types", {})
    if not isinstance(types, dict) or not types:
        _fail("types", "a spec needs at least one afferent type table, e.g. [types.SAI]")
    codes = {}
    for kind in types:
        try:
            codes[kind] = normalize_type(kind)
        except ValueError:
            _fail(f"types.{kind}", f"unknown afferent type; allowed: {', '.join(afferent_type_codes())} "
                                   "(or SA-I, FA-I, FA-II, SA-II)")
    if len(set(codes.values())) != len(codes):
        _fail("types", f"two tables name one afferent type: {', '.join(codes)}")
    data = dict(data, types={codes[kind]: table for kind, table in types.items()})
    if "map" in data and "region" in data:
        _fail("region", "a spec with a [map] places afferents by the map; remove [region]")
    return _build(PopulationSpec, data, "", {
        "types": lambda d, k: {kind: _type_spec(t, f"types.{kind}") for kind, t in d.items()},
        "region": lambda d, k: _build(Region, d, "region"),
        "current": _current_table,
        "map": lambda d, k: _build(MapSpec, d, "map"),
        "neuron": _neuron_table,
    })


def _neuron_table(data, key) -> dict:
    """``[neuron.<TYPE>]`` tables: `NeuronParams` by type code, each starting from the type's paper values."""
    if not isinstance(data, dict):
        _fail(key, f"must be a table of afferent types, got {type(data).__name__}")
    out = {}
    for kind, table in data.items():
        try:
            code = normalize_type(kind)
        except ValueError:
            _fail(f"{key}.{kind}", f"unknown afferent type; allowed: {', '.join(afferent_type_codes())}")
        base = afferent_type_info(code).neuron
        built = _build(NeuronParams, {**dataclasses.asdict(base), **table} if isinstance(table, dict) else table,
                       f"{key}.{kind}")
        out[code] = built
    return out


def _current_table(data, key) -> CurrentParams:
    """``[current]``: the shared fields, and ``[current.<TYPE>]`` tables of `TypeParams` fields, each starting
    from the type's registered defaults.  The old flat keys (``g_sai``) still work for one release."""
    if not isinstance(data, dict):
        _fail(key, f"must be a table, got {type(data).__name__}")
    shared, types, legacy = {}, {}, {}
    for name, value in data.items():
        if isinstance(value, dict):
            try:
                code = normalize_type(name)
            except ValueError:
                _fail(f"{key}.{name}", f"unknown afferent type; allowed: {', '.join(afferent_type_codes())}")
            base = dataclasses.asdict(afferent_type_info(code).current)
            unknown = sorted(set(value) - set(base))
            if unknown:
                _fail(f"{key}.{name}.{unknown[0]}", f"unknown key; allowed: {', '.join(base)}")
            types[code] = _build(TypeParams, {**base, **value}, f"{key}.{name}")
        elif name in ("cutoff_hz", "filter_order", "i_sat"):
            shared[name] = value
        elif name in LEGACY_FIELDS:
            legacy[name] = value
        else:
            _fail(f"{key}.{name}", "unknown key; allowed: cutoff_hz, filter_order, i_sat and a table per afferent "
                                   f"type ([{key}.SAI], ...)")
    for name in legacy:
        code, field = LEGACY_FIELDS[name]
        warn_renamed(f"[{key}] {name}", f"[{key}.{code}] {field}", stacklevel=6)
    try:
        with warnings.catch_warnings():  # warned above, in the file's terms
            warnings.simplefilter("ignore", DeprecationWarning)
            return CurrentParams(**shared, types=types, **legacy)
    except (TypeError, ValueError) as exc:
        _fail(key, str(exc))


def _preset_table(name: str) -> dict:
    """A packaged preset's TOML structure, as written."""
    return tomllib.loads(resources.files("ddmm.population").joinpath("presets", f"{name}.toml").read_text())


def _resolve_extends(data: dict, seen: tuple) -> dict:
    """``data`` with its ``extends = "<preset>"`` laid on that preset's tables (`merge_tables`).

    The base's ``name`` is not inherited and its ``description`` is marked as
    changed, so a derived spec never passes for its base.
    """
    data = dict(data)
    if "extends" not in data:
        return data
    base = data.pop("extends")
    if not isinstance(base, str) or base not in PRESETS:
        _fail("extends", f"{base!r} is not a preset; allowed: {', '.join(PRESETS)}")
    if base in seen:
        _fail("extends", f"{base!r} extends itself through {' -> '.join(seen)}")
    table = _resolve_extends(_preset_table(base), seen + (base,))
    table.pop("name", None)
    table["description"] = f"{table.get('description', base)}, changed (extends {base})"
    return merge_tables(table, data, normalize_type)


@functools.lru_cache(maxsize=None)
def _preset(name: str) -> PopulationSpec:
    """A packaged preset, parsed once per process (`load_spec` hands out deep copies)."""
    return spec_from_dict(_preset_table(name), default_name=name)


def load_spec(source) -> PopulationSpec:
    """Load a preset by name (``"fingertip"``, ``"hand"``) or a spec from a TOML path.

    Raises
    ------
    ValueError
        For an unknown preset, a missing file, invalid TOML or an invalid spec.

    Examples
    --------
    >>> load_spec("fingertip").n_afferents()
    {'SAI': 282, 'RAI': 573, 'RAII': 100, 'SAII': 36}
    """
    if isinstance(source, PopulationSpec):
        return source
    if isinstance(source, str) and source in PRESETS:
        return copy.deepcopy(_preset(source))  # 0.1 ms; its dicts are the caller's, the cached spec stays as read
    check_instance(source, "source", (str, os.PathLike), f"a preset name ({', '.join(PRESETS)}) or a .toml path")
    path = Path(source)
    if path.suffix != ".toml":
        raise ValueError(f"population={str(source)!r}: give a preset ({', '.join(PRESETS)}) or a .toml file")
    try:
        text = path.read_text(encoding="utf-8")
    except OSError as exc:
        raise ValueError(f"population file {str(path)!r} cannot be read: {exc.strerror}") from None
    except UnicodeDecodeError as exc:
        raise ValueError(f"population file {str(path)!r} is not UTF-8 text (byte {exc.start}); TOML is UTF-8") from None
    name = path.stem
    try:
        data = tomllib.loads(text)
    except tomllib.TOMLDecodeError as exc:
        raise ValueError(f"population file {str(path)!r} is not valid TOML: {exc}") from None
    except RecursionError:
        raise ValueError(f"population file {str(path)!r} nests arrays or tables too deeply to be a spec") from None
    return spec_from_dict(data, default_name=name)


