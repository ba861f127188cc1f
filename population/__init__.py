"""Populations of afferents: specs, sampling, scenes, simulation, datasets.

Names are imported on first use (PEP 562), so ``import population`` costs
only what a caller touches: no xarray before a dataset is built, no scipy
before a filter is designed.
"""

from models._lazy import lazy_exports

_WHERE = {
    "arrays": ("from_array", "from_long_csv", "save_array"),
    "dataset": ("binned_counts", "binned_rates", "describe_dataset", "load_dataset", "psth", "save_dataset"),
    "neo_export": ("to_neo",),
    "nwb": ("to_nwb",),
    "plan": ("make_plan",),
    "sampling": ("Population", "make_population", "sample_population"),
    "scenes": ("Contact", "Scene", "Sites", "Stage", "birznieks", "from_csv", "press_push_lift", "rotating_shear",
               "taxel_radius"),
    "simulate": ("plan_run", "simulate"),
    "spec": ("PopulationSpec", "load_spec", "spec_from_dict"),
}
__all__, __getattr__, __dir__ = lazy_exports(__name__, _WHERE)
