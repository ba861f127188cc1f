"""Stimulation: from afferent populations to safe pulse trains for a nerve interface.

- `electrodes`: electrode tables (projected fields and every pulse limit),
  from CSV, TOML or Python;
- `rules`: encoding rules by name (biomimetic, linear-amplitude, linear-frequency);
- `pulses`: the pulse generator, safe by construction, causal and stateful;
- `encode`: pulses of a simulated run, their Dataset, `check_pulses`, files;
- `stream`: the same rules fed by the streaming encoder, in closed loop.
"""

from ddmm.utils.lazy import lazy_exports

_WHERE = {
    "electrodes": ("Electrode", "ElectrodeTable", "read_electrodes"),
    "rules": ("Biomimetic", "LinearAmplitude", "LinearFrequency", "RULES", "get_rule"),
    "pulses": ("PulseKernel", "field_weights"),
    "encode": ("stimulation_pulses", "check_pulses", "save_pulses", "load_pulses"),
    "stream": ("StimulationEncoder", "PulseEvents"),
}
__all__, __getattr__, __dir__ = lazy_exports(__name__, _WHERE)
