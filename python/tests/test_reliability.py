# SPDX-License-Identifier: MIT
"""Hostile inputs and threads: every bad argument raises a clear error, nothing is truncated,
wrapped or corrupted, and objects shared between threads stay whole."""
import threading

import numpy as np
import pytest

from taxel import fusion, image, learn, sensor


def _pad_stack(value=None):
    readings = np.zeros((2, 14, 6))
    if value is not None:
        readings[0, 1, 2] = value
    return readings, np.tile(np.eye(4), (2, 1, 1))


@pytest.mark.parametrize("value", [65536 + 100, 100.7, np.nan, np.inf, 1e10, -1])
def test_readings_outside_uint16_or_fractional_are_refused(value):
    readings, poses = _pad_stack(value)
    with pytest.raises(ValueError, match=r"whole numbers in \[0, 65535\].*at \[0, 1, 2\]"):
        sensor.contacts_from_readings(readings, poses)
    cloud = fusion.ContactCloud()
    with pytest.raises(ValueError, match="whole numbers"):
        cloud.insert_readings(readings, poses)
    assert len(cloud) == 0


def test_readings_as_whole_floats_or_wide_integers_are_read_exactly():
    readings, poses = _pad_stack()
    readings[0, 3:6, 2:4] = 900.0
    as_float = sensor.contacts_from_readings(readings, poses)
    as_int64 = sensor.contacts_from_readings(readings.astype(np.int64), poses)
    as_u16 = sensor.contacts_from_readings(readings.astype(np.uint16), poses)
    assert len(as_float) == len(as_int64) == len(as_u16) > 0


@pytest.mark.parametrize(
    "y, why",
    [
        ([1.2, 2.7], "got 1.2"),
        ([0.1, 0.9], "got 0.1"),
    ],
)
def test_labels_are_whole_numbers_in_range(y, why):
    x = np.random.default_rng(1).random((10, 3))
    labels = np.array(y * 5)
    with pytest.raises(ValueError, match=why):
        learn.LinearSvm().fit(x, labels)


def test_whole_float_labels_train_their_classes():
    x = np.random.default_rng(1).random((10, 3))
    model = learn.LinearSvm().fit(x, np.array([3.0, 7.0] * 5))
    assert list(model.classes_) == [3, 7] or list(model.classes_) == [7, 3]


def test_regionprops_refuses_fractional_and_overflowing_labels():
    labels = np.zeros((4, 4), np.int64)
    labels[0, 0] = 2**32 + 1
    labels[3, 3] = 1
    with pytest.raises(ValueError, match="4294967297"):
        image.regionprops(labels)
    with pytest.raises(ValueError, match="1.5"):
        image.regionprops(np.full((3, 3), 1.5))
    whole = np.zeros((3, 3))
    whole[1, 1] = 1.0
    assert [r["area"] for r in image.regionprops(whole)] == [1]


@pytest.mark.parametrize(
    "positions",
    [
        np.array([["0", "0", "0"]]),
        np.array([[1 + 1j, 0, 0]]),
        np.array([[np.datetime64("2026-01-01")] * 3]),
        np.array([[0.0, None, 0.0]], dtype=object),
    ],
)
def test_positions_must_be_real_numbers(positions):
    cloud = fusion.ContactCloud()
    with pytest.raises(TypeError, match="real numbers"):
        cloud.insert(positions)
    assert len(cloud) == 0


def test_strict_insert_refuses_what_the_cloud_would_reject_and_inserts_nothing():
    cloud = fusion.ContactCloud()
    with pytest.raises(ValueError, match="contact 1: .*range.*nothing was inserted"):
        cloud.insert(np.array([[0.0, 0.0, 0.0], [1e7, 0.0, 0.0]]))
    assert len(cloud) == 0
    assert cloud.insert(np.array([[0.0, 0.0, 0.0], [1e7, 0.0, 0.0]]), strict=False) == {
        "added": 1,
        "fused": 0,
        "rejected": 1,
    }


def test_reserve_beyond_any_memory_says_so():
    cloud = fusion.ContactCloud()
    with pytest.raises((ValueError, MemoryError), match="reserve|memory"):
        cloud.reserve(2**62)
    assert len(cloud) == 0


def _sphere_contacts(rng, n):
    d = rng.normal(size=(n, 3))
    return 0.04 * d / np.linalg.norm(d, axis=1, keepdims=True)


def test_two_threads_inserting_into_one_cloud_keep_it_whole():
    """Failed before the lock: a segmentation fault, or 'id already stored' and a corrupt
    cloud, within a few hundred rounds."""
    rng = np.random.default_rng(7)
    batches = [_sphere_contacts(rng, 3) for _ in range(64)]
    cloud = fusion.ContactCloud("kalman")
    rounds = 10_000
    counts = []
    errors = []

    def insert():
        added = fused = 0
        try:
            for i in range(rounds // 2):
                r = cloud.insert(batches[i % len(batches)], sigma=1e-3)
                added += r["added"]
                fused += r["fused"]
        except Exception as e:  # noqa: BLE001 - reported below
            errors.append(e)
        counts.append((added, fused))

    threads = [threading.Thread(target=insert) for _ in range(2)]
    for t in threads:
        t.start()
    for t in threads:
        t.join()
    assert not errors
    added = sum(a for a, _ in counts)
    fused = sum(f for _, f in counts)
    assert added + fused == rounds * 3
    assert len(cloud) == added
    means = cloud.means
    assert np.isfinite(means).all()
    assert (cloud.observations.sum()) == rounds * 3


def test_reading_while_another_thread_inserts():
    rng = np.random.default_rng(8)
    cloud = fusion.ContactCloud()
    stop = threading.Event()
    errors = []
    rounds = 10_000

    def read():
        try:
            while not stop.is_set():
                m = cloud.means
                c = cloud.covariances
                assert m.shape[1:] == (3,) and c.shape[1:] == (3, 3)
                assert np.isfinite(m).all() and np.isfinite(c).all()
        except Exception as e:  # noqa: BLE001 - reported below
            errors.append(e)

    reader = threading.Thread(target=read)
    reader.start()
    try:
        for _ in range(rounds):
            cloud.insert(_sphere_contacts(rng, 2), sigma=1e-3)
    finally:
        stop.set()
        reader.join()
    assert not errors
    assert cloud.observations.sum() == 2 * rounds


def test_predicting_while_another_thread_refits():
    rng = np.random.default_rng(9)
    x = rng.random((200, 4))
    y = (x[:, 0] > 0.5).astype(int)
    model = learn.LinearSvm().fit(x, y)
    stop = threading.Event()
    errors = []

    def predict():
        try:
            while not stop.is_set():
                p = model.predict(x)
                assert set(np.unique(p)) <= {0, 1}
                assert model.decision_function(x).shape[0] == 200
        except Exception as e:  # noqa: BLE001 - reported below
            errors.append(e)

    reader = threading.Thread(target=predict)
    reader.start()
    try:
        for _ in range(200):
            model.fit(x, y)
    finally:
        stop.set()
        reader.join()
    assert not errors
