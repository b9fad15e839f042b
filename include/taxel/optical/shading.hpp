// SPDX-License-Identifier: MIT
// How a camera-based tactile sensor turns the gel's surface gradient into colour, for
// simulation: a polynomial in the gradient per colour channel, the published practice for
// rendering such sensors (Si and Yuan, "Taxim: An Example-based Simulation Model for
// GelSight Tactile Sensors", IEEE RA-L 7(2), 2022), scaled by a lighting falloff toward the
// frame's edge, over a vignetted no-contact background.
#pragma once

#include <array>
#include <cmath>
#include <numbers>
#include <random>
#include <stdexcept>
#include <string>

#include "taxel/optical/types.hpp"

namespace taxel::optical {

/// The colour change a gradient (gx, gy) causes (x along columns, y along rows, height
/// positive into the gel): channel k changes by
///   s(u, v) * (a_k0 gx + a_k1 gy + a_k2 gx^2 + a_k3 gx gy + a_k4 gy^2)   [levels]
/// with s(u, v) = 1 - falloff * (u^2 + v^2) / 2, (u, v) the pixel's position in [-1, 1] across
/// the frame. The defaults light the gel from three sides, 120 degrees apart (red from +x,
/// green and blue from the other two), and darken steep slopes, as GelSight-type sensors do.
struct ShadingModel {
  /// Per channel (R, G, B): coefficients of gx, gy, gx^2, gx gy, gy^2 [levels].
  std::array<std::array<double, 5>, 3> coeff{{{110.0, 0.0, -45.0, 0.0, -45.0},
                                              {-55.0, 95.0, -45.0, 0.0, -45.0},
                                              {-55.0, -95.0, -45.0, 0.0, -45.0}}};
  double falloff = 0.35;  ///< share of the change lost at the frame's corner, in [0, 1)
  /// The no-contact background's levels at the frame's centre (R, G, B), and its vignetting:
  /// the share lost at the corners.
  std::array<double, 3> background{120.0, 105.0, 135.0};
  double vignetting = 0.2;  ///< in [0, 1)

  /// Channel k's change at gradient (gx, gy) and position (u, v) in [-1, 1]^2.
  double change(int k, double gx, double gy, double u, double v) const {
    const auto& a = coeff[static_cast<std::size_t>(k)];
    const double s = 1.0 - falloff * 0.5 * (u * u + v * v);
    return s * (a[0] * gx + a[1] * gy + a[2] * gx * gx + a[3] * gx * gy + a[4] * gy * gy);
  }
  /// Throws std::invalid_argument naming the field out of range.
  void validate() const {
    if (!(falloff >= 0 && falloff < 1)) {
      throw std::invalid_argument("ShadingModel::falloff must be in [0, 1)");
    }
    if (!(vignetting >= 0 && vignetting < 1)) {
      throw std::invalid_argument("ShadingModel::vignetting must be in [0, 1)");
    }
    for (const auto& row : coeff) {
      for (const double c : row) {
        if (!std::isfinite(c))
          throw std::invalid_argument("ShadingModel: a coefficient is not finite");
      }
    }
  }
};

/// Position of pixel (r, c) in [-1, 1]^2 across a rows x cols frame.
inline double frame_u(int c, int cols) { return cols > 1 ? 2.0 * c / (cols - 1) - 1.0 : 0.0; }
/// See frame_u.
inline double frame_v(int r, int rows) { return rows > 1 ? 2.0 * r / (rows - 1) - 1.0 : 0.0; }

/// The model's no-contact background for a rows x cols frame, as colour planes.
template <class = void>
Colour render_background(const ShadingModel& model, int rows, int cols) {
  model.validate();
  image::detail::checked_pixels("render_background", rows, cols);
  Colour out;
  for (int k = 0; k < 3; ++k) {
    Plane& p = out[static_cast<std::size_t>(k)];
    p.resize(rows, cols);
    for (int r = 0; r < rows; ++r) {
      for (int c = 0; c < cols; ++c) {
        const double u = frame_u(c, cols), v = frame_v(r, rows);
        p(r, c) = model.background[static_cast<std::size_t>(k)] *
                  (1.0 - model.vignetting * 0.5 * (u * u + v * v));
      }
    }
  }
  return out;
}

/// A frame of the gel with gradient planes (gx, gy) over `background`: each channel is the
/// background plus the model's change, plus Gaussian noise of `noise` levels from `rng`,
/// rounded to 8 bits. Throws std::invalid_argument for planes of different sizes.
template <class Rng>
RgbFrame render(const Plane& gx, const Plane& gy, const Colour& background,
                const ShadingModel& model, double noise, Rng& rng) {
  model.validate();
  const Eigen::Index rows = gx.rows(), cols = gx.cols();
  if (gy.rows() != rows || gy.cols() != cols) {
    throw std::invalid_argument("render: gx and gy differ in size");
  }
  for (const Plane& b : background) {
    if (b.rows() != rows || b.cols() != cols) {
      throw std::invalid_argument("render: the background's size differs from the gradients'");
    }
  }
  if (!(noise >= 0) || !std::isfinite(noise)) {
    throw std::invalid_argument("render: noise must be finite and >= 0 [levels]");
  }
  std::normal_distribution<double> gauss(0.0, 1.0);
  Colour out = background;
  for (int r = 0; r < rows; ++r) {
    for (int c = 0; c < cols; ++c) {
      const double u = frame_u(c, static_cast<int>(cols)), v = frame_v(r, static_cast<int>(rows));
      for (int k = 0; k < 3; ++k) {
        out[static_cast<std::size_t>(k)](r, c) +=
            model.change(k, gx(r, c), gy(r, c), u, v) + (noise > 0 ? noise * gauss(rng) : 0.0);
      }
    }
  }
  return to_frame(out);
}

}  // namespace taxel::optical
