"""The paper's results reproduced: Tables II-IV and Figs 6-8, cell by cell (``ddmm reproduce``).

- `reproduce`: the reproduction scenes, the SF runs and the figures' data (`ReproConfig`);
- `cells`: Tables II-III and Fig. 8 cell by cell under a calibration;
- `calibrations`: the ``paper`` and ``gains-only`` calibrations (their fits live in
  `ddmm.experiments.calibration`);
- `table4`: the pilot's Table IV on a recording.

The published numbers themselves are library data: `ddmm.population.data.published`.
"""

from ddmm.utils.lazy import lazy_exports

_WHERE = {
    "reproduce": ("PROFILES", "ReproConfig", "reproduce_all", "scene_sf"),
    "cells": ("reproduce_cells", "type_cells"),
    "calibrations": ("CALIBRATIONS", "FITTED_CELLS", "GAINS_ONLY", "PAPER_CALIBRATION"),
}
__all__, __getattr__, __dir__ = lazy_exports(__name__, _WHERE)
