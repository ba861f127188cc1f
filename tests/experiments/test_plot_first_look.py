"""The first-look figure: force, then a raster of every trial and a PSTH per type."""

import numpy as np
from matplotlib.figure import Figure

from ddmm.experiments.plots.first_look import plot_ramp_and_hold, ramp_and_hold, ramp_and_hold_scene
from ddmm.population import sample_population


def test_scene_ramps_holds_and_releases_at_the_given_rate():
    scene = ramp_and_hold_scene(force_n=2.0, rate_n_per_s=10.0, hold_s=1.0)
    assert scene.fz.max() == 2.0 and scene.fz[0] == 0.0 and scene.fz[-1] == 0.0
    assert abs(np.max(np.diff(scene.fz)) * scene.fs - 10.0) < 1e-9  # N/s
    assert [s.label for s in scene.stages] == ["loading", "hold", "release"]


def test_raster_rows_hold_every_trial_of_every_afferent():
    ds = ramp_and_hold(sample_population("fingertip", rng=0), per_type=3, trials=4)
    fig = plot_ramp_and_hold(ds)
    assert isinstance(fig, Figure)
    kinds = np.unique(ds.afferent_type.values)
    assert len(fig.axes) == 1 + 2 * kinds.size
    raster = fig.axes[1]  # the first type's raster: its points are its spikes, on rows afferent * trials + trial
    first = ds.afferent_type.values[ds.spike_afferent.values] == "SAI"
    assert raster.collections[0].get_offsets().shape[0] == int(first.sum())
    assert raster.get_ylim()[1] == 3 * 4
