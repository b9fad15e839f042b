// SPDX-License-Identifier: MIT
// A preprocessed ICP target: points, unit normals (given, or estimated by PCA over the k
// nearest neighbours), two static exact nearest-neighbour indexes (a uniform grid, about twice
// as fast as a kd-tree near the surface, and a kd-tree for queries far from it), the centroid
// and principal axes. Built once per
// model and shared, read-only, by any number of alignments.
#pragma once

#include <Eigen/Eigenvalues>
#include <array>
#include <cmath>
#include <cstddef>
#include <limits>
#include <optional>
#include <stdexcept>
#include <string>
#include <utility>
#include <vector>

#include "taxel/core/point_cloud.hpp"
#include "taxel/index/kdtree.hpp"
#include "taxel/index/uniform_grid.hpp"

namespace taxel::registration {

/// How a Target gets its normals.
struct TargetConfig {
  /// Neighbours of the PCA normal estimate (the point itself included), >= 3.
  int normal_neighbors = 12;
  /// Estimate normals even when the cloud has them.
  bool recompute_normals = false;
  /// Cell of the nearest-neighbour grid in mean point spacings (UniformGrid::Config): cells
  /// larger than the typical distance of a cloud point to the model answer most queries from
  /// 8 cells.
  double grid_spacing_factor = 4.0;
  /// Closest-point field for approximate correspondences (IcpConfig::approximate): cell edge
  /// [m] (0: none) and margin around the points' bounding box [m]. Each cell stores the exact
  /// nearest point to its centre, so a lookup errs by at most half a cell diagonal.
  double field_cell = 0.0;
  double field_margin = 0.02;  ///< Margin of the field around the points [m].
  /// Largest number of field cells, >= 1: on a model too large for `field_cell` the cell grows
  /// until the field fits (`Target::field_cell()` tells the edge used), so any legal model gets
  /// a field of bounded memory (4 bytes a cell).
  std::size_t field_max_cells = std::size_t{1} << 22;
};

/// A model prepared for registration. Normals estimated by PCA are oriented away from the
/// centroid (right for convex objects; point-to-plane ICP does not depend on the sign).
/// Immutable after construction (every member function is const), so one Target may serve
/// any number of threads.
template <Scalar S = double>
class Target {
 public:
  /// Throws std::invalid_argument when the cloud is empty, a point or normal is not finite, a
  /// given normal is zero or the normals do not match the points, or normal_neighbors < 3.
  explicit Target(PointCloud<S> cloud, TargetConfig cfg = {})
      : cfg_(cfg),
        grid_(checked(cloud, cfg),
              typename index::UniformGrid<S>::Config{S(0), std::size_t{1} << 22,
                                                     cfg.grid_spacing_factor}),
        tree_(grid_.points()) {
    const std::vector<Vec3<S>>& pts = grid_.points();
    if (cloud.has_normals() && !cfg.recompute_normals) {
      normals_ = std::move(cloud.normals);
      // Normals already of unit length (to rounding) stay as they are, so that a target made
      // again from another's normals (a pickled one) has the same ones to the bit.
      for (auto& n : normals_) {
        if (std::abs(n.squaredNorm() - S(1)) > S(64) * std::numeric_limits<S>::epsilon()) {
          n.normalize();
        }
      }
    }
    Vec3<double> sum = Vec3<double>::Zero();
    for (const auto& p : pts) sum += p.template cast<double>();
    centroid_ = sum / static_cast<double>(pts.size());
    Mat3d cov = Mat3d::Zero();
    for (const auto& p : pts) {
      const Vec3d d = p.template cast<double>() - centroid_;
      cov += d * d.transpose();
    }
    cov /= static_cast<double>(pts.size());
    Eigen::SelfAdjointEigenSolver<Mat3d> eig(cov);
    // Columns by decreasing variance, right-handed.
    axes_.col(0) = eig.eigenvectors().col(2);
    axes_.col(1) = eig.eigenvectors().col(1);
    axes_.col(2) = axes_.col(0).cross(axes_.col(1));
    variances_ = Vec3d(eig.eigenvalues()(2), eig.eigenvalues()(1), eig.eigenvalues()(0));
    radius_ = 0.0;
    for (const auto& p : pts) {
      radius_ = std::max(radius_, (p.template cast<double>() - centroid_).norm());
    }
    if (normals_.empty()) estimate_normals(cfg.normal_neighbors);
    if (cfg.field_cell > 0.0) build_field(cfg.field_cell, cfg.field_margin, cfg.field_max_cells);
  }

  /// The configuration it was built with.
  [[nodiscard]] const TargetConfig& config() const noexcept { return cfg_; }
  /// Number of points.
  [[nodiscard]] std::size_t size() const noexcept { return grid_.size(); }
  /// The points [m].
  [[nodiscard]] const std::vector<Vec3<S>>& points() const noexcept { return grid_.points(); }
  /// Unit normals, one per point.
  [[nodiscard]] const std::vector<Vec3<S>>& normals() const noexcept { return normals_; }
  /// The static index over the points (point i has id i).
  [[nodiscard]] const index::UniformGrid<S>& index() const noexcept { return grid_; }
  /// The kd-tree over the same points.
  [[nodiscard]] const index::KdTree<S>& kdtree() const noexcept { return tree_; }

  /// The closest point within distance r of q (ties by id), if any: exact. With a
  /// closest-point field, the point stored for q's field cell bounds the answer from below
  /// (its distance to the cell centre minus half the cell diagonal: far queries end at once)
  /// and from above (its distance to q): within a grid cell of q the grid reads only the cells
  /// of that ball, farther the kd-tree searches no farther. Without a field (or when the
  /// stored point lies beyond r) the grid serves searches up to three cells from q and the
  /// kd-tree those beyond.
  [[nodiscard]] std::optional<index::Neighbor<S>> nearest_within(const Vec3<S>& q, S r) const {
    if (!(r >= S(0)) || !q.allFinite()) return std::nullopt;
    if (const auto cell = field_cell_of(q)) {
      const index::PointId hint = field_[*cell];
      const Vec3d p = grid_.points()[hint].template cast<double>();
      const double lower = (field_centre(*cell) - p).norm() - field_half_diagonal_;
      if (lower > static_cast<double>(r)) return std::nullopt;
      // The stored point is within `upper`, so the nearest is too: near the surface the grid
      // reads the few cells of that ball, farther the kd-tree searches no farther.
      const double upper = (q.template cast<double>() - p).norm();
      if (upper <= static_cast<double>(r)) {
        if (upper <= kHintCells * static_cast<double>(grid_.cell())) {
          return grid_.nearest_within(q, r, hint);
        }
        return tree_.nearest_within(q, static_cast<S>(upper) * (S(1) + S(1e-6)) + S(1e-12));
      }
    }
    const S near = S(3) * grid_.cell();
    if (r <= near) return grid_.nearest_within(q, r);
    if (auto nb = grid_.nearest_within(q, near)) return nb;  // nothing nearer lies beyond
    return tree_.nearest_within(q, r);
  }

  /// The same answer as nearest_within(q, r), searched from `hint`: any point id whose
  /// distance to q bounds the answer's (in ICP, the previous iteration's match of the same
  /// source point). A hint within three grid cells of q reads only the cells of the ball it
  /// bounds; otherwise, or out of range, the search runs without it.
  [[nodiscard]] std::optional<index::Neighbor<S>> nearest_within(const Vec3<S>& q, S r,
                                                                 index::PointId hint) const {
    if (hint < size() && q.allFinite() && r >= S(0)) {
      const S near = S(3) * grid_.cell();
      const S h2 = index::squared_distance(grid_.points()[hint], q);
      // The answer lies within sqrt(h2) <= min(r, near): the grid alone finds it.
      if (h2 <= r * r && h2 <= near * near) return grid_.nearest_within(q, std::min(r, near), hint);
    }
    return nearest_within(q, r);
  }

  /// nearest_within(q, r, hint), with the radius of the ball of queries around q that share
  /// its answer (index::UniformGrid::nearest_stable); the radius is 0 where the search does
  /// not take the grid's hinted path.
  [[nodiscard]] std::optional<typename index::UniformGrid<S>::Stable> nearest_stable(
      const Vec3<S>& q, S r, index::PointId hint) const {
    if (hint < size() && q.allFinite() && r >= S(0)) {
      const S near = S(3) * grid_.cell();
      const S h2 = index::squared_distance(grid_.points()[hint], q);
      if (h2 <= r * r && h2 <= near * near) return grid_.nearest_stable(q, std::min(r, near), hint);
    }
    const auto nb = nearest_within(q, r);
    using Stable = typename index::UniformGrid<S>::Stable;
    return nb ? std::optional<Stable>(Stable{*nb, 0.0}) : std::nullopt;
  }

  /// The id of the point nearest to the centre of q's closest-point-field cell, or nothing
  /// outside the field (or without one). One memory load; errs by up to half a cell diagonal.
  [[nodiscard]] std::optional<index::PointId> field_nearest(const Vec3<S>& q) const {
    const auto cell = field_cell_of(q);
    return cell ? std::optional<index::PointId>(field_[*cell]) : std::nullopt;
  }
  /// True when the target has a closest-point field.
  [[nodiscard]] bool has_field() const noexcept { return !field_.empty(); }
  /// The field's cell edge [m] (TargetConfig::field_cell, or larger on a model too big for it;
  /// 0 without a field).
  [[nodiscard]] double field_cell() const noexcept { return field_cell_; }

  /// Centroid of the points.
  [[nodiscard]] const Vec3d& centroid() const noexcept { return centroid_; }
  /// Principal axes as columns, by decreasing variance; a rotation (det = +1).
  [[nodiscard]] const Mat3d& principal_axes() const noexcept { return axes_; }
  /// Variances along the principal axes, decreasing [m^2].
  [[nodiscard]] const Vec3d& principal_variances() const noexcept { return variances_; }
  /// Largest distance of a point from the centroid [m].
  [[nodiscard]] double radius() const noexcept { return radius_; }

 private:
  static std::vector<Vec3<S>> checked(const PointCloud<S>& cloud, const TargetConfig& cfg) {
    if (cloud.empty()) throw std::invalid_argument("Target: the cloud has no points");
    if (cfg.normal_neighbors < 3) {
      throw std::invalid_argument("TargetConfig::normal_neighbors = " +
                                  std::to_string(cfg.normal_neighbors) + " is below 3");
    }
    if (const Outcome o = cloud.validate(); !o) throw std::invalid_argument("Target: " + o.message);
    if (cloud.has_normals() && !cfg.recompute_normals) {
      for (std::size_t i = 0; i < cloud.normals.size(); ++i) {
        if (!cloud.normals[i].allFinite() || !(cloud.normals[i].norm() > S(0))) {
          throw std::invalid_argument("Target: normal " + std::to_string(i) +
                                      " is zero or not finite");
        }
      }
    }
    return cloud.points;
  }

  std::optional<std::size_t> field_cell_of(const Vec3<S>& q) const {
    if (field_.empty()) return std::nullopt;
    const Vec3d c = (q.template cast<double>() - field_lo_) * field_inv_cell_;
    if (!(c.minCoeff() >= 0.0) || !(c.x() < field_dims_[0]) || !(c.y() < field_dims_[1]) ||
        !(c.z() < field_dims_[2])) {
      return std::nullopt;
    }
    return (static_cast<std::size_t>(c.z()) * static_cast<std::size_t>(field_dims_[1]) +
            static_cast<std::size_t>(c.y())) *
               static_cast<std::size_t>(field_dims_[0]) +
           static_cast<std::size_t>(c.x());
  }

  Vec3d field_centre(std::size_t i) const {
    const auto nx = static_cast<std::size_t>(field_dims_[0]);
    const auto ny = static_cast<std::size_t>(field_dims_[1]);
    const double x = static_cast<double>(i % nx);
    const double y = static_cast<double>((i / nx) % ny);
    const double z = static_cast<double>(i / (nx * ny));
    return field_lo_ + field_cell_ * Vec3d(x + 0.5, y + 0.5, z + 0.5);
  }

  void build_field(double cell, double margin, std::size_t max_cells) {
    if (!std::isfinite(cell) || !(margin >= 0.0) || !std::isfinite(margin) || max_cells == 0) {
      throw std::invalid_argument(
          "TargetConfig: field_cell and field_margin must be finite, field_margin >= 0 and "
          "field_max_cells >= 1");
    }
    const auto& pts = grid_.points();
    Vec3d lo = pts.front().template cast<double>(), hi = lo;
    for (const auto& p : pts) {
      lo = lo.cwiseMin(p.template cast<double>());
      hi = hi.cwiseMax(p.template cast<double>());
    }
    field_lo_ = lo - Vec3d::Constant(margin);
    const Vec3d extent = hi - lo + Vec3d::Constant(2.0 * margin);
    if (!extent.allFinite()) {
      throw std::invalid_argument("TargetConfig::field_margin: the field's box overflows");
    }
    // Never finer than extent / 2^20 per axis, so the counts below are exact and finite.
    cell = std::max(cell, extent.maxCoeff() * 0x1p-20);
    std::array<double, 3> n{};
    for (;;) {
      double cells = 1.0;
      for (std::size_t a = 0; a < 3; ++a) {
        n[a] = std::ceil(extent[static_cast<int>(a)] / cell) + 1.0;
        cells *= n[a];
      }
      if (cells <= static_cast<double>(max_cells)) break;
      cell *= std::cbrt(cells / static_cast<double>(max_cells)) * 1.01;
    }
    for (std::size_t a = 0; a < 3; ++a) field_dims_[a] = static_cast<int>(n[a]);
    field_cell_ = cell;
    field_inv_cell_ = 1.0 / cell;
    field_half_diagonal_ = 0.5 * std::sqrt(3.0) * cell;
    const std::size_t cells = static_cast<std::size_t>(field_dims_[0]) *
                              static_cast<std::size_t>(field_dims_[1]) *
                              static_cast<std::size_t>(field_dims_[2]);
    // Filled aside: nearest_within uses field_ only once it is complete.
    std::vector<index::PointId> field(cells);
    std::size_t i = 0;
    for (int z = 0; z < field_dims_[2]; ++z) {
      for (int y = 0; y < field_dims_[1]; ++y) {
        for (int x = 0; x < field_dims_[0]; ++x, ++i) {
          const Vec3d centre = field_lo_ + cell * Vec3d(x + 0.5, y + 0.5, z + 0.5);
          const auto nb =
              nearest_within(centre.template cast<S>(), std::numeric_limits<S>::infinity());
          field[i] = nb ? nb->id : 0;
        }
      }
    }
    field_ = std::move(field);
  }

  void estimate_normals(int k) {
    const std::vector<Vec3<S>>& pts = grid_.points();
    normals_.resize(pts.size());
    for (std::size_t i = 0; i < pts.size(); ++i) {
      const auto nbrs = grid_.knn(pts[i], static_cast<std::size_t>(k));
      Vec3d mean = Vec3d::Zero();
      for (const auto& nb : nbrs) mean += pts[nb.id].template cast<double>();
      mean /= static_cast<double>(nbrs.size());
      Mat3d cov = Mat3d::Zero();
      for (const auto& nb : nbrs) {
        const Vec3d d = pts[nb.id].template cast<double>() - mean;
        cov += d * d.transpose();
      }
      Vec3d n = Vec3d::UnitZ();
      if (nbrs.size() >= 3) {
        Eigen::SelfAdjointEigenSolver<Mat3d> eig(cov);
        n = eig.eigenvectors().col(0);
      }
      if (n.dot(pts[i].template cast<double>() - centroid_) < 0) n = -n;
      normals_[i] = n.template cast<S>();
    }
  }

  // A field point this many grid cells from the query bounds a grid search; beyond, the
  // kd-tree's.
  static constexpr double kHintCells = 1.0;

  TargetConfig cfg_;
  index::UniformGrid<S> grid_;  // owns the points
  index::KdTree<S> tree_;
  std::vector<index::PointId> field_;  // closest-point field, x fastest
  std::array<int, 3> field_dims_{0, 0, 0};
  Vec3d field_lo_ = Vec3d::Zero();
  double field_cell_ = 0.0;
  double field_inv_cell_ = 0.0;
  double field_half_diagonal_ = 0.0;
  std::vector<Vec3<S>> normals_;
  Vec3d centroid_ = Vec3d::Zero();
  Mat3d axes_ = Mat3d::Identity();
  Vec3d variances_ = Vec3d::Zero();
  double radius_ = 0.0;
};

}  // namespace taxel::registration
