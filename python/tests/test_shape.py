# SPDX-License-Identifier: MIT
"""taxel.shape: the implicit surface against scikit-learn's Gaussian process, its mesh, touch
scoring, pickling, threads and bad input."""
import copy
import pickle
import threading

import numpy as np
import pytest

import taxel
from taxel import shape


def _sphere_points(n, r=0.02, seed=0):
    rng = np.random.default_rng(seed)
    u = rng.normal(size=(n, 3))
    u /= np.linalg.norm(u, axis=1, keepdims=True)
    return r * u, u


def test_matches_scikit_learn_where_one_expert_holds_every_point():
    sklearn = pytest.importorskip("sklearn.gaussian_process")
    kernels = pytest.importorskip("sklearn.gaussian_process.kernels")
    rng = np.random.default_rng(3)
    L = 0.03
    # In the lower half of cell 0 along every axis: the experts around hold every point.
    x = rng.uniform(0.001, 0.5 * L - 0.001, size=(10, 3))
    normals = rng.normal(size=(10, 3))
    var = rng.uniform(1e-8, 4e-7, size=10)
    centre, radius = np.array([0.004, 0.006, 0.005]), 0.003
    s = shape.ImplicitSurface(expert_size=L, normal_offset=0.0, inside_offset=0.0, min_sigma=1e-6, prior_centre=centre,
                              prior_radius=radius, length_scale=0.012, sigma=0.008)
    assert (s.insert(x, normals, var) >= 0).all()
    prior = lambda p: np.linalg.norm(p - centre, axis=1) - radius  # noqa: E731
    gp = sklearn.GaussianProcessRegressor(
        kernels.ConstantKernel(0.008**2, "fixed") * kernels.Matern(0.012, "fixed", nu=1.5),
        alpha=var, optimizer=None)
    gp.fit(x, -prior(x))  # the surface observes f = 0: residual -m(x)
    q = rng.uniform(-0.8 * L, 0.8 * L, size=(20, 3))
    mean, variance, gradient = s.predict(q)
    want_mean, want_std = gp.predict(q, return_std=True)
    np.testing.assert_allclose(mean, want_mean + prior(q), rtol=1e-7, atol=1e-12)
    np.testing.assert_allclose(np.sqrt(variance), want_std, rtol=1e-7)
    np.testing.assert_allclose(s.mean(q), mean, atol=1e-14)
    h = 1e-7
    fd = np.stack([(s.mean(q + h * e) - s.mean(q - h * e)) / (2 * h) for e in np.eye(3)], axis=1)
    np.testing.assert_allclose(gradient, fd, atol=1e-5)


def test_mesh_of_a_sphere_and_its_sigma():
    p, n = _sphere_points(600, 0.02)
    s = shape.ImplicitSurface(expert_size=0.01, prior_radius=0.015)
    ids = s.insert(p, n, np.full(600, 1e-8))
    assert len(s) == 600 and (ids == np.arange(600)).all()
    m = s.mesh([-0.03] * 3, [0.03] * 3, 0.002)
    r = np.linalg.norm(m["vertices"], axis=1)
    assert m["triangles"].dtype == np.uint32 and m["triangles"].shape[1] == 3
    assert np.abs(r - 0.02).max() < 1e-3
    assert m["sigma"].shape == r.shape and m["sigma"].max() < 2e-3
    assert (np.einsum("ij,ij->i", m["normals"], m["vertices"]) > 0).mean() > 0.99


def test_score_touches_prefers_the_untouched_side():
    p, n = _sphere_points(400, 0.02)
    top = p[:, 2] > 0.005
    s = shape.ImplicitSurface(expert_size=0.01, prior_radius=0.02)
    s.insert(p[top], n[top])
    m = s.mesh([-0.03] * 3, [0.03] * 3, 0.003)
    origins = np.array([[0.0, 0.0, 0.06], [0.0, 0.0, -0.06], [0.1, 0.1, 0.1]])
    directions = np.array([[0.0, 0.0, -1.0], [0.0, 0.0, 1.0], [1.0, 0.0, 0.0]])
    r = s.score_touches(origins, directions, m["vertices"], [-0.03] * 3, [0.03] * 3)
    assert r["contact"].tolist() == [True, True, False]
    assert r["gain"][1] > 3 * r["gain"][0] and r["gain"][2] == 0.0
    np.testing.assert_allclose(np.linalg.norm(r["point"][:2], axis=1), 0.02, atol=1e-3)
    o, d = shape.approach_rays([0, 0, 0], 0.08, 0.02, 50, seed=4)
    o2, d2 = shape.approach_rays([0, 0, 0], 0.08, 0.02, 50, seed=4)
    assert o.shape == (50, 3) and (o == o2).all() and (d == d2).all()
    np.testing.assert_allclose(np.linalg.norm(o, axis=1), 0.08)
    np.testing.assert_allclose(np.linalg.norm(d, axis=1), 1.0)


def test_marching_tetrahedra_on_a_sampled_sphere():
    h, R = 0.002, 0.02
    g = np.arange(-0.025, 0.0251, h)
    X, Y, Z = np.meshgrid(g, g, g, indexing="ij")
    f = np.sqrt(X**2 + Y**2 + Z**2) - R
    v, t = shape.marching_tetrahedra(f, [g[0]] * 3, h)
    bound = 3 * h * h / 8 / (R - np.sqrt(3) * h)
    assert np.abs(np.linalg.norm(v, axis=1) - R).max() <= bound
    # Closed: every directed edge once, and its reverse once.
    edges = np.concatenate([t[:, [0, 1]], t[:, [1, 2]], t[:, [2, 0]]])
    assert len({tuple(e) for e in edges}) == len(edges)
    assert {tuple(e) for e in edges} == {tuple(e[::-1]) for e in edges}
    _, t_closed = shape.marching_tetrahedra(-np.ones((4, 4, 4)), [0, 0, 0], 1.0, close=True)
    assert len(t_closed) > 0
    with pytest.raises(ValueError, match="3-D"):
        shape.marching_tetrahedra(np.zeros((4, 4)), [0, 0, 0], 1.0)
    with pytest.raises(ValueError, match="not finite"):
        shape.marching_tetrahedra(np.full((3, 3, 3), np.nan), [0, 0, 0], 1.0)


def test_pickle_and_deepcopy_keep_every_point_and_id():
    p, n = _sphere_points(120, 0.02, seed=5)
    s = shape.ImplicitSurface(expert_size=0.012, prior_radius=0.018, length_scale=0.015)
    s.insert(p, n, np.full(120, 2e-8))
    s.erase(7)
    s.update(3, p[3] * 1.01, n[3], 1e-8)
    s.insert_free(np.array([[0.0, 0.0, 0.03]]), 0.003, 1e-6)
    q = np.random.default_rng(1).uniform(-0.03, 0.03, size=(30, 3))
    for twin in (pickle.loads(pickle.dumps(s)), copy.deepcopy(s)):
        assert len(twin) == len(s) and twin.expert_count == s.expert_count
        for a, b in zip(twin.predict(q), s.predict(q)):
            np.testing.assert_allclose(a, b, rtol=1e-9, atol=1e-15)
        with pytest.raises(IndexError):
            twin.erase(7)
    assert "ImplicitSurface(120 points" in repr(s)


def test_threads_share_a_surface():
    p, n = _sphere_points(2000, 0.02, seed=6)
    s = shape.ImplicitSurface(expert_size=0.01, prior_radius=0.02)
    q = np.random.default_rng(2).uniform(-0.03, 0.03, size=(500, 3))
    errors = []

    def writer():
        try:
            for k in range(0, 2000, 100):
                s.insert(p[k:k + 100], n[k:k + 100])
        except Exception as e:  # pragma: no cover - reported below
            errors.append(e)

    def reader():
        try:
            for _ in range(10):
                mean, var, _ = s.predict(q)
                assert np.isfinite(mean).all() and (var >= 0).all()
        except Exception as e:  # pragma: no cover - reported below
            errors.append(e)

    threads = [threading.Thread(target=writer)] + [threading.Thread(target=reader) for _ in range(3)]
    for t in threads:
        t.start()
    for t in threads:
        t.join()
    assert errors == [] and len(s) == 2000


def test_bad_input_is_refused_clearly():
    with pytest.raises(ValueError, match="expert_size"):
        shape.ImplicitSurface(expert_size=0.0)
    with pytest.raises(ValueError, match="length_scale"):
        shape.ImplicitSurface(length_scale=-1.0)
    s = shape.ImplicitSurface()
    ids = s.insert(np.array([[0.0, 0.0, np.nan], [0.0, 0.0, 0.01]]), np.array([[0, 0, 1.0], [0, 0, 0.0]]))
    assert ids.tolist() == [-1, -1] and len(s) == 0
    with pytest.raises(ValueError, match="differ in length"):
        s.insert(np.zeros((2, 3)), np.zeros((3, 3)))
    with pytest.raises(ValueError, match=r"\(N, 3\)"):
        s.predict(np.zeros((4, 2)))
    with pytest.raises(IndexError):
        s.erase(0)
    with pytest.raises(ValueError, match="spacing"):
        s.mesh([0, 0, 0], [1, 1, 1], 0.0)
    with pytest.raises(ValueError, match="standoff"):
        shape.approach_rays([0, 0, 0], 0.01, 0.02, 3)
    with pytest.raises(ValueError, match="noise_sigma"):
        s.score_touches(np.zeros((1, 3)), np.ones((1, 3)), np.zeros((1, 3)), [-1] * 3, [1] * 3,
                        spacing=0.1, noise_sigma=0.0)
    assert taxel.shape is shape
