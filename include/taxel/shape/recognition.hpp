// SPDX-License-Identifier: MIT
// Which known object is being touched, and where to touch to tell: a belief over hypotheses
// (model, pose) and touches scored by the expected drop of its entropy (after Hebert, Howard,
// Hudson, Ma and Burdick, "The next best touch for model-based localization", ICRA 2013).
//
// The hypotheses are the models of a registration::ObjectLibrary, each at the pose its
// multi-start ICP found for the fused cloud, with probability
//   p_m ~ exp(-n s_m^2 / (2 sigma^2)),   n = min(points, max_points),
// s_m the model's truncated RMS distance to the cloud. The points of a fused cloud are not
// independent (neighbours share contacts and pose error), so n is capped.
//
// A candidate touch (an approach ray) is predicted under each hypothesis by casting the ray
// against the model's points at its pose: sphere tracing on the distance to the nearest model
// point, until within `surface_tolerance` (a contact at distance t along the ray), or a miss.
// If hypothesis h is true the touch observes its outcome o_h; hypothesis j then explains it
// with likelihood exp(-(t_h - t_j)^2 / (2 ray_sigma^2)) when both hit, 1 when both miss and
// `confusion` otherwise. The score is the entropy now minus the expected entropy after:
//   H(p) - sum_h p_h H(p(. | o_h)),   p(j | o_h) ~ p_j L(o_h | j),
// exact for this discrete model (the tests check it by enumeration).
#pragma once

#include <Eigen/Geometry>
#include <algorithm>
#include <cmath>
#include <limits>
#include <optional>
#include <stdexcept>
#include <string>
#include <vector>

#include "taxel/core/types.hpp"
#include "taxel/registration/object_library.hpp"
#include "taxel/registration/target.hpp"
#include "taxel/shape/next_touch.hpp"

namespace taxel::shape {

/// Settings of the recognition belief and its touch scoring. Lengths in metres.
struct BeliefConfig {
  double sigma = 1e-3;                ///< spread of a good fit's score, > 0
  std::size_t max_points = 50;        ///< n's cap, >= 1
  double ray_sigma = 2e-3;            ///< spread of a predicted contact along its ray, > 0
  double surface_tolerance = 1.5e-3;  ///< a ray this close to a model point touches it, > 0
  double confusion = 1e-3;            ///< likelihood of a hit where a miss was due, in [0, 1)
  std::size_t hypotheses = 6;         ///< most probable hypotheses a touch is scored on, >= 2

  /// Throws std::invalid_argument naming the first setting out of range.
  void validate() const {
    const auto positive = [](double v) { return v > 0.0 && std::isfinite(v); };
    if (!positive(sigma)) throw std::invalid_argument("BeliefConfig::sigma must be finite and > 0");
    if (max_points < 1) throw std::invalid_argument("BeliefConfig::max_points must be >= 1");
    if (!positive(ray_sigma))
      throw std::invalid_argument("BeliefConfig::ray_sigma must be finite and > 0");
    if (!positive(surface_tolerance))
      throw std::invalid_argument("BeliefConfig::surface_tolerance must be finite and > 0");
    if (!(confusion >= 0.0) || !(confusion < 1.0))
      throw std::invalid_argument("BeliefConfig::confusion must be in [0, 1)");
    if (hypotheses < 2) throw std::invalid_argument("BeliefConfig::hypotheses must be >= 2");
  }
};

/// One hypothesis: a model at a pose.
struct Hypothesis {
  std::string name;                                      ///< the model's name
  std::size_t model = 0;                                 ///< its index in the library
  Isometry3d model_from_world = Isometry3d::Identity();  ///< T_model_cloud of its ICP
  double score = 0.0;                                    ///< truncated RMS distance [m]
  double probability = 0.0;                              ///< p_m
};

/// Entropy [nats] of probabilities that sum to 1 (zeros contribute nothing).
template <class = void>
[[nodiscard]] double entropy(const std::vector<double>& p) {
  double h = 0.0;
  for (const double v : p) h -= v > 0.0 ? v * std::log(v) : 0.0;
  return h;
}

/// The hypotheses of a recognition of a cloud of `points` points, most probable first (see
/// the file comment). Empty for a failed recognition.
template <class = void>
[[nodiscard]] std::vector<Hypothesis> hypotheses(const registration::ObjectRecognition& r,
                                                 std::size_t points,
                                                 const BeliefConfig& config = {}) {
  config.validate();
  std::vector<Hypothesis> out;
  if (!r.ok() || r.ranking.empty()) return out;
  const double n = double(std::min(points, config.max_points));
  double best = std::numeric_limits<double>::infinity();
  for (const auto& m : r.ranking) best = std::min(best, m.score);
  double total = 0.0;
  for (const auto& m : r.ranking) {
    // Relative to the best, so that the exponent never underflows for all at once.
    const double w =
        std::exp(-n * (m.score * m.score - best * best) / (2 * config.sigma * config.sigma));
    out.push_back({m.name, m.model, m.transform, m.score, w});
    total += w;
  }
  for (auto& h : out) h.probability /= total;
  std::stable_sort(out.begin(), out.end(), [](const Hypothesis& a, const Hypothesis& b) {
    return a.probability > b.probability;
  });
  return out;
}

/// Where the ray origin + t direction (world frame, unit direction) first comes within
/// `tolerance` of `target`'s points placed by `model_from_world`: its t, or nothing within
/// max_distance.
template <class S>
[[nodiscard]] std::optional<double> cast_ray(const registration::Target<S>& target,
                                             const Isometry3d& model_from_world,
                                             const Vec3d& origin, const Vec3d& direction,
                                             double max_distance, double tolerance) {
  const Vec3d o = model_from_world * origin;
  const Vec3d d = model_from_world.linear() * direction;
  double t = 0.0;
  for (int it = 0; it < 10000 && t <= max_distance; ++it) {
    const Vec3<S> q = (o + t * d).template cast<S>();
    const auto nn = target.kdtree().knn(q, 1);
    if (nn.empty()) return std::nullopt;
    const double dist = std::sqrt(double(nn.front().squared_distance));
    if (dist <= tolerance) return t;
    t += std::max(dist - tolerance, 0.25 * tolerance);
  }
  return std::nullopt;
}

/// The expected drop of the belief's entropy for each candidate touch (see the file comment),
/// over the `config.hypotheses` most probable of `belief` (the rest keep their probability and
/// are not predicted, so they count as unchanged mass). Throws std::invalid_argument for a bad
/// configuration or a hypothesis whose model the library does not have.
template <class S>
[[nodiscard]] std::vector<double> score_recognition_touches(
    const registration::ObjectLibrary<S>& library, const std::vector<Hypothesis>& belief,
    const std::vector<TouchCandidate>& candidates, const BeliefConfig& config = {}) {
  config.validate();
  std::vector<double> out(candidates.size(), 0.0);
  const std::size_t m = std::min(belief.size(), config.hypotheses);
  if (m < 2) return out;
  for (std::size_t j = 0; j < m; ++j) {
    if (belief[j].model >= library.size())
      throw std::invalid_argument("score_recognition_touches: no model " +
                                  std::to_string(belief[j].model) + " in the library");
  }
  std::vector<double> p(m);
  double mass = 0.0;
  for (std::size_t j = 0; j < m; ++j) mass += p[j] = belief[j].probability;
  if (!(mass > 0.0)) return out;
  for (double& v : p) v /= mass;
  const double before = entropy(p);
  std::vector<std::optional<double>> t(m);
  std::vector<double> post(m);
  for (std::size_t c = 0; c < candidates.size(); ++c) {
    const TouchCandidate& cand = candidates[c];
    if (!cand.origin.allFinite() || !cand.direction.allFinite() || !(cand.direction.norm() > 0.0))
      continue;
    const Vec3d dir = cand.direction.normalized();
    for (std::size_t j = 0; j < m; ++j) {
      t[j] = cast_ray(library.target(belief[j].model), belief[j].model_from_world, cand.origin, dir,
                      cand.max_distance, config.surface_tolerance);
    }
    double after = 0.0;
    for (std::size_t h = 0; h < m; ++h) {
      double z = 0.0;
      for (std::size_t j = 0; j < m; ++j) {
        double like = config.confusion;
        if (t[h] && t[j]) {
          const double e = (*t[h] - *t[j]) / config.ray_sigma;
          like = std::exp(-0.5 * e * e);
        } else if (!t[h] && !t[j]) {
          like = 1.0;
        }
        z += post[j] = p[j] * like;
      }
      for (double& v : post) v /= z;
      after += p[h] * entropy(post);
    }
    out[c] = before - after;
  }
  return out;
}

}  // namespace taxel::shape
