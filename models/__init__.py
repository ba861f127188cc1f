"""Single-afferent physics of the DDMM: NAP geometry, attenuation, currents, neurons, engines.

Names are imported on first use (PEP 562): ``import models`` loads nothing
heavy until a name is touched.
"""

from importlib import import_module

_WHERE = {
    "attenuation": ("F_TH", "UNTUNED", "attenuated_force", "attenuation_factor", "shear_magnitude"),
    "currents": ("AFFERENT_TYPES", "CurrentParams", "afferent_current", "filter_force"),
    "engines": ("ENGINES", "METHODS", "NeuronState", "SpikeResult", "integrate", "substeps_for"),
    "metrics": ("CONTACT_THRESHOLD", "direction_index", "spiking_frequency"),
    "nap": ("PROFILES", "boundary_radius", "k_from_selectivity", "selectivity_from_k"),
    "neuron": ("NEURON_PARAMS", "NeuronParams", "resting_state"),
    "pipeline": ("compute_currents", "simulate"),
}
_MODULE_OF = {name: module for module, names in _WHERE.items() for name in names}

__all__ = sorted(_MODULE_OF)


def __getattr__(name):
    if name not in _MODULE_OF:
        raise AttributeError(f"module 'models' has no attribute {name!r}")
    value = getattr(import_module(f".{_MODULE_OF[name]}", __name__), name)
    globals()[name] = value
    return value


def __dir__():
    return sorted(set(globals()) | set(__all__))
