// SPDX-License-Identifier: MIT
// Recognition of a partial tactile cloud among known object models by multi-start ICP
// (the first paper's "ICP alignment and classification"): every model is tried from starts
// that align the cloud's principal axes with the model's (4 proper sign choices) and from the
// 24 rotations of the cube's rotation group, each about the centroids. Each start runs a few
// point-to-plane iterations on a 64-point subsample against the model's closest-point field;
// hopeless starts stop after three; the best two per model are refined on 512 points, still on
// the field; the three best models are then refined with exact correspondences. Models are
// ranked by the truncated RMS distance of all cloud points to the model (points beyond the gate
// count as the gate), and the answer is `unknown` when even the best model is farther than a
// threshold.
#pragma once

#include <Eigen/Eigenvalues>
#include <algorithm>
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
#include "taxel/registration/icp.hpp"
#include "taxel/registration/target.hpp"

namespace taxel::registration {

/// The 24 proper rotations that map the coordinate axes onto themselves (signed permutation
/// matrices with determinant +1), identity first.
template <class = void>
inline std::vector<Mat3d> cube_rotations() {
  std::vector<Mat3d> out;
  const std::array<std::array<int, 3>, 6> perms{
      {{0, 1, 2}, {0, 2, 1}, {1, 0, 2}, {1, 2, 0}, {2, 0, 1}, {2, 1, 0}}};
  for (const auto& p : perms) {
    for (int signs = 0; signs < 8; ++signs) {
      Mat3d m = Mat3d::Zero();
      for (int r = 0; r < 3; ++r)
        m(r, p[static_cast<std::size_t>(r)]) = (signs >> r) & 1 ? -1.0 : 1.0;
      if (m.determinant() > 0) out.push_back(m);
    }
  }
  return out;
}

/// Options of ObjectLibrary. Distances in metres.
struct LibraryConfig {
  /// Refinement (point-to-plane) of the best coarse starts on `refine_points` of the cloud.
  IcpConfig refine{.max_iterations = 20,
                   .max_distance = 0.01,
                   .trim_fraction = 0.1,
                   .translation_tolerance = 1e-5,
                   .rotation_tolerance = 1e-4,
                   .relative_error_tolerance = 1e-3};
  int coarse_iterations = 10;       ///< point-to-plane iterations per start on the subsample, >= 1
  std::size_t coarse_points = 64;   ///< subsample size of the coarse stage, >= 6
  std::size_t refine_points = 512;  ///< subsample size of the refinement, >= 6
  double coarse_trim = 0.0;         ///< trimmed fraction in the coarse stage, [0, 1)
  bool pca_starts = true;           ///< the 4 principal-axes starts
  int rotation_starts = 24;         ///< starts from the cube rotation group, [0, 24]
  int refine_best = 2;              ///< coarse starts refined per model, >= 1
  int exact_models = 3;             ///< best models refined with exact correspondences, >= 1
  /// A start whose coarse RMS distance after 3 iterations exceeds this multiple of the best
  /// coarse result so far (any model) stops there.
  double hopeless_factor = 3.0;
  /// Cell of the models' closest-point fields, used by the coarse stage [m] (TargetConfig).
  double field_cell = 2e-3;
  /// Gate of the score: points farther than this from the model count as this far.
  double score_gate = 0.01;
  /// `unknown` when the best model's score exceeds this.
  double unknown_score = 3e-3;
};

/// How well one model explains the cloud.
struct ModelMatch {
  std::string name;
  std::size_t model = 0;                          ///< index in the library
  double score = 0.0;                             ///< truncated RMS distance [m], lower is better
  double rmse = 0.0;                              ///< ICP inlier RMSE [m]
  double inlier_fraction = 0.0;                   ///< ICP inliers / cloud points
  Isometry3d transform = Isometry3d::Identity();  ///< T_model_cloud
  Status icp_status = Status::ok;                 ///< of the exact refinement
  bool exact = false;                             ///< refined with exact correspondences
  int starts = 0;                                 ///< starts tried
  int starts_stopped_early = 0;                   ///< hopeless starts cut short
};

/// The answer of ObjectLibrary::recognize. `ranking` is sorted by score; `best` is its first
/// entry's name, or "unknown".
struct ObjectRecognition : Outcome {
  std::vector<ModelMatch> ranking;
  std::string best = "unknown";
  bool unknown = true;
  double margin = 0.0;  ///< second score - best score [m] (0 with one model)
};

/// Named object models, each preprocessed once into a Target.
/// Thread-safety: `recognize` is const and keeps its state on the stack, so several
/// threads may recognise at once; `add` must not overlap with any other call.
template <Scalar S = double>
class ObjectLibrary {
 public:
  /// Throws std::invalid_argument naming the first bad field.
  explicit ObjectLibrary(LibraryConfig cfg = {}) : cfg_(std::move(cfg)) {
    const auto bad = [](const std::string& what) {
      throw std::invalid_argument("LibraryConfig::" + what);
    };
    if (cfg_.coarse_iterations < 1) bad("coarse_iterations must be >= 1");
    if (cfg_.coarse_points < 6 || cfg_.refine_points < 6) {
      bad("coarse_points and refine_points must be >= 6");
    }
    if (!(cfg_.coarse_trim >= 0.0 && cfg_.coarse_trim < 1.0)) bad("coarse_trim must be in [0, 1)");
    if (cfg_.rotation_starts < 0 || cfg_.rotation_starts > 24)
      bad("rotation_starts must be in [0, 24]");
    if (!cfg_.pca_starts && cfg_.rotation_starts == 0) bad("pca_starts or rotation_starts needed");
    if (cfg_.refine_best < 1 || cfg_.exact_models < 1) {
      bad("refine_best and exact_models must be >= 1");
    }
    if (!(cfg_.hopeless_factor > 1.0)) bad("hopeless_factor must be > 1");
    if (!(cfg_.score_gate > 0.0) || !(cfg_.unknown_score > 0.0)) {
      bad("score_gate and unknown_score must be > 0");
    }
    if (!(cfg_.field_cell >= 0.0) || !std::isfinite(cfg_.field_cell)) {
      bad("field_cell must be finite and >= 0");
    }
    (void)Icp<PointToPlane>(cfg_.refine);  // validates the refinement options
  }

  /// Adds a model (points with or without normals). Throws std::invalid_argument for an empty
  /// name, a duplicate name or a cloud Target refuses.
  void add(std::string name, PointCloud<S> model, TargetConfig target = {}) {
    if (name.empty()) throw std::invalid_argument("ObjectLibrary::add: empty model name");
    for (const auto& m : models_) {
      if (m.name == name) {
        throw std::invalid_argument("ObjectLibrary::add: a model named '" + name + "' exists");
      }
    }
    if (target.field_cell == 0.0) target.field_cell = cfg_.field_cell;
    models_.push_back({std::move(name), Target<S>(std::move(model), target)});
  }

  [[nodiscard]] std::size_t size() const noexcept { return models_.size(); }
  [[nodiscard]] const std::string& name(std::size_t i) const { return models_.at(i).name; }
  [[nodiscard]] const Target<S>& target(std::size_t i) const { return models_.at(i).target; }
  [[nodiscard]] const LibraryConfig& config() const noexcept { return cfg_; }

  /// Ranks every model for `cloud`. Non-finite points are ignored. An empty library or fewer
  /// than 6 finite points give `invalid_input`; a collinear or planar cloud still gets a ranking
  /// (its starts then differ only by the cube rotations).
  [[nodiscard]] ObjectRecognition recognize(const PointCloud<S>& cloud) const {
    ObjectRecognition out;
    std::vector<Vec3<S>> pts;
    pts.reserve(cloud.size());
    for (const auto& p : cloud.points) {
      if (p.allFinite()) pts.push_back(p);
    }
    if (models_.empty() || pts.size() < 6) {
      out.status = Status::invalid_input;
      out.message = models_.empty() ? "the library has no models"
                                    : std::to_string(pts.size()) +
                                          " finite cloud points; recognition needs at least 6";
      return out;
    }
    // Cloud frame: centroid and principal axes.
    Vec3d centre = Vec3d::Zero();
    for (const auto& p : pts) centre += p.template cast<double>();
    centre /= static_cast<double>(pts.size());
    const Mat3d axes = principal_axes(pts, centre);
    // Subsamples: evenly spaced in the cloud's order.
    const std::vector<Vec3<S>> coarse = subsample(pts, cfg_.coarse_points);
    const std::vector<Vec3<S>> fine = subsample(pts, cfg_.refine_points);

    std::vector<Mat3d> rotations;  // of the cloud's frame into the model's, before centring
    const std::vector<Mat3d> group = cube_rotations();

    IcpConfig coarse_cfg;
    coarse_cfg.max_iterations = std::min(3, cfg_.coarse_iterations);
    coarse_cfg.trim_fraction = cfg_.coarse_trim;
    coarse_cfg.translation_tolerance = 1e-4;
    coarse_cfg.rotation_tolerance = 1e-3;
    coarse_cfg.approximate = true;
    Icp<PointToPlane> early(coarse_cfg);
    coarse_cfg.max_iterations = std::max(1, cfg_.coarse_iterations - 3);
    Icp<PointToPlane> rest(coarse_cfg);
    // Refinement: first on the closest-point fields, then exact from there.
    IcpConfig approx_cfg = cfg_.refine;
    approx_cfg.approximate = true;
    Icp<PointToPlane> refine_approx(approx_cfg);
    Icp<PointToPlane> refine(cfg_.refine);
    double best_coarse = std::numeric_limits<double>::infinity();

    for (std::size_t mi = 0; mi < models_.size(); ++mi) {
      const Target<S>& tg = models_[mi].target;
      rotations.clear();
      if (cfg_.pca_starts) {
        for (const Vec3d& d :
             {Vec3d(1, 1, 1), Vec3d(-1, -1, 1), Vec3d(-1, 1, -1), Vec3d(1, -1, -1)}) {
          rotations.push_back(tg.principal_axes() * d.asDiagonal() * axes.transpose());
        }
      }
      for (int k = 0; k < cfg_.rotation_starts; ++k)
        rotations.push_back(group[static_cast<std::size_t>(k)]);

      ModelMatch match;
      match.name = models_[mi].name;
      match.model = mi;
      std::vector<std::pair<double, Isometry3d>> starts;  // coarse rmse, transform
      for (const Mat3d& r : rotations) {
        Isometry3d t = Isometry3d::Identity();
        t.linear() = r;
        t.translation() = tg.centroid() - r * centre;
        ++match.starts;
        IcpResult res = early.align(tg, std::span<const Vec3<S>>(coarse), t);
        if (res.status == Status::invalid_input) continue;
        if (res.rmse > cfg_.hopeless_factor * best_coarse || res.inliers < 6) {
          ++match.starts_stopped_early;
        } else {
          res = rest.align(tg, std::span<const Vec3<S>>(coarse), res.transform);
        }
        const double s = truncated_rms(tg, coarse, res.transform, true);
        best_coarse = std::min(best_coarse, s);
        starts.emplace_back(s, res.transform);
      }
      std::sort(starts.begin(), starts.end(),
                [](const auto& a, const auto& b) { return a.first < b.first; });
      // The best starts refined on the closest-point field; the best of them kept.
      match.score = std::numeric_limits<double>::infinity();
      const std::size_t refined =
          std::min<std::size_t>(starts.size(), static_cast<std::size_t>(cfg_.refine_best));
      for (std::size_t k = 0; k < refined; ++k) {
        const IcpResult res =
            refine_approx.align(tg, std::span<const Vec3<S>>(fine), starts[k].second);
        const double s = truncated_rms(tg, fine, res.transform, true);
        if (s < match.score) {
          match.score = s;
          match.transform = res.transform;
        }
      }
      out.ranking.push_back(std::move(match));
    }
    // The leading models refined exactly; every model scored exactly on the whole cloud.
    std::stable_sort(out.ranking.begin(), out.ranking.end(),
                     [](const ModelMatch& a, const ModelMatch& b) { return a.score < b.score; });
    for (std::size_t k = 0; k < out.ranking.size(); ++k) {
      ModelMatch& match = out.ranking[k];
      const Target<S>& tg = models_[match.model].target;
      if (k < static_cast<std::size_t>(cfg_.exact_models)) {
        const IcpResult res = refine.align(tg, std::span<const Vec3<S>>(fine), match.transform);
        match.transform = res.transform;
        match.rmse = res.rmse;
        match.inlier_fraction = res.inlier_fraction;
        match.icp_status = res.status;
        match.exact = true;
      }
      match.score = truncated_rms(tg, pts, match.transform, false);
    }
    std::stable_sort(out.ranking.begin(), out.ranking.end(),
                     [](const ModelMatch& a, const ModelMatch& b) { return a.score < b.score; });
    out.margin = out.ranking.size() > 1 ? out.ranking[1].score - out.ranking[0].score : 0.0;
    out.unknown = !(out.ranking[0].score <= cfg_.unknown_score);
    out.best = out.unknown ? "unknown" : out.ranking[0].name;
    return out;
  }

 private:
  struct Model {
    std::string name;
    Target<S> target;
  };

  static std::vector<Vec3<S>> subsample(const std::vector<Vec3<S>>& pts, std::size_t n) {
    const std::size_t m = std::min(n, pts.size());
    std::vector<Vec3<S>> out;
    out.reserve(m);
    for (std::size_t i = 0; i < m; ++i) out.push_back(pts[i * pts.size() / m]);
    return out;
  }

  static Mat3d principal_axes(const std::vector<Vec3<S>>& pts, const Vec3d& centre) {
    Mat3d cov = Mat3d::Zero();
    for (const auto& p : pts) {
      const Vec3d d = p.template cast<double>() - centre;
      cov += d * d.transpose();
    }
    const Eigen::SelfAdjointEigenSolver<Mat3d> eig(cov);
    Mat3d axes;
    axes.col(0) = eig.eigenvectors().col(2);
    axes.col(1) = eig.eigenvectors().col(1);
    axes.col(2) = axes.col(0).cross(axes.col(1));
    return axes;
  }

  // sqrt(mean(min(d^2, gate^2))) over the points under t; d from the closest-point field
  // where `approximate` and the field covers the point.
  double truncated_rms(const Target<S>& tg, const std::vector<Vec3<S>>& pts, const Isometry3d& t,
                       bool approximate) const {
    const double g2 = cfg_.score_gate * cfg_.score_gate;
    double sum = 0.0;
    for (const auto& p : pts) {
      const Vec3d q = t * p.template cast<double>();
      const Vec3<S> qs = q.template cast<S>();
      if (const auto id = approximate ? tg.field_nearest(qs) : std::nullopt) {
        sum += std::min((q - tg.points()[*id].template cast<double>()).squaredNorm(), g2);
        continue;
      }
      const auto nb = tg.nearest_within(qs, static_cast<S>(cfg_.score_gate));
      sum += nb ? std::min(static_cast<double>(nb->squared_distance), g2) : g2;
    }
    return std::sqrt(sum / static_cast<double>(pts.size()));
  }

  LibraryConfig cfg_;
  std::vector<Model> models_;
};

}  // namespace taxel::registration
