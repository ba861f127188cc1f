"""Populations of afferents: scenes, specs, sampling, simulation, datasets, decoding."""
