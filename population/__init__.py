"""Populations of afferents: from a spec to spikes in an xarray Dataset, and what to do with them.

The main path is four modules at this level:

- `spec`: population specs (TOML or dataclasses) and the shipped presets;
- `sampling`: `sample_population` draws a `Population` from a spec;
- `simulation`: `simulate` runs a population on scenes, block by block;
- `dataset`: the Dataset's schema, netCDF round trip, rates and PSTHs.

Around it, one subpackage per concern:

- `anatomy`: the hand map and receptive fields;
- `stimuli`: scenes (fingertip forces) and multi-site scenes (torsion, slip);
- `runtime`: what a run computes (`make_plan`), noise streams, the streaming
  encoder, the step chosen for a tolerance, Dask;
- `analysis`: direction tuning, decoders, torque and slip, the physiology
  scorecard;
- `io`: sensor-array readers, recorded LSL sessions (XDF), NWB and Neo export.

Names are imported on first use (PEP 562), so ``import ddmm.population``
costs only what a caller touches: no xarray before a dataset is built, no
scipy before a filter is designed.
"""

from ddmm.utils.lazy import lazy_exports

_WHERE = {
    "io.arrays": ("from_array", "from_long_csv"),
    "io.array_writers": ("save_array",),
    "io.xdf": ("from_xdf", "read_xdf"),
    "dataset": ("binned_counts", "binned_rates", "describe_dataset", "load_dataset", "psth", "save_dataset"),
    "io.neo_export": ("to_neo",),
    "io.brian2_export": ("to_brian2",),
    "io.nwb": ("to_nwb",),
    "runtime.plan": ("make_plan",),
    "runtime.stream": ("Encoder",),
    "sampling": ("Population", "make_population", "sample_population"),
    "stimuli.scenes": ("Contact", "Scene", "Sites", "Stage", "birznieks", "press_push_lift",
                       "rotating_shear", "taxel_radius"),
    "stimuli.recordings": ("from_csv", "RecordingBandWarning"),
    "stimuli.conditioning": ("Conditioning", "condition_forces"),
    "simulation": ("plan_run", "simulate"),
    "spec": ("PopulationSpec", "load_spec", "spec_from_dict"),
}
__all__, __getattr__, __dir__ = lazy_exports(__name__, _WHERE)
