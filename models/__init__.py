"""Single-afferent physics of the DDMM: NAP geometry, attenuation, currents, neurons, engines.

Names are imported on first use (PEP 562): ``import models`` loads nothing
heavy until a name is touched.
"""

from ._lazy import lazy_exports

_WHERE = {
    "attenuation": ("F_TH", "UNTUNED", "attenuated_force", "attenuation_factor", "shear_magnitude"),
    "currents": ("AFFERENT_TYPES", "CurrentParams", "afferent_current", "filter_force"),
    "engines": ("ENGINES", "METHODS", "NeuronState", "SpikeResult", "integrate", "substeps_for"),
    "metrics": ("CONTACT_THRESHOLD", "direction_index", "spiking_frequency"),
    "nap": ("PROFILES", "boundary_radius", "k_from_selectivity", "selectivity_from_k"),
    "neuron": ("NEURON_PARAMS", "NeuronParams", "resting_state"),
    "pipeline": ("compute_currents", "simulate"),
}
__all__, __getattr__, __dir__ = lazy_exports(__name__, _WHERE)
