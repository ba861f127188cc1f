"""Populations of afferents: specs, sampling, scenes, simulation, datasets."""

from .arrays import from_array, from_long_csv, save_array
from .dataset import binned_counts, binned_rates, describe_dataset, load_dataset, psth, save_dataset
from .plan import make_plan
from .sampling import Population, make_population, sample_population
from .scenes import Contact, Scene, Sites, Stage, birznieks, from_csv, press_push_lift, rotating_shear, taxel_radius
from .simulate import plan_run, simulate
from .spec import PopulationSpec, load_spec, spec_from_dict

__all__ = [
    "from_array", "from_long_csv", "save_array",
    "binned_counts", "binned_rates", "describe_dataset", "load_dataset", "psth", "save_dataset",
    "make_plan", "Population", "make_population", "sample_population",
    "Contact", "Scene", "Sites", "Stage", "birznieks", "from_csv", "press_push_lift", "rotating_shear", "taxel_radius",
    "plan_run", "simulate", "PopulationSpec", "load_spec", "spec_from_dict",
]
