"""Single-afferent response measures: spiking frequency (SF) and PRSI/DSI (eqs 7, 19)."""

from __future__ import annotations

import numpy as np

from ddmm.utils.validation import as_finite_array, as_float_array, check_count, check_positive, shown

__all__ = ["CONTACT_THRESHOLD", "SF_DEFINITIONS", "active_mask", "spiking_frequency", "direction_index"]

#: Normal force in newtons above which the finger is "in contact"; SF is
#: averaged over that active period (paper §IV.C, docs/model.md §1.8).
CONTACT_THRESHOLD = 0.05
#: Readings of the paper's SF.  ``contact_mean``: spikes in the active period
#: over its length (the text of paper §IV.C).  ``peak_bin``: the largest count
#: in consecutive ``bin_s`` bins from t = 0 (spikes in the active period
#: only), over ``bin_s``: every value of paper Table III is a multiple of
#: 2.5 pulses/s, which a contact average over ~22 s cannot give and a 0.4 s
#: histogram bin does (docs/model.md, the paper's inconsistencies).
SF_DEFINITIONS = ("contact_mean", "peak_bin")


def active_mask(fz, threshold: float = CONTACT_THRESHOLD) -> np.ndarray:
    """Samples in contact: ``F_Z > threshold`` (newtons).

    Examples
    --------
    >>> active_mask([0.0, 0.1, 2.0]).tolist()
    [False, True, True]
    """
    return as_finite_array(fz, "fz", ndim=1) > threshold


def spiking_frequency(step, n_afferents: int, *, fz, fs: float, substeps: int, afferent=None,
                      threshold: float = CONTACT_THRESHOLD, definition: str = "contact_mean",
                      bin_s: float = 0.4) -> np.ndarray:
    """SF in pulses/s: spikes inside the active period divided by its length (or their peak bin rate).

    Parameters
    ----------
    step : array_like of int
        Step index of each spike.
    n_afferents : int
        Number of afferents.
    fz : array_like, shape (n_samples,)
        Normal force in newtons, at ``fs``.
    fs : float
        Force sample rate in Hz.
    substeps : int
        Integration steps per force sample.
    afferent : array_like of int, optional
        Afferent index of each spike (default: all spikes belong to afferent 0).
    threshold : float
        Contact threshold in newtons.
    definition : {"contact_mean", "peak_bin"}
        The reading of SF (`SF_DEFINITIONS`); default the paper's text.
    bin_s : float
        Bin length in seconds for ``"peak_bin"``.

    Returns
    -------
    sf : ndarray, shape (n_afferents,)
        Pulses per second; 0 when the scene has no active period.

    Examples
    --------
    >>> spiking_frequency([0, 15], 1, fz=[1.0, 1.0], fs=1000.0, substeps=10).tolist()
    [1000.0]
    >>> spiking_frequency([0, 15, 9000], 1, fz=[1.0] * 1000, fs=1000.0, substeps=10,
    ...                   definition="peak_bin", bin_s=0.5).tolist()
    [4.0]
    """
    if definition not in SF_DEFINITIONS:
        raise ValueError(f"definition={definition!r} is not allowed; allowed: {', '.join(SF_DEFINITIONS)}")
    active = active_mask(fz, threshold)
    fs = check_positive(fs, "fs", "Hz")
    substeps = check_count(substeps, "substeps")
    n_afferents = check_count(n_afferents, "n_afferents", minimum=0)
    step = _indices(step, "step")
    afferent = np.zeros_like(step) if afferent is None else _indices(afferent, "afferent", n_afferents)
    if afferent.shape != step.shape:
        raise ValueError(f"afferent must have one entry per spike ({step.size}), got {afferent.size}")
    sample = np.minimum(step // substeps, active.size - 1)
    inside = active[sample]
    if definition == "peak_bin":
        per_bin = max(1, int(round(check_positive(bin_s, "bin_s", "s") * fs)))
        n_bins = -(-active.size // per_bin)
        counts = np.zeros((n_afferents, n_bins))
        np.add.at(counts, (afferent[inside], sample[inside] // per_bin), 1.0)
        return counts.max(axis=1) / (per_bin / fs) if n_bins else np.zeros(n_afferents)
    counts = np.bincount(afferent[inside], minlength=n_afferents).astype(float)
    seconds = active.sum() / fs
    return counts / seconds if seconds > 0 else np.zeros(n_afferents)


def _indices(values, name: str, end: int | None = None) -> np.ndarray:
    """``values`` as a 1-D int64 array of whole numbers >= 0 (and < ``end``); errors name ``name``."""
    arr = as_float_array(values, name, ndim=1)
    bad = ~np.isfinite(arr) | (arr < 0) | (arr != np.floor(arr)) | (arr >= (np.inf if end is None else end))
    if np.any(bad):
        allowed = "whole numbers >= 0" + ("" if end is None else f" and < {end}")
        raise ValueError(f"{name} must hold {allowed}, got {shown(arr[bad][0])} at index {int(np.flatnonzero(bad)[0])}")
    return arr.astype(np.int64)


def direction_index(r0, r90, r180, r270):
    """Directional sensitivity index of eq. 7 (DSI), equal to the PRSI of eq. 19.

    ``sqrt((r0 - r180)^2 + (r90 - r270)^2) / (r0 + r90 + r180 + r270)``; the
    responses may be arrays (one value per afferent).  Where all four are zero
    the index is 0 (no response carries no direction), never NaN.

    Examples
    --------
    >>> float(direction_index(1.0, 3.0, 1.0, 1.0))
    0.333...
    """
    r = [as_finite_array(x, name) for x, name in zip((r0, r90, r180, r270), ("r0", "r90", "r180", "r270"))]
    for x, name in zip(r, ("r0", "r90", "r180", "r270")):
        if np.any(x < 0):
            raise ValueError(f"{name} must be a response >= 0 (a rate or count), got {shown(x[x < 0].flat[0])}")
    total = r[0] + r[1] + r[2] + r[3]
    num = np.hypot(r[0] - r[2], r[1] - r[3])
    with np.errstate(invalid="ignore", divide="ignore"):
        out = np.where(total > 0, num / np.where(total > 0, total, 1.0), 0.0)
    return out[()] if out.ndim == 0 else out
