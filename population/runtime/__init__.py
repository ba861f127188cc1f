"""Runtime: how a run is carried out, beside the simulation core.

- `plan`: what a run computes and what it skips (`make_plan`);
- `memory`: a run's peak memory, spike events included, estimated before it
  starts (`estimate_memory`), and the refusal of a run that cannot fit;
- `noise`: counter-based current noise, keyed so chunking never changes it;
- `stream`: the streaming encoder (`Encoder`), live force in, spikes out;
- `step_choice`: the (dt, method) that meets an accuracy tolerance;
- `distributed`: a run's afferent blocks as Dask tasks;
- `lsl`, `lsl_outlets`, `lsl_bridge`: Lab Streaming Layer streams (forces in;
  spikes and pulses out) and the bridge between them and an `Encoder` (extra
  ``ddmm[lsl]``); `spike_formats`: the spike stream's formats (one sample per
  spike, or a frame per push) and their decoder, `decode_spikes`.
"""

from ddmm.utils.lazy import lazy_exports

_WHERE = {
    "plan": ("RECORD_CHOICES", "ConditionPlan", "Plan", "make_plan"),
    "noise": ("noise_key", "root_seed"),
    "stream": ("Encoder", "StreamSpikes"),
    "step_choice": ("choose_setting", "load_table"),
    "distributed": ("dask_client",),
    "lsl": ("ForceStream", "open_force_stream", "open_force_outlet", "lsl_clock"),
    "lsl_outlets": ("SpikeOutlet", "PulseOutlet", "read_spike_metadata"),
    "spike_formats": ("SPIKE_FORMATS", "decode_spikes"),
    "lsl_bridge": ("Bridge", "BridgeSummary", "check_stamps", "take_stamps", "play_forces"),
}
__all__, __getattr__, __dir__ = lazy_exports(__name__, _WHERE)
