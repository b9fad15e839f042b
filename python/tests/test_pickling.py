# SPDX-License-Identifier: MIT
"""Every value-like class pickles and deep-copies to an equal object; the few that hold live
state say so with a TypeError. The learners are in test_estimators.py."""
import copy
import inspect
import pickle

import numpy as np
import pytest

import taxel
from taxel import fusion, image, learn, optical, registration, sensor, sim

# Classes that do not pickle, with the reason (none today; a test keeps the list honest).
NOT_PICKLED = {}


def equal(a, b, path="obj"):
    """Deep equality of two taxel objects through their public attributes."""
    if isinstance(a, np.ndarray) or isinstance(b, np.ndarray):
        np.testing.assert_array_equal(np.asarray(a), np.asarray(b), err_msg=path)
        return
    if isinstance(a, (list, tuple)):
        assert len(a) == len(b), path
        for i, (x, y) in enumerate(zip(a, b)):
            equal(x, y, f"{path}[{i}]")
        return
    if isinstance(a, dict):
        assert a.keys() == b.keys(), path
        for k in a:
            equal(a[k], b[k], f"{path}[{k!r}]")
        return
    if type(a).__module__.startswith("taxel"):
        assert type(a) is type(b), path
        # memory_bytes counts reserved capacity, which a copy need not repeat.
        names = [n for n in dir(a) if not n.startswith("_") and n != "memory_bytes"]
        for n in names:
            x = getattr(a, n)
            if callable(x):
                continue
            equal(x, getattr(b, n), f"{path}.{n}")
        return
    if isinstance(a, float) and np.isnan(a):
        assert np.isnan(b), path
        return
    assert a == b, path


def round_trips(obj):
    for other in (pickle.loads(pickle.dumps(obj)), copy.deepcopy(obj)):
        equal(obj, other)
    return pickle.loads(pickle.dumps(obj))


def test_shapes_and_configs():
    rng = np.random.default_rng(3)
    q = rng.normal(scale=0.05, size=(50, 3))
    mesh = sim.TriangleMesh(np.array([[0, 0, 0], [1, 0, 0], [0, 1, 0], [0, 0, 1.0]]) * 0.05,
                            np.array([[0, 2, 1], [0, 1, 3], [0, 3, 2], [1, 2, 3]]))
    shapes = [sim.Sphere(0.03), sim.Cylinder(0.02, 0.04), sim.Box(np.array([0.01, 0.02, 0.03])),
              sim.Cone(0.02, 0.05), sim.Ellipsoid(np.array([0.05, 0.03, 0.02])), sim.Torus(0.04, 0.01),
              mesh]
    for s in shapes:
        other = round_trips(s)
        np.testing.assert_array_equal(other.signed_distance(q), s.signed_distance(q))
    round_trips(sensor.SensorModel(rows=8, cols=4, pitch=2e-3, sigma_tilt=0.01))
    round_trips(sensor.ContactOptions(mode="per_pad", tactel_area=True))
    round_trips(registration.Icp(kernel="huber", kernel_scale=2e-3, max_iterations=7))
    synth = round_trips(sim.PalmGraspSynth(16, 16, fingers=3, seed=9))
    equal(synth.dataset(1, 1), sim.PalmGraspSynth(16, 16, fingers=3, seed=9).dataset(1, 1))


def test_clouds_contacts_and_fusion():
    pts = sim.Sphere(0.03).sample_surface(4000, 1).points
    normals = pts / np.linalg.norm(pts, axis=1, keepdims=True)
    pc = taxel.PointCloud(pts, normals, {"w": np.arange(len(pts), dtype=float)})
    round_trips(pc)
    assert copy.deepcopy(pc) is pc  # immutable
    round_trips(taxel.Contacts(pts[:100], normals=normals[:100], sigma=1e-3, times=np.arange(100.0)))
    for policy in fusion.POLICIES:
        cloud = fusion.ContactCloud(policy, association_radius=4e-3)
        cloud.insert(pts[:2000], sigma=3e-4, normals=normals[:2000])
        again = round_trips(cloud)
        # The copy fuses on exactly as the original.
        assert cloud.insert(pts[2000:], sigma=3e-4) == again.insert(pts[2000:], sigma=3e-4)
        equal(cloud.to_point_cloud(), again.to_point_cloud())


def test_results():
    data = sim.PalmGraspSynth(seed=2).dataset(1, 1)
    img = data["images"][0]
    round_trips(image.segment(img))
    round_trips(image.kmeans1d(img, 3))
    rec = image.Recognizer()
    round_trips(rec.recognize(img))
    equal(round_trips(rec).recognize(img), rec.recognize(img))
    target_pts = sim.Sphere(0.03).sample_surface(500, 2).points
    target = registration.Target(target_pts)
    round_trips(registration.Icp().align(target, target_pts[::3] + 1e-3))
    lib = registration.ObjectLibrary()
    lib.add("ball", target_pts)
    lib.add("box", sim.Box().sample_surface(500, 3).points)
    rec3d = lib.recognize(target_pts[::5])
    round_trips(rec3d)
    # Targets and libraries rebuild their indexes, and then answer as the originals.
    t2 = round_trips(target)
    equal(t2.nearest(target_pts[:30] + 1e-4), target.nearest(target_pts[:30] + 1e-4))
    lib2 = round_trips(lib)
    equal(lib2.recognize(target_pts[::5]), rec3d)
    x = np.random.default_rng(1).normal(size=(60, 3))
    y = np.arange(60) % 2
    x[y == 1] += 2
    round_trips(learn.cross_validate(learn.Lda(), x, y, folds=3))
    round_trips(learn.five_by_two_cv(learn.Lda(), learn.Knn(), x, y))


def test_explorations_trackers_and_reconstructors():
    ex = sim.explore_sliding(sim.Sphere(0.03), slides=1, frames=20, seed=3)
    again = round_trips(ex)
    np.testing.assert_array_equal(again.readings, ex.readings)
    np.testing.assert_array_equal(again.poses(), ex.poses())
    rng = np.random.default_rng(5)
    grid = np.stack(np.meshgrid(np.arange(10.0, 200, 20), np.arange(10.0, 150, 20)), axis=-1).reshape(-1, 2)
    dots = np.column_stack([grid, np.full(len(grid), 12.0)])
    tracker = optical.MarkerTracker(dots)
    tracker.update(dots + [[1.5, -0.5, 0]])
    twin = round_trips(tracker)
    moved = dots + [[3.0, -1.0, 0]]
    moved = moved[rng.permutation(len(moved))[5:]]  # some lost
    tracker.update(moved)
    twin.update(moved)
    equal(twin.tracks, tracker.tracks)


def test_every_class_is_covered():
    """A new class must pickle (and be tested above) or be listed in NOT_PICKLED."""
    import copyreg

    missing = []
    for sub in ("fusion", "image", "io", "optical", "registration", "sensor", "shape", "sim"):
        mod = getattr(taxel, sub)
        for name, cls in vars(mod).items():
            if not inspect.isclass(cls) or issubclass(cls, BaseException) or name.startswith("_"):
                continue
            if f"{sub}.{name}" in NOT_PICKLED:
                continue
            if "__setstate__" not in vars(cls) and cls not in copyreg.dispatch_table:
                missing.append(f"{sub}.{name}")
    assert missing == []
