// SPDX-License-Identifier: MIT
// Sobel gradients as MATLAB's imgradientxy / imgradient: correlation
// with the Sobel kernels, replicate border; Gy > 0 when intensity grows downwards;
// magnitude = hypot(Gx, Gy), direction = atan2(-Gy, Gx) in degrees. Also the contour pixels of a
// region (MATLAB's bwperim, 4-connected).
#pragma once

#include <algorithm>
#include <cmath>
#include <limits>
#include <numbers>
#include <utility>

#include "taxel/image/types.hpp"

namespace taxel::image {

namespace detail {

/// atan(num / den) for 0 <= num <= den, den > 0, within 1 ulp of std::atan: Cephes' rational
/// approximation (S. L. Moshier, Cephes Math Library, atan.c: the coefficients below), with its
/// reduction atan(t) = pi/4 + atan((t - 1) / (t + 1)) above t = 0.66, taken here straight from
/// num and den so that one division forms the argument. Written without branches.
inline double atan_ratio(double num, double den) noexcept {
  constexpr double p0 = -8.750608600031904122785e-1, p1 = -1.615753718733365076637e1,
                   p2 = -7.500855792314704667340e1, p3 = -1.228866684490136173410e2,
                   p4 = -6.485021904942025371773e1;
  constexpr double q0 = 2.485846490142306297962e1, q1 = 1.650270098316988542046e2,
                   q2 = 4.328810604912902668951e2, q3 = 4.853903996359136964868e2,
                   q4 = 1.945506571482613964425e2;
  constexpr double kMoreBits = 6.123233995736765886130e-17;  // pi/2 - double(pi/2)
  const bool high = num > 0.66 * den;
  const double x = high ? (num - den) / (num + den) : num / den;
  const double z = x * x;
  const double p = (((p0 * z + p1) * z + p2) * z + p3) * z + p4;
  const double q = ((((z + q0) * z + q1) * z + q2) * z + q3) * z + q4;
  const double base = high ? std::numbers::pi / 4 : 0.0;
  const double extra = high ? 0.5 * kMoreBits : 0.0;
  return base + (x * (z * p / q) + x + extra);
}

/// atan2(y, x) within 4 ulp (absolute error below 1e-15) of std::atan2 for finite arguments,
/// signed zeros included; several times faster than glibc's. Non-finite arguments and (0, 0)
/// go to std::atan2.
inline double fast_atan2(double y, double x) noexcept {
  const double ax = std::abs(x);
  const double ay = std::abs(y);
  if (!(ax + ay > 0.0) || !(ax + ay < std::numeric_limits<double>::infinity())) {
    return std::atan2(y, x);
  }
  const bool steep = ay > ax;
  double r = atan_ratio(steep ? ax : ay, steep ? ay : ax);
  r = steep ? std::numbers::pi / 2 - r : r;
  r = std::signbit(x) ? std::numbers::pi - r : r;
  return std::signbit(y) ? -r : r;
}

}  // namespace detail

/// Sobel derivatives of `img` into `gx` and `gy` (resized to the image's size).
/// `gx = I (x) [-1 0 1; -2 0 2; -1 0 1]`, `gy = I (x) [-1 -2 -1; 0 0 0; 1 2 1]`.
template <class = void>
inline void sobel(const ImageView& img, ImageD& gx, ImageD& gy) {
  const Eigen::Index rows = img.rows();
  const Eigen::Index cols = img.cols();
  gx.resize(rows, cols);
  gy.resize(rows, cols);
  if (rows == 0 || cols == 0) return;
  const Eigen::Index stride = img.outerStride();
  for (Eigen::Index r = 0; r < rows; ++r) {
    // Replicate border: clamped neighbour rows, and clamped columns at the two ends only.
    const double* up = img.data() + (r > 0 ? r - 1 : 0) * stride;
    const double* mid = img.data() + r * stride;
    const double* dn = img.data() + (r + 1 < rows ? r + 1 : rows - 1) * stride;
    double* ox = &gx(r, 0);
    double* oy = &gy(r, 0);
    auto at = [&](Eigen::Index c, Eigen::Index cl, Eigen::Index cr) {
      ox[c] = (up[cr] + 2 * mid[cr] + dn[cr]) - (up[cl] + 2 * mid[cl] + dn[cl]);
      oy[c] = (dn[cl] + 2 * dn[c] + dn[cr]) - (up[cl] + 2 * up[c] + up[cr]);
    };
    at(0, 0, cols > 1 ? 1 : 0);
    for (Eigen::Index c = 1; c + 1 < cols; ++c) at(c, c - 1, c + 1);
    if (cols > 1) at(cols - 1, cols - 2, cols - 1);
  }
}

/// Gradient magnitude and direction (degrees in (-180, 180], counter-clockwise from +x with y
/// up) of `img`, as MATLAB's `[Gmag, Gdir] = imgradient(I)`. `gx`, `gy` are scratch.
template <class = void>
inline void gradient(const ImageView& img, ImageD& magnitude, ImageD& direction, ImageD& gx,
                     ImageD& gy) {
  sobel(img, gx, gy);
  magnitude.resize(img.rows(), img.cols());
  direction.resize(img.rows(), img.cols());
  for (Eigen::Index i = 0; i < gx.size(); ++i) {
    const double x = gx.data()[i];
    const double y = gy.data()[i];
    // sqrt unless the squares could overflow; hypot is several times slower.
    const double big = std::max(std::abs(x), std::abs(y));
    magnitude.data()[i] = big < 1e150 ? std::sqrt(x * x + y * y) : std::hypot(x, y);
    direction.data()[i] = detail::fast_atan2(-y, x) * (180.0 / std::numbers::pi);
  }
}

/// Sobel derivatives (gx, gy) at one pixel, replicate border; as `sobel` computes them.
template <class = void>
inline std::pair<double, double> sobel_at(const ImageView& img, Eigen::Index r,
                                          Eigen::Index c) noexcept {
  const Eigen::Index rows = img.rows();
  const Eigen::Index cols = img.cols();
  const Eigen::Index ru = r > 0 ? r - 1 : 0;
  const Eigen::Index rd = r + 1 < rows ? r + 1 : rows - 1;
  const Eigen::Index cl = c > 0 ? c - 1 : 0;
  const Eigen::Index cr = c + 1 < cols ? c + 1 : cols - 1;
  const double a = img(ru, cl), b = img(ru, c), d = img(ru, cr);
  const double e = img(r, cl), f = img(r, cr);
  const double g = img(rd, cl), h = img(rd, c), k = img(rd, cr);
  return {(d + 2 * f + k) - (a + 2 * e + g), (g + 2 * h + k) - (a + 2 * b + d)};
}

namespace detail {

// Sobel magnitude of `img` into `out` (rows * cols values, row-major). The border pixels take
// the replicate rule; the interior loop has no tests, so that it vectorises.
template <class = void>
inline void gradient_magnitude_into(const ImageView& img, double* out) noexcept {
  const Eigen::Index rows = img.rows();
  const Eigen::Index cols = img.cols();
  const Eigen::Index stride = img.outerStride();
  auto border = [&](Eigen::Index r, Eigen::Index c) {
    const auto [x, y] = sobel_at(img, r, c);
    out[r * cols + c] = std::sqrt(x * x + y * y);
  };
  for (Eigen::Index r = 0; r < rows; ++r) {
    if (cols < 3) {
      for (Eigen::Index c = 0; c < cols; ++c) border(r, c);
      continue;
    }
    // Replicate border: the first and last rows take themselves as their missing neighbour.
    const double* up = img.data() + (r > 0 ? r - 1 : 0) * stride;
    const double* mid = img.data() + r * stride;
    const double* dn = img.data() + (r + 1 < rows ? r + 1 : rows - 1) * stride;
    double* o = out + r * cols;
    border(r, 0);
    for (Eigen::Index c = 1; c + 1 < cols; ++c) {
      const double x =
          (up[c + 1] + 2 * mid[c + 1] + dn[c + 1]) - (up[c - 1] + 2 * mid[c - 1] + dn[c - 1]);
      const double y = (dn[c - 1] + 2 * dn[c] + dn[c + 1]) - (up[c - 1] + 2 * up[c] + up[c + 1]);
      o[c] = x * x + y * y;
    }
    // Eigen's packet square root: std::sqrt keeps a scalar errno path under default flags.
    Eigen::Map<Eigen::ArrayXd> inner(o + 1, cols - 2);
    inner = inner.sqrt();
    border(r, cols - 1);
  }
}

}  // namespace detail

/// Sobel gradient magnitude only, `sqrt(gx^2 + gy^2)` (no direction), into `magnitude`.
/// The fast path of the hybrid features: interior pixels without border tests.
template <class = void>
inline void gradient_magnitude(const ImageView& img, ImageD& magnitude) {
  magnitude.resize(img.rows(), img.cols());
  detail::gradient_magnitude_into(img, magnitude.data());
}

/// Allocating convenience: gradient magnitude and direction of `img`.
template <class = void>
inline void gradient(const ImageView& img, ImageD& magnitude, ImageD& direction) {
  ImageD gx, gy;
  gradient(img, magnitude, direction, gx, gy);
}

/// True when pixel (r, c) of `region` is a contour pixel: inside the region with at least one
/// 4-neighbour outside it or outside the image (MATLAB's `bwperim(BW, 4)`).
template <class = void>
inline bool is_contour_pixel(const MaskView& region, Eigen::Index r, Eigen::Index c) noexcept {
  if (region(r, c) == 0) return false;
  if (r == 0 || c == 0 || r + 1 == region.rows() || c + 1 == region.cols()) return true;
  return region(r - 1, c) == 0 || region(r + 1, c) == 0 || region(r, c - 1) == 0 ||
         region(r, c + 1) == 0;
}

/// The contour pixels of `region` into `out` (resized).
template <class = void>
inline void contour(const MaskView& region, Mask& out) {
  out.resize(region.rows(), region.cols());
  for (Eigen::Index r = 0; r < region.rows(); ++r) {
    for (Eigen::Index c = 0; c < region.cols(); ++c) {
      out(r, c) = is_contour_pixel(region, r, c) ? 1 : 0;
    }
  }
}

}  // namespace taxel::image
