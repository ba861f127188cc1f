"""Single-afferent physics of the DDMM: NAP geometry, attenuation, currents, neurons, engines."""

from .attenuation import F_TH, UNTUNED, attenuated_force, attenuation_factor, shear_magnitude
from .currents import AFFERENT_TYPES, CurrentParams, afferent_current, filter_force
from .engines import ENGINES, METHODS, NeuronState, SpikeResult, integrate, substeps_for
from .metrics import CONTACT_THRESHOLD, direction_index, spiking_frequency
from .nap import PROFILES, boundary_radius, k_from_selectivity, selectivity_from_k
from .neuron import NEURON_PARAMS, NeuronParams, resting_state
from .pipeline import compute_currents, simulate

__all__ = [
    "F_TH", "UNTUNED", "attenuated_force", "attenuation_factor", "shear_magnitude",
    "AFFERENT_TYPES", "CurrentParams", "afferent_current", "filter_force",
    "ENGINES", "METHODS", "NeuronState", "SpikeResult", "integrate", "substeps_for",
    "CONTACT_THRESHOLD", "direction_index", "spiking_frequency",
    "PROFILES", "boundary_radius", "k_from_selectivity", "selectivity_from_k",
    "NEURON_PARAMS", "NeuronParams", "resting_state",
    "compute_currents", "simulate",
]
