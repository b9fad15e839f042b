// SPDX-License-Identifier: MIT
// How good a reconstructed cloud is against the true shape: distances of the points to the
// surface (mean, RMS, max), coverage (the fraction of the surface within a distance of some
// point, estimated on uniform surface samples), point count and compaction (contacts per point).
#pragma once

#include <cstddef>
#include <cstdint>
#include <stdexcept>
#include <vector>

#include "taxel/core/point_cloud.hpp"
#include "taxel/index/kdtree.hpp"
#include "taxel/sim/sampling.hpp"
#include "taxel/sim/sliding.hpp"

namespace taxel::sim {

/// Options of reconstruction_metrics.
struct MetricsConfig {
  double coverage_radius = 5e-3;         ///< a surface sample is covered within this [m], > 0
  std::size_t coverage_samples = 20000;  ///< uniform surface samples, >= 1
  std::uint64_t seed = 1;                ///< of the surface samples
};

/// Quality of a reconstructed cloud.
struct ReconstructionMetrics {
  SurfaceError error;        ///< distances of the points to the surface [m]
  double coverage = 0.0;     ///< fraction of the surface within coverage_radius of a point
  std::size_t points = 0;    ///< cloud size
  std::size_t contacts = 0;  ///< contacts the cloud was made from
  double compaction = 0.0;   ///< contacts / points (0 for an empty cloud)
};

/// Metrics of `points` (any range of Vec3) made from `contacts` contacts against `shape`.
/// Non-finite points count in `points` but not in the distances or coverage. Throws
/// std::invalid_argument for a bad configuration.
template <SampleableShape Sh>
ReconstructionMetrics reconstruction_metrics(const Sh& shape, const std::vector<Vec3d>& points,
                                             std::size_t contacts, const MetricsConfig& cfg = {}) {
  if (!(cfg.coverage_radius > 0.0) || cfg.coverage_samples < 1) {
    throw std::invalid_argument(
        "MetricsConfig: coverage_radius must be > 0 and coverage_samples >= 1");
  }
  ReconstructionMetrics m;
  m.points = points.size();
  m.contacts = contacts;
  m.compaction =
      points.empty() ? 0.0 : static_cast<double>(contacts) / static_cast<double>(points.size());
  std::vector<Vec3d> finite;
  finite.reserve(points.size());
  for (const auto& p : points) {
    if (p.allFinite()) finite.push_back(p);
  }
  m.error = surface_error(shape, finite);
  if (finite.empty()) return m;
  const index::KdTree<double> tree(finite);
  const PointCloud<double> surface = sample_surface(shape, cfg.coverage_samples, cfg.seed);
  std::size_t covered = 0;
  for (const auto& s : surface.points)
    covered += tree.nearest_within(s, cfg.coverage_radius) ? 1 : 0;
  m.coverage = static_cast<double>(covered) / static_cast<double>(surface.size());
  return m;
}

}  // namespace taxel::sim
