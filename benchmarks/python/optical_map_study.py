#!/usr/bin/env python3
# SPDX-License-Identifier: MIT
"""Does a small MLP map colour change (and pixel position) to surface slope better than the
calibration's polynomial and lookup table? Held-out RMS slope error inside the contact circles, on
the calibration's own split (fit on the even presses, measure on the odd ones) and its own
training samples: inside each contact circle less a 2-pixel margin, the sphere's slopes; beyond
the drape band, slope 0 at every third pixel.

    PYTHONPATH=<build>/python python3 benchmarks/python/optical_map_study.py [--real DIR]

The presses are rendered here with a shading model of this script's own (not taxel's), with
three noise levels; --real adds a folder of real GelSight presses (frame0.jpg, the background,
and Im_*.jpg, a 1.98 mm ball at 0.03026 mm per pixel, as in the gelsight_driver calibration
set). The MLP is scikit-learn's MLPRegressor, a stand-in for any small MLP: 5 inputs (the
three changes / 100, the position in [-1, 1]^2), hidden layers of 32 (and 32, 32), tanh,
Adam, early stopping on a tenth of the training samples (at most 20 000), two seeds.
"""
import argparse
import pathlib

import numpy as np

from taxel import optical

ROWS, COLS, PIXEL, BALL = 120, 160, 0.0634e-3, 2e-3


def ball(depth, cx, cy):
    y, x = np.mgrid[0:ROWS, 0:COLS].astype(float)
    u, v = (x - cx) * PIXEL, (y - cy) * PIXEL
    rho2 = u * u + v * v
    inside = rho2 < BALL**2 - (BALL - depth) ** 2
    root = np.sqrt(np.maximum(BALL**2 - rho2, 1e-12))
    return np.where(inside, -u / root, 0.0), np.where(inside, -v / root, 0.0)


def render(gx, gy, rng, noise):
    """Three lights at 120 degrees, Lambert-like with a position-dependent falloff."""
    y, x = np.mgrid[0:ROWS, 0:COLS].astype(float)
    fall = 1.0 - 0.3 * (((x - COLS / 2) / COLS) ** 2 + ((y - ROWS / 2) / ROWS) ** 2)
    n = np.stack([-gx, -gy, np.ones_like(gx)], axis=-1)
    n /= np.linalg.norm(n, axis=-1, keepdims=True)
    out = []
    for k, base in enumerate((110.0, 125.0, 100.0)):
        a = 2 * np.pi * k / 3
        light = np.array([0.6 * np.cos(a), 0.6 * np.sin(a), 0.8])
        out.append(base * fall * (0.4 + 0.75 * np.clip(n @ light, 0, None)))
    img = np.stack(out, axis=-1) + rng.normal(0, noise, (ROWS, COLS, 3))
    return np.clip(np.rint(img), 0, 255).astype(np.uint8)


def rendered(seed, noise, presses=8):
    rng = np.random.default_rng(seed)
    zero = np.zeros((ROWS, COLS))
    background = render(zero, zero, rng, noise)
    frames = []
    for _ in range(presses):
        d, cx, cy = rng.uniform(0.25e-3, 0.45e-3), rng.uniform(30, 130), rng.uniform(30, 90)
        frames.append(render(*ball(d, cx, cy), rng, noise))
    return background, frames, BALL, PIXEL


def samples(background, frames, circles, ball_radius, pixel, margin=2.0, stride=3):
    """The calibration's samples: (features, slopes, press) as taxel's calibrate takes them."""
    rows, cols = background.shape[:2]
    y, x = np.mgrid[0:rows, 0:cols].astype(float)
    u = 2 * x / (cols - 1) - 1
    v = 2 * y / (rows - 1) - 1
    flat = (np.arange(rows * cols).reshape(rows, cols) % stride) == 0
    feats, slopes, press, inner_flags = [], [], [], []
    for p, (frame, (cx, cy, radius)) in enumerate(zip(frames, circles)):
        change = frame.astype(float) - background.astype(float)
        dx, dy = x - cx, y - cy
        rho = np.hypot(dx, dy)
        inner, outer = radius - margin, radius + max(margin, 0.5 * radius)
        inside = rho < inner
        outside = (rho > outer) & flat
        root = np.sqrt(np.maximum(ball_radius**2 - (rho * pixel) ** 2, 1e-18))
        gx = np.where(inside, -dx * pixel / root, 0.0)
        gy = np.where(inside, -dy * pixel / root, 0.0)
        keep = inside | outside
        f = np.column_stack([change[keep] / 100.0, u[keep], v[keep]])
        feats.append(f)
        slopes.append(np.column_stack([gx[keep], gy[keep]]))
        press.append(np.full(keep.sum(), p))
        inner_flags.append(inside[keep])
    return np.vstack(feats), np.vstack(slopes), np.concatenate(press), np.concatenate(inner_flags)


def mlp_heldout(f, g, press, inside, hidden, seed):
    from sklearn.neural_network import MLPRegressor

    train, test = press % 2 == 0, press % 2 == 1
    # At most 20 000 training samples (every press keeps its share): more changed nothing.
    idx = np.flatnonzero(train)
    if idx.size > 20000:
        idx = np.random.default_rng(seed).choice(idx, 20000, replace=False)
    train = np.zeros_like(train)
    train[idx] = True
    model = MLPRegressor(hidden_layer_sizes=hidden, activation="tanh", solver="adam",
                         learning_rate_init=3e-3, max_iter=200, early_stopping=True,
                         validation_fraction=0.1, n_iter_no_change=15, random_state=seed)
    model.fit(f[train], g[train])
    test &= inside  # the error is measured inside the circles, as the calibration's is
    err = model.predict(f[test]) - g[test]
    return float(np.sqrt(np.mean(np.sum(err**2, axis=1))))


def study(name, background, frames, ball_radius, pixel):
    cal = optical.calibrate(frames, background, ball_radius=ball_radius, pixel=pixel, markers=False)
    f, g, press, inside = samples(background, frames, cal.circles, ball_radius, pixel)
    row = [f"{name:28}", f"{cal.heldout_polynomial:.4f}", f"{cal.heldout_table:.4f}"]
    for hidden in ((32,), (32, 32)):
        errs = [mlp_heldout(f, g, press, inside, hidden, seed) for seed in range(2)]
        row.append(f"{min(errs):.4f}-{max(errs):.4f}")
    print(" | ".join(row), flush=True)


def main():
    ap = argparse.ArgumentParser()
    ap.add_argument("--real", type=pathlib.Path, help="a folder of real GelSight presses")
    args = ap.parse_args()
    print("data | polynomial | lookup table | MLP 32 (2 seeds) | MLP 32-32 (2 seeds)", flush=True)
    for noise in (0.5, 1.5, 3.0):
        for seed in (1, 2):
            study(f"rendered, noise {noise}, seed {seed}", *rendered(seed, noise))
    if args.real:
        from PIL import Image  # Debian python3-pil (matplotlib's dependency)

        def load(path):
            return np.asarray(Image.open(path).convert("RGB"), dtype=np.uint8)

        frames = [load(p) for p in sorted(args.real.glob("Im_*.jpg"))]
        study(f"real GelSight, {len(frames)} presses", load(args.real / "frame0.jpg"), frames,
              1.98e-3, 0.03026e-3)

if __name__ == "__main__":
    main()
