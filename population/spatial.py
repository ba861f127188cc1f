"""Receptive fields: how strongly a contact drives each afferent, by distance.

An afferent inside the contact disc gets weight 1.  Outside, the weight
falls as a Gaussian of the distance beyond the disc's edge, with a width
per type, and is exactly 0 beyond ``RF_SUPPORT`` widths (so such afferents
provably stay at rest and are skipped).  Widths follow receptive-field sizes
in human glabrous skin (Johansson & Vallbo 1980): SA-I and FA-I fields are a
few mm across, FA-II (Pacinian) fields cover much of a finger.
"""

from __future__ import annotations

import numpy as np

from models.currents import AFFERENT_TYPES

__all__ = ["RF_SIGMA_MM", "RF_SUPPORT", "receptive_field_weight"]

#: Receptive-field fall-off width (Gaussian sigma) per type, in mm.
RF_SIGMA_MM = {"SAI": 1.0, "RAI": 1.5, "RAII": 8.0, "SAII": 2.2}  # SA-II: ~5x the SA-I field area (row 17)
#: Weights are exactly 0 beyond this many widths outside the contact.
RF_SUPPORT = 3.0


def receptive_field_weight(x_mm, y_mm, afferent_type, contact) -> np.ndarray:
    """Drive weight in [0, 1] of afferents at (x, y) for a contact disc.

    Parameters
    ----------
    x_mm, y_mm : array_like
        Afferent positions in mm.
    afferent_type : array_like of str
        Type of each afferent (selects the width).
    contact : population.scenes.Contact
        Centre and radius of the contact, in mm.

    Examples
    --------
    >>> from population.scenes import Contact
    >>> w = receptive_field_weight([0.0, 2.0, 9.0], [0.0, 0.0, 0.0], ["SAI"] * 3, Contact(0.0, 0.0, 1.0))
    >>> w.round(3).tolist()
    [1.0, 0.607, 0.0]
    """
    x = np.asarray(x_mm, dtype=float)
    y = np.asarray(y_mm, dtype=float)
    types = np.asarray(afferent_type, dtype=object)
    sigma = np.empty(x.shape)
    for kind in AFFERENT_TYPES:
        sigma[types == kind] = RF_SIGMA_MM[kind]
    excess = np.maximum(np.hypot(x - contact.x_mm, y - contact.y_mm) - contact.radius_mm, 0.0)
    weight = np.exp(-0.5 * (excess / sigma) ** 2)
    weight[excess > RF_SUPPORT * sigma] = 0.0
    return weight
