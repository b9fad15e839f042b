# SPDX-License-Identifier: MIT
"""Readers and writers: round trips, numpy's own files, and bad files refused by name."""
import numpy as np
import pytest

import taxel
from taxel import io, registration, sim


def test_ply_round_trip(tmp_path, rng):
    pts = rng.normal(size=(50, 3))
    normals = pts / np.linalg.norm(pts, axis=1, keepdims=True)
    cloud = taxel.PointCloud(pts, normals, {"observations": np.arange(50.0)})
    tri = np.array([[0, 1, 2], [2, 3, 4]])
    for binary in (True, False):
        path = tmp_path / f"c{binary}.ply"
        io.write_ply(str(path), cloud, tri, binary=binary)
        back, faces = io.read_ply(str(path))
        np.testing.assert_array_equal(back.points, pts)
        np.testing.assert_array_equal(back.normals, normals)
        np.testing.assert_array_equal(back.fields["observations"], np.arange(50.0))
        np.testing.assert_array_equal(faces, tri)


def test_bad_files_are_refused_by_name(tmp_path):
    with pytest.raises(taxel.IoError, match="missing.ply"):
        io.read_ply(str(tmp_path / "missing.ply"))
    cut = tmp_path / "cut.ply"
    cut.write_bytes(b"ply\nformat binary_little_endian 1.0\nelement vertex 10\nproperty double x\n"
                    b"property double y\nproperty double z\nend_header\n" + b"\0" * 40)
    with pytest.raises(OSError, match="cut.ply"):
        io.read_ply(str(cut))
    with pytest.raises(ValueError, match="triangles"):
        io.write_ply(str(tmp_path / "t.ply"), taxel.PointCloud(np.zeros((3, 3))), np.array([[0, 1, 5]]))
    assert not (tmp_path / "t.ply").exists()
    with pytest.raises(OSError):
        io.write_image(str(tmp_path / "no" / "dir" / "x.npy"), np.zeros((2, 2)))
    assert list(tmp_path.iterdir()) == [cut]  # nothing partial left behind


def test_images_read_numpy_files_and_round_trip(tmp_path, rng):
    stack = rng.uniform(0, 255, size=(4, 6, 5))
    np.save(tmp_path / "s.npy", stack)
    np.testing.assert_array_equal(io.read_image(str(tmp_path / "s.npy")), stack)
    np.save(tmp_path / "u8.npy", stack.astype(np.uint8))
    np.testing.assert_array_equal(io.read_image(str(tmp_path / "u8.npy")), stack.astype(np.uint8))
    np.savetxt(tmp_path / "t.csv", stack[0])  # whitespace-separated, numpy's default
    np.testing.assert_allclose(io.read_image(str(tmp_path / "t.csv"))[0], stack[0], rtol=1e-15)
    io.write_image(str(tmp_path / "w.csv"), stack[0])
    np.testing.assert_array_equal(io.read_image(str(tmp_path / "w.csv"))[0], stack[0])
    io.write_image(str(tmp_path / "w.npy"), stack)
    np.testing.assert_array_equal(np.load(tmp_path / "w.npy"), stack)
    levels = np.round(stack[0])
    io.write_image(str(tmp_path / "w.pgm"), levels)
    np.testing.assert_array_equal(io.read_image(str(tmp_path / "w.pgm"))[0], levels)
    bad = tmp_path / "bad.csv"
    bad.write_text("1,2,3\n4,nan,6\n")
    with pytest.raises(OSError, match="pixel row 1, column 1"):
        io.read_image(str(bad))
    with pytest.raises(ValueError, match="only be written as .npy"):
        io.write_image(str(tmp_path / "x.csv"), stack)


def test_contacts_csv(tmp_path, rng):
    pos = rng.normal(size=(20, 3)) * 0.01
    normals = np.full((20, 3), np.nan)
    normals[::2] = [0, 0, 1]
    c = taxel.Contacts(pos, sigma=2e-4, normals=normals, times=np.arange(20) * 1e-3)
    path = tmp_path / "c.csv"
    io.write_contacts_csv(str(path), c)
    back = io.read_contacts_csv(str(path))
    np.testing.assert_array_equal(back.positions, c.positions)
    np.testing.assert_array_equal(back.covariances, c.covariances)
    np.testing.assert_array_equal(back.normals, c.normals)
    lines = path.read_text().splitlines()
    lines[3] = lines[3].replace(lines[3].split(",")[1], "oops", 1)
    path.write_text("\n".join(lines) + "\n")
    with pytest.raises(OSError, match="c.csv:4"):
        io.read_contacts_csv(str(path))
    with pytest.warns(UserWarning, match="1 bad rows skipped"):
        assert len(io.read_contacts_csv(str(path), strict=False)) == 19


def test_pad_poses_csv(tmp_path):
    path = tmp_path / "poses.csv"
    path.write_text("frame,pad,time,x,y,z,qw,qx,qy,qz\n0,0,0.5,0.1,0.2,0.3,1,0,0,0\n1,0,0.6,0,0,0,0,0,0,1\n")
    p = io.read_pad_poses_csv(str(path))
    np.testing.assert_array_equal(p["frame"], [0, 1])
    np.testing.assert_allclose(p["pose"][0][:3, 3], [0.1, 0.2, 0.3])
    np.testing.assert_allclose(p["pose"][1][:3, :3], np.diag([-1.0, -1.0, 1.0]), atol=1e-15)


def test_model_cloud_samples_a_mesh(tmp_path):
    path = tmp_path / "ball.ply"
    # An icosahedron: 12 vertices, 20 faces.
    t = (1 + 5 ** 0.5) / 2
    v = np.array([[-1, t, 0], [1, t, 0], [-1, -t, 0], [1, -t, 0], [0, -1, t], [0, 1, t],
                  [0, -1, -t], [0, 1, -t], [t, 0, -1], [t, 0, 1], [-t, 0, -1], [-t, 0, 1]]) * 0.01
    f = np.array([[0, 11, 5], [0, 5, 1], [0, 1, 7], [0, 7, 10], [0, 10, 11], [1, 5, 9], [5, 11, 4],
                  [11, 10, 2], [10, 7, 6], [7, 1, 8], [3, 9, 4], [3, 4, 2], [3, 2, 6], [3, 6, 8],
                  [3, 8, 9], [4, 9, 5], [2, 4, 11], [6, 2, 10], [8, 6, 7], [9, 8, 1]])
    io.write_ply(str(path), taxel.PointCloud(v), f)
    cloud, text = registration.model_cloud(str(path), spacing=1e-3)
    area = sim.TriangleMesh(v, f).surface_area()
    assert abs(len(cloud) - area / 1e-6) < 0.05 * area / 1e-6
    assert text.startswith(f"20 triangles: {len(cloud)} points sampled")
    assert np.abs(sim.TriangleMesh(v, f).signed_distance(cloud.points)).max() < 1e-12
