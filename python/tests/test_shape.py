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
    s = shape.ImplicitSurface(expert_size=L, normal_offset=0.0, inside_offset=0.0, min_sigma=1e-6,
                              prior_centre=centre, prior_radius=radius, length_scale=0.012,
                              sigma=0.008)
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


def _cap(centre_dir, n, r=0.03, half_angle=0.35, seed=0):
    """n contacts on a cap of a sphere of radius r around unit direction centre_dir."""
    rng = np.random.default_rng(seed)
    d = np.asarray(centre_dir, float) / np.linalg.norm(centre_dir)
    u = d + half_angle * rng.normal(size=(n, 3))
    u /= np.linalg.norm(u, axis=1, keepdims=True)
    return r * u, u


def test_explorer_fuses_touches_and_scores_the_untouched_side():
    ex = shape.Explorer(workspace_min=[-0.045] * 3, workspace_max=[0.045] * 3, grid_spacing=3e-3)
    assert len(ex) == 0 and "Explorer(0 fused points" in repr(ex)
    added = 0
    for k, d in enumerate([(1, 0, 0), (0, 1, 0), (0, 0, 1), (-1, 0, 0), (0, -1, 0)]):
        p, n = _cap(d, 300, seed=k)
        added += ex.add_contacts(p, normals=n, sigma=2e-4)
    assert added >= len(ex) and 0 < len(ex) <= 1500  # added or moved
    assert ex.points.shape == (len(ex), 3)
    assert abs(ex.prior_radius - 0.03) < 2e-3  # refitted to the points' mean distance
    est = ex.estimate()
    r = np.linalg.norm(est["vertices"], axis=1)
    assert est["triangles"].dtype == np.uint32 and len(est["triangles"]) > 0
    # Where touched (+x), the estimate lies on the sphere, and is surer than on the -z side.
    touched = est["vertices"][:, 0] > 0.025
    assert np.abs(r[touched] - 0.03).max() < 1e-3
    untouched = est["vertices"][:, 2] < -0.025
    assert est["sigma"][touched].mean() < 0.5 * est["sigma"][untouched].mean()
    field = ex.field()
    assert field.shape == (31, 31, 31) and np.isclose(ex.grid_spacing, 3e-3)
    # The field sampled on the grid is the surface's mean there.
    node = ex.grid_origin + ex.grid_spacing * np.array([20, 15, 15])
    mean, var = ex.predict(node[None])
    assert abs(field[20, 15, 15] - mean[0]) < 1e-12 and var[0] >= 0
    # Two rays at the centre, from +x (touched) and from -z (not): -z teaches more.
    origins = np.array([[0.07, 0, 0], [0, 0, -0.07]])
    scores = ex.score(origins, -origins / 0.07)
    assert scores["contact"].all()
    assert scores["gain"][1] > 2 * scores["gain"][0]
    np.testing.assert_allclose(np.linalg.norm(scores["point"], axis=1), 0.03, atol=1.5e-3)
    # Free space along a ray that passes the sphere.
    assert ex.add_free_space([0.07, 0.0, 0.04], [-0.07, 0.0, 0.04]) >= 0


def test_explorer_pickles_and_copies_whole():
    ex = shape.Explorer(workspace_min=[-0.045] * 3, workspace_max=[0.045] * 3, grid_spacing=3e-3,
                        inside_offset=0.002)
    for k, d in enumerate([(1, 0, 0), (0, 1, 0), (0, 0, 1)]):
        p, n = _cap(d, 200, seed=k)
        ex.add_contacts(p, normals=n, sigma=2e-4)
    ex.add_free_space([0.07, 0.0, 0.04], [-0.07, 0.0, 0.04])
    for twin in (pickle.loads(pickle.dumps(ex)), copy.deepcopy(ex)):
        assert len(twin) == len(ex) and twin.prior_radius == ex.prior_radius
        np.testing.assert_array_equal(twin.points, ex.points)
        np.testing.assert_allclose(twin.field(), ex.field(), atol=1e-12)
        a, b = twin.estimate(), ex.estimate()
        np.testing.assert_allclose(a["vertices"], b["vertices"], atol=1e-9)
        np.testing.assert_allclose(a["sigma"], b["sigma"], atol=1e-9)
        # And they go on alike.
        p, n = _cap((-1, 0, 0), 200, seed=9)
        assert twin.add_contacts(p, normals=n, sigma=2e-4) > 0
    ex.add_contacts(p, normals=n, sigma=2e-4)
    assert len(twin) == len(ex)
    np.testing.assert_allclose(twin.field(), ex.field(), atol=1e-12)
    state = ex.__getstate__()
    broken = (state[0], (state[1][0], state[1][1], state[1][2], state[1][3], state[1][4],
                         state[1][5][:-1]))
    with pytest.raises(ValueError, match="surface ids"):
        shape.Explorer.__new__(shape.Explorer).__setstate__(broken)


def test_explorer_refuses_bad_input():
    with pytest.raises(ValueError, match="grid_spacing|spacing"):
        shape.Explorer(grid_spacing=0.0)
    with pytest.raises(ValueError, match="2\\^27 grid nodes"):
        shape.Explorer(workspace_min=[-10.0] * 3, workspace_max=[10.0] * 3, grid_spacing=1e-3)
    with pytest.raises(ValueError, match="inside_offset"):
        shape.Explorer(inside_offset=-1.0)
    ex = shape.Explorer()
    p = np.array([[0.0, 0.0, 0.03], [np.nan, 0.0, 0.0]])
    with pytest.raises(ValueError, match="contact 1"):
        ex.add_contacts(p, sigma=1e-3)
    assert len(ex) == 0  # nothing was added
    with pytest.raises(ValueError, match="differ in length"):
        ex.score(np.zeros((2, 3)), np.ones((3, 3)))
    with pytest.raises(ValueError, match="max_distance"):
        ex.score(np.zeros((1, 3)), np.ones((1, 3)), max_distance=-1.0)


def test_explorer_threads_add_and_score_together():
    ex = shape.Explorer(workspace_min=[-0.045] * 3, workspace_max=[0.045] * 3, grid_spacing=3e-3)
    errors = []

    def add(k):
        try:
            p, n = _cap([(1, 0, 0), (0, 1, 0), (0, 0, 1), (0, 0, -1)][k], 200, seed=k)
            ex.add_contacts(p, normals=n, sigma=2e-4)
            ex.estimate()
            ex.score(np.array([[0.07, 0.0, 0.0]]), np.array([[-1.0, 0.0, 0.0]]))
        except Exception as e:  # noqa: BLE001
            errors.append(e)

    threads = [threading.Thread(target=add, args=(k,)) for k in range(4)]
    for t in threads:
        t.start()
    for t in threads:
        t.join()
    assert not errors
    # The same contacts one after another give the same fused cloud size.
    one = shape.Explorer(workspace_min=[-0.045] * 3, workspace_max=[0.045] * 3, grid_spacing=3e-3)
    for k in range(4):
        p, n = _cap([(1, 0, 0), (0, 1, 0), (0, 0, 1), (0, 0, -1)][k], 200, seed=k)
        one.add_contacts(p, normals=n, sigma=2e-4)
    assert abs(len(one) - len(ex)) <= 0.02 * len(one)  # order changes which contacts merge


def _ball(r, n=2000, seed=0):
    p, _ = _sphere_points(n, r, seed)
    return p


def _brick(a, b, c, n=3000, seed=0):
    rng = np.random.default_rng(seed)
    p = rng.uniform(-1, 1, size=(n, 3)) * [a, b, c]
    axis = rng.integers(0, 3, size=n)
    p[np.arange(n), axis] = np.sign(rng.uniform(-1, 1, n)) * np.array([a, b, c])[axis]
    return p


def test_recognition_belief_and_touch_scores():
    lib = taxel.registration.ObjectLibrary()
    lib.add("ball", _ball(0.03))
    lib.add("brick", _brick(0.04, 0.03, 0.02))
    cloud = _ball(0.03, 400, seed=5)
    cloud = cloud[cloud[:, 2] > 0.01]  # a cap: the ball explains it, the brick does not
    belief = shape.hypotheses(lib.recognize(cloud), len(cloud))
    assert [h.name for h in belief][0] == "ball"
    assert abs(sum(h.probability for h in belief) - 1.0) < 1e-12
    assert belief[0].model_from_world.shape == (4, 4)
    h2 = pickle.loads(pickle.dumps(belief[0]))
    assert h2.name == "ball" and h2.probability == belief[0].probability
    # Two equally likely hypotheses, both at the identity: a ray at 33 mm from the centre along
    # +z meets the ball (within tolerance) and misses the brick; one through the centre meets
    # both at 10 mm apart.
    eq = [shape.Hypothesis(name="ball", model=0, model_from_world=np.eye(4), probability=0.5),
          shape.Hypothesis(name="brick", model=1, model_from_world=np.eye(4), probability=0.5)]
    origins = np.array([[-0.1, 0.0, 0.028], [-0.1, 0.0, 0.0], [-0.1, 0.0, 0.2]])
    dirs = np.array([[1.0, 0, 0]] * 3)
    gain = shape.score_recognition_touches(lib, eq, origins, dirs, confusion=1e-3)
    # Hit against miss: each outcome leaves p = (1, c) / (1 + c): gain = ln 2 - H(1 / (1 + c)).
    c = 1e-3
    q = np.array([1.0, c]) / (1.0 + c)
    want = np.log(2.0) + (q * np.log(q)).sum()
    assert gain[0] == pytest.approx(want, rel=1e-9)
    assert 0.0 < gain[1] <= np.log(2.0) + 1e-12  # both hit, 10 mm apart at ray_sigma 2 mm
    assert gain[2] == pytest.approx(0.0, abs=1e-12)  # both miss: nothing learnt
    with pytest.raises(ValueError, match="no model 7"):
        shape.score_recognition_touches(
            lib, [eq[0], shape.Hypothesis(name="x", model=7, model_from_world=np.eye(4),
                                          probability=0.5)], origins, dirs)
    with pytest.raises(ValueError, match="rigid|model_from_world"):
        shape.Hypothesis(name="x", model=0, model_from_world=np.ones((4, 4)), probability=1.0)
