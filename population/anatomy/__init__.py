"""Anatomy: where afferents sit on the hand and how far their receptive fields reach.

- `hand_map`: regions of the glabrous skin of a right hand, densities per type;
- `receptive_fields`: how strongly each force site drives each afferent.
"""

from ddmm.utils.lazy import lazy_exports

_WHERE = {
    "hand_map": ("HandRegion", "REGIONS", "get_region", "outline", "region_at", "region_counts", "region_names",
                 "region_table", "sample_in_region"),
    "receptive_fields": ("RF_SIGMA_MM", "RF_SUPPORT", "frame_theta", "local_mixing", "receptive_field_weight",
                         "site_coverage", "site_weights"),
}
__all__, __getattr__, __dir__ = lazy_exports(__name__, _WHERE)
