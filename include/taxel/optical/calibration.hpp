// SPDX-License-Identifier: MIT
// Calibration of a camera-based tactile sensor from presses of a ball of known radius: each
// press's contact circle, found in the colour change against the no-contact background, gives
// the target gradient inside it, -(x - cx, y - cy) p / sqrt(R^2 - rho^2) (R the ball's radius,
// p the pixel size, rho the distance from the circle's centre); outside it the gradient is 0.
// Two maps from colour change to gradient are fitted to those targets:
//  - a lookup table over the three channels' changes (W. Yuan's, in the GelSight driver:
//    Yuan, Dong and Adelson, "GelSight: High-Resolution Robot Tactile Sensors for Estimating
//    Geometry and Force", Sensors 17(12), 2017), bins x bins x bins cells, each the mean
//    target of its samples, an empty cell taking its nearest filled one's;
//  - a polynomial of degree 3 in the changes, each term also weighted by the pixel's squared
//    distance from the frame's centre and by its position (lighting falls off toward the
//    gel's edge), fitted by ridge-regularised least squares.
// The presses are split in two (every other one): each map is fitted on one half and its
// gradient error measured on the other; the map with the lower error is kept, refitted on all
// presses.
#pragma once

#include <Eigen/Cholesky>
#include <Eigen/Core>
#include <algorithm>
#include <cmath>
#include <cstdint>
#include <cstdio>
#include <limits>
#include <optional>
#include <stdexcept>
#include <string>
#include <utility>
#include <vector>

#include "taxel/image/components.hpp"
#include "taxel/optical/markers.hpp"
#include "taxel/optical/types.hpp"

namespace taxel::optical {

/// The colour change of `frame` against `background` (I - B, per channel) [levels].
template <class = void>
Colour colour_change(const RgbFrame& frame, const Colour& background) {
  validate_frame(frame, "colour_change");
  if (background[0].rows() != frame.rows || background[0].cols() != frame.cols) {
    throw std::invalid_argument("colour_change: the frame is " + std::to_string(frame.rows) +
                                " x " + std::to_string(frame.cols) + ", the background " +
                                std::to_string(background[0].rows()) + " x " +
                                std::to_string(background[0].cols()));
  }
  Colour c;
  for (Plane& p : c) p.resize(frame.rows, frame.cols);
  const std::uint8_t* px = frame.data.data();
  const Eigen::Index n = frame.rows * frame.cols;
  for (Eigen::Index i = 0; i < n; ++i, px += 3) {  // (row-major planes: one index each)
    for (std::size_t k = 0; k < 3; ++k) c[k].data()[i] = double(px[k]) - background[k].data()[i];
  }
  return c;
}

/// The pixels whose colour change exceeds `threshold` levels (Euclidean over the channels),
/// less the 8-connected regions of fewer than `min_area` of them (specks of noise or of a dot's
/// edge; 0 keeps every region), with the holes of what remains filled (a ball's centre, flat,
/// barely changes colour): the regions of the complement that do not reach the frame's border
/// (4-connected), searched within the mask's bounding box widened by a pixel (a region that
/// reaches that box's border reaches the outside too).
template <class = void>
image::Mask touched_mask(const Colour& change, double threshold, int min_area) {
  const Eigen::Index rows = change[0].rows(), cols = change[0].cols();
  image::Mask mask(rows, cols);
  const double t2 = threshold * threshold;
  for (Eigen::Index i = 0; i < mask.size(); ++i) {
    const double a = change[0].data()[i], b = change[1].data()[i], d = change[2].data()[i];
    mask.data()[i] = a * a + b * b + d * d > t2 ? 1 : 0;
  }
  image::Components comp;
  if (min_area > 1) {
    const int n = comp.compute(mask, image::Connectivity::eight);
    const image::Labels& lab = comp.labels();
    for (Eigen::Index i = 0; i < mask.size(); ++i) {
      const int l = lab.data()[i];
      if (l > 0 && l <= n && comp.area(l) < min_area) mask.data()[i] = 0;
    }
  }
  Eigen::Index r0 = rows, r1 = -1, c0 = cols, c1 = -1;
  for (Eigen::Index r = 0; r < rows; ++r) {
    for (Eigen::Index c = 0; c < cols; ++c) {
      if (!mask(r, c)) continue;
      r0 = std::min(r0, r);
      r1 = std::max(r1, r);
      c0 = std::min(c0, c);
      c1 = std::max(c1, c);
    }
  }
  if (r1 < 0) return mask;
  r0 = std::max<Eigen::Index>(r0 - 1, 0);
  c0 = std::max<Eigen::Index>(c0 - 1, 0);
  r1 = std::min<Eigen::Index>(r1 + 1, rows - 1);
  c1 = std::min<Eigen::Index>(c1 + 1, cols - 1);
  const Eigen::Index h = r1 - r0 + 1, w = c1 - c0 + 1;
  const image::Mask outside = (mask.block(r0, c0, h, w) == 0).cast<std::uint8_t>();
  const int n = comp.compute(outside, image::Connectivity::four);
  std::vector<char> border(static_cast<std::size_t>(n) + 1, 0);
  const image::Labels& lab = comp.labels();
  for (Eigen::Index r = 0; r < h; ++r) {
    for (Eigen::Index c = 0; c < w; ++c) {
      if (r == 0 || c == 0 || r == h - 1 || c == w - 1) {
        border[static_cast<std::size_t>(lab(r, c))] = 1;
      }
    }
  }
  for (Eigen::Index r = 0; r < h; ++r) {
    for (Eigen::Index c = 0; c < w; ++c) {
      const auto l = lab(r, c);
      if (l > 0 && !border[static_cast<std::size_t>(l)]) mask(r0 + r, c0 + c) = 1;
    }
  }
  return mask;
}

/// The pixels whose colour change exceeds `threshold` levels, with the holes of each region
/// filled (touched_mask keeping every region).
template <class = void>
image::Mask contact_mask(const Colour& change, double threshold) {
  return touched_mask(change, threshold, 0);
}

/// A contact circle in pixels: centre (column, row) and radius.
struct Circle {
  double cx = 0;      ///< centre column [px]
  double cy = 0;      ///< centre row [px]
  double radius = 0;  ///< [px]
};

/// A ball press's contact circle: the largest 8-connected region of the contact mask and the
/// least-squares circle through its boundary pixels (Kasa, "A circle fitting procedure and its
/// error analysis", IEEE Trans. Instrum. Meas. 25(1), 1976), widened by half a pixel (boundary
/// pixel centres lie inside the edge). Throws std::runtime_error when no region of at least
/// `min_pixels` pixels changes colour (a press with no contact).
template <class = void>
Circle find_contact_circle(const Colour& change, double threshold = 12.0, int min_pixels = 30) {
  const image::Mask mask = contact_mask(change, threshold);
  image::Components comp;
  const int n = comp.compute(mask, image::Connectivity::eight);
  int best = 0;
  for (int i = 1; i <= n; ++i) {
    if (best == 0 || comp.area(i) > comp.area(best)) best = i;
  }
  if (best == 0 || comp.area(best) < min_pixels) {
    throw std::runtime_error("find_contact_circle: no contact (no region of " +
                             std::to_string(min_pixels) + " pixels changes colour by more than " +
                             std::to_string(threshold) + " levels)");
  }
  const image::Labels& lab = comp.labels();
  const Eigen::Index rows = lab.rows(), cols = lab.cols();
  // Kasa: x^2 + y^2 + D x + E y + F = 0 by least squares over the boundary pixels.
  Eigen::Matrix3d A = Eigen::Matrix3d::Zero();
  Eigen::Vector3d b = Eigen::Vector3d::Zero();
  double ox = 0, oy = 0;
  int count = 0;
  for (Eigen::Index r = 0; r < rows; ++r) {
    for (Eigen::Index c = 0; c < cols; ++c) {
      if (lab(r, c) != best) continue;
      ox += double(c);
      oy += double(r);
      ++count;
    }
  }
  ox /= count;
  oy /= count;
  for (Eigen::Index r = 0; r < rows; ++r) {
    for (Eigen::Index c = 0; c < cols; ++c) {
      if (lab(r, c) != best) continue;
      const bool edge = r == 0 || c == 0 || r == rows - 1 || c == cols - 1 ||
                        lab(r - 1, c) != best || lab(r + 1, c) != best || lab(r, c - 1) != best ||
                        lab(r, c + 1) != best;
      if (!edge) continue;
      const double x = double(c) - ox, y = double(r) - oy;
      const Eigen::Vector3d row(x, y, 1.0);
      A += row * row.transpose();
      b -= row * (x * x + y * y);
    }
  }
  const Eigen::Vector3d s = A.ldlt().solve(b);
  Circle out;
  out.cx = ox - 0.5 * s[0];
  out.cy = oy - 0.5 * s[1];
  out.radius = std::sqrt(std::max(0.25 * (s[0] * s[0] + s[1] * s[1]) - s[2], 0.0)) + 0.5;
  return out;
}

/// A ball press's contact circle on a real gel, whose colour also changes around the contact
/// (the gel drapes from the ball's edge to the flat, and lighting shifts): starting from
/// find_contact_circle's, the circle of radius at most `max_radius` [px] (the ball's radius)
/// whose inner ring, from 0.755 times its radius to its edge, changes colour most beyond the
/// band outside it (half its radius wide, at least 5 px). This contrast is largest at the
/// edge of the contact, where a sphere's slope is steepest and the drape begins (the score of
/// Yuan et al.'s GelSight calibration, MIT GelSight-lab/gelsight_driver, 2018). Pixels of
/// `dots` (marker dots; may be empty) are left out. Centres within a third of the starting
/// radius (at most max_radius) are searched on a 2 px grid, then on a 0.5 px grid around the
/// best, radii on a 0.5 px grid with a parabola through the best score and its neighbours.
/// Throws std::runtime_error as find_contact_circle does, std::invalid_argument for
/// max_radius < 4.
template <class = void>
Circle find_press_circle(const Colour& change, const image::Mask& dots, double max_radius,
                         double threshold = 12.0) {
  if (!(max_radius >= 4)) throw std::invalid_argument("find_press_circle: max_radius < 4 px");
  const Circle start = find_contact_circle(change, threshold);
  const double min_radius = std::max(3.0, 0.3 * std::min(start.radius, max_radius));
  const Eigen::Index rows = change[0].rows(), cols = change[0].cols();
  const bool use_dots = dots.rows() == rows && dots.cols() == cols;
  Plane m(rows, cols);
  for (Eigen::Index r = 0; r < rows; ++r) {
    for (Eigen::Index c = 0; c < cols; ++c) {
      const double a = change[0](r, c), b = change[1](r, c), d = change[2](r, c);
      m(r, c) = use_dots && dots(r, c) ? -1.0 : std::sqrt(a * a + b * b + d * d);
    }
  }
  const double top = max_radius * 1.5 + 5.0;  // the outer band's reach for the largest radius
  const int bins = static_cast<int>(2.0 * top) + 2;
  std::vector<double> sum(static_cast<std::size_t>(bins)), count(sum.size());
  std::vector<double> csum(sum.size() + 1), ccount(sum.size() + 1);
  // The best (score, radius) for a centre; radii on a 0.5 px grid from 3 px to max_radius.
  const auto score_at = [&](double cx, double cy, double& best_r) {
    std::fill(sum.begin(), sum.end(), 0.0);
    std::fill(count.begin(), count.end(), 0.0);
    const auto r0 = static_cast<Eigen::Index>(std::max(0.0, std::floor(cy - top)));
    const auto r1 = static_cast<Eigen::Index>(std::min(double(rows - 1), std::ceil(cy + top)));
    const auto c0 = static_cast<Eigen::Index>(std::max(0.0, std::floor(cx - top)));
    const auto c1 = static_cast<Eigen::Index>(std::min(double(cols - 1), std::ceil(cx + top)));
    for (Eigen::Index r = r0; r <= r1; ++r) {
      for (Eigen::Index c = c0; c <= c1; ++c) {
        const double v = m(r, c);
        if (v < 0) continue;
        const double rho = std::hypot(double(c) - cx, double(r) - cy);
        const int k = static_cast<int>(2.0 * rho);
        if (k >= bins) continue;
        sum[std::size_t(k)] += v;
        count[std::size_t(k)] += 1;
      }
    }
    for (int k = 0; k < bins; ++k) {
      csum[std::size_t(k) + 1] = csum[std::size_t(k)] + sum[std::size_t(k)];
      ccount[std::size_t(k) + 1] = ccount[std::size_t(k)] + count[std::size_t(k)];
    }
    const auto mean = [&](int a, int b) {  // over bins [a, b)
      const double n = ccount[std::size_t(b)] - ccount[std::size_t(a)];
      return n > 0 ? (csum[std::size_t(b)] - csum[std::size_t(a)]) / n : 0.0;
    };
    // The ring profile, smoothed over 1.5 px, and its peak between min_radius and max_radius.
    const int kmin = static_cast<int>(2.0 * min_radius), kmax = static_cast<int>(2.0 * max_radius);
    std::vector<double> prof(std::size_t(kmax + 2), 0.0);
    for (int k = std::max(1, kmin - 1); k <= kmax + 1 && k + 2 <= bins; ++k) {
      prof[std::size_t(k)] = mean(k - 1, k + 2);
    }
    int at = kmin;
    for (int k = kmin; k <= kmax; ++k) {
      if (prof[std::size_t(k)] > prof[std::size_t(at)]) at = k;
    }
    double offset = 0;
    if (at > kmin && at < kmax) {
      const double l = prof[std::size_t(at - 1)], c = prof[std::size_t(at)],
                   rr = prof[std::size_t(at + 1)], curve = l - 2 * c + rr;
      if (curve < 0) offset = std::clamp(0.5 * (l - rr) / curve, -0.5, 0.5);
    }
    // (bin k holds radii [k / 2, (k + 1) / 2); kept inside the ball, whose edge is vertical)
    best_r = std::min(0.5 * (double(at) + offset + 0.5), 0.98 * max_radius);
    return prof[std::size_t(at)];
  };
  // The centre: where the colour change is most nearly odd. A slope's colour change is
  // mostly linear in the slope, and a ball's slopes are odd about its centre, so the change at
  // c + u and at c - u cancel; the drape and the lighting's fall-off do not move that point.
  // Centres c on the half-pixel grid pair whole pixels c + u and c - u.
  const double disk = std::min(max_radius, start.radius);
  const auto oddness = [&](int hx, int hy) {  // centre (hx / 2, hy / 2)
    double cross = 0, energy = 0;
    const int reach = static_cast<int>(disk);
    for (int dy = -reach; dy <= reach; ++dy) {
      const int r1 = (hy + dy * 2) >> 1, r2 = hy - r1;  // rows r1 + r2 = hy
      if (dy < 0 || r1 < 0 || r2 < 0 || r1 >= rows || r2 >= rows) continue;
      for (int dx = -reach; dx <= reach; ++dx) {
        if (dy == 0 && dx < 0) continue;  // each pair once
        const int c1 = (hx + dx * 2) >> 1, c2 = hx - c1;
        if (c1 < 0 || c2 < 0 || c1 >= cols || c2 >= cols) continue;
        const double x = 0.5 * (c1 - c2), y = 0.5 * (r1 - r2);
        if (x * x + y * y > disk * disk) continue;
        if (m(r1, c1) < 0 || m(r2, c2) < 0) continue;
        for (int k = 0; k < 3; ++k) {
          const double a = change[std::size_t(k)](r1, c1), b = change[std::size_t(k)](r2, c2);
          cross += a * b;
          energy += 0.5 * (a * a + b * b);
        }
      }
    }
    return energy > 0 ? cross / energy : 1.0;
  };
  int bx = static_cast<int>(std::lround(2 * start.cx)),
      by = static_cast<int>(std::lround(2 * start.cy));
  const int reach = 2 * static_cast<int>(std::max(4.0, disk / 2.5));
  double best = 2.0;
  for (int step : {4, 1}) {
    const int span = step == 4 ? reach : 4;
    const int x0 = bx, y0 = by;
    for (int i = -span; i <= span; i += step) {
      for (int j = -span; j <= span; j += step) {
        const double v = oddness(x0 + j, y0 + i);
        if (v < best) {
          best = v;
          bx = x0 + j;
          by = y0 + i;
        }
      }
    }
  }
  Circle out;
  out.cx = 0.5 * bx;
  out.cy = 0.5 * by;
  score_at(out.cx, out.cy, out.radius);
  return out;
}

/// How a calibration is made.
struct CalibrationOptions {
  double ball_radius = 0;   ///< the ball's radius [m], > 0
  double pixel = 0;         ///< the gel's size of one pixel [m], > 0
  double threshold = 12.0;  ///< a contact changes colour by more than this [levels]
  double margin = 2.0;      ///< pixels next to a circle's edge are left out [px]
  int table_bins = 32;      ///< lookup-table cells per channel, in [4, 128]
  double ridge = 1e-6;      ///< the polynomial's ridge, relative to the features' scale
  int outside_stride = 3;   ///< every n-th pixel outside the circles is a sample of 0
  bool markers = true;      ///< leave marker dots out (markers.hpp)
  MarkerOptions marker{};   ///< how dots are found
};

/// A map from colour change to surface gradient, and what it was measured to do.
struct Calibration {
  /// The map in use.
  enum class Method { polynomial, lookup_table };
  int rows = 0;                        ///< frame rows the calibration is for
  int cols = 0;                        ///< frame columns the calibration is for
  double pixel = 0;                    ///< [m]
  double threshold = 12;               ///< contact threshold [levels]
  Colour background;                   ///< the no-contact frame's colour planes
  Method method = Method::polynomial;  ///< the map kept
  Eigen::MatrixXd polynomial;          ///< features x 2 (gx, gy) coefficients
  int table_bins = 0;                  ///< cells per channel
  double table_range = 0;              ///< the table covers changes in [-range, range) [levels]
  std::vector<float> table;            ///< bins^3 x (gx, gy)
  std::vector<Circle> circles;         ///< each press's contact circle [px]
  bool markers = true;                 ///< marker dots are left out and filled in
  MarkerOptions marker{};              ///< how dots are found
  image::Mask background_markers;      ///< the background's dots (when `markers`)
  double heldout_polynomial = 0;       ///< held-out RMS gradient error of the polynomial [-]
  double heldout_table = 0;            ///< held-out RMS gradient error of the table [-]

  /// The kept map's held-out RMS gradient error.
  double heldout() const {
    return method == Method::polynomial ? heldout_polynomial : heldout_table;
  }

  /// Gradient (gx, gy) of a colour change (dr, dg, db) at pixel (r, c).
  void gradient(double dr, double dg, double db, int r, int c, double& gx, double& gy) const {
    if (method == Method::lookup_table) {
      const std::size_t i = cell(dr, dg, db);
      gx = table[2 * i];
      gy = table[2 * i + 1];
      return;
    }
    double f[kFeatures];
    features(dr, dg, db, frame_position(c, cols), frame_position(r, rows), f);
    gx = gy = 0;
    for (int k = 0; k < kFeatures; ++k) {
      gx += f[k] * polynomial(k, 0);
      gy += f[k] * polynomial(k, 1);
    }
  }

  /// The polynomial's features: the changes (scaled by 1/100) up to degree 3 (19 terms), those
  /// times the squared distance from the centre (19), the linear ones times u and v (6), and 1.
  static constexpr int kFeatures = 45;
  /// Position of index i of n in [-1, 1] (a pixel's column or row across the frame).
  static double frame_position(int i, int n) { return n > 1 ? 2.0 * i / (n - 1) - 1.0 : 0.0; }
  /// Writes the kFeatures features of a colour change at position (u, v) to f.
  static void features(double dr, double dg, double db, double u, double v, double* f) {
    const double a = dr / 100, b = dg / 100, c = db / 100;
    const double m[19] = {a,         b,         c,         a * a,     b * b,
                          c * c,     a * b,     a * c,     b * c,     a * a * a,
                          b * b * b, c * c * c, a * a * b, a * a * c, b * b * a,
                          b * b * c, c * c * a, c * c * b, a * b * c};
    const double rho2 = 0.5 * (u * u + v * v);
    f[0] = 1.0;
    for (int k = 0; k < 19; ++k) {
      f[1 + k] = m[k];
      f[20 + k] = rho2 * m[k];
    }
    f[39] = u * a;
    f[40] = u * b;
    f[41] = u * c;
    f[42] = v * a;
    f[43] = v * b;
    f[44] = v * c;
  }

  /// The lookup table's cell of a colour change.
  std::size_t cell(double dr, double dg, double db) const {
    const auto bin = [&](double d) {
      const double t = (d + table_range) / (2 * table_range) * table_bins;
      return static_cast<std::size_t>(std::clamp(t, 0.0, double(table_bins) - 1.0));
    };
    const auto n = static_cast<std::size_t>(table_bins);
    return (bin(dr) * n + bin(dg)) * n + bin(db);
  }
};

namespace detail {
struct GradientSample {
  double d[3];
  int r, c;
  double gx, gy;
  int press;
  bool inside;
};

template <class = void>
Eigen::MatrixXd fit_polynomial(const std::vector<GradientSample>& s, int rows, int cols,
                               double ridge, const std::vector<char>& use) {
  constexpr int F = Calibration::kFeatures;
  Eigen::MatrixXd ata = Eigen::MatrixXd::Zero(F, F), atb = Eigen::MatrixXd::Zero(F, 2);
  double f[F];
  for (std::size_t i = 0; i < s.size(); ++i) {
    if (!use[static_cast<std::size_t>(s[i].press)]) continue;
    Calibration::features(s[i].d[0], s[i].d[1], s[i].d[2],
                          Calibration::frame_position(s[i].c, cols),
                          Calibration::frame_position(s[i].r, rows), f);
    const Eigen::Map<const Eigen::VectorXd> x(f, F);
    ata.selfadjointView<Eigen::Lower>().rankUpdate(x);
    atb.col(0) += x * s[i].gx;
    atb.col(1) += x * s[i].gy;
  }
  ata.triangularView<Eigen::StrictlyUpper>() = ata.transpose();
  const double scale = ata.diagonal().mean();
  ata.diagonal().array() += ridge * scale;
  return ata.ldlt().solve(atb);
}

template <class = void>
void fit_table(Calibration& cal, const std::vector<GradientSample>& s, const std::vector<char>& use,
               int bins) {
  double range = 1.0;
  for (const auto& x : s) {
    for (const double d : x.d) range = std::max(range, std::abs(d));
  }
  cal.table_bins = bins;
  cal.table_range = range * (1 + 1e-9);
  const auto n = static_cast<std::size_t>(bins) * static_cast<std::size_t>(bins) *
                 static_cast<std::size_t>(bins);
  std::vector<double> sum(2 * n, 0.0), count(n, 0.0);
  for (const auto& x : s) {
    if (!use[static_cast<std::size_t>(x.press)]) continue;
    const std::size_t i = cal.cell(x.d[0], x.d[1], x.d[2]);
    sum[2 * i] += x.gx;
    sum[2 * i + 1] += x.gy;
    count[i] += 1;
  }
  std::vector<std::size_t> filled;
  for (std::size_t i = 0; i < n; ++i) {
    if (count[i] > 0) filled.push_back(i);
  }
  cal.table.assign(2 * n, 0.0f);
  if (filled.empty()) return;
  const auto coords = [&](std::size_t i, int& a, int& b, int& c) {
    c = static_cast<int>(i % static_cast<std::size_t>(bins));
    b = static_cast<int>(i / static_cast<std::size_t>(bins) % static_cast<std::size_t>(bins));
    a = static_cast<int>(i / (static_cast<std::size_t>(bins) * static_cast<std::size_t>(bins)));
  };
  for (std::size_t i = 0; i < n; ++i) {
    std::size_t from = i;
    if (count[i] == 0) {
      int a, b, c;
      coords(i, a, b, c);
      long best = std::numeric_limits<long>::max();
      for (const std::size_t j : filled) {
        int x, y, z;
        coords(j, x, y, z);
        const long d = long(x - a) * (x - a) + long(y - b) * (y - b) + long(z - c) * (z - c);
        if (d < best) {
          best = d;
          from = j;
        }
      }
    }
    cal.table[2 * i] = static_cast<float>(sum[2 * from] / count[from]);
    cal.table[2 * i + 1] = static_cast<float>(sum[2 * from + 1] / count[from]);
  }
}

// RMS gradient error over the samples inside the circles of the presses in `use`.
inline double gradient_rms(const Calibration& cal, const std::vector<GradientSample>& s,
                           const std::vector<char>& use) {
  double e = 0;
  std::size_t n = 0;
  for (const auto& x : s) {
    if (!x.inside || !use[static_cast<std::size_t>(x.press)]) continue;
    double gx, gy;
    cal.gradient(x.d[0], x.d[1], x.d[2], x.r, x.c, gx, gy);
    e += (gx - x.gx) * (gx - x.gx) + (gy - x.gy) * (gy - x.gy);
    ++n;
  }
  return n ? std::sqrt(e / double(n)) : std::numeric_limits<double>::quiet_NaN();
}
}  // namespace detail

/// Calibrates from ball presses over a no-contact `background` frame. `circles`, when given,
/// overrides the circle found in each press (one per press; a user's review). Throws
/// std::invalid_argument for bad options, frames of another size than the background's or
/// fewer than two presses, and std::runtime_error naming a press with no contact.
template <class = void>
Calibration calibrate(const std::vector<RgbFrame>& presses, const RgbFrame& background,
                      const CalibrationOptions& o, const std::vector<Circle>& circles = {}) {
  if (!(o.ball_radius > 0) || !std::isfinite(o.ball_radius)) {
    throw std::invalid_argument("calibrate: ball_radius must be finite and > 0 [m]");
  }
  if (!(o.pixel > 0) || !std::isfinite(o.pixel)) {
    throw std::invalid_argument("calibrate: pixel must be finite and > 0 [m]");
  }
  if (o.table_bins < 4 || o.table_bins > 128) {
    throw std::invalid_argument("calibrate: table_bins must be in [4, 128]");
  }
  if (!(o.threshold > 0) || !(o.margin >= 0) || o.outside_stride < 1 || !(o.ridge >= 0)) {
    throw std::invalid_argument(
        "calibrate: threshold > 0, margin >= 0, ridge >= 0 and "
        "outside_stride >= 1 are needed");
  }
  if (presses.size() < 2) throw std::invalid_argument("calibrate: at least two presses");
  if (!circles.empty() && circles.size() != presses.size()) {
    throw std::invalid_argument("calibrate: " + std::to_string(circles.size()) + " circles for " +
                                std::to_string(presses.size()) + " presses");
  }
  validate_frame(background, "calibrate (background)");
  if (o.ball_radius / o.pixel < 4) {
    char buf[64];
    std::snprintf(buf, sizeof buf, "%.2g", o.ball_radius / o.pixel);
    throw std::invalid_argument(std::string("calibrate: the ball's radius is ") + buf +
                                " px, under 4: check ball_radius and pixel (both in metres)");
  }
  Calibration cal;
  cal.rows = static_cast<int>(background.rows);
  cal.cols = static_cast<int>(background.cols);
  cal.pixel = o.pixel;
  cal.threshold = o.threshold;
  cal.background = colour_planes(background);
  cal.markers = o.markers;
  cal.marker = o.marker;
  if (o.markers) cal.background_markers = marker_mask(background, o.marker);
  std::vector<detail::GradientSample> samples;
  const double R2 = o.ball_radius * o.ball_radius;
  for (std::size_t p = 0; p < presses.size(); ++p) {
    if (presses[p].rows != cal.rows || presses[p].cols != cal.cols) {
      throw std::invalid_argument("calibrate: press " + std::to_string(p) + " is " +
                                  std::to_string(presses[p].rows) + " x " +
                                  std::to_string(presses[p].cols) + ", the background " +
                                  std::to_string(cal.rows) + " x " + std::to_string(cal.cols));
    }
    Colour change = colour_change(presses[p], cal.background);
    image::Mask dots;
    if (o.markers) {
      dots = marker_mask(presses[p], o.marker);
      dots = (dots != 0 || cal.background_markers != 0).cast<std::uint8_t>();
      for (Plane& ch : change) ch = (dots != 0).select(0.0, ch);
    }
    Circle circle;
    if (!circles.empty()) {
      circle = circles[p];
    } else {
      try {
        circle = find_press_circle(change, dots, o.ball_radius / o.pixel, o.threshold);
      } catch (const std::runtime_error& e) {
        throw std::runtime_error("calibrate: press " + std::to_string(p) + ": " + e.what());
      }
    }
    if (!(circle.radius * o.pixel < o.ball_radius)) {
      char buf[32];
      std::snprintf(buf, sizeof buf, "%.4g", circle.radius);
      throw std::runtime_error("calibrate: press " + std::to_string(p) + ": its contact circle (" +
                               buf + " px) is wider than the ball; check ball_radius and pixel");
    }
    cal.circles.push_back(circle);
    std::size_t inside = 0;
    // Outside, the gel is flat (slope 0) beyond the band where it drapes from the ball's edge
    // (half the contact's radius), which is left out.
    const double inner = circle.radius - o.margin,
                 outer = circle.radius + std::max(o.margin, 0.5 * circle.radius);
    for (int r = 0; r < cal.rows; ++r) {
      for (int c = 0; c < cal.cols; ++c) {
        if (o.markers && dots(r, c)) continue;
        const double x = c - circle.cx, y = r - circle.cy;
        const double rho = std::hypot(x, y);
        detail::GradientSample s{{change[0](r, c), change[1](r, c), change[2](r, c)},
                                 r,
                                 c,
                                 0.0,
                                 0.0,
                                 static_cast<int>(p),
                                 false};
        if (rho < inner) {
          const double root = std::sqrt(R2 - rho * rho * o.pixel * o.pixel);
          s.gx = -x * o.pixel / root;
          s.gy = -y * o.pixel / root;
          s.inside = true;
        } else if (rho <= outer || (r * cal.cols + c) % o.outside_stride != 0) {
          continue;
        }
        samples.push_back(s);
        inside += s.inside;
      }
    }
    if (inside < 20) {
      throw std::runtime_error("calibrate: press " + std::to_string(p) + ": only " +
                               std::to_string(inside) +
                               " pixels inside its contact circle (at least 20 are needed)");
    }
  }
  std::vector<char> even(presses.size()), odd(presses.size()), all(presses.size(), 1);
  for (std::size_t p = 0; p < presses.size(); ++p) {
    even[p] = p % 2 == 0;
    odd[p] = p % 2 == 1;
  }
  // Held-out errors: fit on the even presses, measure on the odd ones.
  cal.method = Calibration::Method::polynomial;
  cal.polynomial = detail::fit_polynomial(samples, cal.rows, cal.cols, o.ridge, even);
  cal.heldout_polynomial = detail::gradient_rms(cal, samples, odd);
  detail::fit_table(cal, samples, even, o.table_bins);
  cal.method = Calibration::Method::lookup_table;
  cal.heldout_table = detail::gradient_rms(cal, samples, odd);
  // The better map, refitted on every press.
  if (cal.heldout_polynomial <= cal.heldout_table) {
    cal.method = Calibration::Method::polynomial;
    cal.polynomial = detail::fit_polynomial(samples, cal.rows, cal.cols, o.ridge, all);
  } else {
    detail::fit_table(cal, samples, all, o.table_bins);
  }
  return cal;
}

}  // namespace taxel::optical
