# SPDX-License-Identifier: MIT
"""k-nearest and radius queries (taxel.index.KdTree, ContactCloud) against scipy's cKDTree."""
import copy
import pickle
import threading

import numpy as np
import pytest

from taxel import fusion, index, sim

spatial = pytest.importorskip("scipy.spatial")


@pytest.fixture
def cloud_points(rng):
    # A grid makes ties in distance; the rest random.
    grid = np.stack(np.meshgrid(*[np.arange(4) * 1e-3] * 3), axis=-1).reshape(-1, 3)
    return np.vstack([grid, rng.uniform(-0.01, 0.01, size=(2000, 3))])


def check_knn(dist, ids, points, queries, k):
    ref_d, ref_i = spatial.cKDTree(points).query(queries, k=k)
    np.testing.assert_allclose(dist, ref_d, rtol=1e-12, atol=1e-15)
    # Ids agree except where distances tie; there ours are ordered by id.
    d = np.linalg.norm(points[np.minimum(ids, len(points) - 1)] - queries[:, None, :] if k > 1 else
                       points[np.minimum(ids, len(points) - 1)] - queries, axis=-1)
    found = ids < len(points)
    np.testing.assert_allclose(d[found], np.asarray(dist)[found], rtol=1e-12, atol=1e-15)
    np.testing.assert_array_equal(ids == len(points), ref_i == len(points))
    if k > 1:
        for row_d, row_i in zip(dist, ids):
            for a in range(k - 1):
                if row_d[a] == row_d[a + 1]:
                    assert row_i[a] < row_i[a + 1]


@pytest.mark.parametrize("k", [1, 2, 7])
def test_kdtree_knn_matches_ckdtree(rng, cloud_points, k):
    tree = index.KdTree(cloud_points)
    queries = np.vstack([cloud_points[:20], rng.uniform(-0.012, 0.012, size=(300, 3))])
    dist, ids = tree.query(queries, k=k)
    assert dist.shape == ids.shape == ((len(queries),) if k == 1 else (len(queries), k))
    assert ids.dtype == np.int64
    check_knn(dist, ids, cloud_points, queries, k)


def test_kdtree_radius_matches_ckdtree(rng, cloud_points):
    tree = index.KdTree(cloud_points)
    queries = rng.uniform(-0.01, 0.01, size=(200, 3))
    ref = spatial.cKDTree(cloud_points).query_ball_point(queries, 2e-3)
    got = tree.query_ball_point(queries, 2e-3)
    assert len(got) == len(queries)
    for q, ours, theirs in zip(queries, got, ref):
        assert sorted(ours.tolist()) == sorted(theirs)
        d = np.linalg.norm(cloud_points[ours] - q, axis=1)
        assert np.all(np.diff(d) >= 0)


def test_fewer_points_than_k_and_bad_input():
    tree = index.KdTree(np.array([[0.0, 0, 0], [1e-3, 0, 0]]))
    dist, ids = tree.query(np.zeros((1, 3)), k=4)
    np.testing.assert_array_equal(ids, [[0, 1, 2, 2]])
    assert np.isinf(dist[0, 2:]).all()
    d, i = tree.query(np.array([[np.nan, 0, 0]]))
    assert np.isinf(d[0]) and i[0] == 2
    with pytest.raises(ValueError, match="point 1 is not finite"):
        index.KdTree(np.array([[0.0, 0, 0], [np.inf, 0, 0]]))
    with pytest.raises(ValueError, match=r"\(M, 3\)"):
        tree.query(np.zeros(3))
    with pytest.raises(ValueError, match="k must be >= 1"):
        tree.query(np.zeros((1, 3)), k=0)
    with pytest.raises(ValueError, match="r must be >= 0"):
        tree.query_ball_point(np.zeros((1, 3)), -1.0)


def test_kdtree_view_pickle_and_threads(cloud_points):
    tree = index.KdTree(cloud_points, leaf_size=4)
    assert not tree.points.flags.writeable and len(tree) == len(cloud_points)
    np.testing.assert_array_equal(tree.points, cloud_points)
    assert repr(tree) == f"KdTree({len(cloud_points)} points, leaf_size=4)"
    for other in (pickle.loads(pickle.dumps(tree)), copy.deepcopy(tree)):
        assert other.leaf_size == 4
        np.testing.assert_array_equal(other.query(cloud_points[:50], k=3)[1], tree.query(cloud_points[:50], k=3)[1])
    results = [None] * 4

    def work(i):
        results[i] = tree.query(cloud_points, k=5)[1]

    threads = [threading.Thread(target=work, args=(i,)) for i in range(4)]
    for t in threads:
        t.start()
    for t in threads:
        t.join()
    for r in results:
        np.testing.assert_array_equal(r, results[0])


@pytest.mark.parametrize("index_name", fusion.INDEXES)
def test_contact_cloud_queries_match_ckdtree(rng, index_name):
    pts = sim.Sphere(0.03).sample_surface(3000, 4).points
    cloud = fusion.ContactCloud("kalman", index_name, association_radius=2e-3)
    cloud.insert(pts, sigma=2e-4)
    means = cloud.means
    queries = rng.normal(scale=0.03, size=(100, 3))
    for k in (1, 5):
        dist, ids = cloud.query(queries, k=k)
        check_knn(dist, ids, means, queries, k)
    ref = spatial.cKDTree(means).query_ball_point(queries, 5e-3)
    for ours, theirs in zip(cloud.query_ball_point(queries, 5e-3), ref):
        assert sorted(ours.tolist()) == sorted(theirs)


def test_point_cloud_arrays_are_read_only_views(rng):
    import gc

    import taxel

    pts = rng.normal(size=(1000, 3))
    normals = pts / np.linalg.norm(pts, axis=1, keepdims=True)
    pc = taxel.PointCloud(pts, normals, {"w": np.arange(1000.0)})
    a, b = pc.points, pc.points
    assert np.shares_memory(a, b)  # no copy: both look at the cloud's memory
    assert not np.shares_memory(a, pts)  # the constructor copied in
    for view in (a, pc.normals, pc.fields["w"]):
        assert not view.flags.writeable
        with pytest.raises(ValueError, match="read-only"):
            view[0] = 1.0
    del pc
    gc.collect()
    np.testing.assert_array_equal(a, pts)  # the view keeps the cloud alive
    np.testing.assert_array_equal(b[:, 0], pts[:, 0])
