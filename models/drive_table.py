"""What each afferent's drive can do, given its type and parameters: one `DriveTable` of per-afferent rules.

The current stage's rules that decide which afferents a run may skip or
share (`ddmm.population.runtime.plan`) read only a type's registry entry
(`ddmm.models.afferent_types.AfferentType`) and its resolved parameters
(`ddmm.models.current_params.CurrentParams.for_type`).  `DriveTable.of`
evaluates them once per registered type, one comparison per type, and
spreads them over the afferents; its methods then combine them with the
facts of a scene (its largest shear, whether it presses) that the caller
gathers.
"""

from __future__ import annotations

from dataclasses import dataclass, fields
from typing import NamedTuple

import numpy as np

from ddmm.models import variability
from ddmm.models.afferent_types import afferent_type_codes, afferent_type_info
from ddmm.models.current_params import CurrentParams
from ddmm.utils.validation import check_instance

__all__ = ["DriveTable"]


class _Rules(NamedTuple):
    """One type's row of rules."""

    stretch: bool = False
    shallow: bool = False
    shear_gained: bool = False
    biased: bool = False
    normal_driven: bool = False
    excitable: bool = False
    phase_spread: bool = False
    bias_cv: float = 0.0


def _rules(code: str, params) -> _Rules:
    kind, st = afferent_type_info(code), params.for_type(code)
    pressure = not kind.stretch_drive  # its drive is F_A
    return _Rules(kind.stretch_drive, pressure and st.depth < 1.0, pressure and st.shear > 0.0, st.bias != 0.0,
                  kind.stretch_drive and st.normal > 0.0, params.excite_cv(code) > 0.0,
                  kind.phase_spread and st.phase > 0.0, float(st.bias_cv))


@dataclass(frozen=True, eq=False)
class DriveTable:
    """The drive's rules per afferent, from its type's `AfferentType` and `TypeParams` (read-only arrays).

    Attributes
    ----------
    type_index : ndarray of int
        Position of each afferent's type in `afferent_type_codes`.
    stretch : ndarray of bool
        Its drive is the signed stretch drive (`AfferentType.stretch_drive`); else F_A (a pressure type).
    shallow : ndarray of bool
        A pressure type keeping part of its normal drive at AF = 0 (`TypeParams.depth` < 1).
    shear_gained : ndarray of bool
        A pressure type whose drive adds a shear-magnitude term (`TypeParams.shear` > 0).
    biased : ndarray of bool
        A tonic current (`TypeParams.bias` != 0).
    normal_driven : ndarray of bool
        A stretch type whose drive reads the normal force (`TypeParams.normal` > 0).
    excitable : ndarray of bool
        A trial-to-trial excitability (`TypeParams.excite_cv` > 0).
    phase_spread : ndarray of bool
        Start phases spread per (trial, afferent) (`AfferentType.phase_spread` and `TypeParams.phase` > 0).
    bias_cv : ndarray of float
        Spread of the tonic current across units (`TypeParams.bias_cv`; 0: none).

    Examples
    --------
    >>> from ddmm.models.current_params import CurrentParams
    >>> table = DriveTable.of(np.array(["SAI", "SAII"]), CurrentParams().with_type("SAI", shear=0.5))
    >>> table.stretch.tolist(), table.shear_gained.tolist(), table.type_index.tolist()
    ([False, True], [True, False], [0, 3])
    """

    type_index: np.ndarray
    stretch: np.ndarray
    shallow: np.ndarray
    shear_gained: np.ndarray
    biased: np.ndarray
    normal_driven: np.ndarray
    excitable: np.ndarray
    phase_spread: np.ndarray
    bias_cv: np.ndarray

    def __post_init__(self):
        for f in fields(self):  # read-only views: the caller's arrays stay as they were
            view = np.asarray(getattr(self, f.name)).view()
            view.flags.writeable = False
            object.__setattr__(self, f.name, view)

    @classmethod
    def of(cls, afferent_type, params) -> DriveTable:
        """The table of afferents of types ``afferent_type`` (registered codes) under ``params`` (a `CurrentParams`).

        Raises
        ------
        TypeError
            When ``params`` is not a `CurrentParams`.
        ValueError
            When a type is not registered (the message names it and the registered codes).
        """
        check_instance(params, "params", CurrentParams, "a CurrentParams")
        afferent_type = np.asarray(afferent_type)
        codes = afferent_type_codes()
        index = np.full(afferent_type.shape, -1, dtype=np.int64)
        for i, code in enumerate(codes):  # one comparison a type (np.isin would sort the strings)
            index[afferent_type == code] = i
        if np.any(index < 0):
            raise ValueError(f"afferent_type={str(afferent_type[index < 0][0])!r} is not a registered type; "
                             f"allowed: {', '.join(codes)}")
        rows = [_rules(code, params) for code in codes]
        columns = [np.array(column)[index] for column in zip(*rows)]
        return cls(index, *columns)

    def take(self, index) -> DriveTable:
        """The table of the afferents at ``index``."""
        return type(self)(*(getattr(self, f.name)[index] for f in fields(self)))

    def bias_multiplier(self, afferent_id) -> np.ndarray:
        """Each unit's multiplier of its tonic current (`ddmm.models.variability.bias_multiplier` at its type's
        `TypeParams.bias_cv`, keyed by ``afferent_id``, one per afferent of the table; 1 without a spread).

        Examples
        --------
        >>> from ddmm.models.current_params import CurrentParams
        >>> table = DriveTable.of(np.array(["SAI", "SAII"]), CurrentParams().with_type("SAII", bias_cv=0.3))
        >>> m = table.bias_multiplier([7, 7])
        >>> float(m[0]), bool(m[1] == variability.bias_multiplier(0.3, [7])[0])
        (1.0, True)
        """
        out = np.ones(self.bias_cv.shape)
        for cv in np.unique(self.bias_cv[self.bias_cv > 0.0]):
            out = np.where(self.bias_cv == cv, variability.bias_multiplier(float(cv), afferent_id), out)
        return out

    def varies_by_trial(self, noise_sigma, noise_cv) -> np.ndarray:
        """Whose current or start differs from trial to trial, so no integration can be shared.

        Receptor noise (additive ``noise_sigma``, drive-proportional
        ``noise_cv``, per afferent), a trial excitability
        (`TypeParams.excite_cv`) or a keyed start phase per (trial, afferent)
        (`TypeParams.phase` of a phase-spread type).
        """
        return (np.asarray(noise_sigma) > 0) | (np.asarray(noise_cv) > 0) | self.excitable | self.phase_spread

    def reads_af(self, tuned, max_shear: float, computes_af: bool) -> np.ndarray:
        """Whose current depends on its NAP's AF, given which afferents are ``tuned`` (a NAP, not untuned).

        A drive that takes the shear (a stretch type's, or a pressure
        type's shear-magnitude term, `TypeParams.shear`) reads AF wherever
        the scene has shear (``max_shear`` > 0, in N); F_A alone reads it
        only when the AF stage runs (``computes_af``), otherwise AF is one
        constant for every NAP.
        """
        return np.asarray(tuned) & np.where(self.stretch | self.shear_gained, max_shear > 0.0, computes_af)

    def quiet(self, scale, noise_sigma, tuned, *, max_shear: float, pressed: bool, loaded: bool,
              computes_af: bool, af_constant: float) -> np.ndarray:
        """Whose noise-free current is provably identically zero: they stay at their resting fixed point.

        A pressure type's drive is F_A plus its shear-magnitude term
        (`TypeParams.shear`).  It is zero when the afferent feels no force
        (``scale``, its receptive-field weight times gain, is 0), or when no
        shear-magnitude term acts (``shear`` 0, or ``max_shear`` 0) and
        either nothing presses (no normal force > 0, ``pressed`` False; the
        stage rectifies F_A) or AF is 0 throughout: a ``tuned`` afferent
        whose AF stage is skipped (not ``computes_af``) with
        ``af_constant`` 0 (``no_shear="block"``), at the paper's full depth
        (a `TypeParams.depth` < 1 keeps ``1 - depth`` of F_Z at AF = 0).
        A stretch type's drive is the attenuated shear plus ``normal F_Z``
        (`TypeParams.normal`): zero without force, or with no shear at all
        (``max_shear`` 0) and no normal force it reads (``loaded``: some
        normal force != 0).  A tonic current (`TypeParams.bias` != 0) or
        additive receptor noise (``noise_sigma`` > 0) lifts either off zero.
        Drive-proportional noise (``noise_cv``) is zero with the drive, and
        the trial excitability (`TypeParams.excite_cv`) is a factor on the
        current: neither stops an afferent from being quiet.

        Examples
        --------
        >>> from ddmm.models.current_params import CurrentParams
        >>> table = DriveTable.of(np.array(["SAI", "SAII"]), CurrentParams())
        >>> table.quiet(np.ones(2), np.zeros(2), np.ones(2, bool), max_shear=0.0, pressed=True, loaded=True,
        ...             computes_af=False, af_constant=1.0).tolist()
        [False, True]
        """
        scale, tuned = np.asarray(scale), np.asarray(tuned)
        blocked = tuned & (not computes_af) & (af_constant == 0.0) & ~self.shallow
        sheared = self.shear_gained & (max_shear > 0.0)  # the shear-magnitude term drives them
        pressure_quiet = (scale == 0.0) | ((blocked | (not pressed)) & ~sheared)
        pressing = self.normal_driven & bool(loaded)
        stretch_quiet = (scale == 0.0) | ((max_shear == 0.0) & ~pressing)
        return np.where(self.stretch, stretch_quiet, pressure_quiet) & ~self.biased & (np.asarray(noise_sigma) == 0.0)
