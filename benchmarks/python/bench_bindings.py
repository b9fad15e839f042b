#!/usr/bin/env python3
# SPDX-License-Identifier: MIT
"""Costs of the Python bindings: the overhead of small calls; a point cloud's arrays (views, no
copy); k-nearest queries of taxel.index.KdTree against scipy's cKDTree; pickling; and a batch
insert of arrays against the same insert done by the C++ loop (a taxel.Contacts, converted
beforehand).

    PYTHONPATH=<build>/python python3 benchmarks/python/bench_bindings.py [--repeats 9]

Prints min and median over the repeats; the A/B pairs alternate, so machine noise hits both.
"""
import argparse
import statistics
import timeit

import numpy as np

import taxel
from taxel import fusion, image, learn, sim


def per_call(stmt, number, repeats):
    times = [t / number * 1e6 for t in timeit.repeat(stmt, number=number, repeat=repeats)]
    return min(times), statistics.median(times)


def main():
    ap = argparse.ArgumentParser()
    ap.add_argument("--repeats", type=int, default=9)
    ap.add_argument("--contacts", type=int, default=200_000)
    args = ap.parse_args()
    print(f"taxel {taxel.__version__}, numpy {np.__version__}")

    rng = np.random.default_rng(1)
    cloud = fusion.ContactCloud()
    cloud.insert(sim.Sphere(0.04).sample_surface(2000, 1).points, sigma=2e-4)
    x11 = rng.normal(size=(200, 11))
    y = np.arange(200, dtype=np.int32) % 4
    svm = learn.LinearSvm().fit(x11, y)
    one = x11[:1].copy()
    p = np.array([0.04, 0.0, 0.0])
    small = rng.uniform(0, 255, size=64)
    calls = {
        "len(cloud)": lambda: len(cloud),
        "cloud.insert_one(position)": lambda: cloud.insert_one(p, 2e-4),
        "svm.predict(1 x 11 features)": lambda: svm.predict(one),
        "svm.model_.predict (compiled)": lambda: svm.model_.predict(one),
        "image.kmeans1d(64 values)": lambda: image.kmeans1d(small),
    }
    print(f"\n{'small call':32} {'min [us]':>9} {'median [us]':>12}")
    for name, fn in calls.items():
        lo, med = per_call(fn, 20000, args.repeats)
        print(f"{name:32} {lo:9.3f} {med:12.3f}")

    # A million points: the arrays a PointCloud hands out are read-only views.
    big = taxel.PointCloud(rng.random((1_000_000, 3)))
    for name, fn, number in (
        ("cloud.points (1 M points)", lambda: big.points, 20000),
        ("1000 x cloud.points[i, 0]", lambda: [big.points[i, 0] for i in range(1000)], 20),
    ):
        lo, med = per_call(fn, number, args.repeats)
        print(f"{name:32} {lo:9.3f} {med:12.3f}")

    # k-nearest queries, in alternation with scipy's cKDTree (one worker).
    try:
        from scipy.spatial import cKDTree
    except ImportError:
        cKDTree = None
    if cKDTree is not None:
        pts, queries = rng.random((100_000, 3)), rng.random((100_000, 3))
        runs = {"taxel KdTree build": [], "cKDTree build": [], "taxel query k=8": [], "cKDTree query k=8": []}
        for _ in range(args.repeats):
            runs["taxel KdTree build"].append(timeit.timeit(lambda: taxel.index.KdTree(pts), number=1))
            runs["cKDTree build"].append(timeit.timeit(lambda: cKDTree(pts), number=1))
            ours, theirs = taxel.index.KdTree(pts), cKDTree(pts)
            runs["taxel query k=8"].append(timeit.timeit(lambda: ours.query(queries, k=8), number=1))
            runs["cKDTree query k=8"].append(timeit.timeit(lambda: theirs.query(queries, k=8, workers=1), number=1))
        print(f"\n{'100 000 points, 100 000 queries':32} {'min [ms]':>9} {'median [ms]':>12}")
        for name, ts in runs.items():
            print(f"{name:32} {min(ts) * 1e3:9.2f} {statistics.median(ts) * 1e3:12.2f}")

    import pickle

    print(f"\n{'pickle round trip':32} {'min [ms]':>9} {'median [ms]':>12}")
    for name, obj in (("ContactCloud (surfel)", cloud), ("LinearSvm (4 classes)", svm), ("PointCloud (1 M points)", big)):
        lo, med = per_call(lambda: pickle.loads(pickle.dumps(obj)), 5, args.repeats)
        print(f"{name:32} {lo / 1e3:9.3f} {med / 1e3:12.3f}")

    # 200 000 contacts of a simulated grasp exploration (real covariances and normals).
    ex = sim.explore_grasps(sim.Sphere(0.04), grasps=52, seed=2)
    contacts = ex.contacts
    n = min(args.contacts, len(contacts))
    pos = np.ascontiguousarray(contacts.positions[:n])
    cov = np.ascontiguousarray(contacts.covariances[:n])
    nrm = np.ascontiguousarray(contacts.normals[:n])
    t = np.ascontiguousarray(contacts.times[:n])
    cpp = taxel.Contacts(pos, cov, nrm, times=t)

    def arrays(strict):
        c = fusion.ContactCloud()
        c.insert(pos, cov, nrm, times=t, strict=strict)
        return c

    def loop():
        c = fusion.ContactCloud()
        c.insert(cpp)
        return c

    np.testing.assert_array_equal(arrays(True).means, loop().means)
    runs = {"arrays, strict": [], "arrays, strict=False": [], "C++ loop (Contacts)": []}
    for _ in range(args.repeats):
        runs["C++ loop (Contacts)"].append(timeit.timeit(loop, number=1))
        runs["arrays, strict"].append(timeit.timeit(lambda: arrays(True), number=1))
        runs["arrays, strict=False"].append(timeit.timeit(lambda: arrays(False), number=1))
    base = min(runs["C++ loop (Contacts)"])
    base_med = statistics.median(runs["C++ loop (Contacts)"])
    print(f"\n{'insert ' + str(n) + ' contacts':32} {'min [ms]':>9} {'median [ms]':>12} {'min ratio':>10} {'median ratio':>13}")
    for name, ts in runs.items():
        print(f"{name:32} {min(ts) * 1e3:9.2f} {statistics.median(ts) * 1e3:12.2f} "
              f"{min(ts) / base:10.3f} {statistics.median(ts) / base_med:13.3f}")


if __name__ == "__main__":
    main()
