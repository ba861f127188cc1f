"""Direction tuning as microneurography measures it (Birznieks et al. 2001).

Protocol (docs/model.md §2; docs/references.md row 9): five force conditions on the fingertip, a 4 N
normal ramp-hold-release alone and inclined 20 deg toward radial (0 deg),
distal (90), ulnar (180) and proximal (270), each repeated over trials.

For every afferent:

* **Significance of direction dependence.**  A one-way ANOVA (F-test) on
  impulse counts across the five conditions, separately in the loading and
  the plateau phase; the afferent is *tuned* if either phase is significant
  at ``alpha`` (0.05).  This is the usual microneurography criterion: a
  significant effect of stimulus direction on the number of impulses in a
  response phase.  Its false-positive rate per afferent is 1 - 0.95^2 =
  9.75% (two phases; measured 9.8% on Poisson null data), not 5%.
  ``correction="bonferroni"`` halves alpha per phase, for at most 5%.  Degenerate cases are
  decided exactly: identical counts everywhere are untuned (p = 1); zero
  within-condition variance with different means is tuned (p = 0).
* **DSI** (paper eq. 7) on the mean counts of the four tangential
  directions over loading + plateau (the force-application period).
* **Preferred direction**: the angle of the vector sum of those mean
  counts, in degrees; ``has_preferred`` is 0 where the sum vanishes (an
  axial or untuned afferent), and ``preferred_deg`` is then 0 by convention.

Statistics use *responsive* afferents (at least one impulse in the
analysed phases), as a microneurographer only records units that respond.
"""

from __future__ import annotations

import warnings

import numpy as np
import xarray as xr

from ddmm.models.afferent_types import afferent_type_codes
from ddmm.models.metrics import direction_index
from ddmm.population.stimuli.scenes import birznieks
from ddmm.utils.validation import check_dataset, check_real

__all__ = ["TUNING_DIRECTIONS", "DEFAULT_TRIALS", "RECORDED_TYPES", "tuning_scenes", "phase_counts", "tuned_criterion",
           "direction_tuning",
           "tuning_summary"]

#: Tangential directions of the protocol, degrees (frame: 0 radial, 90 distal).
TUNING_DIRECTIONS = {"radial": 0.0, "distal": 90.0, "ulnar": 180.0, "proximal": 270.0}
#: Repetitions per condition: five, a recording session's worth (an afferent is
#: typically held for minutes, enough for 5 x 5 stimuli of 0.5 s plus rests).
DEFAULT_TRIALS = 5
_PHASES = ("loading", "plateau")
#: The afferent types pooled into the human 86% (Birznieks et al. 2001): no FA-II
#: (`ddmm.models.afferent_types.AfferentType.recorded_by_humans`).
RECORDED_TYPES = afferent_type_codes("recorded_by_humans")


def tuning_scenes(**kwargs) -> list:
    """The five conditions: normal only, then radial, distal, ulnar, proximal (20 deg).

    Keyword arguments go to `ddmm.population.stimuli.scenes.birznieks`.

    Examples
    --------
    >>> [s.name for s in tuning_scenes()]
    ['normal', 'birznieks_0', 'birznieks_90', 'birznieks_180', 'birznieks_270']
    """
    return [birznieks(None, **kwargs)] + [birznieks(d, **kwargs) for d in TUNING_DIRECTIONS.values()]


def phase_counts(ds: xr.Dataset, phases=_PHASES) -> xr.DataArray:
    """Impulse counts per (phase, condition, trial, afferent) from the spike events."""
    missing = [p for p in phases if "stage" not in ds.coords or p not in ds.stage.values]
    if missing:
        raise ValueError(f"the dataset has no stage {missing[0]!r}; simulate scenes with stages "
                         "(e.g. tuning_scenes())")
    if "spike_time" not in ds:
        raise ValueError("the dataset has no spike events; simulate with record including 'spikes'")
    out = np.zeros((len(phases), ds.sizes["condition"], ds.sizes["trial"], ds.sizes["afferent"]), np.int32)
    cond = ds.spike_condition.values
    for p, phase in enumerate(phases):
        start = ds.stage_start.sel(stage=phase).values[cond]
        end = ds.stage_end.sel(stage=phase).values[cond]
        keep = (ds.spike_time.values >= start) & (ds.spike_time.values < end)
        np.add.at(out[p], (cond[keep], ds.spike_trial.values[keep], ds.spike_afferent.values[keep]), 1)
    return xr.DataArray(out, dims=("phase", "condition", "trial", "afferent"),
                        coords={"phase": list(phases), "condition": ds.condition, "afferent": ds.afferent})


def _anova_p(counts: np.ndarray) -> np.ndarray:
    """One-way ANOVA p-value per afferent; ``counts`` is (condition, trial, afferent)."""
    from scipy import stats  # scipy.stats costs 0.25 s of import: only when a test runs
    means = counts.mean(axis=1)
    within = ((counts - means[:, None, :]) ** 2).sum(axis=(0, 1))
    between = ((means - means.mean(axis=0)) ** 2).sum(axis=0)
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        p = stats.f_oneway(*counts, axis=0).pvalue
    p = np.where(within == 0, np.where(between > 0, 0.0, 1.0), p)  # exact degenerate cases
    return np.asarray(p, dtype=float)


def _tangential_means(counts: xr.DataArray, ds: xr.Dataset) -> np.ndarray:
    """Mean counts over loading + plateau at 0, 90, 180, 270 deg: shape (4, afferent)."""
    total = counts.sum("phase").mean("trial").values  # (condition, afferent)
    rows = []
    for angle in TUNING_DIRECTIONS.values():
        match = np.flatnonzero((ds.has_theta_r.values == 1) & np.isclose(ds.theta_r.values, angle))
        if match.size == 0:
            raise ValueError(f"the dataset has no condition at theta_r = {angle:g} deg; use tuning_scenes()")
        rows.append(total[match[0]])
    return np.array(rows)


def tuned_criterion(p, alpha: float = 0.05, correction: str = "none") -> np.ndarray:
    """Tuned if any phase's p-value (rows of ``p``) is below alpha (or alpha / phases, Bonferroni).

    With two independent phases and no correction the false-positive rate
    per afferent is ``1 - (1 - alpha)^2``, 9.75% at alpha = 0.05; Bonferroni
    holds it at or below alpha.

    Examples
    --------
    >>> tuned_criterion(np.array([[0.04, 0.5], [0.5, 0.5]])).tolist()
    [True, False]
    """
    p = np.asarray(p, dtype=float)
    level = alpha / p.shape[0] if correction == "bonferroni" else alpha
    return p.min(axis=0) < level


def direction_tuning(ds: xr.Dataset, *, alpha: float = 0.05, correction: str = "none") -> xr.Dataset:
    """Per-afferent tuning statistics of a `tuning_scenes` dataset.

    Returns
    -------
    xarray.Dataset
        On ``afferent`` (with the dataset's afferent coordinates):
        ``p_loading``, ``p_plateau`` (ANOVA p-values), ``tuned`` and
        ``responsive`` (0/1), ``dsi`` (eq. 7) and ``preferred_deg``.
    """
    check_dataset(ds)
    if not 0 < check_real(alpha, "alpha") < 1:
        raise ValueError(f"alpha must be in (0, 1), got {float(alpha)!r}")
    if correction not in ("none", "bonferroni"):
        raise ValueError(f"correction={correction!r} is not allowed; allowed: none, bonferroni")
    if ds.sizes["trial"] < 2 or ds.sizes["condition"] < 2:
        raise ValueError(f"a tuning test needs >= 2 conditions and >= 2 trials each; got "
                         f"{ds.sizes['condition']} and {ds.sizes['trial']}")
    counts = phase_counts(ds)
    p = np.stack([_anova_p(counts.sel(phase=ph).values) for ph in _PHASES])
    responsive = counts.sum(("phase", "condition", "trial")).values > 0
    r = _tangential_means(counts, ds)
    vx, vy = r[0] - r[2], r[1] - r[3]
    has_preferred = np.hypot(vx, vy) > 1e-9 * (1.0 + r.sum(axis=0))
    preferred = np.where(has_preferred, np.rad2deg(np.arctan2(vy, vx)) % 360.0, 0.0)
    out = xr.Dataset(
        {"p_loading": ("afferent", p[0]), "p_plateau": ("afferent", p[1]),
         "tuned": ("afferent", (tuned_criterion(p, alpha, correction) & responsive).astype(np.int8)),
         "responsive": ("afferent", responsive.astype(np.int8)),
         "dsi": ("afferent", np.asarray(direction_index(r[0], r[1], r[2], r[3]), dtype=float)),
         "preferred_deg": ("afferent", preferred), "has_preferred": ("afferent", has_preferred.astype(np.int8))},
        coords=ds.afferent.coords, attrs={"alpha": alpha, "correction": correction, "trials": ds.sizes["trial"]})
    for name, unit in (("p_loading", "1"), ("p_plateau", "1"), ("tuned", "1"), ("responsive", "1"), ("dsi", "1"),
                       ("preferred_deg", "deg")):
        out[name].attrs["units"] = unit
    return out


def tuning_summary(tuning: xr.Dataset) -> dict:
    """Tuned fraction (overall, per type, and over the recorded types) and DSI mean and SD per type.

    Fractions and DSIs are over responsive afferents.  ``"recorded"`` pools
    the types Birznieks et al. 2001 recorded into their 86% (SA-I, SA-II,
    FA-I; no FA-II), the like-for-like comparison.  A type absent from the
    data (or with no responsive afferent) is reported as ``"absent"``.
    """
    check_dataset(tuning, "tuning")
    missing = [v for v in ("responsive", "tuned", "dsi", "afferent_type") if v not in tuning.variables]
    if missing:
        raise ValueError(f"tuning must be a direction_tuning result; it has no {missing[0]!r}")
    resp = tuning.responsive.values == 1
    types = tuning.afferent_type.values
    fractions, dsi, counts = {}, {}, {}
    for kind in afferent_type_codes():
        sel = resp & (types == kind)
        counts[kind] = int(sel.sum())
        if not sel.any():
            fractions[kind] = dsi[kind] = "absent"
            continue
        fractions[kind] = float(tuning.tuned.values[sel].mean())
        values = tuning.dsi.values[sel]
        dsi[kind] = {"mean": float(values.mean()), "sd": float(values.std(ddof=1)) if values.size > 1 else 0.0}
    fractions["all"] = float(tuning.tuned.values[resp].mean()) if resp.any() else "absent"
    recorded = resp & np.isin(types, RECORDED_TYPES)
    fractions["recorded"] = float(tuning.tuned.values[recorded].mean()) if recorded.any() else "absent"
    return {"tuned_fraction": fractions, "dsi": dsi, "n_responsive": counts}
