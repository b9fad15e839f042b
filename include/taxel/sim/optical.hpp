// SPDX-License-Identifier: MIT
// The gel of a camera-based tactile sensor pressed by simple indenters, with exact heights and
// gradients: a ball (the calibration press), a cylinder and a straight edge. Heights are
// positive into the gel [m]; gradients are dimensionless (height over distance, x along the
// frame's columns, y along its rows). The gel is taken to follow the indenter exactly.
#pragma once

#include <Eigen/Core>
#include <algorithm>
#include <cmath>
#include <cstdint>
#include <stdexcept>
#include <string>
#include <vector>

#include "taxel/optical/types.hpp"

namespace taxel::sim {

/// A pressed gel: heights [m] and gradients, rows x cols.
struct GelPress {
  optical::Plane height;  ///< indentation into the gel [m], 0 where untouched
  optical::Plane gx;      ///< d height / dx (along columns)
  optical::Plane gy;      ///< d height / dy (along rows)
};

namespace detail {
inline void check_press(int rows, int cols, double pixel, double depth, const char* who) {
  image::detail::checked_pixels(who, rows, cols);
  if (rows < 3 || cols < 3)
    throw std::invalid_argument(std::string(who) + ": at least 3 x 3 pixels");
  if (!(pixel > 0) || !std::isfinite(pixel)) {
    throw std::invalid_argument(std::string(who) + ": the pixel size must be finite and > 0 [m]");
  }
  if (!(depth > 0) || !std::isfinite(depth)) {
    throw std::invalid_argument(std::string(who) + ": the depth must be finite and > 0 [m]");
  }
}
}  // namespace detail

/// A ball of radius `radius` [m] pressed `depth` [m] (< radius) into the gel, its centre above
/// pixel (cx, cy) (column, row; fractional). Inside the contact circle, of radius
/// sqrt(R^2 - (R - d)^2), the height is sqrt(R^2 - rho^2) - (R - d) and its gradient
/// -(x - cx, y - cy) pixel / sqrt(R^2 - rho^2).
template <class = void>
GelPress press_ball(int rows, int cols, double pixel, double radius, double depth, double cx,
                    double cy) {
  detail::check_press(rows, cols, pixel, depth, "press_ball");
  if (!(radius > depth) || !std::isfinite(radius)) {
    throw std::invalid_argument("press_ball: the radius must be finite and larger than the depth");
  }
  GelPress g{optical::Plane::Zero(rows, cols), optical::Plane::Zero(rows, cols),
             optical::Plane::Zero(rows, cols)};
  const double base = radius - depth;
  for (int r = 0; r < rows; ++r) {
    for (int c = 0; c < cols; ++c) {
      const double x = (c - cx) * pixel, y = (r - cy) * pixel;
      const double s2 = radius * radius - x * x - y * y;
      if (s2 <= 0) continue;
      const double s = std::sqrt(s2);
      if (s <= base) continue;
      g.height(r, c) = s - base;
      g.gx(r, c) = -x / s;
      g.gy(r, c) = -y / s;
    }
  }
  return g;
}

/// A cylinder of radius `radius` [m] lying in the gel's plane along direction `angle` [rad]
/// (from the columns' axis) through pixel (cx, cy), pressed `depth` [m].
template <class = void>
GelPress press_cylinder(int rows, int cols, double pixel, double radius, double depth, double cx,
                        double cy, double angle) {
  detail::check_press(rows, cols, pixel, depth, "press_cylinder");
  if (!(radius > depth) || !std::isfinite(radius)) {
    throw std::invalid_argument(
        "press_cylinder: the radius must be finite and larger than the depth");
  }
  GelPress g{optical::Plane::Zero(rows, cols), optical::Plane::Zero(rows, cols),
             optical::Plane::Zero(rows, cols)};
  const double nx = -std::sin(angle), ny = std::cos(angle);  // across the axis
  const double base = radius - depth;
  for (int r = 0; r < rows; ++r) {
    for (int c = 0; c < cols; ++c) {
      const double t = ((c - cx) * nx + (r - cy) * ny) * pixel;
      const double s2 = radius * radius - t * t;
      if (s2 <= 0) continue;
      const double s = std::sqrt(s2);
      if (s <= base) continue;
      g.height(r, c) = s - base;
      g.gx(r, c) = -t / s * nx;
      g.gy(r, c) = -t / s * ny;
    }
  }
  return g;
}

/// A straight edge (two flat faces meeting at a crease, each sloping down at `slope`) along
/// direction `angle` [rad] through pixel (cx, cy), pressed `depth` [m]: the height is
/// depth - slope |t| where positive, t the distance across the crease.
template <class = void>
GelPress press_edge(int rows, int cols, double pixel, double slope, double depth, double cx,
                    double cy, double angle) {
  detail::check_press(rows, cols, pixel, depth, "press_edge");
  if (!(slope > 0) || !std::isfinite(slope)) {
    throw std::invalid_argument("press_edge: the slope must be finite and > 0");
  }
  GelPress g{optical::Plane::Zero(rows, cols), optical::Plane::Zero(rows, cols),
             optical::Plane::Zero(rows, cols)};
  const double nx = -std::sin(angle), ny = std::cos(angle);
  for (int r = 0; r < rows; ++r) {
    for (int c = 0; c < cols; ++c) {
      const double t = ((c - cx) * nx + (r - cy) * ny) * pixel;
      const double h = depth - slope * std::abs(t);
      if (h <= 0) continue;
      g.height(r, c) = h;
      const double sgn = t > 0 ? -1.0 : t < 0 ? 1.0 : 0.0;
      g.gx(r, c) = sgn * slope * nx;
      g.gy(r, c) = sgn * slope * ny;
    }
  }
  return g;
}

/// Centres [px] (column, row) of a square grid of marker dots `pitch` pixels apart, starting
/// `pitch / 2` from the frame's top-left corner.
template <class = void>
std::vector<Eigen::Vector2d> marker_grid(int rows, int cols, double pitch) {
  if (!(pitch >= 2) || !std::isfinite(pitch)) {
    throw std::invalid_argument("marker_grid: pitch must be finite and >= 2 [px]");
  }
  std::vector<Eigen::Vector2d> out;
  for (double y = 0.5 * pitch; y < rows; y += pitch) {
    for (double x = 0.5 * pitch; x < cols; x += pitch) out.emplace_back(x, y);
  }
  return out;
}

/// Darkens `frame` by `darkness` (share of the light removed, in (0, 1]) inside discs of
/// `radius` pixels at `centres` (column, row), as a gel's printed markers do.
template <class = void>
void draw_markers(optical::RgbFrame& frame, const std::vector<Eigen::Vector2d>& centres,
                  double radius, double darkness) {
  if (!(radius > 0) || !(darkness > 0 && darkness <= 1)) {
    throw std::invalid_argument("draw_markers: radius > 0 and darkness in (0, 1]");
  }
  const auto rows = static_cast<int>(frame.rows), cols = static_cast<int>(frame.cols);
  for (const Eigen::Vector2d& m : centres) {
    const int r0 = std::max(0, int(std::floor(m.y() - radius))),
              r1 = std::min(rows - 1, int(std::ceil(m.y() + radius)));
    const int c0 = std::max(0, int(std::floor(m.x() - radius))),
              c1 = std::min(cols - 1, int(std::ceil(m.x() + radius)));
    for (int r = r0; r <= r1; ++r) {
      for (int c = c0; c <= c1; ++c) {
        if (std::hypot(c - m.x(), r - m.y()) > radius) continue;
        std::uint8_t* p = frame.data.data() + (static_cast<std::size_t>(r) * cols + c) * 3;
        for (int k = 0; k < 3; ++k) p[k] = static_cast<std::uint8_t>(p[k] * (1.0 - darkness) + 0.5);
      }
    }
  }
}

}  // namespace taxel::sim
