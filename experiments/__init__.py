"""Reproductions, biology comparisons, calibration, benchmarks and the ddmm CLI."""
