"""Analysis of simulated spikes, as a physiologist or a decoder would read them.

- `tuning`: direction tuning as microneurography measures it;
- `decode`: shear-direction decoders (population vector, maximum likelihood,
  first-spike latency);
- `ml`: the decoders as scikit-learn estimators, and `features` for them
  (needs scikit-learn: ``pip install 'ddmm[ml]'``; imported only on use);
- `array_decode`: torque and slip from force fields;
- `physiology`: the physiology scorecard against human recordings;
- `surface_maps`: spatial event plots of scanned surfaces (each spike placed on the surface).
"""

from ddmm.utils.lazy import lazy_exports

_WHERE = {
    "tuning": ("direction_tuning", "tuning_scenes", "tuning_summary"),
    "decode": ("DECODERS", "FirstSpikeLatency", "MaximumLikelihood", "PopulationVector", "angular_error",
               "select_afferents", "window_responses"),
    "ml": ("ESTIMATORS", "FirstSpikeLatencyDecoder", "MaximumLikelihoodDecoder", "PopulationVectorDecoder",
           "circular_score", "example_features", "features"),
    "array_decode": ("CentroidClassifier", "SlipDetector", "evaluate_slip", "onset_counts", "stage_onset"),
    "physiology": ("PROPERTIES", "score_physiology", "summarise_scorecard"),
    "surface_maps": ("ScanPath", "event_rate_map", "relief_correlation", "spatial_events"),
}
__all__, __getattr__, __dir__ = lazy_exports(__name__, _WHERE)
