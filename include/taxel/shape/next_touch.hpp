// SPDX-License-Identifier: MIT
// Where to touch next: each candidate touch is an approach ray the robot can follow. Its
// contact is predicted on the current estimate (the first crossing of the posterior mean's
// zero level along the ray), and it is scored by the expected reduction of the surface's
// uncertainty: as in GPAtlasRRT (Rosales et al., "GPAtlasRRT: a local tactile exploration
// planner for recovering the shape of novel objects", IJHR 2018), touches go where the surface
// is least certain. A touch observes the field (value 0) at its contact and at
// `patch_points` points on a circle of `patch_radius` around it in the predicted tangent plane,
// each with noise sigma^2. With the expert e whose cell holds the contact, whose posterior
// covariance is C(a, b) = k(|a - b|) - v(a)' v(b) (GaussianProcess::whiten), those
// observations O lower the variance at a target point q by
//   gain(q) = c' S^-1 c,   c = C(q, O),   S = C(O, O) + sigma^2 I,
// which does not depend on the values observed, so it is exact before touching. The score is
// the sum of gain(q) over the targets q (e.g. the estimated surface's vertices) within `radius`
// of the contact; 0 when the ray predicts no contact.
#pragma once

#include <Eigen/Cholesky>
#include <Eigen/Core>
#include <cmath>
#include <numbers>
#include <optional>
#include <random>
#include <stdexcept>
#include <string>
#include <unordered_set>
#include <vector>

#include "taxel/core/types.hpp"
#include "taxel/index/kdtree.hpp"
#include "taxel/shape/grid.hpp"
#include "taxel/shape/implicit_surface.hpp"

namespace taxel::shape {

/// A touch the robot can make: along the ray origin + t direction, 0 <= t <= max_distance.
struct TouchCandidate {
  Vec3d origin = Vec3d::Zero();       ///< [m]
  Vec3d direction = -Vec3d::UnitZ();  ///< any length > 0 (normalised on use)
  double max_distance = 0.5;          ///< [m]
};

/// A candidate's predicted outcome.
struct TouchPrediction {
  bool contact = false;          ///< whether the ray meets the estimated surface
  Vec3d point = Vec3d::Zero();   ///< the predicted contact [m]
  Vec3d normal = Vec3d::Zero();  ///< the estimate's outward normal there
  double gain = 0.0;             ///< expected reduction of summed variance [m^2]
};

/// Settings of score_touches. Lengths in metres.
struct ScoringConfig {
  double noise_sigma = 0.3e-3;  ///< sigma: noise of each predicted observation, > 0
  double radius = 0.012;        ///< targets farther from the contact do not count, > 0
  int patch_points = 0;         ///< points on the circle around the contact, in [0, 64]
  double patch_radius = 3e-3;   ///< the circle's radius, >= 0
  /// The targets are thinned to the first in each cube of this side (a mesh's vertices are
  /// far denser than the variance changes); 0 keeps them all. Finite and >= 0.
  double target_spacing = 4e-3;

  /// Throws std::invalid_argument naming the first setting out of range.
  void validate() const {
    if (!(noise_sigma > 0.0) || !std::isfinite(noise_sigma))
      throw std::invalid_argument("ScoringConfig::noise_sigma must be finite and > 0 [m]");
    if (!(radius > 0.0) || !std::isfinite(radius))
      throw std::invalid_argument("ScoringConfig::radius must be finite and > 0 [m]");
    if (patch_points < 0 || patch_points > 64)
      throw std::invalid_argument("ScoringConfig::patch_points must be in [0, 64], got " +
                                  std::to_string(patch_points));
    if (!(patch_radius >= 0.0) || !std::isfinite(patch_radius))
      throw std::invalid_argument("ScoringConfig::patch_radius must be finite and >= 0 [m]");
    if (!(target_spacing >= 0.0) || !std::isfinite(target_spacing))
      throw std::invalid_argument("ScoringConfig::target_spacing must be finite and >= 0 [m]");
  }
};

/// `count` approach rays, each from a uniformly random point on the sphere of radius
/// `standoff` around `centre` towards a uniformly random point of the ball of radius
/// `aim_radius` around it, reaching 2 * standoff. Throws std::invalid_argument unless
/// standoff > aim_radius >= 0 and count >= 0.
template <class Rng>
[[nodiscard]] std::vector<TouchCandidate> approach_rays(const Vec3d& centre, double standoff,
                                                        double aim_radius, int count, Rng& rng) {
  if (!centre.allFinite() || !(aim_radius >= 0.0) || !(standoff > aim_radius) ||
      !std::isfinite(standoff) || count < 0) {
    throw std::invalid_argument(
        "approach_rays: needs a finite centre, standoff > aim_radius >= 0 and count >= 0");
  }
  std::normal_distribution<double> g(0.0, 1.0);
  std::uniform_real_distribution<double> u(0.0, 1.0);
  const auto unit = [&] {
    Vec3d d(g(rng), g(rng), g(rng));
    while (!(d.norm() > 1e-12)) d = Vec3d(g(rng), g(rng), g(rng));
    return Vec3d(d.normalized());
  };
  std::vector<TouchCandidate> out;
  out.reserve(static_cast<std::size_t>(count));
  for (int i = 0; i < count; ++i) {
    const Vec3d from = centre + standoff * unit();
    const Vec3d aim = centre + aim_radius * std::cbrt(u(rng)) * unit();
    out.push_back({from, (aim - from).normalized(), 2.0 * standoff});
  }
  return out;
}

/// The observation points of a touch at `point` with outward normal `normal` (see the file
/// comment): the contact first, then the circle.
template <class = void>
[[nodiscard]] std::vector<Vec3d> touch_patch(const Vec3d& point, const Vec3d& normal,
                                             const ScoringConfig& config) {
  std::vector<Vec3d> out{point};
  const Vec3d n = normal.norm() > 0.0 ? Vec3d(normal.normalized()) : Vec3d::UnitZ();
  const Vec3d u = n.unitOrthogonal(), v = n.cross(u);
  for (int i = 0; i < config.patch_points; ++i) {
    const double a = 2.0 * std::numbers::pi * i / config.patch_points;
    out.push_back(point + config.patch_radius * (std::cos(a) * u + std::sin(a) * v));
  }
  return out;
}

/// Predicts and scores every candidate touch (see the file comment) on `surface`, whose
/// posterior mean is `field` on `grid` (ImplicitSurface::sample). The targets, the points whose
/// uncertainty counts, are `all_targets` thinned by config.target_spacing. Throws
/// std::invalid_argument for a bad configuration, a field that does not fit the grid or a
/// non-finite target.
template <Kernel K>
[[nodiscard]] std::vector<TouchPrediction> score_touches(
    const ImplicitSurface<K>& surface, const Grid& grid, const std::vector<double>& field,
    const std::vector<Vec3d>& all_targets, const std::vector<TouchCandidate>& candidates,
    const ScoringConfig& config = {}) {
  config.validate();
  grid.validate();
  if (field.size() != grid.size())
    throw std::invalid_argument("score_touches: the field does not fit the grid");
  std::vector<TouchPrediction> out(candidates.size());
  for (const Vec3d& t : all_targets) {
    if (!t.allFinite()) throw std::invalid_argument("score_touches: a target is not finite");
  }
  std::vector<Vec3d> targets;
  if (config.target_spacing > 0.0) {
    std::unordered_set<std::uint64_t> seen;
    for (const Vec3d& t : all_targets) {
      const Vec3d u = t / config.target_spacing;
      const CellIndex c{static_cast<int>(std::floor(u[0])), static_cast<int>(std::floor(u[1])),
                        static_cast<int>(std::floor(u[2]))};
      if (seen.insert(ImplicitSurface<K>::cell_key(c)).second) targets.push_back(t);
    }
  } else {
    targets = all_targets;
  }
  if (targets.empty()) return out;
  const index::KdTree<double> tree(targets);
  const double noise = config.noise_sigma * config.noise_sigma;
  for (std::size_t c = 0; c < candidates.size(); ++c) {
    const TouchCandidate& cand = candidates[c];
    if (!cand.origin.allFinite() || !cand.direction.allFinite() || !(cand.direction.norm() > 0.0))
      continue;
    const Vec3d dir = cand.direction.normalized();
    const std::optional<Vec3d> hit =
        first_crossing(grid, field, cand.origin, dir, cand.max_distance);
    if (!hit) continue;
    TouchPrediction& p = out[c];
    p.contact = true;
    p.point = *hit;
    Vec3d g = Vec3d::Zero();
    (void)surface.mean(*hit, g);
    p.normal = g.norm() > 0.0 ? Vec3d(g.normalized()) : Vec3d(-dir);
    const std::vector<Vec3d> patch = touch_patch(p.point, p.normal, config);
    const auto near = tree.within(p.point, config.radius);
    if (near.empty()) continue;
    const CellIndex cell = surface.nearest_expert(p.point);
    const auto* e = surface.find(cell);
    // An expert with no observations is the prior: the same formula with n = 0.
    const GaussianProcess<K> prior(surface.kernel());
    const GaussianProcess<K>& gp = e != nullptr ? e->process : prior;
    // gain(q) = c' S^-1 c with c = k(q, O) - W_O' w_q = k(q, O) - U' k(X, q), U = K^-1 k(X, O)
    // = L^-T W_O: two triangular solves per touch, none per target.
    const auto m = static_cast<Eigen::Index>(patch.size());
    Eigen::Matrix3Xd o(3, m);
    for (Eigen::Index i = 0; i < m; ++i) o.col(i) = patch[static_cast<std::size_t>(i)];
    Eigen::MatrixXd wo(static_cast<Eigen::Index>(gp.size()), m), u(wo.rows(), m);
    for (Eigen::Index i = 0; i < m; ++i) {
      Eigen::VectorXd v = gp.whiten(o.col(i));  // one triangular solve per column: no packing
      wo.col(i) = v;
      gp.solve_upper(v);
      u.col(i) = v;
    }
    Eigen::MatrixXd s(m, m);
    for (Eigen::Index i = 0; i < m; ++i)
      for (Eigen::Index j = 0; j < m; ++j) s(i, j) = surface.kernel()((o.col(i) - o.col(j)).norm());
    s.noalias() -= wo.transpose() * wo;
    s.diagonal().array() += noise;
    const Eigen::LLT<Eigen::MatrixXd> llt(s);
    Eigen::VectorXd cq(m);
    for (const auto& nb : near) {
      const Vec3d& q = targets[nb.id];
      for (Eigen::Index i = 0; i < m; ++i)
        cq(i) = surface.kernel()((q - o.col(i)).norm()) - gp.weighted_sum(q, u.col(i));
      p.gain += cq.dot(llt.solve(cq));
    }
  }
  return out;
}

}  // namespace taxel::shape
