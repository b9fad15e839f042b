# SPDX-License-Identifier: MIT
"""ICP against known transforms; object recognition against the truth."""
import numpy as np
import pytest
from conftest import pose

from taxel import registration, sim


def surface(shape, n=3000, seed=1):
    return shape.sample_surface(n, seed).points


@pytest.mark.parametrize("error", ["point_to_plane", "point_to_point"])
@pytest.mark.parametrize("kernel", ["none", "huber", "cauchy", "geman_mcclure", "tukey"])
def test_icp_recovers_a_known_transform(error, kernel):
    model = surface(sim.Ellipsoid())
    truth = pose([1, 2, 3], 0.12, [0.004, -0.003, 0.002])  # T_target_source
    source = (model - truth[:3, 3]) @ truth[:3, :3]  # truth^-1 applied to the model
    result = registration.Icp(error, kernel, max_iterations=100).align(registration.Target(model), source)
    assert result.ok, result.message
    np.testing.assert_allclose(result.transform, truth, atol=1e-7)
    assert result.rmse < 1e-8
    assert result.inliers == len(source)


def test_icp_initial_guess_and_errors():
    model = surface(sim.Box())
    target = registration.Target(model)
    truth = pose([0, 0, 1], 0.3, [0.01, 0, 0])
    source = (model - truth[:3, 3]) @ truth[:3, :3]
    result = registration.Icp().align(target, source, initial=truth)
    assert result.ok and result.iterations <= 2
    np.testing.assert_allclose(result.transform, truth, atol=1e-9)
    with pytest.raises(ValueError, match="not a rotation"):
        registration.Icp().align(target, source, initial=np.diag([2.0, 1, 1, 1]))
    with pytest.raises(ValueError, match="trim_fraction"):
        registration.Icp(trim_fraction=1.5)
    with pytest.raises(ValueError, match="unknown value 'welsch'"):
        registration.Icp(kernel="welsch")
    with pytest.raises(ValueError):
        registration.Target(np.zeros((0, 3)))
    # NaN source points are skipped and counted, not fatal.
    noisy = source.copy()
    noisy[0] = np.nan
    assert registration.Icp().align(target, noisy, initial=truth).skipped == 1


def test_target_nearest_matches_brute_force(rng):
    model = surface(sim.Torus(), 2000)
    target = registration.Target(model)
    q = rng.uniform(-0.06, 0.06, size=(200, 3))
    ids, dist = target.nearest(q)
    d = np.linalg.norm(target.points[None, :, :] - q[:, None, :], axis=2)
    np.testing.assert_allclose(dist, d.min(axis=1), rtol=1e-12)
    np.testing.assert_allclose(d[np.arange(len(q)), ids], dist, rtol=1e-12)


def test_object_library_ranks_the_true_object_first():
    shapes = {"box": sim.Box(), "cylinder": sim.Cylinder(), "cone": sim.Cone(), "torus": sim.Torus()}
    lib = registration.ObjectLibrary()
    for name, shape in shapes.items():
        lib.add(name, surface(shape, 4000))
    assert lib.names == list(shapes)
    truth = pose([1, 1, 0], 0.4, [0.01, 0.02, -0.01])
    for name, shape in shapes.items():
        cloud = surface(shape, 600, seed=7)  # other samples than the model's
        seen = cloud @ truth[:3, :3].T + truth[:3, 3]
        rec = lib.recognize(seen)
        assert rec.best == name, rec.ranking
        # The score is a distance to the nearest model point, about half the model spacing.
        assert rec.ranking[0].score < 2e-3 and rec.margin > 0
        # The pose maps the cloud onto the model.
        t = rec.ranking[0].transform
        back = seen @ t[:3, :3].T + t[:3, 3]
        assert np.abs(shape.signed_distance(back)).max() < 2e-3
    # One thread or three: the same ranking, scores and poses, to the bit.
    single = registration.ObjectLibrary(threads=1)
    triple = registration.ObjectLibrary(threads=3)
    for name, shape in shapes.items():
        single.add(name, surface(shape, 4000))
        triple.add(name, surface(shape, 4000))
    seen = surface(shapes["cone"], 600, seed=7) @ truth[:3, :3].T + truth[:3, 3]
    a, b = single.recognize(seen), triple.recognize(seen)
    assert [m.name for m in a.ranking] == [m.name for m in b.ranking]
    assert [m.score for m in a.ranking] == [m.score for m in b.ranking]
    for ma, mb in zip(a.ranking, b.ranking):
        assert np.array_equal(ma.transform, mb.transform)
