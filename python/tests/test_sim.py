# SPDX-License-Identifier: MIT
"""Shapes against closed forms; explorations deterministic and consistent."""
import numpy as np
import pytest

from taxel import sim


def test_sphere_closed_forms(rng):
    s = sim.Sphere(0.05)
    p = rng.normal(size=(100, 3)) * 0.1
    r = np.linalg.norm(p, axis=1)
    np.testing.assert_allclose(s.signed_distance(p), r - 0.05, atol=1e-15)
    np.testing.assert_allclose(s.closest_point(p), p / r[:, None] * 0.05, atol=1e-15)
    np.testing.assert_allclose(s.normal(p), p / r[:, None], atol=1e-15)
    assert s.surface_area() == pytest.approx(4 * np.pi * 0.05**2)


@pytest.mark.parametrize("shape", [sim.Sphere(), sim.Cylinder(), sim.Box(), sim.Cone(), sim.Ellipsoid(),
                                   sim.Torus(), sim.icosphere(0.03, 2)], ids=lambda s: type(s).__name__)
def test_samples_lie_on_the_surface(shape):
    pc = shape.sample_surface(2000, 5)
    assert len(pc) == 2000
    assert np.abs(shape.signed_distance(pc.points)).max() < 1e-9
    np.testing.assert_allclose(np.linalg.norm(pc.normals, axis=1), 1.0, atol=1e-12)
    np.testing.assert_array_equal(pc.points, shape.sample_surface(2000, 5).points)


def test_mesh_against_the_sphere_it_approximates(rng):
    mesh = sim.icosphere(0.04, 4)
    q = rng.normal(size=(300, 3)) * 0.05
    exact = sim.Sphere(0.04).signed_distance(q)
    assert np.abs(mesh.signed_distance(q) - exact).max() < 2e-4  # the chord error of the faces
    with pytest.raises(ValueError, match="no area"):
        sim.TriangleMesh(np.zeros((3, 3)), np.array([[0, 1, 2]]))
    with pytest.raises(ValueError, match="refers to vertex"):
        sim.TriangleMesh(np.eye(3), np.array([[0, 1, 3]]))


def test_exploration_is_deterministic_and_placed():
    t = np.eye(4)
    t[:3, 3] = [0.1, 0.0, 0.05]
    a = sim.explore_sliding(sim.Cylinder(), slides=2, frames=100, object_pose=t, seed=4)
    b = sim.explore_sliding(sim.Cylinder(), slides=2, frames=100, object_pose=t, seed=4)
    np.testing.assert_array_equal(a.contacts.positions, b.contacts.positions)
    assert len(a) == 200 and a.readings.shape == (200, 1, 14, 6)
    err = sim.surface_error(sim.Cylinder(), a.contacts.positions, t)
    assert err["rms"] < 1e-3 and abs(err["signed_mean"]) < err["rms"]
    far = sim.surface_error(sim.Cylinder(), a.contacts.positions)  # the wrong placement
    assert far["rms"] > 0.01
    with pytest.raises(ValueError, match="SlideParams"):
        sim.explore_sliding(sim.Sphere(), slides=0)
    with pytest.raises(ValueError, match="more than a million frames"):
        sim.explore_palpation(sim.Sphere(), touches=1, press_speed=1e-9)
    with pytest.raises(ValueError, match="indentation must be in"):
        sim.explore_sliding(sim.Sphere(), indentation=1.0e3)
    with pytest.raises(TypeError, match="shape"):
        sim.explore_sliding("sphere")


def test_palm_grasp_dataset():
    d = sim.PalmGraspSynth(seed=1).dataset(2, 3)
    assert d["images"].shape == (2 * 4 * 3 * 2, 32, 32)
    assert set(d["labels"]) == {1, 2, 3, 4}
    assert d["images"].min() >= 0 and d["images"].max() <= 255
