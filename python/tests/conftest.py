# SPDX-License-Identifier: MIT
import numpy as np
import pytest


@pytest.fixture
def rng():
    return np.random.default_rng(20261123)


def rotation(axis, angle):
    """Rodrigues' rotation matrix."""
    axis = np.asarray(axis, float) / np.linalg.norm(axis)
    k = np.array([[0, -axis[2], axis[1]], [axis[2], 0, -axis[0]], [-axis[1], axis[0], 0]])
    return np.eye(3) + np.sin(angle) * k + (1 - np.cos(angle)) * k @ k


def pose(axis, angle, translation):
    t = np.eye(4)
    t[:3, :3] = rotation(axis, angle)
    t[:3, 3] = translation
    return t
