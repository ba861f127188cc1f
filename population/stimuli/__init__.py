"""Stimuli: the forces a population feels.

- `scenes`: three-axis fingertip force on a uniform time base (`Scene`), the
  paper's protocols, CSV recordings, contacts and force sites;
- `site_scenes`: scenes only force fields can express (torsion, slip, grasp).
"""

from ddmm.models._lazy import lazy_exports

_WHERE = {
    "scenes": ("DEFAULT_FS", "Contact", "Scene", "Sites", "Stage", "birznieks", "from_csv", "press_push_lift",
               "rotating_shear", "taxel_radius"),
    "site_scenes": ("contact_grid", "grasp", "incipient_slip", "torsion"),
}
__all__, __getattr__, __dir__ = lazy_exports(__name__, _WHERE)
