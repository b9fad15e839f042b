# SPDX-License-Identifier: MIT
"""taxel.optical on frames rendered here in numpy, independently of taxel's own shading model:
calibration from ball presses, heights against the truth, files, marker tracking, bad input."""
import numpy as np
import pytest

import taxel
from taxel import optical

ROWS, COLS, PIXEL, BALL = 120, 160, 0.0634e-3, 1.5e-3


def ball(depth, cx, cy):
    """Heights [m] and slopes of a ball pressed `depth` into the gel above pixel (cx, cy)."""
    y, x = np.mgrid[0:ROWS, 0:COLS].astype(float)
    u, v = (x - cx) * PIXEL, (y - cy) * PIXEL
    rho2 = u * u + v * v
    inside = rho2 < BALL**2 - (BALL - depth) ** 2
    root = np.sqrt(np.maximum(BALL**2 - rho2, 1e-12))
    h = np.where(inside, root - (BALL - depth), 0.0)
    gx = np.where(inside, -u / root, 0.0)
    gy = np.where(inside, -v / root, 0.0)
    return h, gx, gy


def render(gx, gy, rng, dots=None):
    """Three lights: each channel's change is linear and quadratic in the slope, on a
    vignetted background, with 1.5 levels of noise; dark dots where given."""
    y, x = np.mgrid[0:ROWS, 0:COLS].astype(float)
    fall = 1.0 - 0.25 * (((x - COLS / 2) / COLS) ** 2 + ((y - ROWS / 2) / ROWS) ** 2)
    base = np.stack([120 * fall, 135 * fall, 110 * fall], axis=-1)
    change = np.stack(
        [90 * gx + 30 * gx * gx, 90 * gy - 20 * gy * gy, -60 * gx - 60 * gy + 25 * (gx * gx + gy * gy)],
        axis=-1,
    )
    img = base + change + rng.normal(0, 1.5, base.shape)
    if dots is not None:
        for cx, cy in dots:
            d = (x - cx) ** 2 + (y - cy) ** 2 <= 2.5**2
            img[d] *= 0.3
    return np.clip(np.rint(img), 0, 255).astype(np.uint8)


@pytest.fixture(scope="module")
def rig():
    rng = np.random.default_rng(3)
    zero = np.zeros((ROWS, COLS))
    background = render(zero, zero, rng)
    presses, truth = [], []
    for _ in range(8):
        d, cx, cy = rng.uniform(0.25e-3, 0.45e-3), rng.uniform(30, 130), rng.uniform(30, 90)
        _, gx, gy = ball(d, cx, cy)
        presses.append(render(gx, gy, rng))
        truth.append((cx, cy, np.sqrt(BALL**2 - (BALL - d) ** 2) / PIXEL))
    cal = optical.calibrate(presses, background, ball_radius=BALL, pixel=PIXEL, markers=False)
    return rng, background, presses, truth, cal


def test_calibration_finds_the_circles_and_reconstructs_held_out_balls(rig):
    rng, _, _, truth, cal = rig
    assert cal.rows == ROWS and cal.cols == COLS and cal.pixel == PIXEL
    assert cal.method in ("polynomial", "lookup_table")
    assert cal.heldout == min(cal.heldout_polynomial, cal.heldout_table) < 0.15
    circles = cal.circles
    assert circles.shape == (8, 3)
    for (cx, cy, r), (tx, ty, tr) in zip(circles, truth):
        assert abs(cx - tx) <= 0.6 and abs(cy - ty) <= 0.6
        assert tr - 2.0 < r <= tr + 0.3
    rec = optical.Reconstructor(cal)
    for cx, cy in [(50.0, 60.0), (110.0, 55.0)]:
        h, gx, gy = ball(0.4e-3, cx, cy)
        m = rec(render(gx, gy, rng))
        assert m["height"].shape == (ROWS, COLS) and m["height"].dtype == np.float64
        assert m["mask"].dtype == np.bool_ and m["contact"].dtype == np.bool_
        inside = h > 0
        rms = np.sqrt(np.mean((m["height"][inside] - h[inside]) ** 2))
        assert rms < 0.04e-3
        assert m["height"].max() == pytest.approx(0.4e-3, rel=0.15)
        # The contact mask: deformed, and at least 0.3 of the deepest height.
        assert not (m["contact"] & ~m["mask"]).any()
        radius, fx, fy = optical.fit_ball(m["height"], m["contact"], PIXEL)
        assert radius == pytest.approx(BALL, rel=0.15)  # measured +2 % and +13 %
        assert abs(fx - cx) < 1.5 and abs(fy - cy) < 1.5
    # The function form gives the same heights.
    h, gx, gy = ball(0.3e-3, 80, 60)
    frame = render(gx, gy, rng)
    assert np.array_equal(optical.reconstruct(frame, cal)["height"], rec(frame)["height"])


def test_calibration_files_round_trip(rig, tmp_path):
    rng, _, _, _, cal = rig
    _, gx, gy = ball(0.35e-3, 70, 50)
    frame = render(gx, gy, rng)
    for name in ("cal.json", "cal.txcal"):
        cal.save(str(tmp_path / name))
        back = optical.Calibration.load(str(tmp_path / name))
        assert back.method == cal.method and np.array_equal(back.circles, cal.circles)
        assert np.array_equal(optical.reconstruct(frame, back)["height"], optical.reconstruct(frame, cal)["height"])
    assert (tmp_path / "cal.json").read_text().startswith("{")
    assert "Calibration 120x160" in repr(cal)
    with pytest.raises(taxel.IoError, match="missing.txcal"):
        optical.Calibration.load(str(tmp_path / "missing.txcal"))


def test_median_background_and_bad_input(rig):
    rng, background, presses, _, cal = rig
    median = optical.median_background(np.stack(presses))
    assert median.shape == (ROWS, COLS, 3) and median.dtype == np.uint8
    assert np.abs(median.astype(int) - background.astype(int)).mean() < 2.0
    with pytest.raises(ValueError, match=r"shape \(rows, cols, 3\)"):
        optical.reconstruct(np.zeros((ROWS, COLS), np.uint8), cal)
    with pytest.raises(ValueError, match="the frame is 60 x 80"):
        optical.reconstruct(np.zeros((60, 80, 3), np.uint8), cal)
    with pytest.raises(ValueError, match="no gel in view"):
        optical.reconstruct(np.zeros((ROWS, COLS, 3), np.uint8), cal)
    with pytest.raises(RuntimeError, match="press 1: find_contact_circle: no contact"):
        optical.calibrate([presses[0], background], background, ball_radius=BALL, pixel=PIXEL)
    with pytest.raises(TypeError):
        optical.calibrate(presses, background, BALL, PIXEL)  # keywords only
    with pytest.raises(ValueError, match="ball_radius"):
        optical.calibrate(presses, background, ball_radius=-1.0, pixel=PIXEL)


def test_marker_dots_are_tracked_through_a_shift():
    rng = np.random.default_rng(9)
    zero = np.zeros((ROWS, COLS))
    grid = [(x + 0.4, y + 0.2) for y in range(8, ROWS - 4, 16) for x in range(8, COLS - 4, 16)]
    ref = optical.find_dots(render(zero, zero, rng, grid))
    assert ref.shape == (len(grid), 3)
    tracker = optical.MarkerTracker(ref)
    assert tracker.max_step == pytest.approx(0.4 * 16, rel=0.05)
    for k in range(1, 9):
        moved = [(x + 0.7 * k, y - 0.3 * k) for x, y in grid]
        kept = [p for p in moved if 4 <= p[0] <= COLS - 5 and 4 <= p[1] <= ROWS - 5]
        tracker.update(optical.find_dots(render(zero, zero, rng, kept)))
    tracks = tracker.tracks
    assert tracks.shape[1] == 6
    seen = tracks[: len(grid)][tracks[: len(grid), 4] == 1]
    assert len(seen) > 0.8 * len(grid)
    np.testing.assert_allclose(seen[:, 2] - seen[:, 0], 5.6, atol=0.3)
    np.testing.assert_allclose(seen[:, 3] - seen[:, 1], -2.4, atol=0.3)
    dx, dy = tracker.field(ROWS, COLS)
    assert dx.shape == (ROWS, COLS)
    assert abs(np.median(dx) - 5.6) < 0.3 and abs(np.median(dy) + 2.4) < 0.3
    assert "MarkerTracker" in repr(tracker)
    with pytest.raises(ValueError, match="fewer than two"):
        optical.MarkerTracker(ref[:1])


def test_a_reconstructor_follows_a_drift_of_the_lighting(rig):
    rng, _, _, _, cal = rig
    zero = np.zeros((ROWS, COLS))
    h, gx, gy = ball(0.4e-3, 80, 60)
    follow = optical.Reconstructor(cal, drift_rate=0.05)
    assert follow.drift_rate == 0.05 and "following drift" in repr(follow)
    for k in range(1, 121):
        pressed = k % 10 == 0
        frame = render(gx if pressed else zero, gy if pressed else zero, rng)
        # The lamp brightens by 0.2 % a frame: 24 % after 120 frames.
        frame = np.clip(np.rint(frame * (1 + 0.002 * k)), 0, 255).astype(np.uint8)
        m = follow(frame)
    inside = h > 0
    assert np.sqrt(np.mean((m["height"][inside] - h[inside]) ** 2)) < 0.05e-3
    assert m["mask"].mean() < 0.1
    assert optical.Reconstructor(cal)(frame)["mask"].mean() > 0.5  # without it, all deformed
    with pytest.raises(ValueError, match="drift_rate"):
        optical.Reconstructor(cal, drift_rate=2.0)


def test_calibrations_pickle_and_copy(rig):
    import copy
    import pickle

    _, background, presses, _, cal = rig
    again = pickle.loads(pickle.dumps(cal))
    for name in ("rows", "cols", "pixel", "method", "heldout", "heldout_polynomial", "heldout_table"):
        assert getattr(again, name) == getattr(cal, name)
    np.testing.assert_array_equal(again.circles, cal.circles)
    a = optical.reconstruct(presses[0], cal)
    b = optical.reconstruct(presses[0], again)
    np.testing.assert_array_equal(a["height"], b["height"])
    assert copy.deepcopy(cal) is cal  # immutable


def test_a_drifting_reconstructor_pickles_with_its_background(rig):
    import pickle

    _, background, presses, _, cal = rig
    r = optical.Reconstructor(cal, drift_rate=0.2)
    brighter = np.clip(background.astype(int) + 6, 0, 255).astype(np.uint8)
    for _ in range(3):
        r(brighter)
    twin = pickle.loads(pickle.dumps(r))
    assert twin.drift_rate == r.drift_rate
    a, b = r(presses[1]), twin(presses[1])
    np.testing.assert_array_equal(a["height"], b["height"])
