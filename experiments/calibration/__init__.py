"""Fits of the model's free constants (``ddmm calibrate``), each with its objective and constraints.

- `presets`: the physiological presets fitted to human tuning data under rate
  constraints (``ddmm calibrate``);
- `paper`: the paper's unpublished constants fitted to its Tables II-III, type by
  type (``ddmm calibrate --target paper``; the result is `ddmm.experiments.paper.calibrations`);
- `gains`: the current gains fitted to Table III's CMM column, and the scans behind
  the derivative cut-off (``python -m ddmm.experiments.calibration.gains``).
"""

from ddmm.utils.lazy import lazy_exports

_WHERE = {
    "presets": ("calibrate", "spec_to_toml"),
    "paper": ("calibrate_paper",),
    "gains": ("fit_gains",),
}
__all__, __getattr__, __dir__ = lazy_exports(__name__, _WHERE)
