// SPDX-License-Identifier: MIT
// Marker tracking: the gel's printed dots found in each frame and followed from frame to frame
// as a displacement (shear) field.
// A dot is an 8-connected region of marker_mask (markers.hpp, not grown), at its centre of
// darkness: each pixel weighted by how much darker it is than the ring of pixels around the
// region. A tracker keeps one track per dot of a reference frame (the gel at rest). Each frame:
//  1. every track predicts where its dot is: where it was last seen, or, when it was lost,
//     its reference position moved by the displacement interpolated from the tracks seen last
//     frame (an affine field fitted to the `neighbours` nearest in the reference, weighted by
//     inverse squared distance);
//  2. dots and predictions are paired greedily, closest pair first, within `max_step` pixels
//     (by default 0.4 times the reference's median spacing of neighbouring dots, so that a dot
//     cannot be taken for its neighbour); a dot and a track are paired at most once;
//  3. a paired track moves to its dot; an unpaired one is lost for this frame and stands where
//     the field of this frame's paired tracks moves its reference position; a dot no track claims
//     starts a new track (a dot entering the frame, or one found again after a track gave up),
//     whose reference is its position less the displacement interpolated there, so that the field
//     stays continuous.
// The displacement of a track is its position less its reference position [px]. A dense field
// interpolates the tracks seen in the last frame the same way.
#pragma once

#include <algorithm>
#include <cmath>
#include <cstddef>
#include <cstdint>
#include <limits>
#include <stdexcept>
#include <utility>
#include <vector>

#include <Eigen/Cholesky>
#include <Eigen/Eigenvalues>

#include "taxel/image/components.hpp"
#include "taxel/optical/markers.hpp"

namespace taxel::optical {

/// A marker dot in a frame.
struct Dot {
  double x = 0;     ///< centre column [px]
  double y = 0;     ///< centre row [px]
  double area = 0;  ///< [px]
};

/// The dots of a frame (see the header comment); regions of fewer than `min_area` or more than
/// `max_area` pixels are left out (noise; a press's dark shading or a smudge). Throws
/// std::invalid_argument for bad options or a bad frame.
template <class = void>
std::vector<Dot> find_dots(const RgbFrame& frame, const MarkerOptions& options = {},
                           int min_area = 3, int max_area = 400) {
  if (min_area < 1 || max_area < min_area) {
    throw std::invalid_argument("find_dots: need 1 <= min_area <= max_area");
  }
  MarkerOptions o = options;
  o.grow = 0;
  const image::Mask mask = marker_mask(frame, o);
  const auto rows = static_cast<int>(frame.rows), cols = static_cast<int>(frame.cols);
  image::Components comp;
  const int n = comp.compute(mask, image::Connectivity::eight);
  const image::Labels& lab = comp.labels();
  const auto lum = [&](int r, int c) {
    const std::uint8_t* p = frame.data.data() + (static_cast<std::size_t>(r) * cols + c) * 3;
    return (double(p[0]) + p[1] + p[2]) / 3.0;
  };
  // Per region: the ring's luminance (pixels outside the mask next to it), then the darkness
  // weighted sums.
  std::vector<double> ring(static_cast<std::size_t>(n) + 1, 0.0),
      ring_n(static_cast<std::size_t>(n) + 1, 0.0);
  for (int r = 0; r < rows; ++r) {
    for (int c = 0; c < cols; ++c) {
      if (mask(r, c)) continue;
      int seen[8], k = 0;
      for (int dr = -1; dr <= 1; ++dr) {
        for (int dc = -1; dc <= 1; ++dc) {
          const int rr = r + dr, cc = c + dc;
          if (rr < 0 || cc < 0 || rr >= rows || cc >= cols || !mask(rr, cc)) continue;
          const int l = lab(rr, cc);
          if (std::find(seen, seen + k, l) != seen + k) continue;
          seen[k++] = l;
          ring[static_cast<std::size_t>(l)] += lum(r, c);
          ring_n[static_cast<std::size_t>(l)] += 1;
        }
      }
    }
  }
  std::vector<double> w(static_cast<std::size_t>(n) + 1, 0.0), wx(w.size(), 0.0), wy(w.size(), 0.0);
  for (int r = 0; r < rows; ++r) {
    for (int c = 0; c < cols; ++c) {
      if (!mask(r, c)) continue;
      const auto l = static_cast<std::size_t>(lab(r, c));
      const double base = ring_n[l] > 0 ? ring[l] / ring_n[l] : 255.0;
      const double weight = std::max(base - lum(r, c), 1e-3);
      w[l] += weight;
      wx[l] += weight * c;
      wy[l] += weight * r;
    }
  }
  std::vector<Dot> dots;
  for (int l = 1; l <= n; ++l) {
    const int area = comp.area(l);
    if (area < min_area || area > max_area) continue;
    const auto k = static_cast<std::size_t>(l);
    dots.push_back({wx[k] / w[k], wy[k] / w[k], double(area)});
  }
  return dots;
}

/// How a MarkerTracker pairs dots.
struct TrackerOptions {
  /// The farthest a dot moves between two frames [px]; 0: 0.4 times the reference's median
  /// spacing of neighbouring dots.
  double max_step = 0;
  int neighbours = 8;  ///< tracks interpolating a displacement, >= 1
};

/// One dot followed through the frames.
struct MarkerTrack {
  double x0 = 0;     ///< reference position, column [px]
  double y0 = 0;     ///< reference position, row [px]
  double x = 0;      ///< column in the last frame [px]: its dot's, or where the field moves it
  double y = 0;      ///< row in the last frame [px]
  bool seen = true;  ///< its dot was found in the last frame
  int missed = 0;    ///< frames in a row without its dot
  /// The displacement since the reference [px], along columns.
  double dx() const { return x - x0; }
  /// The displacement since the reference [px], along rows.
  double dy() const { return y - y0; }
};

/// Follows marker dots from a reference frame (see the header comment).
class MarkerTracker {
 public:
  /// Tracks for the dots of the reference frame. Throws std::invalid_argument for fewer than
  /// two dots or bad options.
  explicit MarkerTracker(const std::vector<Dot>& reference, const TrackerOptions& options = {})
      : options_(options) {
    if (reference.size() < 2) {
      throw std::invalid_argument("MarkerTracker: the reference frame has fewer than two dots");
    }
    if (options.neighbours < 1 || !(options.max_step >= 0) || !std::isfinite(options.max_step)) {
      throw std::invalid_argument("MarkerTracker: neighbours >= 1 and a finite max_step >= 0");
    }
    for (const Dot& d : reference) tracks_.push_back({d.x, d.y, d.x, d.y, true, 0});
    if (options_.max_step == 0) {
      std::vector<double> nearest;
      for (std::size_t i = 0; i < reference.size(); ++i) {
        double best = std::numeric_limits<double>::infinity();
        for (std::size_t j = 0; j < reference.size(); ++j) {
          if (i != j) {
            best = std::min(
                best, std::hypot(reference[i].x - reference[j].x, reference[i].y - reference[j].y));
          }
        }
        nearest.push_back(best);
      }
      std::nth_element(nearest.begin(), nearest.begin() + std::ptrdiff_t(nearest.size() / 2),
                       nearest.end());
      options_.max_step = 0.4 * nearest[nearest.size() / 2];
    }
  }

  /// The tracks, the reference's dots first in their order, then the dots found later.
  const std::vector<MarkerTrack>& tracks() const { return tracks_; }
  /// The options, max_step resolved (never 0).
  const TrackerOptions& options() const { return options_; }

  /// A tracker that goes on from `tracks` and `options` as saved from another (tracks(),
  /// options()). Throws std::invalid_argument for fewer than two tracks, a position that is not
  /// finite, a negative miss count or options out of range (max_step must be > 0).
  static MarkerTracker restore(std::vector<MarkerTrack> tracks, const TrackerOptions& options) {
    if (tracks.size() < 2 || options.neighbours < 1 || !(options.max_step > 0) ||
        !std::isfinite(options.max_step)) {
      throw std::invalid_argument(
          "MarkerTracker::restore: two tracks or more, neighbours >= 1 and a finite max_step > 0");
    }
    for (const MarkerTrack& t : tracks) {
      if (!std::isfinite(t.x0) || !std::isfinite(t.y0) || !std::isfinite(t.x) ||
          !std::isfinite(t.y) || t.missed < 0) {
        throw std::invalid_argument("MarkerTracker::restore: a track is not finite");
      }
    }
    MarkerTracker out;
    out.options_ = options;
    out.tracks_ = std::move(tracks);
    return out;
  }
  /// The pairing distance in use [px].
  double max_step() const { return options_.max_step; }

  /// Follows the dots of the next frame. Returns the number of tracks whose dot was found.
  std::size_t update(const std::vector<Dot>& dots) {
    // 1. Predictions: lost tracks from the field of the tracks seen last frame.
    std::vector<std::size_t> seen_before;
    for (std::size_t i = 0; i < tracks_.size(); ++i) {
      if (tracks_[i].seen) seen_before.push_back(i);
    }
    std::vector<std::pair<double, double>> predicted(tracks_.size());
    for (std::size_t i = 0; i < tracks_.size(); ++i) {
      MarkerTrack& t = tracks_[i];
      if (t.seen) {
        predicted[i] = {t.x, t.y};
      } else {
        const auto [dx, dy] = interpolate(t.x0, t.y0, seen_before, true);
        predicted[i] = {t.x0 + dx, t.y0 + dy};
      }
    }
    // 2. Pairs within max_step, found through a grid of max_step cells over the dots.
    const double cell = options_.max_step;
    double min_x = 0, min_y = 0;
    for (const Dot& d : dots) {
      min_x = std::min(min_x, d.x);
      min_y = std::min(min_y, d.y);
    }
    std::vector<std::pair<long long, std::size_t>> grid;  // (cell key, dot)
    const auto key = [&](double x, double y) {
      const auto gx = static_cast<long long>(std::floor((x - min_x) / cell));
      const auto gy = static_cast<long long>(std::floor((y - min_y) / cell));
      return gy * 1000003LL + gx;
    };
    for (std::size_t j = 0; j < dots.size(); ++j) grid.push_back({key(dots[j].x, dots[j].y), j});
    std::sort(grid.begin(), grid.end());
    struct Pair {
      double d2;
      std::size_t track, dot;
    };
    std::vector<Pair> pairs;
    for (std::size_t i = 0; i < tracks_.size(); ++i) {
      const auto [px, py] = predicted[i];
      for (int oy = -1; oy <= 1; ++oy) {
        for (int ox = -1; ox <= 1; ++ox) {
          const long long k = key(px + ox * cell, py + oy * cell);
          auto it = std::lower_bound(grid.begin(), grid.end(), std::pair{k, std::size_t{0}});
          for (; it != grid.end() && it->first == k; ++it) {
            const Dot& d = dots[it->second];
            const double d2 = (d.x - px) * (d.x - px) + (d.y - py) * (d.y - py);
            if (d2 <= cell * cell) pairs.push_back({d2, i, it->second});
          }
        }
      }
    }
    std::sort(pairs.begin(), pairs.end(), [](const Pair& a, const Pair& b) {
      return a.d2 < b.d2 ||
             (a.d2 == b.d2 && (a.track < b.track || (a.track == b.track && a.dot < b.dot)));
    });
    std::vector<char> track_done(tracks_.size(), 0), dot_done(dots.size(), 0);
    std::size_t found = 0;
    for (const Pair& p : pairs) {
      if (track_done[p.track] || dot_done[p.dot]) continue;
      track_done[p.track] = dot_done[p.dot] = 1;
      MarkerTrack& t = tracks_[p.track];
      t.x = dots[p.dot].x;
      t.y = dots[p.dot].y;
      t.seen = true;
      t.missed = 0;
      ++found;
    }
    // 3. Lost tracks at their predictions; new tracks for the dots nobody claimed.
    std::vector<std::size_t> seen_now;
    for (std::size_t i = 0; i < tracks_.size(); ++i) {
      MarkerTrack& t = tracks_[i];
      if (track_done[i]) {
        seen_now.push_back(i);
        continue;
      }
      t.seen = false;
      ++t.missed;
    }
    for (std::size_t i = 0; i < tracks_.size(); ++i) {
      MarkerTrack& t = tracks_[i];
      if (t.seen) continue;
      const auto [dx, dy] = interpolate(t.x0, t.y0, seen_now, true);
      t.x = t.x0 + dx;
      t.y = t.y0 + dy;
    }
    for (std::size_t j = 0; j < dots.size(); ++j) {
      if (dot_done[j]) continue;
      const auto [dx, dy] = interpolate(dots[j].x, dots[j].y, seen_now, false);
      tracks_.push_back({dots[j].x - dx, dots[j].y - dy, dots[j].x, dots[j].y, true, 0});
      ++found;
    }
    return found;
  }

  /// The displacement field of the last frame at every pixel of a rows x cols frame [px]:
  /// interpolated from the tracks seen (see the header comment); zero when none was.
  void field(int rows, int cols, Plane& dx, Plane& dy) const {
    if (rows < 1 || cols < 1) throw std::invalid_argument("MarkerTracker::field: empty frame");
    std::vector<std::size_t> seen;
    for (std::size_t i = 0; i < tracks_.size(); ++i) {
      if (tracks_[i].seen) seen.push_back(i);
    }
    dx.resize(rows, cols);
    dy.resize(rows, cols);
    for (int r = 0; r < rows; ++r) {
      for (int c = 0; c < cols; ++c) {
        const auto [u, v] = interpolate(c, r, seen, false);
        dx(r, c) = u;
        dy(r, c) = v;
      }
    }
  }

 private:
  // The displacement at (x, y) from the tracks `from` (in the reference when `reference`, else
  // where they are now): an affine field fitted by least squares to the `neighbours` nearest,
  // weighted by inverse squared distance, taken at the point (exact for a uniform shift, shear
  // or turn, and unbiased at the frame's edge, where the neighbours lie on one side); their
  // weighted mean when they do not span a plane; a track at the point itself gives its own.
  std::pair<double, double> interpolate(double x, double y, const std::vector<std::size_t>& from,
                                        bool reference) const {
    if (from.empty()) return {0.0, 0.0};
    const std::size_t k = std::min<std::size_t>(std::size_t(options_.neighbours), from.size());
    std::vector<std::pair<double, std::size_t>> near;
    near.reserve(from.size());
    for (const std::size_t i : from) {
      const MarkerTrack& t = tracks_[i];
      const double ax = reference ? t.x0 : t.x, ay = reference ? t.y0 : t.y;
      near.push_back({(ax - x) * (ax - x) + (ay - y) * (ay - y), i});
    }
    std::partial_sort(near.begin(), near.begin() + std::ptrdiff_t(k), near.end());
    Eigen::Matrix3d A = Eigen::Matrix3d::Zero();
    Eigen::Vector3d bu = Eigen::Vector3d::Zero(), bv = Eigen::Vector3d::Zero();
    double sw = 0, su = 0, sv = 0;
    for (std::size_t j = 0; j < k; ++j) {
      const MarkerTrack& t = tracks_[near[j].second];
      if (near[j].first < 1e-12) return {t.dx(), t.dy()};
      const double w = 1.0 / near[j].first;
      const Eigen::Vector3d row(1.0, (reference ? t.x0 : t.x) - x, (reference ? t.y0 : t.y) - y);
      A += w * row * row.transpose();
      bu += w * t.dx() * row;
      bv += w * t.dy() * row;
      sw += w;
      su += w * t.dx();
      sv += w * t.dy();
    }
    // The affine fit when the neighbours span a plane well (the smallest eigenvalue of their
    // weighted spread, relative to the largest, above 1e-3).
    if (k >= 3) {
      const Eigen::SelfAdjointEigenSolver<Eigen::Matrix2d> spread(
          A.bottomRightCorner<2, 2>() / sw - A.block<2, 1>(1, 0) * A.block<1, 2>(0, 1) / (sw * sw));
      const auto ev = spread.eigenvalues();
      if (ev(0) > 1e-3 * ev(1) && ev(1) > 0) {
        const Eigen::LDLT<Eigen::Matrix3d> ldlt(A);
        return {ldlt.solve(bu)(0), ldlt.solve(bv)(0)};
      }
    }
    return {su / sw, sv / sw};
  }

  MarkerTracker() = default;

  TrackerOptions options_;
  std::vector<MarkerTrack> tracks_;
};

}  // namespace taxel::optical
