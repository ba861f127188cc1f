"""Validation protocols: the runs behind the claims of docs/validation.md that the physiology scorecard
(`ddmm.population.analysis.physiology`, ``ddmm physiology``) does not hold itself.

- `accuracy`: what a coarser step or a cheaper method costs against the reference solver (``ddmm accuracy``);
- `decoding`: shear direction decoded from population spikes (``ddmm decode``);
- `array_tasks`: torque and slip decoded from multi-site scenes (``ddmm decode --task torque|slip``);
- `recordings`: noisy recordings at 100 Hz-5 kHz through the conditioning stage
  (``python -m ddmm.experiments.validation.recordings``);
- `everyday`: presses and releases at 0.5-40 N/s and each unit's vibration threshold, on unseen
  seeds (``python -m ddmm.experiments.validation.everyday``);
- `tilt`: tilted loads in 12 directions against the normal load alone, and SA-I's peak rates in fast
  loading (``python -m ddmm.experiments.validation.tilt``).
"""

from ddmm.utils.lazy import lazy_exports

_WHERE = {
    "accuracy": ("run_accuracy", "tolerance_table"),
    "decoding": ("run_decoding", "summarise"),
    "array_tasks": ("run_slip", "run_torque"),
    "recordings": ("run_check",),
    "everyday": ("run_everyday",),
    "tilt": ("run_tilt",),
}
__all__, __getattr__, __dir__ = lazy_exports(__name__, _WHERE)
