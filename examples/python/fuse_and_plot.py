#!/usr/bin/env python3
# SPDX-License-Identifier: MIT
"""Fuses a simulated grasp exploration of a sphere with every fusion policy, prints the surface
error of each cloud and plots the default policy's cloud, coloured by its distance to the
surface.

    python3 examples/python/fuse_and_plot.py [--out DIR]
"""
import argparse
import os
import pathlib

import numpy as np

import taxel
from taxel import fusion, sensor, sim


def main():
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--out", type=pathlib.Path, default=pathlib.Path("."), help="where the plot goes")
    ap.add_argument("--grasps", type=int, default=2 if os.environ.get("TAXEL_EXAMPLE_QUICK") else 8)
    args = ap.parse_args()

    shape = sim.Sphere(0.04)
    # A three-finger hand with two 14 x 6 pads per finger closes on the sphere; the readings
    # become contacts with local normals and the censoring bias removed.
    ex = sim.explore_grasps(shape, grasps=args.grasps, seed=1)
    readings, poses = ex.readings, ex.poses()
    print(f"{len(ex)} frames of {readings.shape[1]} pads, {len(ex.contacts)} contacts")

    clouds = {}
    print(f"{'policy':8} {'points':>7} {'RMS [mm]':>9} {'signed [mm]':>12}")
    for policy in fusion.POLICIES:
        cloud = fusion.ContactCloud(policy)
        cloud.insert_readings(readings, poses, times=ex.times)
        err = sim.surface_error(shape, cloud.means)
        print(f"{policy:8} {len(cloud):7d} {err['rms'] * 1e3:9.4f} {err['signed_mean'] * 1e3:+12.4f}")
        clouds[policy] = cloud

    cloud = clouds["surfel"]
    keep = cloud.confident(min_observations=3)
    pts = cloud.means[keep]
    d = shape.signed_distance(pts) * 1e3
    print(f"confident points (3 or more contacts): {keep.sum()} of {len(cloud)}")

    import matplotlib

    matplotlib.use(os.environ.get("MPLBACKEND", "Agg"))
    import matplotlib.pyplot as plt

    fig = plt.figure(figsize=(6, 5))
    ax = fig.add_subplot(projection="3d")
    sc = ax.scatter(*(pts * 1e3).T, c=d, cmap="coolwarm", vmin=-0.3, vmax=0.3, s=4)
    fig.colorbar(sc, ax=ax, label="distance to the sphere [mm] (outside +)")
    ax.set_xlabel("x [mm]")
    ax.set_ylabel("y [mm]")
    ax.set_zlabel("z [mm]")
    ax.set_title(f"taxel {taxel.__version__}: surfel cloud of a sphere of radius 40 mm")
    out = args.out / "fused_sphere.png"
    fig.savefig(out, dpi=120)
    print(f"wrote {out}")


if __name__ == "__main__":
    main()
