"""Receptive fields and local drive: how strongly each force site drives each afferent.

**Weights.**  An afferent inside a contact (or site) footprint gets weight
1.  Outside, the weight falls with the distance e beyond the footprint's
edge, with a width sigma per type, in one of two shapes (`RF_SHAPES`, the
population's ``receptive_field``):

* ``"gaussian"``: ``exp(-e^2 / (2 sigma^2))``, exactly 0 beyond
  ``RF_SUPPORT`` widths.  The weight ends at a cliff (0.011 at 3 sigma):
  whatever the force, an afferent beyond it never responds, so a
  receptive field stops growing with force at the cliff.
* ``"tailed"``: the same Gaussian core out to one width, then an
  exponential tail with the same value and slope there,
  ``exp(1/2 - e / sigma)``, exactly 0 where it falls below `RF_TAIL_FLOOR`
  (7.4 widths).  The half-weight radius is 1.193 widths against the
  Gaussian's 1.177 (an area 2.7% larger), so the median field areas below
  still hold; the distance at which a force crosses an afferent's
  threshold grows with the logarithm of the force, as human fields grow
  with force (docs/model.md, "What changed in the model, and why").

Afferents at weight 0 provably stay at rest and are skipped.  The widths
follow docs/references.md row 17 (Johansson & Vallbo 1980): a point probe
drives an afferent at half weight or more over an area equal to the type's
median receptive field, 11.0 mm^2 (SA-I), 12.6 mm^2 (FA-I), about 5x SA-I's
for SA-II and 10x for FA-II.

**Local force of a multi-site scene** (`local_mixing`).  The DDMM's force is
the force on a fingertip-sized contact, so a site's force counts as the
traction over its footprint (area a_s) times the reference area
``REFERENCE_AREA_MM2`` (A_ref).  Afferent i, with weights w_is summing to
S_i over the sites that reach it, receives

    F_i = sum_s (w_is / S_i) (A_ref / a_s) F_s      (three axes)

the weighted mean of the sites' tractions times A_ref, and its drive is
scaled by the coverage ``min(S_i, 1)`` (the one-site scene's weight).  Its
own local shear direction then drives its AF.  A site whose footprint is
A_ref, alone over an afferent, gives F_i = F_s exactly: the one-site scene.
Site forces are in the population's frame (the hand frame of
`ddmm.population.anatomy.hand_map`), so the AF compares them with each afferent's tuning
angle turned into that frame, ``theta_T + frame_deg`` (`frame_theta`); a
one-site scene's force acts in every afferent's own digit frame.
"""

from __future__ import annotations

import numpy as np

from ddmm.models.afferent_types import afferent_type_codes, afferent_type_info
from ddmm.population.stimuli.scenes import REFERENCE_AREA_MM2, Contact, Sites
from ddmm.utils.validation import as_finite_array, check_instance

# RF_AREA_MM2 and RF_SIGMA_MM are views of the registry (the module's __getattr__).
__all__ = ["RF_AREA_MM2", "RF_SIGMA_MM", "RF_SUPPORT", "RF_SHAPES", "RF_TAIL_FLOOR", "REFERENCE_AREA_MM2",  # noqa: F822
           "receptive_field_weight", "population_weight", "site_weights", "local_mixing", "input_sections",
           "site_coverage", "frame_theta"]



def __getattr__(name):
    # Views of the registry, whatever is registered now: each type's median receptive-field area in mm^2
    # (`AfferentType.rf_area_mm2`; docs/references.md row 17: SA-I, FA-I read (V); SA-II about 5x and FA-II about
    # 10x larger, read in a secondary source (V2)) and its Gaussian fall-off width in mm (`AfferentType.rf_sigma_mm`:
    # a point probe gets weight >= 1/2 within sigma * sqrt(2 ln 2), a disc whose area is the type's median field).
    if name == "RF_AREA_MM2":
        return {code: afferent_type_info(code).rf_area_mm2 for code in afferent_type_codes()}
    if name == "RF_SIGMA_MM":
        return {code: afferent_type_info(code).rf_sigma_mm for code in afferent_type_codes()}
    raise AttributeError(f"module {__name__!r} has no attribute {name!r}")

#: Weights are exactly 0 beyond this many widths outside the contact (the ``"gaussian"`` shape).
RF_SUPPORT = 3.0
#: Receptive-field shapes: the Gaussian with a hard support (the package's first form) and the tailed one.
RF_SHAPES = ("gaussian", "tailed")
#: The ``"tailed"`` weight is exactly 0 below this value (beyond 0.5 + ln(1000) = 7.4 widths).
RF_TAIL_FLOOR = 1e-3


def check_shape(shape: str) -> str:
    """``shape`` if it is one of `RF_SHAPES`, else a ValueError naming ``receptive_field``."""
    if shape not in RF_SHAPES:
        raise ValueError(f"receptive_field={shape!r} is not a receptive-field shape; allowed: {', '.join(RF_SHAPES)}")
    return shape


def _falloff(excess, sigma, shape: str) -> np.ndarray:
    """Weight of afferents ``excess`` mm beyond a footprint's edge (widths ``sigma``, mm)."""
    z = excess / sigma
    if shape == "gaussian":
        weight = np.exp(-0.5 * z * z)
        weight[z > RF_SUPPORT] = 0.0
        return weight
    weight = np.where(z <= 1.0, np.exp(-0.5 * z * z), np.exp(0.5 - z))
    weight[weight < RF_TAIL_FLOOR] = 0.0
    return weight


def population_weight(population, contact) -> np.ndarray:
    """`receptive_field_weight` of a population's afferents for a contact, in its ``receptive_field`` shape."""
    return receptive_field_weight(population.x_mm, population.y_mm, population.afferent_type, contact,
                                  population.receptive_field)


def receptive_field_weight(x_mm, y_mm, afferent_type, contact, shape: str = "gaussian") -> np.ndarray:
    """Drive weight in [0, 1] of afferents at (x, y) for a contact disc.

    Parameters
    ----------
    x_mm, y_mm : array_like
        Afferent positions in mm.
    afferent_type : array_like of str
        Type of each afferent (selects the width).
    contact : ddmm.population.stimuli.scenes.Contact
        Centre and radius of the contact, in mm.
    shape : {"gaussian", "tailed"}
        The fall-off beyond the contact's edge (module docstring).

    Examples
    --------
    >>> from ddmm.population.stimuli.scenes import Contact
    >>> x = [0.0, 1.0 + afferent_type_info("SAI").rf_sigma_mm, 9.0]
    >>> receptive_field_weight(x, [0.0] * 3, ["SAI"] * 3, Contact(0.0, 0.0, 1.0)).round(3).tolist()
    [1.0, 0.607, 0.0]
    >>> receptive_field_weight(x, [0.0] * 3, ["SAI"] * 3, Contact(0.0, 0.0, 1.0), "tailed").round(3).tolist()
    [1.0, 0.607, 0.011]
    """
    check_shape(shape)
    check_instance(contact, "contact", Contact, "a Contact")
    sigma, x, y = _afferents(x_mm, y_mm, afferent_type)
    return _weight(sigma, x, y, contact, shape)


def _afferents(x_mm, y_mm, afferent_type) -> tuple:
    """(receptive-field width, x, y) of each afferent, mm; errors name the argument."""
    x, y = as_finite_array(x_mm, "x_mm"), as_finite_array(y_mm, "y_mm")
    types = np.asarray(afferent_type, dtype=object)
    try:
        x, y, types = np.broadcast_arrays(x, y, types)
    except ValueError:
        raise ValueError(f"x_mm, y_mm and afferent_type must have one entry per afferent each, got shapes "
                         f"{x.shape}, {y.shape} and {types.shape}") from None
    sigma = np.full(x.shape, np.nan)
    for kind in afferent_type_codes():
        sigma[types == kind] = afferent_type_info(kind).rf_sigma_mm
    if np.isnan(sigma).any():
        bad = types[np.isnan(sigma)].flat[0]
        raise ValueError(f"afferent_type={bad!r} is unknown; allowed: {', '.join(afferent_type_codes())}")
    return sigma, x, y


def _weight(sigma, x, y, contact, shape: str) -> np.ndarray:
    excess = np.maximum(np.hypot(x - contact.x_mm, y - contact.y_mm) - contact.radius_mm, 0.0)
    return _falloff(excess, sigma, shape)


def site_weights(x_mm, y_mm, afferent_type, sites, shape: str = "gaussian") -> np.ndarray:
    """Receptive-field weight of every afferent for every site, shape (n_afferents, n_sites).

    Each site's footprint is a disc (``sites.radius_mm``); see
    `receptive_field_weight`.

    Examples
    --------
    >>> from ddmm.population.stimuli.scenes import Sites
    >>> w = site_weights([0.0, 9.0], [0.0, 0.0], ["SAI", "SAI"], Sites([0.0, 9.0], [0.0, 0.0], 1.0))
    >>> w.round(3).tolist()
    [[1.0, 0.0], [0.0, 1.0]]
    """
    check_shape(shape)
    check_instance(sites, "sites", Sites, "a Sites")
    sigma, x, y = _afferents(x_mm, y_mm, afferent_type)
    out = np.empty((x.size, len(sites)))
    for s in range(len(sites)):
        disc = Contact(float(sites.x_mm[s]), float(sites.y_mm[s]), float(sites.radius_mm[s]))
        out[:, s] = _weight(sigma, x, y, disc, shape)
    return out


def local_mixing(x_mm, y_mm, afferent_type, sites, shape: str = "gaussian"):
    """Sparse coefficients of each afferent's local force and its coverage (module docstring).

    Returns
    -------
    indptr : ndarray of int64, shape (n_afferents + 1,)
    indices : ndarray of int64
        Sites reaching afferent i: ``indices[indptr[i]:indptr[i + 1]]``.
    coeff : ndarray of float
        Their coefficients ``(w_is / S_i) (A_ref / a_s)`` (dimensionless).
    coverage : ndarray of float, shape (n_afferents,)
        ``min(S_i, 1)``, the drive's scale; 0 for afferents no site reaches.

    Examples
    --------
    >>> from ddmm.population.stimuli.scenes import Sites
    >>> r = float(np.sqrt(REFERENCE_AREA_MM2 / np.pi))
    >>> indptr, indices, coeff, cover = local_mixing([0.0, 40.0], [0.0, 0.0], ["SAI"] * 2, Sites([0.0], [0.0], r))
    >>> indptr.tolist(), coeff.tolist(), cover.tolist()
    ([0, 1, 1], [1.0], [1.0, 0.0])
    """
    check_instance(sites, "sites", Sites, "a Sites")
    if sites.spread is not None:  # the sites' own spread (an indentation's mechanics): the fields do not apply
        return sites.spread.local_mixing(x_mm, y_mm, afferent_type, sites)
    w = site_weights(x_mm, y_mm, afferent_type, sites, shape)
    total = w.sum(axis=1)
    rows, cols = np.nonzero(w)
    factor = REFERENCE_AREA_MM2 / sites.area_mm2
    coeff = (w[rows, cols] / total[rows]) * factor[cols]
    indptr = np.concatenate([[0], np.cumsum(np.bincount(rows, minlength=w.shape[0]))]).astype(np.int64)
    return indptr, cols.astype(np.int64), coeff, np.minimum(total, 1.0)


def input_sections(sites, fs: float):
    """{type code: filter sections} a multi-site scene's spread runs before each type's filters at ``fs`` Hz
    (an indentation's transduction, `ddmm.population.stimuli.indentation.ContactSpread.input_sections`), or
    None: the receptive fields and a spread without ``input_sections`` filter nothing.

    Examples
    --------
    >>> input_sections(Sites([0.0], [0.0], 1.0), 1000.0) is None
    True
    """
    check_instance(sites, "sites", Sites, "a Sites")
    sections = getattr(sites.spread, "input_sections", None)
    return None if sections is None else sections(fs) or None


def site_coverage(population, sites) -> np.ndarray:
    """Each afferent's coverage ``min(S_i, 1)`` by a multi-site scene's sites (its drive scale).

    Raises
    ------
    ValueError
        If a site reaches no afferent of the population (it lies outside
        every region the population covers), naming the site.
    """
    _check_population(population)
    check_instance(sites, "sites", Sites, "a Sites")
    if sites.spread is not None:
        sites.spread.check_reach(population, sites)
        return local_mixing(population.x_mm, population.y_mm, population.afferent_type, sites)[3]
    w = site_weights(population.x_mm, population.y_mm, population.afferent_type, sites, population.receptive_field)
    dead = np.flatnonzero(~np.any(w > 0.0, axis=0))
    if dead.size:
        s = dead[0]
        raise ValueError(f"site {sites.site_id[s]!r} at ({sites.x_mm[s]:g}, {sites.y_mm[s]:g}) mm reaches no "
                         f"afferent of population {population.name!r}: it lies outside every region the "
                         "population covers")
    return np.minimum(w.sum(axis=1), 1.0)


def frame_theta(population) -> np.ndarray:
    """Tuning angles (deg) in the population's frame: theta_T (in the afferent's digit frame) + ``frame_deg``.

    Multi-site forces are given in the population's frame; a one-site
    scene's force acts in every afferent's own digit frame, so it uses
    theta_T alone.
    """
    _check_population(population)
    return population.theta_t + population.frame_deg


def _check_population(population) -> None:
    from ddmm.population.sampling import Population  # sampling imports this module

    check_instance(population, "population", Population, "a Population (from sample_population or make_population)")
