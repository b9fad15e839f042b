// SPDX-License-Identifier: MIT
// A frame to a height map and contacts: the colour change against the calibration's
// background (marker dots left out, markers.hpp), the calibrated map to gradients (the dots'
// filled from around them), the deformed gel's mask (colour change beyond the threshold,
// holes filled, specks dropped, grown by `grow` pixels), gradients set to zero outside it (the
// untouched gel is flat; this keeps the integration's drift out of the contact), and the
// Poisson integration (poisson.hpp, free border: a contact may reach the frame's edge) to
// heights in metres, positive into the gel, the untouched pixels averaging zero. The contact
// mask is the deformed pixels at least `contact_share` of the deepest height: around a
// contact the gel drapes back to the flat, deformed but not touched.
// Contacts, in the sensor frame: x along the frame's columns and y along its rows, from the
// frame's centre, z = -height (the sensing face looks along +z, into the touched object, as a
// pad's does), the normal -(gx, gy, 1) / |(gx, gy, 1)|. Every `stride`-th pixel of the contact
// mask in each direction gives one, standing for a stride x stride footprint.
#pragma once

#include <Eigen/Cholesky>
#include <Eigen/Geometry>
#include <algorithm>
#include <cmath>
#include <cstdint>
#include <stdexcept>
#include <string>
#include <vector>

#include "taxel/core/contact.hpp"
#include "taxel/optical/calibration.hpp"
#include "taxel/optical/markers.hpp"
#include "taxel/optical/poisson.hpp"

namespace taxel::optical {

/// What a frame shows.
struct HeightMap {
  Plane height;      ///< [m], positive into the gel; the untouched gel averages 0
  Plane gx;          ///< d height / dx, along columns (0 outside the mask)
  Plane gy;          ///< d height / dy, along rows (0 outside the mask)
  image::Mask mask;  ///< 1 where the gel is deformed (its colour changed)
  /// 1 where the object touches: deformed and at least ReconstructOptions::contact_share of
  /// the deepest height (the gel drapes from the contact's edge back to the flat, lower).
  image::Mask contact;
};

/// How reconstruct works a frame.
struct ReconstructOptions {
  int grow = 2;       ///< pixels added around the mask before integration, >= 0
  int min_area = 30;  ///< regions of the mask under this many pixels are specks, dropped; >= 0
  /// The contact mask's share of the deepest height, in [0, 1).
  double contact_share = 0.3;
};

/// A frame's height map (see the header comment). Throws std::invalid_argument for a frame of
/// another size than the calibration's, a solver of another size or options out of range.
template <class = void>
HeightMap reconstruct(const RgbFrame& frame, const Calibration& cal, PoissonSolver& solver,
                      const ReconstructOptions& options = {}) {
  validate_frame(frame, "reconstruct");
  if (frame.rows != cal.rows || frame.cols != cal.cols) {
    throw std::invalid_argument("reconstruct: the frame is " + std::to_string(frame.rows) + " x " +
                                std::to_string(frame.cols) + ", the calibration is for " +
                                std::to_string(cal.rows) + " x " + std::to_string(cal.cols));
  }
  if (solver.rows() != cal.rows || solver.cols() != cal.cols) {
    throw std::invalid_argument("reconstruct: the solver is for another frame size");
  }
  const int grow = options.grow, min_area = options.min_area;
  if (grow < 0 || min_area < 0 || !(options.contact_share >= 0 && options.contact_share < 1)) {
    throw std::invalid_argument(
        "reconstruct: grow and min_area must be >= 0, contact_share in [0, 1)");
  }
  Colour change = colour_change(frame, cal.background);
  // A frame far darker than the background (the lights off, the lens covered) or far brighter
  // (saturated) shows no gel: refused rather than read as a press over the whole frame. The
  // change's mean is the frame's minus the background's.
  const double base =
      (cal.background[0].sum() + cal.background[1].sum() + cal.background[2].sum()) /
      double(3 * frame.rows * frame.cols);
  std::uint64_t bytes = 0;
  for (const std::uint8_t v : frame.data) bytes += v;
  const double level = double(bytes) / double(frame.data.size()) - base;
  if (!(std::abs(level) <= 0.5 * base)) {
    throw std::invalid_argument(
        "reconstruct: the frame's mean level differs from the "
        "background's (" +
        std::to_string(base) + ") by " + std::to_string(level) +
        ": no gel in view (lights off, lens covered or saturated)?");
  }
  HeightMap out;
  image::Mask dots;
  if (cal.markers) {
    dots = marker_mask(frame, cal.marker);
    // The background's dots too; no colour change where a dot is, in one pass.
    const bool known = cal.background_markers.size() == dots.size();
    for (Eigen::Index i = 0; i < dots.size(); ++i) {
      if (known && cal.background_markers.data()[i]) dots.data()[i] = 1;
      if (dots.data()[i]) {
        for (Plane& ch : change) ch.data()[i] = 0.0;
      }
    }
  }
  out.mask = touched_mask(change, cal.threshold, min_area);
  // The mask's bounding box, grown with it: the loops below stay inside it.
  int r0 = cal.rows, r1 = -1, c0 = cal.cols, c1 = -1;
  {
    // Rows, then columns, that hold any of the mask (a running maximum, no branch per pixel).
    std::vector<std::uint8_t> in_col(static_cast<std::size_t>(cal.cols), 0);
    for (int r = 0; r < cal.rows; ++r) {
      const std::uint8_t* row = out.mask.data() + static_cast<std::ptrdiff_t>(r) * cal.cols;
      std::uint8_t any = 0;
      for (int c = 0; c < cal.cols; ++c) {
        in_col[static_cast<std::size_t>(c)] |= row[c];
        any |= row[c];
      }
      if (any) {
        r0 = std::min(r0, r);
        r1 = r;
      }
    }
    for (int c = 0; c < cal.cols; ++c) {
      if (!in_col[static_cast<std::size_t>(c)]) continue;
      c0 = std::min(c0, c);
      c1 = c;
    }
  }
  image::Mask grown = out.mask;
  for (int g = 0; g < grow && r1 >= 0; ++g) {
    r0 = std::max(r0 - 1, 0);
    c0 = std::max(c0 - 1, 0);
    r1 = std::min(r1 + 1, cal.rows - 1);
    c1 = std::min(c1 + 1, cal.cols - 1);
    // The box holds the mask with a pixel to spare: growing it there grows the whole mask.
    const int h = r1 - r0 + 1, w = c1 - c0 + 1;
    grown.block(r0, c0, h, w) = detail::dilate4(grown.block(r0, c0, h, w));
  }
  out.gx = Plane::Zero(cal.rows, cal.cols);
  out.gy = Plane::Zero(cal.rows, cal.cols);
  for (int r = r0; r <= r1; ++r) {
    for (int c = c0; c <= c1; ++c) {
      if (!grown(r, c) || (cal.markers && dots(r, c))) continue;
      cal.gradient(change[0](r, c), change[1](r, c), change[2](r, c), r, c, out.gx(r, c),
                   out.gy(r, c));
    }
  }
  if (cal.markers && r1 >= 0) {
    // The dots' gradients from around them (within the grown mask's box, widened by the dots'
    // reach), then zero again outside the grown mask.
    const int reach = cal.marker.reach + 1;
    const int br0 = std::max(r0 - reach, 0), bc0 = std::max(c0 - reach, 0);
    const int bh = std::min(r1 + reach, cal.rows - 1) - br0 + 1;
    const int bw = std::min(c1 + reach, cal.cols - 1) - bc0 + 1;
    const image::Mask holes = dots.block(br0, bc0, bh, bw);
    for (Plane* g : {&out.gx, &out.gy}) {
      Plane part = g->block(br0, bc0, bh, bw);
      fill_holes(part, holes);
      g->block(br0, bc0, bh, bw) = (grown.block(br0, bc0, bh, bw) != 0).select(part, 0.0);
    }
  }
  // Only the contact's neighbourhood is integrated: the grown mask's bounding box, widened by
  // half its size and at least 16 pixels each way, its sides rounded up to multiples of 32
  // pixels (so that few solver sizes recur) within the frame. Outside it the gel is flat, at
  // height 0; inside, the untouched pixels average 0. A frame without contact is flat.
  out.height = Plane::Zero(cal.rows, cal.cols);
  if (r1 >= 0) {
    const auto window = [](int lo, int hi, int size, int& start, int& length) {
      const int pad = std::max(16, (hi - lo + 1) / 2);
      length = std::min(size, ((hi - lo + 1 + 2 * pad + 31) / 32) * 32);
      start = std::clamp((lo + hi + 1) / 2 - length / 2, 0, size - length);
    };
    int top = 0, rows = 0, left = 0, cols = 0;
    window(r0, r1, static_cast<int>(cal.rows), top, rows);
    window(c0, c1, static_cast<int>(cal.cols), left, cols);
    const image::Mask untouched = (grown.block(top, left, rows, cols) == 0).cast<std::uint8_t>();
    out.height.block(top, left, rows, cols) =
        solver.part(rows, cols)
            .integrate(out.gx.block(top, left, rows, cols), out.gy.block(top, left, rows, cols),
                       cal.pixel, PoissonBorder::free, untouched);
  }
  // The mask, and so the contact, lies within rows r0..r1 and columns c0..c1 (grown).
  out.contact = image::Mask::Zero(cal.rows, cal.cols);
  if (r1 < 0) return out;
  double deepest = 0;
  for (int r = r0; r <= r1; ++r) {
    for (int c = c0; c <= c1; ++c) {
      if (out.mask(r, c)) deepest = std::max(deepest, out.height(r, c));
    }
  }
  if (!(deepest > 0)) return out;
  const double floor = options.contact_share * deepest;
  for (int r = r0; r <= r1; ++r) {
    for (int c = c0; c <= c1; ++c) out.contact(r, c) = out.mask(r, c) && out.height(r, c) >= floor;
  }
  return out;
}

/// Follows a slow drift of the lighting (a warming lamp, a camera's auto exposure): moves the
/// calibration's background toward `frame` by `rate` (an exponential average over about
/// 1 / rate frames) where `map`, the frame's height map, shows the gel untouched, more than
/// `margin` pixels from its mask. Call it after each frame's reconstruct. The background's
/// marker dots stay where they were found. Throws std::invalid_argument for sizes that differ,
/// a rate outside (0, 1] or a negative margin.
template <class = void>
void track_background(Calibration& cal, const RgbFrame& frame, const HeightMap& map,
                      double rate = 0.05, int margin = 10) {
  validate_frame(frame, "track_background");
  if (frame.rows != cal.rows || frame.cols != cal.cols || map.mask.rows() != cal.rows ||
      map.mask.cols() != cal.cols) {
    throw std::invalid_argument(
        "track_background: the frame, the map and the calibration differ in size");
  }
  if (!(rate > 0 && rate <= 1) || margin < 0) {
    throw std::invalid_argument("track_background: rate in (0, 1] and margin >= 0 are needed");
  }
  // The untouched pixels: outside the mask grown by `margin` (a square reach: the running
  // maximum of the mask, as the marker search's).
  const auto rows = static_cast<int>(cal.rows), cols = static_cast<int>(cal.cols);
  const Plane mask = map.mask.cast<double>();
  const Plane near = margin > 0 ? detail::running_max_2d(mask, margin) : mask;
  for (int r = 0; r < rows; ++r) {
    for (int c = 0; c < cols; ++c) {
      if (near(r, c) > 0) continue;
      const std::uint8_t* p = frame.data.data() + (static_cast<std::size_t>(r) * cols + c) * 3;
      for (int k = 0; k < 3; ++k) {
        double& b = cal.background[static_cast<std::size_t>(k)](r, c);
        b += rate * (double(p[k]) - b);
      }
    }
  }
}

/// Contacts of a height map (see the header comment), in the world through `T_world_sensor`,
/// at `time` [s]. Each states `sigma_height` [m] along its normal and its footprint across it
/// (stride pixels wide), and `normal_sigma` [rad] as its normal's uncertainty; its `pressure`
/// field holds the indentation [m] (an optical sensor measures no force). Appends to `out` and
/// returns the number appended. Throws std::invalid_argument for a stride < 1 or sigmas not
/// finite and > 0.
template <class = void>
std::size_t height_contacts(const HeightMap& map, double pixel,
                            const Eigen::Isometry3d& T_world_sensor, double time,
                            double sigma_height, double normal_sigma, int stride,
                            std::vector<Contact<double>>& out) {
  if (stride < 1) throw std::invalid_argument("height_contacts: stride must be >= 1");
  if (!(sigma_height > 0) || !std::isfinite(sigma_height) || !(normal_sigma > 0) ||
      !std::isfinite(normal_sigma) || !(pixel > 0) || !std::isfinite(pixel)) {
    throw std::invalid_argument(
        "height_contacts: pixel, sigma_height and normal_sigma must be "
        "finite and > 0");
  }
  const Eigen::Index rows = map.height.rows(), cols = map.height.cols();
  const double footprint = stride * pixel / std::sqrt(12.0);
  std::size_t added = 0;
  for (Eigen::Index r = stride / 2; r < rows; r += stride) {
    for (Eigen::Index c = stride / 2; c < cols; c += stride) {
      if (!map.contact(r, c)) continue;
      const Vec3d local((double(c) - 0.5 * double(cols - 1)) * pixel,
                        (double(r) - 0.5 * double(rows - 1)) * pixel, -map.height(r, c));
      const Vec3d n_local = -Vec3d(map.gx(r, c), map.gy(r, c), 1.0).normalized();
      Contact<double> ct;
      ct.position = T_world_sensor * local;
      const Vec3d n = T_world_sensor.linear() * n_local;
      ct.normal = n;
      ct.covariance = pad_covariance<double>(n, sigma_height, footprint);
      ct.footprint_sigma = footprint;
      ct.normal_sigma = normal_sigma;
      ct.time = time;
      ct.pressure = map.height(r, c);
      out.push_back(ct);
      ++added;
    }
  }
  return added;
}

/// A sphere fitted to a height map inside its contact: the algebraic least-squares sphere
/// through the surface points (x, y, -height) of the contact mask's pixels.
struct BallFit {
  double radius = 0;       ///< [m]
  double cx = 0;           ///< centre above this column [px]
  double cy = 0;           ///< centre above this row [px]
  std::size_t points = 0;  ///< pixels used
};

/// See BallFit. Throws std::runtime_error when the contact has fewer than 10 pixels.
template <class = void>
BallFit fit_ball(const HeightMap& map, double pixel) {
  const Eigen::Index rows = map.height.rows(), cols = map.height.cols();
  double ox = 0, oy = 0;
  std::size_t n = 0;
  for (Eigen::Index r = 0; r < rows; ++r) {
    for (Eigen::Index c = 0; c < cols; ++c) {
      if (!map.contact(r, c)) continue;
      ox += double(c);
      oy += double(r);
      ++n;
    }
  }
  if (n < 10) throw std::runtime_error("fit_ball: fewer than 10 pixels of the contact");
  ox /= double(n);
  oy /= double(n);
  // x^2 + y^2 + z^2 + D x + E y + F z + G = 0, about the pixels' centroid.
  Eigen::Matrix4d A = Eigen::Matrix4d::Zero();
  Eigen::Vector4d b = Eigen::Vector4d::Zero();
  for (Eigen::Index r = 0; r < rows; ++r) {
    for (Eigen::Index c = 0; c < cols; ++c) {
      if (!map.contact(r, c)) continue;
      const double x = (double(c) - ox) * pixel, y = (double(r) - oy) * pixel;
      const double z = -map.height(r, c);
      const Eigen::Vector4d v(x, y, z, 1.0);
      A += v * v.transpose();
      b -= v * (x * x + y * y + z * z);
    }
  }
  const Eigen::Vector4d s = A.ldlt().solve(b);
  BallFit fit;
  fit.radius = std::sqrt(std::max(0.25 * (s[0] * s[0] + s[1] * s[1] + s[2] * s[2]) - s[3], 0.0));
  fit.cx = ox - 0.5 * s[0] / pixel;
  fit.cy = oy - 0.5 * s[1] / pixel;
  fit.points = n;
  return fit;
}

}  // namespace taxel::optical
