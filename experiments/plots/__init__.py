"""Figures: each function takes data and returns a `matplotlib.figure.Figure`; the CLI saves them.

- `common`: datasets (raster, PSTH, polar, forces), tuning, decoding, accuracy and scaling;
- `first_look`: the ramp-and-hold a physiologist looks at first;
- `hand`: spike counts on the hand map;
- `physiology`: the scorecard's figures;
- `neurostim`: stimulation pulses beside the forces that made them;
- `texture`: spatial event plots of scanned surfaces.
"""

from ddmm.utils.lazy import lazy_exports

_WHERE = {
    "common": ("TYPE_COLOURS", "plot_forces", "plot_polar_counts", "plot_psth", "plot_raster"),
    "first_look": ("plot_ramp_and_hold",),
    "hand": ("plot_hand",),
    "physiology": ("physiology_figures",),
    "neurostim": ("plot_stimulation",),
    "texture": ("plot_spatial_events",),
}
__all__, __getattr__, __dir__ = lazy_exports(__name__, _WHERE)
