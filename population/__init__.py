"""Populations of afferents: specs, sampling, scenes, simulation, datasets.

Names are imported on first use (PEP 562), so ``import population`` costs
only what a caller touches: no xarray before a dataset is built, no scipy
before a filter is designed.
"""

from importlib import import_module

_WHERE = {
    "arrays": ("from_array", "from_long_csv", "save_array"),
    "dataset": ("binned_counts", "binned_rates", "describe_dataset", "load_dataset", "psth", "save_dataset"),
    "plan": ("make_plan",),
    "sampling": ("Population", "make_population", "sample_population"),
    "scenes": ("Contact", "Scene", "Sites", "Stage", "birznieks", "from_csv", "press_push_lift", "rotating_shear",
               "taxel_radius"),
    "simulate": ("plan_run", "simulate"),
    "spec": ("PopulationSpec", "load_spec", "spec_from_dict"),
}
_MODULE_OF = {name: module for module, names in _WHERE.items() for name in names}

__all__ = sorted(_MODULE_OF)


def __getattr__(name):
    if name not in _MODULE_OF:
        raise AttributeError(f"module 'population' has no attribute {name!r}")
    value = getattr(import_module(f".{_MODULE_OF[name]}", __name__), name)
    globals()[name] = value
    return value


def __dir__():
    return sorted(set(globals()) | set(__all__))
