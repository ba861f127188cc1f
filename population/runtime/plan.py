"""Planning: simulate only the effects a scene calls for, exactly.

`make_plan` inspects the scenes and the population and decides, per
condition, what can be skipped without changing a single spike:

* the NAP/AF stage when no shear ever exceeds F_TH (AF is then 1 under
  ``no_shear="pass"`` and 0 under ``"block"``), or, under ``"smooth"`` and
  for SA-II's stretch and the pressure types' shear-magnitude term, when
  there is no shear at all;
* spatial weighting when the scene has no contact geometry;
* afferent types that were not requested;
* afferents whose current is provably identically zero: they stay at
  their resting fixed point and never spike
  (`ddmm.models.drive_table.DriveTable.quiet` says when, and why);
* noise generation for afferents without noise;
* recording variables nobody asked for.

Noiseless afferents with identical parameters share one integration, and
their trials collapse to one; an afferent with receptor noise, a trial
excitability or a spread start phase is simulated on every trial
(`ddmm.models.drive_table.DriveTable.varies_by_trial`).  The plan gathers
the scene's facts; the rules of each type's drive are its `DriveTable`'s.
With ``enabled=False`` nothing is skipped (the brute-force reference that
tests hold the plan to).
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from ddmm.models.afferent_types import afferent_type_codes, normalize_type, type_mask
from ddmm.models.attenuation import F_TH, UNTUNED
from ddmm.models.drive_table import DriveTable
from ddmm.population.anatomy.receptive_fields import population_weight, site_coverage
from ddmm.population.sampling import Population
from ddmm.population.stimuli.scenes import as_scenes
from ddmm.utils.deprecation import renamed_keyword, warn_renamed
from ddmm.utils.validation import check_choice, check_count, check_instance

__all__ = ["RECORD_CHOICES", "ConditionPlan", "Plan", "af_threshold", "make_plan"]

#: Optional dataset variables; spike counts are always recorded.
RECORD_CHOICES = ("spikes", "forces")
_BYTES_PER_ELEMENT = 8 * 5  # F_A, current, noise, AF and a temporary, float64


@dataclass(frozen=True, eq=False)
class ConditionPlan:
    """What one condition (scene) needs.

    Attributes
    ----------
    name : str
        Condition name.
    n_samples : int
        Force samples.
    computes_af : bool
        Whether AF is computed (False: AF is constant).
    af_constant : float
        AF of tuned afferents when the stage is skipped (1 pass, 0 block).
    weights : ndarray or None
        Receptive-field weight per selected afferent, None without contact.
    units : ndarray of int
        Selected-afferent index of each deterministic integration unit.
    member_unit : ndarray of int
        Unit of each selected afferent, -1 for noisy afferents (simulated
        per trial) and -2 for quiet ones (provably silent, not simulated).
    """

    name: str
    n_samples: int
    computes_af: bool
    af_constant: float
    weights: np.ndarray | None
    units: np.ndarray
    member_unit: np.ndarray

    @property
    def af_stage(self) -> bool:
        """Deprecated name of `computes_af` ("stage" names a scene's interval)."""
        warn_renamed("ConditionPlan.af_stage", "computes_af")
        return self.computes_af

    @property
    def noisy(self) -> np.ndarray:
        """Selected-afferent indices simulated once per trial."""
        return np.flatnonzero(self.member_unit == -1)

    @property
    def n_quiet(self) -> int:
        """Afferents skipped because their current is identically zero."""
        return int(np.sum(self.member_unit == -2))


@dataclass(frozen=True, eq=False)
class Plan:
    """The whole run: which afferents, which stages, how it is chunked.

    Attributes
    ----------
    selected : ndarray of int
        Population indices that are simulated (requested types).
    keep : ndarray of int
        Positions within ``selected`` that go into the dataset.
    trials : int
        Trials per condition.
    conditions : tuple of ConditionPlan
    chunk_size : int
        Afferents per chunk.
    time_chunk : int
        Samples per time chunk.
    record : tuple of str
        Optional variables recorded.
    enabled : bool
        False for the brute-force reference run.
    """

    selected: np.ndarray
    keep: np.ndarray
    trials: int
    conditions: tuple
    chunk_size: int
    time_chunk: int
    record: tuple
    enabled: bool

    def work(self) -> int:
        """Afferent-samples to integrate (progress-bar total)."""
        total = 0
        for cond in self.conditions:
            total += (cond.units.size + cond.noisy.size * self.trials) * cond.n_samples
        return total

    def describe(self, population, scenes) -> str:
        """A printable summary of what is simulated and what is skipped."""
        n_types = {t: int(np.sum(population.afferent_type[self.selected] == t)) for t in afferent_type_codes()}
        lines = [f"population {population.name!r}: {len(population)} afferents; simulating "
                 + ", ".join(f"{n} {t}" for t, n in n_types.items() if n)
                 + f"; {self.trials} trial(s); planning {'on' if self.enabled else 'off'}"]
        for cond, scene in zip(self.conditions, scenes):
            lines.append(f"- condition {cond.name!r}: {scene.duration:g} s at {scene.fs:g} Hz, "
                         f"max shear {scene.max_shear():.3g} N")
            lines.append(f"    AF stage: {_af_note(cond)}")
            lines.append("    spatial weighting: " + ("skipped (no contact geometry)" if cond.weights is None
                                                       else f"on, {int(np.sum(cond.weights > 0))} afferents in range"))
            noisy = cond.noisy.size
            lines.append(f"    noise: {'on for ' + str(noisy) + ' afferents' if noisy else 'off (skipped)'}")
            lines.append(f"    quiet (identically zero current, skipped): {cond.n_quiet}" + _by_region(population, self, cond))
            lines.append(f"    integrations: {cond.units.size} deterministic unit(s) for "
                         f"{int(np.sum(cond.member_unit >= 0))} noiseless afferents"
                         + (f" (once for all {self.trials} trials)" if self.trials > 1 else "")
                         + f", {noisy} x {self.trials} noisy")
        mb = self.chunk_size * self.time_chunk * _BYTES_PER_ELEMENT / 1e6
        lines.append(f"chunks: {self.chunk_size} afferents x {self.time_chunk} samples (~{mb:.0f} MB working set)")
        lines.append("recording: spike_count" + "".join(f", {r}" for r in self.record))
        return "\n".join(lines)


def _by_region(population, plan, cond) -> str:
    """`` (by region: D4d 120, ...)`` when the population carries regions."""
    regions = population.region[plan.selected[cond.member_unit == -2]]
    regions = regions[regions != ""]
    if regions.size == 0:
        return ""
    names, counts = np.unique(regions, return_counts=True)
    return " (by region: " + ", ".join(f"{n} {c}" for n, c in zip(names, counts)) + ")"


def _af_note(cond: ConditionPlan) -> str:
    if cond.computes_af:
        return "computed"
    return f"skipped (no shear that changes AF; AF = {cond.af_constant:g})"


def _unit_keys(pop, sel, table, tuned, scale, local):
    """Rows that identify afferents whose currents are bit-identical (``local``: also their position)."""
    type_code = table.type_index.astype(float)
    nap_code = np.where(tuned, np.unique(pop.nap, return_inverse=True)[1][sel], -1).astype(float)
    theta = np.where(tuned, pop.theta_t[sel], 0.0)
    k = np.where(tuned, pop.k[sel], 0.0)
    columns = [type_code, nap_code, theta, k, scale, pop.sensitivity[sel]]  # sensitivity: gain and dead zone
    if np.any(table.bias_cv > 0.0):  # each unit's own tonic current (``TypeParams.bias_cv``)
        columns.append(table.bias_multiplier(pop.afferent_id[sel]))
    if local:  # each afferent feels its own force, a function of its type and position
        columns += [pop.x_mm[sel], pop.y_mm[sel]]
    return np.column_stack(columns)


def af_threshold(no_shear: str) -> float:
    """Shear (N) above which the AF stage matters: F_TH for eq. 17's readings, 0 for "smooth"."""
    return 0.0 if no_shear == "smooth" else F_TH


def _quiet(pop, sel, table, scene, scale, computes_af, af_constant):
    """Afferents whose noise-free current is identically zero (they never leave rest): the scene's facts,
    judged by the drive's rules (`DriveTable.quiet`)."""
    return table.quiet(scale, pop.noise_sigma[sel], pop.nap[sel] != UNTUNED, max_shear=scene.max_shear(),
                       pressed=bool(np.any(scene.fz > 0.0)), loaded=bool(np.any(scene.fz != 0.0)),
                       computes_af=computes_af, af_constant=af_constant)


def _condition_plan(pop, sel, table, scene, no_shear, enabled) -> ConditionPlan:
    n, local = sel.size, scene.sites is not None
    # A multi-site scene's local shear is a weighted sum of the sites' and can cross F_TH where none does.
    computes_af = scene.max_shear() > (0.0 if local else af_threshold(no_shear)) or not enabled
    af_constant = 0.0 if no_shear == "block" else 1.0
    weights = None
    if local:
        weights = site_coverage(pop, scene.sites)[sel]
    elif scene.contact is not None or not enabled:
        weights = (np.ones(n) if scene.contact is None else
                   population_weight(pop, scene.contact)[sel])
    scale = pop.gain[sel] * (1.0 if weights is None else weights)
    noisy = table.varies_by_trial(pop.noise_sigma[sel], pop.noise_cv[sel])
    if not enabled:
        return ConditionPlan(scene.name, scene.n_samples, True, af_constant, weights,
                             np.empty(0, np.int64), np.full(n, -1, np.int64))
    quiet = _quiet(pop, sel, table, scene, scale, computes_af, af_constant)
    deterministic = np.flatnonzero(~noisy & ~quiet)
    member = np.where(quiet, -2, -1).astype(np.int64)
    units = np.empty(0, np.int64)
    if deterministic.size:
        kept = table.take(deterministic)
        tuned = kept.reads_af(pop.nap[sel[deterministic]] != UNTUNED, scene.max_shear(), computes_af)
        keys = _unit_keys(pop, sel[deterministic], kept, tuned, scale[deterministic], local)
        _, first, inverse = np.unique(keys, axis=0, return_index=True, return_inverse=True)
        order = np.argsort(first)  # units in population order, for readable plans
        rank = np.empty_like(order)
        rank[order] = np.arange(order.size)
        units = deterministic[first[order]]
        member[deterministic] = rank[inverse.ravel()]
    return ConditionPlan(scene.name, scene.n_samples, computes_af, af_constant, weights, units, member)


@renamed_keyword("types", "afferent_types")
def make_plan(population, scenes, *, afferent_types=None, trials: int = 1, record=RECORD_CHOICES,
              no_shear: str = "smooth", chunk_size: int = 4096, time_chunk: int = 2000,
              enabled: bool = True) -> Plan:
    """Decide what to simulate (see the module docstring).

    Parameters
    ----------
    population : Population
    scenes : sequence of Scene
    afferent_types : sequence of str, optional
        Afferent types to simulate (default: all present).
    trials : int
        Trials per condition.
    record : sequence of str
        Optional variables to record (``"spikes"``, ``"forces"``).
    no_shear : {"pass", "block", "smooth"}
        Reading of eq. 17.
    chunk_size, time_chunk : int
        Afferents and samples per chunk.
    enabled : bool
        False: skip nothing (brute-force reference).

    Returns
    -------
    Plan
    """
    check_instance(population, "population", Population, "a Population (from sample_population or make_population)")
    scenes = as_scenes(scenes)
    for name, value in (("trials", trials), ("chunk_size", chunk_size), ("time_chunk", time_chunk)):
        check_count(value, name)
    named = (("afferent_types", () if afferent_types is None else afferent_types, ("SAI",)),
             ("record", record, RECORD_CHOICES))
    for name, value, example in named:
        if isinstance(value, str) or not hasattr(value, "__iter__"):
            raise TypeError(f"{name} must be a sequence of names, e.g. {example}, got {type(value).__name__}")
    requested = (tuple(afferent_type_codes()) if afferent_types is None
                 else tuple(normalize_type(t, "afferent_types") for t in afferent_types))
    for r in record:
        check_choice(r, "record", RECORD_CHOICES)
    wanted = type_mask(population.afferent_type, lambda kind: kind.code in requested)
    selected = np.arange(len(population)) if not enabled else np.flatnonzero(wanted)
    keep = np.flatnonzero(wanted[selected])
    table = DriveTable.of(population.afferent_type[selected], population.current)  # the drive's rules, once
    conds = tuple(_condition_plan(population, selected, table, s, no_shear, enabled) for s in scenes)
    return Plan(selected, keep, trials, conds, chunk_size, time_chunk, tuple(record), enabled)
