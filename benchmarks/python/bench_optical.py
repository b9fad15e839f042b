#!/usr/bin/env python3
# SPDX-License-Identifier: MIT
"""One camera-tactile frame (240 x 320, a ball pressed in, no marker dots) to slopes, mask and
heights: taxel.optical.Reconstructor against the same steps vectorised in numpy and scipy
(colour change, threshold, holes filled, specks dropped, mask grown, a 32^3 lookup table, the
free-border Poisson solve by scipy.fft's DCT), over the whole frame and, like taxel, over the
contact's neighbourhood only.

    PYTHONPATH=<build>/python python3 benchmarks/python/bench_optical.py [--repeats 9]

Prints min and median per frame over the repeats; the three run in alternation, so machine
noise hits all of them.
"""
import argparse
import statistics
import timeit

import numpy as np
from scipy import fft, ndimage

import taxel
from taxel import optical

ROWS, COLS, PIXEL, BALL = 240, 320, 0.0634e-3, 2e-3


def ball(depth, cx, cy):
    y, x = np.mgrid[0:ROWS, 0:COLS].astype(float)
    u, v = (x - cx) * PIXEL, (y - cy) * PIXEL
    rho2 = u * u + v * v
    inside = rho2 < BALL**2 - (BALL - depth) ** 2
    root = np.sqrt(np.maximum(BALL**2 - rho2, 1e-12))
    return np.where(inside, -u / root, 0.0), np.where(inside, -v / root, 0.0)


def render(gx, gy, rng):
    y, x = np.mgrid[0:ROWS, 0:COLS].astype(float)
    fall = 1.0 - 0.25 * (((x - COLS / 2) / COLS) ** 2 + ((y - ROWS / 2) / ROWS) ** 2)
    base = np.stack([120 * fall, 135 * fall, 110 * fall], axis=-1)
    change = np.stack([90 * gx + 30 * gx * gx, 90 * gy - 20 * gy * gy, -60 * (gx + gy)], axis=-1)
    return np.clip(np.rint(base + change + rng.normal(0, 1.5, base.shape)), 0, 255).astype(np.uint8)


class NumpyReconstructor:
    """The steps of taxel's reconstruct, vectorised."""

    def __init__(self, background, table, bins, span, crop):
        self.background = background.astype(np.float64)
        self.table, self.bins, self.span, self.crop = table, bins, span, crop
        self.cross = ndimage.generate_binary_structure(2, 1)

    def poisson(self, gx, gy, untouched):
        rows, cols = gx.shape
        east = np.zeros_like(gx)
        east[:, :-1] = 0.5 * (gx[:, :-1] + gx[:, 1:])
        south = np.zeros_like(gy)
        south[:-1, :] = 0.5 * (gy[:-1, :] + gy[1:, :])
        west = np.zeros_like(gx)
        west[:, 1:] = east[:, :-1]
        north = np.zeros_like(gy)
        north[1:, :] = south[:-1, :]
        f = PIXEL * ((east - west) + (south - north))
        d = fft.dctn(f, type=2)
        lam = (2 * np.cos(np.pi * np.arange(rows) / rows) - 4)[:, None] + 2 * np.cos(
            np.pi * np.arange(cols) / cols)[None, :]
        lam[0, 0] = 1.0
        d /= lam
        d[0, 0] = 0.0
        h = fft.idctn(d, type=2)
        return h - h[untouched].mean()

    def __call__(self, frame):
        change = frame - self.background
        mask = (change**2).sum(axis=-1) > 12.0**2
        labels, n = ndimage.label(mask, structure=np.ones((3, 3)))
        area = np.bincount(labels.ravel(), minlength=n + 1)
        mask &= area[labels] >= 30
        mask = ndimage.binary_fill_holes(mask)
        grown = ndimage.binary_dilation(mask, self.cross, iterations=2)
        cells = np.clip(((change + self.span) * (self.bins / (2 * self.span))).astype(int), 0, self.bins - 1)
        g = self.table[cells[..., 0], cells[..., 1], cells[..., 2]]
        gx = np.where(grown, g[..., 0], 0.0)
        gy = np.where(grown, g[..., 1], 0.0)
        height = np.zeros(mask.shape)
        if not grown.any():
            return height, mask
        if self.crop:
            rr, cc = np.nonzero(grown)
            boxes = []
            for lo, hi, size in ((rr.min(), rr.max(), ROWS), (cc.min(), cc.max(), COLS)):
                pad = max(16, (hi - lo + 1) // 2)
                length = min(size, ((hi - lo + 1 + 2 * pad + 31) // 32) * 32)
                start = min(max((lo + hi + 1) // 2 - length // 2, 0), size - length)
                boxes.append(slice(start, start + length))
            box = tuple(boxes)
            height[box] = self.poisson(gx[box], gy[box], ~grown[box])
        else:
            height = self.poisson(gx, gy, ~grown)
        return height, mask


def per_frame(fn, frames, repeats):
    k = iter(range(10**9))
    times = timeit.repeat(lambda: fn(frames[next(k) % len(frames)]), number=20, repeat=repeats)
    times = [t / 20 * 1e3 for t in times]
    return min(times), statistics.median(times)


def main():
    ap = argparse.ArgumentParser()
    ap.add_argument("--repeats", type=int, default=9)
    args = ap.parse_args()
    print(f"taxel {taxel.__version__}, numpy {np.__version__}")
    rng = np.random.default_rng(2)
    zero = np.zeros((ROWS, COLS))
    background = render(zero, zero, rng)
    presses = [render(*ball(rng.uniform(0.3e-3, 0.6e-3), rng.uniform(50, 270), rng.uniform(50, 190)), rng)
               for _ in range(8)]
    cal = optical.calibrate(presses, background, ball_radius=BALL, pixel=PIXEL, markers=False)
    frames = presses[:6]
    ours = optical.Reconstructor(cal)
    table = rng.normal(0, 0.3, size=(32, 32, 32, 2))  # a lookup table's size and access pattern
    whole = NumpyReconstructor(background, table, 32, 128.0, crop=False)
    cropped = NumpyReconstructor(background, table, 32, 128.0, crop=True)
    results = {"taxel": [], "numpy, whole frame": [], "numpy, neighbourhood": []}
    for _ in range(args.repeats):  # alternate, one repeat each
        results["taxel"].append(per_frame(ours, frames, 1)[0])
        results["numpy, whole frame"].append(per_frame(whole, frames, 1)[0])
        results["numpy, neighbourhood"].append(per_frame(cropped, frames, 1)[0])
    base = statistics.median(results["taxel"])
    for name, t in results.items():
        print(f"{name:22s} min {min(t):7.3f} ms  median {statistics.median(t):7.3f} ms  "
              f"({statistics.median(t) / base:5.1f}x taxel's median)")


if __name__ == "__main__":
    main()
