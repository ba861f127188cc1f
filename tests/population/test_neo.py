"""Neo export: the Block's layout, and Elephant's rates and distances on it against our own numbers."""

import sys

import numpy as np
import pytest

from ddmm.population import birznieks, psth, sample_population, simulate, to_neo

pytestmark = pytest.mark.filterwarnings("ignore:The 'copy' argument in Quantity is deprecated")  # elephant 1.2

neo = pytest.importorskip("neo")
pq = pytest.importorskip("quantities")
elephant_statistics = pytest.importorskip("elephant.statistics")
dissimilarity = pytest.importorskip("elephant.spike_train_dissimilarity")


@pytest.fixture(scope="module")
def ds():
    """40 fingertip afferents (SA-I, RA-I with receptor noise: trials differ), a shear and a normal-only press."""
    pop = sample_population("fingertip", rng=0).select(np.r_[0:20, 300:320])
    return simulate(pop, [birznieks(90.0), birznieks(None)], engine="direct", trials=3, seed=2, quiet=True)


@pytest.fixture(scope="module")
def block(ds):
    return to_neo(ds)


def _events(ds, c, t, a):
    keep = (ds.spike_condition.values == c) & (ds.spike_trial.values == t) & (ds.spike_afferent.values == a)
    return ds.spike_time.values[keep]


def test_layout_and_annotations(ds, block):
    assert len(block.segments) == 2 * 3 and len(block.groups) == ds.sizes["afferent"]
    seg = block.segments[4]  # condition 1 (normal only), trial 1
    stages = {str(s): [float(ds.stage_start[1, i]), float(ds.stage_end[1, i])] for i, s in enumerate(ds.stage.values)}
    assert seg.annotations == {"condition": ds.condition.values[1], "condition_index": 1, "trial": 1,
                               "theta_r": 0.0, "has_theta_r": False, "duration": 0.5, "stages": stages}
    assert list(seg.epochs[0].labels) == list(ds.stage.values) and seg.epochs[0].name == "stages"
    force = seg.analogsignals[0]
    assert force.units == pq.N and float(force.sampling_rate.rescale("Hz")) == ds.attrs["fs"]
    np.testing.assert_array_equal(force.magnitude, np.stack([ds[n].values[1] for n in ("fx", "fy", "fz")], axis=1))
    assert np.abs(ds.fy.values[0]).max() > 1  # condition 0 differs (distal shear)
    for a, train in enumerate(seg.spiketrains):
        assert train.units == pq.s and float(train.t_start) == 0.0 and float(train.t_stop) == 0.5
        np.testing.assert_array_equal(train.magnitude, _events(ds, 1, 1, a))
        for name in ("afferent_type", "theta_t", "nap", "k", "gain", "x_mm", "y_mm", "region"):
            assert train.annotations[name] == ds[name].values[a], name
        assert train.annotations["afferent_id"] == ds.afferent.values[a]
        assert any(member is train for member in block.groups[a].spiketrains)
    assert block.annotations["seed"] == 2 and block.annotations["afferent_units"]["theta_t"] == "deg"


def test_multi_site_forces():
    from tests.population.test_nwb import two_sites

    pop = sample_population("fingertip", rng=0).select(range(0, 991, 60))
    seg = to_neo(simulate(pop, two_sites(), engine="direct", quiet=True)).segments[0]
    site = seg.analogsignals[1]
    assert site.name == "site_force" and list(site.array_annotations["channel_names"][:4]) == ["L fx", "L fy",
                                                                                               "L fz", "R fx"]
    np.testing.assert_array_equal(site.magnitude.reshape(-1, 2, 3), two_sites().site_forces)


def test_elephant_time_histogram_is_our_psth(ds, block):
    bin_s = 0.01
    # Spike times are steps of dt = 0.1 ms: some fall exactly on 10 ms bin edges, where binning can disagree.
    q = ds.spike_time.values / bin_s
    assert np.sum(np.abs(q - np.rint(q)) < 1e-8) > 5
    ours = psth(ds, bin_s)
    for c, name in enumerate(ds.condition.values):
        for kind in ("SAI", "RAI"):
            trains = [st for seg in block.segments if seg.annotations["condition_index"] == c
                      for st in seg.spiketrains if st.annotations["afferent_type"] == kind]
            rate = elephant_statistics.time_histogram(trains, bin_s * pq.s, output="rate")
            np.testing.assert_allclose(rate.rescale("Hz").magnitude[:, 0], ours.sel(condition=name,
                                       afferent_type=kind).values, rtol=1e-12, atol=1e-9)


def test_elephant_mean_firing_rate_is_count_over_duration(ds, block):
    rates = [[float(elephant_statistics.mean_firing_rate(st).rescale("Hz")) for st in seg.spiketrains]
             for seg in block.segments]
    ours = (ds.spike_count / ds.duration).values.reshape(len(block.segments), -1)
    np.testing.assert_allclose(rates, ours, rtol=1e-12)
    assert ours.max() > 10


def _victor_purpura(t, u, q):
    """Edit distance: delete or insert a spike costs 1, moving one by dt costs q |dt| (dynamic programming)."""
    d = np.zeros((len(t) + 1, len(u) + 1))
    d[:, 0], d[0, :] = np.arange(len(t) + 1), np.arange(len(u) + 1)
    for i in range(1, len(t) + 1):
        for j in range(1, len(u) + 1):
            d[i, j] = min(d[i - 1, j] + 1, d[i, j - 1] + 1, d[i - 1, j - 1] + q * abs(t[i - 1] - u[j - 1]))
    return d[-1, -1]


def test_elephant_victor_purpura_on_trials_matches_numpy(ds, block):
    q = 50.0  # 1/s: moving a spike by 20 ms costs as much as deleting it
    checked = 0
    for a in range(0, ds.sizes["afferent"], 7):
        trains = [block.segments[t].spiketrains[a] for t in range(3)]  # condition 0, trials 0-2
        got = dissimilarity.victor_purpura_distance(trains, cost_factor=q / pq.s)
        want = [[_victor_purpura(_events(ds, 0, i, a), _events(ds, 0, j, a), q) for j in range(3)] for i in range(3)]
        np.testing.assert_allclose(got, want, rtol=1e-9, atol=1e-12)
        checked += np.count_nonzero(np.asarray(want) > 0)
    assert checked > 0  # noisy trials: the distances are not all zero


def test_missing_neo_is_a_one_line_import_error(ds, monkeypatch):
    monkeypatch.setitem(sys.modules, "neo", None)
    with pytest.raises(ImportError) as info:
        to_neo(ds)
    assert str(info.value) == 'to_neo needs neo: pip install "ddmm[neo]"'


def test_bad_dataset_is_named(ds):
    with pytest.raises(TypeError, match="to_neo: dataset must be an xarray.Dataset.*got list"):
        to_neo([1, 2])
    with pytest.raises(ValueError, match="to_neo: dataset lacks afferent_type"):
        to_neo(ds.drop_vars("afferent_type"))
