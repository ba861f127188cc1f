"""Multi-site scenes: local drive, its exactness across engines, chunkings, planning and streaming."""

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from ddmm.population import Contact, Scene, Sites, birznieks, sample_population, simulate, taxel_radius
from ddmm.population.anatomy.receptive_fields import (
    REFERENCE_AREA_MM2,
    RF_AREA_MM2,
    RF_SIGMA_MM,
    local_mixing,
    receptive_field_weight,
    site_coverage,
)
from ddmm.population.runtime.stream import Encoder
from ddmm.population.simulation import population_currents
from tests.conftest import ENGINES

R_REF = float(np.sqrt(REFERENCE_AREA_MM2 / np.pi))


@pytest.fixture(scope="module")
def pop():
    return sample_population("fingertip", rng=0).select(np.arange(0, 991, 3))


def twist(n_samples=400):
    """Two sites either side of the pad with opposite distal shear: a crude torsion."""
    base = birznieks(90.0)
    f = np.zeros((n_samples, 2, 3))
    f[:, :, 2] = base.fz[:n_samples, None] / 2
    f[:, 0, 1], f[:, 1, 1] = base.fy[:n_samples] / 2, -base.fy[:n_samples] / 2
    return Scene.from_sites(f, Sites([-4.0, 4.0], [0.0, 0.0], 3.0, region=["D2d"] * 2, site_id=["L", "R"]),
                            base.fs, "twist")


def test_receptive_fields_follow_row_17():
    # A point probe drives at half weight or more over the type's median field area.
    for kind, area in RF_AREA_MM2.items():
        r_half = np.sqrt(area / np.pi)
        w = receptive_field_weight([r_half - 1e-9, r_half + 1e-6], [0.0, 0.0], [kind] * 2, Contact(0.0, 0.0, 1e-9))
        assert w[0] >= 0.5 > w[1]
    assert RF_AREA_MM2["SAII"] == 5 * RF_AREA_MM2["SAI"] and RF_AREA_MM2["RAII"] == 10 * RF_AREA_MM2["RAI"]
    assert RF_SIGMA_MM["SAI"] < RF_SIGMA_MM["RAI"] < RF_SIGMA_MM["SAII"] < RF_SIGMA_MM["RAII"]


@pytest.mark.parametrize("engine", ENGINES)
def test_one_site_of_reference_area_is_the_contact_scene(pop, engine):
    one = birznieks(200.0, contact=Contact(1.0, -2.0, R_REF))
    forces = np.stack([one.fx, one.fy, one.fz], axis=1)[:, None, :]
    multi = Scene.from_sites(forces, Sites([1.0], [-2.0], R_REF), one.fs, one.name, one.stages, one.theta_r)
    a = simulate(pop, one, engine=engine, seed=3, quiet=True)
    b = simulate(pop, multi, engine=engine, seed=3, quiet=True)
    assert a.spike_count.sum() > 100
    np.testing.assert_array_equal(a.spike_time.values, b.spike_time.values)
    np.testing.assert_array_equal(a.spike_afferent.values, b.spike_afferent.values)


def test_local_mixing_is_a_weighted_mean_of_tractions():
    sites = Sites([-1.0, 1.0], [0.0, 0.0], [1.0, 2.0])
    indptr, indices, coeff, cover = local_mixing([0.0, 100.0], [0.0, 0.0], ["RAI", "RAI"], sites)
    assert indptr.tolist() == [0, 2, 2] and cover.tolist() == [1.0, 0.0]
    w = np.array([receptive_field_weight([0.0], [0.0], ["RAI"], Contact(x, 0.0, r))[0] for x, r in ((-1, 1), (1, 2))])
    expected = w / w.sum() * REFERENCE_AREA_MM2 / (np.pi * np.array([1.0, 2.0]) ** 2)
    np.testing.assert_allclose(coeff, expected, rtol=1e-15)


def test_afferents_either_side_of_a_twist_feel_opposite_shear(pop):
    sc = twist()
    indptr, indices, coeff, cover = local_mixing(pop.x_mm, pop.y_mm, pop.afferent_type, sc.sites)
    from ddmm.models.fused import mix_forces, mixing_matrix

    local = mix_forces(sc.site_forces[200:201], mixing_matrix(indptr, indices, coeff, 2))[0].T
    sai = (pop.afferent_type == "SAI") & (cover > 0)
    left, right = sai & (pop.x_mm < -4), sai & (pop.x_mm > 4)
    assert left.any() and right.any()
    assert np.all(local[left, 1] > 0) and np.all(local[right, 1] < 0)


@settings(max_examples=6, deadline=None)
@given(chunk=st.integers(37, 4096), time_chunk=st.integers(50, 400), engine=st.sampled_from(ENGINES))
def test_multi_site_runs_do_not_depend_on_chunking_planning_or_engine(pop, chunk, time_chunk, engine):
    sc = twist()
    ref = simulate(pop, sc, engine="direct", seed=1, quiet=True, plan=False)
    got = simulate(pop, sc, engine=engine, seed=1, quiet=True, chunk_size=chunk, time_chunk=time_chunk)
    assert ref.spike_count.sum() > 100
    np.testing.assert_array_equal(got.spike_time.values, ref.spike_time.values)
    np.testing.assert_array_equal(got.spike_afferent.values, ref.spike_afferent.values)


@settings(max_examples=6, deadline=None)
@given(cuts=st.lists(st.integers(1, 399), max_size=12, unique=True))
def test_streaming_multi_site_equals_offline(pop, cuts):
    sc = twist()
    offline = simulate(pop, sc, engine="direct", seed=2, quiet=True)
    enc = Encoder(pop, sc.fs, seed=2, sites=sc.sites, conditioning=None)
    edges = [0] + sorted(cuts) + [sc.n_samples]
    outs = [enc.push(sc.site_forces[a:b]) for a, b in zip(edges[:-1], edges[1:])]
    np.testing.assert_array_equal(np.concatenate([o.afferent for o in outs]), offline.spike_afferent.values)
    np.testing.assert_array_equal(np.concatenate([o.time for o in outs]), offline.spike_time.values)


def test_multi_site_currents_change_only_where_sites_reach(pop):
    sc = twist()
    current = population_currents(pop, sc)
    cover = site_coverage(pop, sc.sites)
    assert np.all(current[:, (cover == 0) & (pop.afferent_type != "SAII")] == 0.0)
    assert np.all(np.abs(current[:, cover > 0.5]).max(axis=0) > 0)


def test_dataset_records_sites(pop):
    ds = simulate(pop, twist(), engine="direct", seed=1, quiet=True, record=("spikes", "forces"))
    assert ds.site.values.tolist() == ["L", "R"] and ds.site_region.values.tolist() == ["D2d", "D2d"]
    np.testing.assert_array_equal(ds.site_fz.values[0], twist().site_forces[:, :, 2])
    assert ds.site_fz.attrs["units"] == "N" and ds.site_x_mm.attrs["units"] == "mm"


def test_bad_sites(pop):
    with pytest.raises(ValueError, match="duplicate site id 'a'"):
        Sites([0.0, 1.0], [0.0, 0.0], 1.0, site_id=["a", "a"])
    with pytest.raises(ValueError, match=r"radius_mm must be in \(0, 200\] mm"):
        Sites([0.0], [0.0], 0.0)
    with pytest.raises(ValueError, match=r"site_forces must have shape \(n_samples, n_sites, 3\) = \(4, 2, 3\)"):
        Scene(np.zeros(4), np.zeros(4), np.ones(4), sites=Sites([0.0, 1.0], [0.0, 0.0], 1.0),
              site_forces=np.ones((4, 3, 3)))
    f = np.ones((4, 1, 3))
    f[2, 0, 2] = -1.0
    with pytest.raises(ValueError, match="fz must be >= 0 N; got -1.0 at site '0'"):
        Scene.from_sites(f, Sites([0.0], [0.0], 1.0))
    far = Scene.from_sites(np.ones((4, 2, 3)), Sites([0.0, 80.0], [0.0, 0.0], 1.0, site_id=["pad", "far"]))
    with pytest.raises(ValueError, match="site 'far' at \\(80, 0\\) mm reaches no afferent"):
        simulate(pop, far, engine="direct", quiet=True)
    with pytest.raises(ValueError, match="mix one-site and multi-site"):
        simulate(pop, [twist(), birznieks(90.0)], engine="direct", quiet=True)
    with pytest.raises(TypeError, match="sites must be a Sites"):
        Encoder(pop, 1000.0, sites=[1, 2])
    with pytest.raises(ValueError, match=r"shape \(n, n_sites, 3\) = \(n, 2, 3\)"):
        Encoder(pop, 1000.0, sites=twist().sites).push(np.ones((5, 3)))


def test_taxel_radius_is_equal_area():
    assert np.isclose(np.pi * taxel_radius(2.5) ** 2, 2.5 ** 2)


@pytest.fixture(scope="module")
def hand():
    return sample_population("hand", rng=0)


def test_a_push_on_d2_leaves_d4_and_the_palm_silent(hand):
    base = birznieks(90.0)
    f = np.stack([base.fx, base.fy, base.fz], axis=1)[:, None, :]
    sc = Scene.from_sites(f, Sites([0.0], [0.0], R_REF, region=["D2d"], site_id=["D2tip"]), base.fs, "d2push")
    from ddmm.population import plan_run

    text = plan_run(hand, [sc]).describe(hand, [sc])
    ds = simulate(hand, sc, engine="direct", seed=0, quiet=True)
    counts, region, kind = ds.spike_count.values[0, 0], ds.region.values, ds.afferent_type.values
    far = np.isin(region, ["D4d", "D4m", "D4p", "palm_central", "palm_distal", "thenar", "hypothenar"])
    assert counts[far & ~np.isin(kind, ["SAII", "RAII"])].sum() == 0  # SA-II fire tonically at rest (row 1)
    # FA-II, with their large fields and low threshold to ramp corners, may give a spike on a neighbouring digit
    assert counts[far & (kind == "RAII")].sum() <= 0.01 * counts[kind == "RAII"].sum()
    assert counts[(region == "D2d") & (kind == "RAI")].sum() > 1000
    quiet = int(text.split("quiet (identically zero current, skipped): ")[1].split()[0])
    assert quiet >= np.sum(far & (kind != "SAII")) and "D4d" in text and "palm_central" in text


def test_site_forces_act_in_the_hand_frame(hand):
    # On the thumb (frame_deg -45), hand-frame shear along the thumb's distal axis is local distal shear.
    thumb = hand.select(np.flatnonzero((hand.region == "D1d") & (hand.afferent_type != "SAII")))
    frame = float(thumb.frame_deg[0])
    assert frame != 0.0 and np.all(thumb.frame_deg == frame)
    local = birznieks(90.0, contact=Contact(float(thumb.x_mm.mean()), float(thumb.y_mm.mean()), 40.0))
    turned = birznieks(90.0 + frame)
    f = np.stack([turned.fx, turned.fy, turned.fz], axis=1)[:, None, :]
    sites = Sites([float(thumb.x_mm.mean())], [float(thumb.y_mm.mean())], 40.0)
    scale = REFERENCE_AREA_MM2 / sites.area_mm2[0]
    multi = Scene.from_sites(f / scale, sites, turned.fs, "thumb")
    np.testing.assert_allclose(population_currents(thumb, multi), population_currents(thumb, local),
                               rtol=1e-9, atol=1e-9)
