// SPDX-License-Identifier: MIT
// Sobel gradients as MATLAB's imgradientxy / imgradient (REFERENCES.md section 2): correlation
// with the Sobel kernels, replicate border; Gy > 0 when intensity grows downwards;
// magnitude = hypot(Gx, Gy), direction = atan2(-Gy, Gx) in degrees. Also the contour pixels of a
// region (MATLAB's bwperim, 4-connected).
#pragma once

#include <algorithm>
#include <cmath>
#include <numbers>
#include <utility>

#include "taxel/image/types.hpp"

namespace taxel::image {

/// Sobel derivatives of `img` into `gx` and `gy` (resized to the image's size).
/// `gx = I (x) [-1 0 1; -2 0 2; -1 0 1]`, `gy = I (x) [-1 -2 -1; 0 0 0; 1 2 1]`.
inline void sobel(const ImageView& img, ImageD& gx, ImageD& gy) {
  const Eigen::Index rows = img.rows();
  const Eigen::Index cols = img.cols();
  gx.resize(rows, cols);
  gy.resize(rows, cols);
  if (rows == 0 || cols == 0) return;
  for (Eigen::Index r = 0; r < rows; ++r) {
    const Eigen::Index ru = std::max<Eigen::Index>(r - 1, 0);
    const Eigen::Index rd = std::min<Eigen::Index>(r + 1, rows - 1);
    for (Eigen::Index c = 0; c < cols; ++c) {
      const Eigen::Index cl = std::max<Eigen::Index>(c - 1, 0);
      const Eigen::Index cr = std::min<Eigen::Index>(c + 1, cols - 1);
      const double a = img(ru, cl), b = img(ru, c), d = img(ru, cr);
      const double e = img(r, cl), f = img(r, cr);
      const double g = img(rd, cl), h = img(rd, c), k = img(rd, cr);
      gx(r, c) = (d + 2 * f + k) - (a + 2 * e + g);
      gy(r, c) = (g + 2 * h + k) - (a + 2 * b + d);
    }
  }
}

/// Gradient magnitude and direction (degrees in (-180, 180], counter-clockwise from +x with y
/// up) of `img`, as MATLAB's `[Gmag, Gdir] = imgradient(I)`. `gx`, `gy` are scratch.
inline void gradient(const ImageView& img, ImageD& magnitude, ImageD& direction, ImageD& gx,
                     ImageD& gy) {
  sobel(img, gx, gy);
  magnitude.resize(img.rows(), img.cols());
  direction.resize(img.rows(), img.cols());
  for (Eigen::Index i = 0; i < gx.size(); ++i) {
    const double x = gx.data()[i];
    const double y = gy.data()[i];
    magnitude.data()[i] = std::hypot(x, y);
    direction.data()[i] = std::atan2(-y, x) * 180.0 / std::numbers::pi;
  }
}

/// Sobel derivatives (gx, gy) at one pixel, replicate border; as `sobel` computes them.
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
inline void gradient_magnitude_into(const ImageView& img, double* out) noexcept {
  const Eigen::Index rows = img.rows();
  const Eigen::Index cols = img.cols();
  const Eigen::Index stride = img.outerStride();
  auto border = [&](Eigen::Index r, Eigen::Index c) {
    const auto [x, y] = sobel_at(img, r, c);
    out[r * cols + c] = std::sqrt(x * x + y * y);
  };
  for (Eigen::Index r = 0; r < rows; ++r) {
    if (r == 0 || r + 1 == rows || cols < 3) {
      for (Eigen::Index c = 0; c < cols; ++c) border(r, c);
      continue;
    }
    const double* up = img.data() + (r - 1) * stride;
    const double* mid = img.data() + r * stride;
    const double* dn = img.data() + (r + 1) * stride;
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
inline void gradient_magnitude(const ImageView& img, ImageD& magnitude) {
  magnitude.resize(img.rows(), img.cols());
  detail::gradient_magnitude_into(img, magnitude.data());
}

/// Allocating convenience: gradient magnitude and direction of `img`.
inline void gradient(const ImageView& img, ImageD& magnitude, ImageD& direction) {
  ImageD gx, gy;
  gradient(img, magnitude, direction, gx, gy);
}

/// True when pixel (r, c) of `region` is a contour pixel: inside the region with at least one
/// 4-neighbour outside it or outside the image (MATLAB's `bwperim(BW, 4)`).
inline bool is_contour_pixel(const MaskView& region, Eigen::Index r, Eigen::Index c) noexcept {
  if (region(r, c) == 0) return false;
  if (r == 0 || c == 0 || r + 1 == region.rows() || c + 1 == region.cols()) return true;
  return region(r - 1, c) == 0 || region(r + 1, c) == 0 || region(r, c - 1) == 0 ||
         region(r, c + 1) == 0;
}

/// The contour pixels of `region` into `out` (resized).
inline void contour(const MaskView& region, Mask& out) {
  out.resize(region.rows(), region.cols());
  for (Eigen::Index r = 0; r < region.rows(); ++r) {
    for (Eigen::Index c = 0; c < region.cols(); ++c) {
      out(r, c) = is_contour_pixel(region, r, c) ? 1 : 0;
    }
  }
}

}  // namespace taxel::image
