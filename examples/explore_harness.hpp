// SPDX-License-Identifier: MIT
// The simulated active-touch loop shared by taxel-explore and the active-touch study: a pad
// pokes a simulated object along approach rays chosen by a policy, the contacts go into a
// shape::Explorer, and after each touch the estimate is scored against the true surface.
#pragma once

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <functional>
#include <limits>
#include <memory>
#include <numbers>
#include <optional>
#include <random>
#include <stdexcept>
#include <string>
#include <taxel/index/kdtree.hpp>
#include <taxel/registration/object_library.hpp>
#include <taxel/shape/explorer.hpp>
#include <taxel/shape/recognition.hpp>
#include <taxel/sim/exploration.hpp>
#include <taxel/sim/sampling.hpp>
#include <taxel/sim/sensor.hpp>
#include <taxel/sim/shapes.hpp>
#include <vector>

namespace taxel_explore {

using taxel::Vec3d;

/// How the next touch is chosen.
enum class Policy { active, random, scripted };

/// Settings of one simulated exploration.
struct Settings {
  Policy policy = Policy::active;
  int touches = 40;                  ///< touches to make
  int candidates = 200;              ///< approach rays drawn per touch
  std::uint64_t seed = 1;            ///< object pose, rays and sensor noise
  double grid_spacing = 3e-3;        ///< of the estimate's field [m]
  double coverage_radius = 5e-3;     ///< a true point within this of a fused point is covered
  std::size_t truth_samples = 3000;  ///< points of each surface the error is measured on
  taxel::sim::ExplorationConfig sensing{};  ///< the pad and its noise (object_pose is set here)
  taxel::sim::PalpationParams press{.touches = 1, .press_speed = 0.05, .hold_frames = 5};
  taxel::shape::ExplorerConfig explorer{};  ///< workspace and prior are set from the object
  /// Models to recognise the object among (none: no recognition).
  const taxel::registration::ObjectLibrary<double>* library = nullptr;
  taxel::shape::BeliefConfig belief{};  ///< how recognitions become probabilities
};

/// The state after one touch.
struct TouchRecord {
  int touch = 0;             ///< 1-based
  bool hit = false;          ///< whether the touch met the object
  std::size_t contacts = 0;  ///< contacts so far
  std::size_t points = 0;    ///< fused points so far
  double surface_rms = 0.0;  ///< symmetric RMS distance estimate <-> truth [m]
  /// mean signed distance of the estimate's samples to the true surface [m], > 0 outside
  double surface_signed = 0.0;
  double coverage = 0.0;     ///< share of the true surface within coverage_radius of a point
  double mean_std = 0.0;     ///< area-weighted mean posterior standard deviation [m]
  std::string top1;          ///< most probable model (with a library; empty before 6 points)
  double probability = 0.0;  ///< its probability
  taxel::shape::SurfaceMesh estimate;  ///< the estimate after the touch (kept when asked)
};

namespace detail {

// Area-uniform points on a mesh's triangles.
inline std::vector<Vec3d> sample_mesh(const taxel::shape::Mesh& mesh, std::size_t n,
                                      std::mt19937_64& rng) {
  std::vector<double> cumulative;
  double total = 0.0;
  for (const auto& t : mesh.triangles) {
    const auto& v = mesh.vertices;
    total += 0.5 * (v[t[1]] - v[t[0]]).cross(v[t[2]] - v[t[0]]).norm();
    cumulative.push_back(total);
  }
  std::vector<Vec3d> out;
  if (!(total > 0.0)) return out;
  std::uniform_real_distribution<double> u(0.0, 1.0);
  for (std::size_t i = 0; i < n; ++i) {
    const auto f = static_cast<std::size_t>(
        std::upper_bound(cumulative.begin(), cumulative.end(), u(rng) * total) -
        cumulative.begin());
    const auto& t = mesh.triangles[std::min(f, mesh.triangles.size() - 1)];
    double a = u(rng), b = u(rng);
    if (a + b > 1.0) {
      a = 1.0 - a;
      b = 1.0 - b;
    }
    const auto& v = mesh.vertices;
    out.push_back(v[t[0]] + a * (v[t[1]] - v[t[0]]) + b * (v[t[2]] - v[t[0]]));
  }
  return out;
}

struct SurfaceError {
  double rms = std::numeric_limits<double>::infinity();
  double signed_mean = 0.0;
};

// Symmetric RMS distance between the estimate and the true surface: estimate samples to the
// truth (exact signed distance) and truth samples to the estimate (closest point on its mesh);
// and the mean signed distance of the estimate's samples (> 0: outside the object).
template <class World>
SurfaceError surface_error(const World& world, const taxel::shape::Mesh& mesh,
                           const std::vector<Vec3d>& truth, std::mt19937_64& rng) {
  std::vector<Vec3d> v = mesh.vertices;
  std::vector<taxel::sim::TriangleMesh::Triangle> tris;
  for (const auto& t : mesh.triangles) {
    if ((v[t[1]] - v[t[0]]).cross(v[t[2]] - v[t[0]]).norm() > 1e-16) tris.push_back(t);
  }
  if (tris.empty()) return {};
  const taxel::sim::TriangleMesh estimate(std::move(v), std::move(tris));
  double sum = 0.0, sum_signed = 0.0;
  std::size_t n = 0;
  for (const Vec3d& p : sample_mesh(mesh, truth.size(), rng)) {
    const double d = world.signed_distance(p);
    sum += d * d;
    sum_signed += d;
    ++n;
  }
  const double estimate_samples = double(n);
  for (const Vec3d& p : truth) {
    const double d = (estimate.closest_point(p) - p).norm();
    sum += d * d;
    ++n;
  }
  return {std::sqrt(sum / double(n)), sum_signed / estimate_samples};
}

}  // namespace detail

/// Any simulated shape behind one interface, so that the exploration loop is compiled once for
/// all of them (a template per shape type took most of the tools' build time).
struct AnyShape {
  std::function<double(const Vec3d&)> distance;
  std::function<Vec3d(const Vec3d&)> closest, outward;
  std::function<void(std::mt19937_64&, Vec3d&, Vec3d&)> draw;

  /// Wraps `shape` (copied).
  template <taxel::sim::SampleableShape Sh>
  static AnyShape of(Sh shape) {
    const auto s = std::make_shared<const Sh>(std::move(shape));
    return {[s](const Vec3d& p) { return s->signed_distance(p); },
            [s](const Vec3d& p) { return Vec3d(s->closest_point(p)); },
            [s](const Vec3d& p) { return Vec3d(s->normal(p)); },
            [s](std::mt19937_64& rng, Vec3d& p, Vec3d& n) { sample_point(*s, rng, p, n); }};
  }
  double signed_distance(const Vec3d& p) const { return distance(p); }
  Vec3d closest_point(const Vec3d& p) const { return closest(p); }
  Vec3d normal(const Vec3d& p) const { return outward(p); }
};

/// A uniform surface point of `s` with its outward normal.
inline void sample_point(const AnyShape& s, std::mt19937_64& rng, Vec3d& p, Vec3d& n) {
  s.draw(rng, p, n);
}

/// Explores `shape` (in its own frame) placed at a random pose drawn from the seed, and
/// records the estimate after every touch. `on_touch` is called after each touch with its
/// record (e.g. to write its mesh and drop it).
inline std::vector<TouchRecord> explore(const AnyShape& shape, Settings s,
                                        const std::function<void(TouchRecord&)>& on_touch) {
  using Sh = AnyShape;
  namespace ts = taxel::sim;
  namespace tsh = taxel::shape;
  if (s.touches < 1 || s.candidates < 1)
    throw std::invalid_argument("explore: touches and candidates must be >= 1");
  std::mt19937_64 rng(s.seed);
  // The object at a random orientation, 5 mm from the origin at most: the robot knows where it
  // is roughly, not its shape.
  std::normal_distribution<double> g(0.0, 1.0);
  const Vec3d axis = Vec3d(g(rng), g(rng), g(rng)).normalized();
  std::uniform_real_distribution<double> u(0.0, 1.0);
  Eigen::Isometry3d pose = Eigen::Isometry3d::Identity();
  pose.linear() = Eigen::AngleAxisd(2 * std::numbers::pi * u(rng), axis).matrix();
  pose.translation() = 0.005 * Vec3d(g(rng), g(rng), g(rng)) / std::sqrt(3.0);
  s.sensing.object_pose = pose;
  const ts::Posed<Sh> world{shape, pose};
  const taxel::PointCloud<double> truth = ts::sample_surface(world, s.truth_samples, s.seed + 7);
  double reach = 0.0;
  for (const Vec3d& p : truth.points) reach = std::max(reach, p.norm());
  reach += 0.005;  // the robot's bound on the object's size
  s.explorer.workspace_min = Vec3d::Constant(-reach - 0.008);
  s.explorer.workspace_max = Vec3d::Constant(reach + 0.008);
  s.explorer.grid_spacing = s.grid_spacing;
  s.explorer.surface.prior_centre = Vec3d::Zero();
  s.explorer.surface.prior_radius = 0.5 * reach;
  tsh::Explorer<> explorer(s.explorer);
  std::vector<TouchRecord> out;
  std::vector<taxel::Contact<double>> contacts, all;
  std::mt19937_64 metric_rng(s.seed + 11);
  std::vector<tsh::Hypothesis> belief;
  double time = 0.0;
  for (int k = 1; k <= s.touches; ++k) {
    std::vector<tsh::TouchCandidate> rays =
        tsh::approach_rays(Vec3d::Zero(), reach + 0.03, 0.5 * reach, s.candidates, rng);
    tsh::TouchCandidate pick = rays.front();
    bool picked = false;
    if (s.policy == Policy::active && s.library != nullptr && belief.size() >= 2) {
      // Recognition first: the touch that best tells the likely models apart.
      const std::vector<double> gain =
          tsh::score_recognition_touches(*s.library, belief, rays, s.belief);
      double best = 1e-6;  // a touch that tells nothing apart leaves the choice to the surface
      for (std::size_t i = 0; i < rays.size(); ++i) {
        if (gain[i] > best) {
          best = gain[i];
          pick = rays[i];
          picked = true;
        }
      }
    }
    if (s.policy == Policy::active && !picked) {
      const std::vector<tsh::TouchPrediction> scores = explorer.score(rays);
      double best = -1.0;
      for (std::size_t i = 0; i < rays.size(); ++i) {
        if (scores[i].contact && scores[i].gain > best) {
          best = scores[i].gain;
          pick = rays[i];
        }
      }
    } else if (s.policy == Policy::scripted) {
      // Directions on a Fibonacci sphere, in order, aimed at the centre.
      const double z = 1.0 - (2.0 * (k - 1) + 1.0) / s.touches;
      const double phi = (k - 1) * std::numbers::pi * (3.0 - std::sqrt(5.0));
      const Vec3d d(std::sqrt(1 - z * z) * std::cos(phi), std::sqrt(1 - z * z) * std::sin(phi), z);
      pick = {(reach + 0.03) * d, -d, 2 * (reach + 0.03)};
    }
    contacts.clear();
    const auto hit = ts::poke(world, s.sensing, pick.origin, pick.direction, pick.max_distance, rng,
                              contacts, s.press, time);
    time += 1.0;
    explorer.add_contacts(contacts);
    // The approach was free up to the first contact along the ray (2 mm short of it), or all
    // the way when the touch met nothing.
    {
      const Vec3d d = pick.direction.normalized();
      double stop = pick.max_distance;
      for (const auto& c : contacts) stop = std::min(stop, (c.position - pick.origin).dot(d));
      explorer.add_free_space(pick.origin, pick.origin + std::max(0.0, stop - 0.002) * d);
    }
    all.insert(all.end(), contacts.begin(), contacts.end());
    TouchRecord r;
    r.touch = k;
    r.hit = hit.has_value();
    r.contacts = all.size();
    r.points = explorer.cloud().size();
    r.estimate = explorer.estimate();
    r.mean_std = r.estimate.mean_sigma();
    const detail::SurfaceError err =
        detail::surface_error(world, r.estimate.mesh, truth.points, metric_rng);
    r.surface_rms = err.rms;
    r.surface_signed = err.signed_mean;
    if (r.points > 0) {
      std::vector<Vec3d> fused;
      for (std::size_t i = 0; i < explorer.cloud().size(); ++i)
        fused.push_back(explorer.cloud().mean(static_cast<taxel::index::PointId>(i)));
      const taxel::index::KdTree<double> tree(fused);
      std::size_t covered = 0;
      for (const Vec3d& p : truth.points)
        covered += tree.nearest_within(p, s.coverage_radius).has_value();
      r.coverage = double(covered) / double(truth.points.size());
    }
    if (s.library != nullptr && r.points >= 6) {
      const taxel::PointCloud<double> cloud = explorer.cloud().to_point_cloud();
      belief = tsh::hypotheses(s.library->recognize(cloud), cloud.size(), s.belief);
      if (!belief.empty()) {
        r.top1 = belief.front().name;
        r.probability = belief.front().probability;
      }
    }
    on_touch(r);
    out.push_back(std::move(r));
  }
  return out;
}

}  // namespace taxel_explore
