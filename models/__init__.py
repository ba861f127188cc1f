"""Single-afferent physics of the DDMM: NAP geometry, attenuation, currents, neurons, engines.

Modules, in the order a force becomes spikes:

- `nap`: neural attenuation profiles (Table I) and their boundary radius;
- `attenuation`: the attenuation factor AF of the shear direction (eqs 9-17);
- `afferent_types`: the registry of afferent types (`AfferentType`): codes, labels, spellings
  and the mechanisms of each type's drive;
- `currents`: type-specific filtering of the attenuated force into currents, with
  its parameters (`current_params`), filters (`current_filters`) and keyed
  per-unit and per-trial draws (`variability`);
- `drive_table`: what each afferent's drive can do given its type and parameters
  (`DriveTable`): which afferents a run may skip as silent, share or simulate per trial;
- `neuron`: Izhikevich parameters per type (eqs 4-6);
- `engines`: the registered engines that integrate the neurons (Brian2, direct);
- `fused`: the whole pipeline for a block of afferents, as the engines consume it (the one
  production path);
- `pipeline`: the one-NAP convenience on it (`compute_currents`, `simulate_afferents`);
- `reference_pipeline`: the reference oracle, the same currents stage by stage in numpy
  (`reference_currents`, `afferent_current`), which the tests hold the production path to;
- `metrics`, `rng`, `reference_solver`: spike-train metrics, counter-based
  random numbers, and a fine-step RK4 reference for accuracy checks.

Names are imported on first use (PEP 562): ``import ddmm.models`` loads
nothing heavy until a name is touched.
"""

from ddmm.utils.lazy import lazy_exports

_WHERE = {
    "attenuation": ("F_TH", "UNTUNED", "attenuation_factor", "shear_magnitude"),
    "afferent_types": ("AFFERENT_TYPES", "normalize_type", "type_label"),
    "current_params": ("CurrentParams",),
    "type_params": ("TypeParams",),
    "drive_table": ("DriveTable",),
    "engines": ("ENGINES", "METHODS", "Engine", "NeuronState", "SpikeResult", "get_engine", "integrate",
                "substeps_for"),
    "metrics": ("CONTACT_THRESHOLD", "direction_index", "spiking_frequency"),
    "nap": ("PROFILES", "boundary_radius", "k_from_selectivity", "selectivity_from_k"),
    "neuron": ("NEURON_PARAMS", "NeuronParams", "resting_state"),
    "pipeline": ("compute_currents", "simulate_afferents"),
    "reference_pipeline": ("afferent_current", "attenuated_force", "filter_force", "reference_currents"),
}
__all__, __getattr__, __dir__ = lazy_exports(__name__, _WHERE)
