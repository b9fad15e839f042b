# SPDX-License-Identifier: MIT
"""ContactCloud against numpy recomputations of each policy, and the index choice against the
brute-force index."""
import itertools

import numpy as np
import pytest

import taxel
from taxel import fusion, sensor, sim


def clusters(rng, centres=40, per=25, sigma=1e-4):
    """Contacts around well separated centres (10 cm apart, noise far below the gate), so each
    cluster fuses into one point; returns positions, covariances and the cluster of each row."""
    c = np.column_stack([0.1 * np.arange(centres), rng.uniform(-0.2, 0.2, (centres, 2))])
    label = np.repeat(np.arange(centres), per)
    rng.shuffle(label)
    pos = c[label] + rng.normal(scale=sigma, size=(label.size, 3))
    a = rng.normal(size=(label.size, 3, 3)) * 1e-4
    cov = a @ a.transpose(0, 2, 1) + np.eye(3) * 1e-8
    return pos, cov, label


def first_seen(label):
    """Cluster ids in order of first appearance (the cloud's point ids)."""
    _, idx = np.unique(label, return_index=True)
    return label[np.sort(idx)]


def test_average_means_are_cluster_means(rng):
    pos, cov, label = clusters(rng)
    cloud = fusion.ContactCloud("average")
    r = cloud.insert(pos, cov)
    order = first_seen(label)
    assert r == {"added": order.size, "fused": label.size - order.size, "rejected": 0}
    expect = np.array([pos[label == k].mean(axis=0) for k in order])
    np.testing.assert_allclose(cloud.means, expect, atol=1e-15, rtol=1e-12)
    np.testing.assert_array_equal(cloud.observations, [np.sum(label == k) for k in order])


def test_kalman_is_the_information_weighted_mean(rng):
    pos, cov, label = clusters(rng)
    cloud = fusion.ContactCloud("kalman")
    cloud.insert(pos, cov)
    for i, k in enumerate(first_seen(label)):
        info = np.linalg.inv(cov[label == k])
        p = np.linalg.inv(info.sum(axis=0))
        x = p @ np.einsum("nij,nj->i", info, pos[label == k])
        np.testing.assert_allclose(cloud.means[i], x, atol=1e-12)
        np.testing.assert_allclose(cloud.covariances[i], p, rtol=1e-6, atol=1e-20)


def test_raw_keeps_every_contact(rng):
    pos, cov, _ = clusters(rng, centres=5, per=4)
    cloud = fusion.ContactCloud("raw")
    assert cloud.insert(pos, cov)["added"] == len(pos)
    np.testing.assert_array_equal(cloud.means, pos)
    np.testing.assert_allclose(cloud.covariances, cov)


@pytest.mark.parametrize("policy", fusion.POLICIES)
def test_every_index_matches_brute_force(rng, policy):
    # Dense, overlapping contacts on a sphere: association decides the result.
    contacts = sim.explore_palpation(sim.Sphere(0.03), touches=6).contacts
    ref = fusion.ContactCloud(policy, "brute_force")
    ref.insert(contacts)
    for index in fusion.INDEXES:
        cloud = fusion.ContactCloud(policy, index)
        cloud.insert(contacts)
        np.testing.assert_array_equal(cloud.means, ref.means)
        np.testing.assert_array_equal(cloud.observations, ref.observations)


def test_surfel_equals_kalman_on_a_plane(rng):
    n = 4000
    pos = np.column_stack([rng.uniform(-0.02, 0.02, (n, 2)), rng.normal(scale=2e-4, size=n)])
    cov = np.diag([1e-6, 1e-6, 4e-8])
    normals = np.tile([0.0, 0.0, 1.0], (n, 1))
    a = fusion.ContactCloud("surfel")
    b = fusion.ContactCloud("kalman")
    a.insert(pos, cov, normals)
    b.insert(pos, cov, normals)
    assert len(a) == len(b)
    np.testing.assert_allclose(a.means, b.means, atol=1e-9)


def test_array_and_contacts_inputs_agree(rng):
    pos, cov, _ = clusters(rng)
    times = np.arange(len(pos)) * 1e-3
    a = fusion.ContactCloud()
    b = fusion.ContactCloud()
    a.insert(pos, cov, times=times)
    contacts = taxel.Contacts(pos, cov, pressures=np.linspace(1.0, 2.0, len(pos)), times=times)
    b.insert(contacts)
    np.testing.assert_array_equal(a.means, b.means)
    # The columns read back as they went in; no contact states a normal or its sigma.
    np.testing.assert_array_equal(contacts.positions, pos)
    np.testing.assert_array_equal(contacts.covariances, cov)
    np.testing.assert_array_equal(contacts.pressures, np.linspace(1.0, 2.0, len(pos)))
    np.testing.assert_array_equal(contacts.times, times)
    assert np.isnan(contacts.normals).all()
    np.testing.assert_array_equal(contacts.normal_sigmas, np.zeros(len(pos)))
    np.testing.assert_array_equal(a.last_times, b.last_times)
    # Non-contiguous and non-float64 inputs are converted, with the same result.
    c = fusion.ContactCloud()
    c.insert(np.asfortranarray(pos), np.ascontiguousarray(cov.transpose(0, 2, 1)).transpose(0, 2, 1), times=times)
    np.testing.assert_array_equal(a.means, c.means)
    p32 = pos.astype(np.float32)
    d, e = fusion.ContactCloud(), fusion.ContactCloud()
    d.insert(p32, cov)
    e.insert(p32.astype(np.float64), cov)
    np.testing.assert_array_equal(d.means, e.means)


def test_bad_input_is_refused_with_nothing_inserted():
    cloud = fusion.ContactCloud()
    good = np.zeros((3, 3))
    good[:, 0] = [0.0, 0.1, 0.2]
    bad = good.copy()
    bad[2, 1] = np.nan
    with pytest.raises(ValueError, match="contact 2: position is not finite"):
        cloud.insert(bad)
    assert len(cloud) == 0
    assert cloud.insert(bad, strict=False) == {"added": 2, "fused": 0, "rejected": 1}
    with pytest.raises(ValueError, match=r"expected an array of shape \(N, 3\), got \(3, 2\)"):
        cloud.insert(np.zeros((3, 2)))
    with pytest.raises(ValueError, match="covariances"):
        cloud.insert(good, np.zeros((2, 3, 3)))
    with pytest.raises(ValueError, match="not positive definite"):
        cloud.insert(good, -np.eye(3))
    with pytest.raises(ValueError, match="covariances or sigma"):
        cloud.insert(good, np.eye(3), sigma=1e-3)
    with pytest.raises(ValueError, match="looks like millimetres"):
        fusion.ContactCloud(association_radius=3.4)
    with pytest.raises(ValueError, match="unknown value 'ekf'"):
        fusion.ContactCloud("ekf")
    with pytest.raises(ValueError, match="only with the average policy"):
        fusion.ContactCloud("kalman", alpha=0.5)


def test_association_gate_widens_for_coarse_contacts(rng):
    # Coarse contacts on the plane z = 0: 1.5 mm along the normal (+z), 1.44 mm across it,
    # against a 6 mm radius. With the radius alone, noise tails start points off the plane
    # whose covariance claims far less than their height; with the default widened gate
    # (6 sigma = 9 mm) no confident point is more than a few of its sigmas off.
    n = 40000
    pos = np.column_stack([rng.uniform(-0.03, 0.03, (n, 2)), np.zeros(n)])
    pos += rng.normal(size=(n, 3)) * [1.44e-3, 1.44e-3, 1.5e-3]
    cov = np.tile(np.diag([1.44e-3**2, 1.44e-3**2, 1.5e-3**2]), (n, 1, 1))
    normals = np.tile([0.0, 0.0, 1.0], (n, 1))
    worst = {}
    for sigmas in (0.0, 6.0):
        cloud = fusion.ContactCloud(association_radius=6e-3, association_sigmas=sigmas)
        cloud.insert(pos, cov, normals)
        keep = cloud.confident(min_observations=3, max_normal_sigma=0.3e-3)
        z = np.abs(cloud.means[keep, 2]) / np.sqrt(cloud.covariances[keep, 2, 2])
        worst[sigmas] = z.max()
    assert worst[0.0] > 6 and worst[6.0] < 4.5
    for bad in (-1.0, float("nan"), float("inf")):
        with pytest.raises(ValueError, match="association_sigmas"):
            fusion.ContactCloud(association_sigmas=bad)


def test_confidence_filter(rng):
    pos, cov, label = clusters(rng, centres=10, per=5)
    single = np.array([[5.0, 5.0, 5.0]])
    cloud = fusion.ContactCloud("kalman")
    cloud.insert(np.vstack([pos, single]), np.concatenate([cov, [np.eye(3) * 1e-6]]))
    keep = cloud.confident(min_observations=3)
    assert keep.sum() == 10 and not keep[-1]
    pc = cloud.to_point_cloud(min_observations=3)
    assert len(pc) == 10
    np.testing.assert_array_equal(pc.points, cloud.means[keep])
    np.testing.assert_array_equal(pc.fields["observations"], cloud.observations[keep])
    np.testing.assert_allclose(pc.fields["cov_xy"], cloud.covariances[keep, 0, 1])
    # max_sigma: the single contact's 1 mm sigma fails a 0.5 mm bound.
    assert not cloud.confident(max_sigma=5e-4)[-1]
    with pytest.raises(ValueError):
        cloud.confident(max_sigma=-1.0)
    # max_normal_sigma: against the smallest eigenvalue of each covariance.
    low = np.sqrt(np.linalg.eigvalsh(cloud.covariances)[:, 0])
    ranked = np.sort(low)
    bound = float(0.5 * (ranked[4] + ranked[5]))  # between two points, not on one
    np.testing.assert_array_equal(cloud.confident(max_normal_sigma=bound), low <= bound)
    assert len(cloud.to_point_cloud(max_normal_sigma=bound)) == int((low <= bound).sum())
    with pytest.raises(ValueError):
        cloud.confident(max_normal_sigma=-1.0)


def test_readings_to_contacts_equal_the_simulators():
    for mode in ("per_tactel", "per_pad"):
        opts = sensor.ContactOptions(mode=mode)
        ex = sim.explore_grasps(sim.Cylinder(), grasps=2, contacts=opts, seed=3)
        made = sensor.contacts_from_readings(ex.readings, ex.poses(), times=ex.times, options=opts)
        want = ex.contacts
        assert len(made) == len(want) > 0
        np.testing.assert_array_equal(made.positions, want.positions)
        np.testing.assert_array_equal(made.covariances, want.covariances)
        np.testing.assert_array_equal(made.times, want.times)
        np.testing.assert_array_equal(made.normal_sigmas, want.normal_sigmas)
        assert (made.normal_sigmas > 0).all()
        a = fusion.ContactCloud()
        a.insert_readings(ex.readings, ex.poses(), times=ex.times, options=opts)
        b = fusion.ContactCloud()
        b.insert(want)
        np.testing.assert_array_equal(a.means, b.means)


def test_readings_errors():
    ex = sim.explore_palpation(sim.Sphere(), touches=2)
    readings, poses = ex.readings, ex.poses()
    with pytest.raises(ValueError, match="poses"):
        sensor.contacts_from_readings(readings, poses[:-1])
    missing = poses.copy()
    touching = np.flatnonzero(readings.reshape(len(readings), -1).max(axis=1) >= 8)[0]
    missing[touching] = np.nan
    with pytest.raises(ValueError, match=f"frame {touching}, pad 0 reads contact but has no pose"):
        sensor.contacts_from_readings(readings, missing)
    skew = poses.copy()
    skew[0, 0, 0, 0] = 2.0
    with pytest.raises(ValueError, match="not a rotation"):
        sensor.contacts_from_readings(readings, skew)
    with pytest.raises(ValueError, match="above the sensor's largest level"):
        sensor.contacts_from_readings(readings, poses, model=sensor.SensorModel(levels=256, threshold=2))
    with pytest.raises(ValueError, match="threshold"):
        sensor.SensorModel(threshold=0)
    # A length in millimetres given as metres, and a noise that would overflow the variances.
    with pytest.raises(ValueError, match="pitch"):
        sensor.SensorModel(pitch=3.4)
    with pytest.raises(ValueError, match="sigma_normal"):
        sensor.SensorModel(sigma_normal=1e300)


def test_refined_and_plug_in_censoring_corrections():
    # A pad pressed flat: every tactel reads 1000 of 4095 (3 mm full scale, threshold 8).
    model = sensor.SensorModel()
    readings = np.full((1, 1, 14, 6), 1000, dtype=np.uint16)
    poses = np.eye(4).reshape(1, 1, 4, 4)
    dq = 3e-3 / 4095
    measured, threshold = 1000 * dq, 7.5 * dq
    plug = sensor.ContactOptions(refine_censoring=False)
    assert sensor.ContactOptions().refine_censoring and not plug.refine_censoring
    flat = sensor.contacts_from_readings(readings, poses, options=plug).positions[:, 2]
    # At the reading: d = m - sigma * lambda((t - m) / sigma).
    want = measured - sensor.truncation_bias(measured, threshold, model.sigma_normal)
    np.testing.assert_allclose(-flat, want, rtol=1e-12)
    # Refined: at the fitted depth, here the corrected depth itself (0.3 um shallower than the
    # plug-in value), plus a second-order term of a few micrometres deeper.
    refined = -sensor.contacts_from_readings(readings, poses).positions[:, 2]
    assert np.all(refined >= want - 1e-6) and np.all(refined <= want + 4e-6)
    assert np.any(refined != want)


def test_footprints_stated_by_readings_and_arrays():
    # Contacts from readings state a tactel's footprint, pitch / sqrt(12); contacts from arrays
    # state none unless told, and a bad footprint is refused before anything is made.
    readings = np.full((1, 1, 14, 6), 1000, dtype=np.uint16)
    poses = np.eye(4).reshape(1, 1, 4, 4)
    pad = sensor.contacts_from_readings(readings, poses)
    np.testing.assert_allclose(pad.footprint_sigmas, 3.4e-3 / np.sqrt(12), rtol=1e-12)
    assert sensor.ContactOptions(tactel_area=True).tactel_area
    assert not sensor.ContactOptions().tactel_area
    assert np.all(taxel.Contacts(np.zeros((3, 3))).footprint_sigmas == 0)
    stated = taxel.Contacts(np.zeros((3, 3)), sigma=1e-3, footprint_sigma=5e-4)
    assert np.all(stated.footprint_sigmas == 5e-4)
    for bad in (-1e-3, float("nan"), float("inf")):
        with pytest.raises(ValueError, match="footprint_sigma"):
            taxel.Contacts(np.zeros((3, 3)), footprint_sigma=bad)
        with pytest.raises(ValueError, match="footprint_sigma"):
            fusion.ContactCloud().insert(np.zeros((3, 3)), footprint_sigma=bad)


def test_surfel_removes_the_lift_of_scatter_not_of_a_footprint():
    # A 15 mm sphere's surface points scattered 1 mm along the tangent plane, kept where their
    # reported position lies within 2 mm of the top (as a point's gate keeps them): stated as
    # scatter, the surfel policy removes their lift (sigma^2 / R = 0.067 mm); stated as a
    # footprint, it does not.
    rng = np.random.default_rng(4)
    R, st, sn, n = 0.015, 1e-3, 0.3e-3, 200000
    xy = rng.uniform(-6e-3, 6e-3, (n, 2))
    true = np.column_stack([xy, np.sqrt(R * R - (xy ** 2).sum(axis=1))])
    normals = true / R
    t1 = np.cross(normals, [1.0, 0.0, 0.0])
    t1 /= np.linalg.norm(t1, axis=1)[:, None]
    t2 = np.cross(normals, t1)
    g = rng.standard_normal((n, 3))
    reported = true + st * (g[:, :1] * t1 + g[:, 1:2] * t2) + sn * g[:, 2:] * normals
    keep = np.hypot(reported[:, 0], reported[:, 1]) < 2e-3
    reported, normals = reported[keep], normals[keep]
    cov = st * st * np.eye(3) + (sn * sn - st * st) * np.einsum("ni,nj->nij", normals, normals)
    heights = []
    for footprint in (0.0, st):
        cloud = fusion.ContactCloud(association_radius=0.02)  # one point for all
        cloud.insert(reported, cov, normals, footprint_sigma=footprint)
        assert len(cloud) == 1
        heights.append(np.linalg.norm(cloud.means[0]) - R)
    assert heights[1] - heights[0] == pytest.approx(st * st / R, rel=0.1)
    assert heights[1] > 0.5 * st * st / R
    assert abs(heights[0]) < 0.35 * st * st / R


def test_truncation_bias_closed_form():
    # At the threshold, the bias of a surviving reading is sigma * phi(0) / (1 - Phi(0)).
    assert sensor.truncation_bias(1e-3, 1e-3, 3e-4) == pytest.approx(3e-4 * np.sqrt(2 / np.pi))
    assert sensor.truncation_bias(1.0, 0.0, 3e-4) == 0.0


def test_policy_and_index_combinations_construct():
    for policy, index in itertools.product(fusion.POLICIES, fusion.INDEXES):
        c = fusion.ContactCloud(policy, index)
        assert (c.policy, c.index) == (policy, index)
        assert c.insert_one([0.0, 0.0, 0.0]) == 0
