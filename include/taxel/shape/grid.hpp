// SPDX-License-Identifier: MIT
// A regular grid of sample points in 3-D and a field sampled on it: the input of marching
// tetrahedra and of ray casting against an estimated surface.
#pragma once

#include <array>
#include <cmath>
#include <cstddef>
#include <limits>
#include <optional>
#include <stdexcept>
#include <string>
#include <vector>

#include "taxel/core/types.hpp"

namespace taxel::shape {

/// Nodes origin + spacing * (i, j, k), 0 <= i < nodes[0] and so on; node (i, j, k) is entry
/// i + nodes[0] * (j + nodes[1] * k) of a sampled field.
struct Grid {
  Vec3d origin = Vec3d::Zero();  ///< position of node (0, 0, 0) [m]
  double spacing = 1e-3;         ///< distance between neighbouring nodes [m]
  std::array<int, 3> nodes{};    ///< nodes along x, y and z

  /// The grid with `spacing` whose nodes cover the box [lo, hi] (lo on a node, hi at most one
  /// spacing beyond the last). Throws std::invalid_argument for a non-finite or empty box, a
  /// spacing that is not finite and > 0, or more than 2^28 nodes.
  [[nodiscard]] static Grid covering(const Vec3d& lo, const Vec3d& hi, double spacing) {
    if (!lo.allFinite() || !hi.allFinite() || !((hi - lo).minCoeff() >= 0.0)) {
      throw std::invalid_argument("Grid::covering: the box must be finite with lo <= hi");
    }
    if (!(spacing > 0.0) || !std::isfinite(spacing)) {
      throw std::invalid_argument("Grid::covering: spacing must be finite and > 0 [m], got " +
                                  std::to_string(spacing));
    }
    Grid g;
    g.origin = lo;
    g.spacing = spacing;
    double total = 1.0;
    for (int a = 0; a < 3; ++a) {
      const double n = std::ceil((hi[a] - lo[a]) / spacing) + 1.0;
      total *= n;
      if (!(total <= double(1 << 28))) {
        throw std::invalid_argument(
            "Grid::covering: more than 2^28 nodes; choose a coarser spacing");
      }
      g.nodes[static_cast<std::size_t>(a)] = static_cast<int>(n);
    }
    return g;
  }
  /// Number of nodes.
  [[nodiscard]] std::size_t size() const noexcept {
    return std::size_t(nodes[0]) * std::size_t(nodes[1]) * std::size_t(nodes[2]);
  }
  /// Entry of node (i, j, k).
  [[nodiscard]] std::size_t index(int i, int j, int k) const noexcept {
    return std::size_t(i) +
           std::size_t(nodes[0]) * (std::size_t(j) + std::size_t(nodes[1]) * std::size_t(k));
  }
  /// Position of node (i, j, k) [m].
  [[nodiscard]] Vec3d node(int i, int j, int k) const noexcept {
    return origin + spacing * Vec3d(i, j, k);
  }
  /// The far corner, node (nodes - 1) [m].
  [[nodiscard]] Vec3d far_corner() const noexcept {
    return node(nodes[0] - 1, nodes[1] - 1, nodes[2] - 1);
  }
  /// Throws std::invalid_argument unless the grid has at least 2 nodes along each axis, a
  /// finite origin and a finite spacing > 0.
  void validate() const {
    if (!origin.allFinite() || !(spacing > 0.0) || !std::isfinite(spacing) || nodes[0] < 2 ||
        nodes[1] < 2 || nodes[2] < 2) {
      throw std::invalid_argument(
          "Grid: needs a finite origin, a finite spacing > 0 and at least 2 nodes per axis");
    }
  }
};

/// Trilinear interpolation of `values` (sampled on `grid`) at `x`; nothing outside the grid.
template <class = void>
[[nodiscard]] std::optional<double> interpolate(const Grid& grid, const std::vector<double>& values,
                                                const Vec3d& x) {
  const Vec3d u = (x - grid.origin) / grid.spacing;
  std::array<int, 3> i{};
  std::array<double, 3> t{};
  for (std::size_t a = 0; a < 3; ++a) {
    const double ua = u[static_cast<Eigen::Index>(a)];
    if (!(ua >= 0.0) || !(ua <= double(grid.nodes[a] - 1))) return std::nullopt;
    i[a] = std::min(static_cast<int>(ua), grid.nodes[a] - 2);
    t[a] = ua - i[a];
  }
  double out = 0.0;
  for (int c = 0; c < 8; ++c) {
    const int dx = c & 1, dy = (c >> 1) & 1, dz = (c >> 2) & 1;
    const double w = (dx ? t[0] : 1 - t[0]) * (dy ? t[1] : 1 - t[1]) * (dz ? t[2] : 1 - t[2]);
    out += w * values[grid.index(i[0] + dx, i[1] + dy, i[2] + dz)];
  }
  return out;
}

/// The first point where the ray origin + t direction (0 <= t <= max_distance, direction a
/// unit vector) enters the region where the sampled field is below `level`, by marching at a
/// quarter of the spacing through the grid and bisecting the step that crosses; nothing when
/// the ray stays above the level inside the grid. A ray that starts below the level returns
/// its first point inside the grid.
template <class = void>
[[nodiscard]] std::optional<Vec3d> first_crossing(const Grid& grid,
                                                  const std::vector<double>& values,
                                                  const Vec3d& origin, const Vec3d& direction,
                                                  double max_distance, double level = 0.0) {
  // Clip the ray to the grid's box (slabs).
  double t0 = 0.0, t1 = max_distance;
  const Vec3d lo = grid.origin, hi = grid.far_corner();
  for (int a = 0; a < 3; ++a) {
    if (std::abs(direction[a]) < 1e-300) {
      if (origin[a] < lo[a] || origin[a] > hi[a]) return std::nullopt;
      continue;
    }
    double ta = (lo[a] - origin[a]) / direction[a], tb = (hi[a] - origin[a]) / direction[a];
    if (ta > tb) std::swap(ta, tb);
    t0 = std::max(t0, ta);
    t1 = std::min(t1, tb);
  }
  if (!(t0 <= t1)) return std::nullopt;
  const double eps = 1e-9 * grid.spacing;
  t0 += eps;
  t1 -= eps;
  const double step = 0.25 * grid.spacing;
  const auto f = [&](double t) { return interpolate(grid, values, origin + t * direction); };
  std::optional<double> prev = f(t0);
  if (!prev) return std::nullopt;
  if (*prev < level) return origin + t0 * direction;
  double tp = t0;
  for (double t = t0 + step;; t += step) {
    t = std::min(t, t1);
    const std::optional<double> v = f(t);
    if (!v) return std::nullopt;
    if (*v < level) {
      double a = tp, b = t;
      for (int it = 0; it < 40; ++it) {
        const double m = 0.5 * (a + b);
        const std::optional<double> vm = f(m);
        (vm && *vm < level ? b : a) = m;
      }
      return origin + b * direction;
    }
    tp = t;
    if (t >= t1) return std::nullopt;
  }
}

}  // namespace taxel::shape
