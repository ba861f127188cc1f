"""Stimuli: the forces a population feels.

- `scenes`: three-axis fingertip force on a uniform time base (`Scene`), the
  paper's protocols, contacts and force sites;
- `recordings`: scenes from recorded force files (`from_csv`: columns, units,
  sign, time base, negative force);
- `conditioning`: the stage between a recording and the model (resampling,
  noise gate, contact and shear deadband), offline and streaming;
- `site_scenes`: scenes only force fields can express (torsion, slip, grasp);
- `contact`: the skin's contact mechanics (rigid pins on an elastic half-space: loads, stress at
  depth, stick and slip);
- `indentation`: indentation stimuli (probes, bars, pin arrays) as scenes through the mechanics, with
  `waveforms` their depths over time (ramps, vibration, noise, taps) and `indentation_spec` their settings
  tables (``ddmm simulate --indent``);
- `transduction`: each type's front end from the stress at its receptor depth to its drive (gain and
  lead-lag; fitted to TouchSim's responses);
- `surfaces`: textured surfaces (gratings, dot patterns, embossed letters, bitmaps) scanned across the
  skin, as indentation scenes.
"""

from ddmm.utils.lazy import lazy_exports

_WHERE = {
    "scenes": ("DEFAULT_FS", "Contact", "Scene", "Sites", "Stage", "birznieks", "press_push_lift",
               "rotating_shear", "taxel_radius"),
    "recordings": ("from_csv", "resample_unconditioned", "RecordingBandWarning", "UNITS"),
    "conditioning": ("Conditioning", "Conditioner", "condition_forces"),
    "site_scenes": ("contact_grid", "digit_tip_sites", "grasp", "incipient_slip", "torsion"),
    "contact": ("SKIN_MODELS", "SkinMechanics", "get_skin_mechanics", "normal_stress", "solve_pin_loads",
                "stress_kernel", "tangential_loads"),
    "indentation": ("Pins", "bar_pins", "circle_pins", "indent", "pin_array", "probe"),
    "waveforms": ("band_noise", "impulse", "ramp_hold", "sinusoid"),
    "indentation_spec": ("indentation_from_dict",),
    "transduction": ("TRANSDUCTIONS", "Transduction", "get_transduction"),
    "surfaces": ("Surface", "dot_pattern", "from_bitmap", "grating", "letters"),
    "scanning": ("min_scan_fs", "scan", "scan_depths"),
}
__all__, __getattr__, __dir__ = lazy_exports(__name__, _WHERE)
