// SPDX-License-Identifier: MIT
// Explorer: the loop of active touch in one object. Contacts are fused into a ContactCloud;
// every fused point that a batch of contacts added or moved is put into (or moved in) the
// implicit surface, with the fusion policy's normal and its variance along that normal; the
// surface's posterior mean is sampled on a grid over the workspace, meshed with each vertex's
// uncertainty, and candidate touches are scored on it.
#pragma once

#include <algorithm>
#include <cmath>
#include <optional>
#include <span>
#include <stdexcept>
#include <string>
#include <vector>

#include "taxel/core/contact.hpp"
#include "taxel/fusion/contact_cloud.hpp"
#include "taxel/fusion/surfel.hpp"
#include "taxel/index/voxel_hash.hpp"
#include "taxel/shape/grid.hpp"
#include "taxel/shape/implicit_surface.hpp"
#include "taxel/shape/kernels.hpp"
#include "taxel/shape/next_touch.hpp"
#include "taxel/shape/surface_mesh.hpp"

namespace taxel::shape {

/// Settings of an Explorer. Lengths in metres.
struct ExplorerConfig {
  Vec3d workspace_min = Vec3d::Constant(-0.06);  ///< corner of the box the object lies in
  Vec3d workspace_max = Vec3d::Constant(0.06);   ///< opposite corner
  double grid_spacing = 2e-3;                    ///< of the sampled field and its mesh, > 0
  SurfaceConfig surface{};                       ///< the implicit surface
  MaternConfig kernel{};                         ///< its kernel
  ScoringConfig scoring{};                       ///< how candidate touches are scored
  /// Re-fit the prior sphere's radius to the points' mean distance from its centre after
  /// every batch (the centre stays surface.prior_centre); off keeps surface.prior_radius.
  bool fit_prior_radius = true;
  /// Free space (add_free_space): spacing of the points along a path, > 0.
  double free_spacing = 5e-3;
  /// Free space: points where the posterior mean is above this are left out (they say what
  /// the estimate already says), > 0.
  double free_threshold = 5e-3;
  /// Free space: the value a point observes is its distance along the path to the path's
  /// end, at most this; its noise standard deviation is half the value. > 0.
  double free_cap = 3e-3;
};

/// Fused cloud, implicit surface, sampled field, mesh and touch scoring for one object (see
/// the file comment). `K` is the surface's kernel, `Cloud` a ContactCloud whose policy
/// estimates normals (Surfel by default; a policy without them leaves the prior's normal).
template <Kernel K = Matern32,
          class Cloud = fusion::ContactCloud<fusion::Surfel<double>, index::VoxelHash<double>>>
class Explorer {
 public:
  /// The fused cloud's type.
  using CloudType = Cloud;

  /// Throws std::invalid_argument for an invalid configuration.
  explicit Explorer(const ExplorerConfig& config = {}, const typename Cloud::Config& fusion = {})
      : config_(checked(config)),
        cloud_(fusion),
        surface_(config_.surface, K(config_.kernel)),
        grid_(Grid::covering(config_.workspace_min, config_.workspace_max, config_.grid_spacing)) {}

  /// Rebuilds an explorer from saved parts, as loading a saved one does: `cloud` and `surface`
  /// as they were, and surface_ids[i] the surface point of the cloud's point i (surface_id).
  /// Throws std::invalid_argument for an invalid configuration or parts that do not fit
  /// together (a size that differs, an id the surface does not have, or one given twice).
  Explorer(const ExplorerConfig& config, Cloud cloud, ImplicitSurface<K> surface,
           std::vector<std::optional<std::size_t>> surface_ids)
      : Explorer(config) {
    if (surface_ids.size() != cloud.size())
      throw std::invalid_argument("Explorer: " + std::to_string(surface_ids.size()) +
                                  " surface ids for " + std::to_string(cloud.size()) +
                                  " fused points");
    std::vector<bool> used(surface.id_count(), false);
    for (const auto& id : surface_ids) {
      if (!id) continue;
      if (*id >= surface.id_count() || used[*id] || !surface.point(*id).alive ||
          surface.point(*id).free)
        throw std::invalid_argument("Explorer: surface id " + std::to_string(*id) +
                                    " is not a live surface point of its own");
      used[*id] = true;
    }
    cloud_ = std::move(cloud);
    surface_ = std::move(surface);
    of_cloud_ = std::move(surface_ids);
  }

  /// The surface point of fused point `id`, if it has one.
  [[nodiscard]] std::optional<std::size_t> surface_id(index::PointId id) const {
    return id < of_cloud_.size() ? of_cloud_[id] : std::nullopt;
  }

  /// Fuses `contacts` and brings the surface up to date. Returns how many fused points were
  /// added or moved.
  std::size_t add_contacts(std::span<const Contact<double>> contacts) {
    std::vector<index::PointId> changed;
    for (const auto& c : contacts) {
      const fusion::InsertResult r = cloud_.insert(c);
      if (r.status != fusion::InsertStatus::rejected) changed.push_back(r.id);
    }
    std::sort(changed.begin(), changed.end());
    changed.erase(std::unique(changed.begin(), changed.end()), changed.end());
    for (const index::PointId id : changed) sync(id);
    if (config_.fit_prior_radius && surface_.size() > 0) {
      double sum = 0.0;
      for (const auto& s : of_cloud_) {
        if (s) sum += (surface_.point(*s).position - config_.surface.prior_centre).norm();
      }
      // Refitted when it moves by more than 5 %: a new prior changes every expert.
      const double r = sum / double(surface_.size()), now = surface_.config().prior_radius;
      if (!(std::abs(r - now) <= 0.05 * now)) surface_.set_prior(config_.surface.prior_centre, r);
    }
    if (!changed.empty()) {
      fresh_ = false;
      mesh_.reset();
    }
    return changed.size();
  }

  /// Tells the surface that the segment from `from` to `to` is free (a finger moved through
  /// it, e.g. along its approach up to the contact, or the whole ray of a touch that met
  /// nothing): points every free_spacing inside the workspace where the estimate puts the
  /// surface near or beyond them become observations of the field's being positive there.
  /// Returns how many points were added.
  std::size_t add_free_space(const Vec3d& from, const Vec3d& to) {
    if (!from.allFinite() || !to.allFinite()) return 0;
    const double length = (to - from).norm();
    const auto steps =
        static_cast<std::size_t>(std::min(1e6, std::floor(length / config_.free_spacing)));
    std::size_t added = 0;
    for (std::size_t i = 0; i <= steps; ++i) {
      const Vec3d x =
          to + (from - to) * (length > 0.0 ? double(i) * config_.free_spacing / length : 0.0);
      if ((x - config_.workspace_min).minCoeff() < 0.0 ||
          (config_.workspace_max - x).minCoeff() < 0.0)
        continue;
      if (surface_.mean(x) > config_.free_threshold) continue;
      const double value = std::min(double(i) * config_.free_spacing, config_.free_cap);
      if (!(value > 0.0)) continue;
      if (surface_.insert_free(x, value, 0.25 * value * value)) ++added;
    }
    if (added > 0) {
      fresh_ = false;
      mesh_.reset();
    }
    return added;
  }

  /// The fused contacts.
  [[nodiscard]] const Cloud& cloud() const noexcept { return cloud_; }
  /// The implicit surface.
  [[nodiscard]] const ImplicitSurface<K>& surface() const noexcept { return surface_; }
  /// The grid over the workspace.
  [[nodiscard]] const Grid& grid() const noexcept { return grid_; }
  /// The settings.
  [[nodiscard]] const ExplorerConfig& config() const noexcept { return config_; }

  /// The posterior mean sampled on the grid (brought up to date after a change, in the cells
  /// next to the experts that changed).
  const std::vector<double>& field() {
    if (!fresh_) {
      if (field_.size() != grid_.size()) {
        field_ = surface_.sample(grid_);
      } else {
        surface_.resample(grid_, field_);
      }
      surface_.clear_changed();
      fresh_ = true;
    }
    return field_;
  }
  /// The estimated surface with per-vertex standard deviations (computed once per change).
  const SurfaceMesh& estimate() {
    if (!mesh_) mesh_ = extract_surface(surface_, grid_, field());
    return *mesh_;
  }
  /// Predicts and scores `candidates` on the current estimate, its vertices the targets.
  std::vector<TouchPrediction> score(const std::vector<TouchCandidate>& candidates) {
    return score_touches(surface_, grid_, field(), estimate().mesh.vertices, candidates,
                         config_.scoring);
  }

 private:
  static const ExplorerConfig& checked(const ExplorerConfig& c) {
    c.surface.validate();
    c.scoring.validate();
    for (const double v : {c.free_spacing, c.free_threshold, c.free_cap}) {
      if (!(v > 0.0) || !std::isfinite(v))
        throw std::invalid_argument(
            "ExplorerConfig: free_spacing, free_threshold and free_cap must be finite and > 0");
    }
    (void)K(c.kernel);
    (void)Grid::covering(c.workspace_min, c.workspace_max, c.grid_spacing);
    return c;
  }
  void sync(index::PointId id) {
    const Vec3d p = cloud_.mean(id);
    Vec3d n = Vec3d::Zero();
    if constexpr (requires { cloud_.policy().normal(cloud_.state(id)); }) {
      n = cloud_.policy().normal(cloud_.state(id));
    }
    if (!(n.norm() > 0.5)) {
      n = p - config_.surface.prior_centre;
      if (!(n.norm() > 0.0)) n = Vec3d::UnitZ();
    }
    n.normalize();
    const double var = n.dot(cloud_.covariance(id) * n);
    if (id >= of_cloud_.size()) of_cloud_.resize(std::size_t{id} + 1);
    auto& slot = of_cloud_[id];
    if (slot) {
      (void)surface_.update(*slot, p, n, var);
    } else {
      slot = surface_.insert(p, n, var);
    }
  }

  ExplorerConfig config_;
  Cloud cloud_;
  ImplicitSurface<K> surface_;
  Grid grid_;
  std::vector<std::optional<std::size_t>> of_cloud_;  // cloud id -> surface id
  std::vector<double> field_;
  bool fresh_ = false;
  std::optional<SurfaceMesh> mesh_;
};

}  // namespace taxel::shape
