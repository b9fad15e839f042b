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
#include <atomic>
#include <cmath>
#include <cstddef>
#include <limits>
#include <optional>
#include <stdexcept>
#include <string>
#include <utility>
#include <vector>

#include "taxel/core/parallel.hpp"
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
  std::size_t coarse_points = 128;  ///< subsample size of the coarse stage, >= 6
  std::size_t refine_points = 512;  ///< subsample size of the refinement, >= 6
  double coarse_trim = 0.0;         ///< trimmed fraction in the coarse stage, [0, 1)
  bool pca_starts = true;           ///< the 4 principal-axes starts
  int rotation_starts = 24;         ///< starts from the cube rotation group, [0, 24]
  int refine_best = 2;              ///< coarse starts refined per model, >= 1
  int exact_models = 3;             ///< best models refined with exact correspondences, >= 1
  /// A start whose inlier RMSE after 3 coarse iterations exceeds this multiple of the best
  /// truncated RMS distance any start (of any model) reached by then stops there.
  double hopeless_factor = 3.0;
  /// Cell of the models' closest-point fields, used by the coarse stage [m] (TargetConfig).
  double field_cell = 2e-3;
  /// Gate of the score: points farther than this from the model count as this far.
  double score_gate = 0.01;
  /// `unknown` when the best model's score exceeds this.
  double unknown_score = 3e-3;
  /// Threads of one recognition (0: every core). The starts, the refinements and the scores
  /// are shared out over them; the answer does not depend on the number.
  unsigned threads = 0;
};

/// How well one model explains the cloud.
struct ModelMatch {
  std::string name;                               ///< The model's name.
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
  std::vector<ModelMatch> ranking;  ///< Every model, best first.
  std::string best = "unknown";     ///< Name of the best model, or "unknown".
  bool unknown = true;              ///< True when no model fits within the threshold.
  double margin = 0.0;              ///< second score - best score [m] (0 with one model)
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

  /// Number of models.
  [[nodiscard]] std::size_t size() const noexcept { return models_.size(); }
  /// The model's name.
  [[nodiscard]] const std::string& name(std::size_t i) const { return models_.at(i).name; }
  /// The preprocessed target of model `i`.
  [[nodiscard]] const Target<S>& target(std::size_t i) const { return models_.at(i).target; }
  /// The configuration.
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

    // Every (model, start) pair, in model order; the starts align the cloud's principal axes
    // with the model's, then the cube rotations, each about the centroids.
    const std::vector<Mat3d> group = cube_rotations();
    struct Start {
      std::size_t model = 0;
      Isometry3d transform = Isometry3d::Identity();
      IcpResult early;
      double score = std::numeric_limits<double>::infinity();  // coarse truncated RMS
      bool valid = false;
      bool stopped = false;
    };
    std::vector<Start> starts;
    for (std::size_t mi = 0; mi < models_.size(); ++mi) {
      const Target<S>& tg = models_[mi].target;
      const auto add = [&](const Mat3d& r) {
        Start st;
        st.model = mi;
        st.transform.linear() = r;
        st.transform.translation() = tg.centroid() - r * centre;
        starts.push_back(std::move(st));
      };
      if (cfg_.pca_starts) {
        for (const Vec3d& d :
             {Vec3d(1, 1, 1), Vec3d(-1, -1, 1), Vec3d(-1, 1, -1), Vec3d(1, -1, -1)}) {
          add(tg.principal_axes() * d.asDiagonal() * axes.transpose());
        }
      }
      for (int k = 0; k < cfg_.rotation_starts; ++k) add(group[static_cast<std::size_t>(k)]);
    }

    IcpConfig coarse_cfg;
    coarse_cfg.max_iterations = std::min(3, cfg_.coarse_iterations);
    coarse_cfg.trim_fraction = cfg_.coarse_trim;
    coarse_cfg.translation_tolerance = 1e-4;
    coarse_cfg.rotation_tolerance = 1e-3;
    coarse_cfg.approximate = true;
    const IcpConfig early_cfg = coarse_cfg;
    coarse_cfg.max_iterations = std::max(1, cfg_.coarse_iterations - 3);
    const IcpConfig rest_cfg = coarse_cfg;
    // Refinement: first on the closest-point fields, then exact from there.
    IcpConfig approx_cfg = cfg_.refine;
    approx_cfg.approximate = true;
    const std::span<const Vec3<S>> coarse_span(coarse), fine_span(fine);

    // Each stage runs its items on the workers, each worker with its own ICP workspace; an
    // item's result depends on its inputs alone, so the answer is the same on any number of
    // threads. Stage 1: three coarse iterations from every start.
    for_each_item(
        starts.size(), [&] { return Icp<PointToPlane>(early_cfg); },
        [&](Icp<PointToPlane>& icp, std::size_t i) {
          Start& st = starts[i];
          const Target<S>& tg = models_[st.model].target;
          st.early = icp.align(tg, coarse_span, st.transform);
          st.valid = st.early.status != Status::invalid_input;
          if (st.valid) st.score = truncated_rms(tg, coarse, st.early.transform, true);
        });
    // A start whose early RMSE exceeds hopeless_factor times the best early score of any
    // model stops there (a threshold that does not depend on the order of the starts).
    double best_early = std::numeric_limits<double>::infinity();
    for (const Start& st : starts) best_early = std::min(best_early, st.score);
    // Stage 2: the remaining coarse iterations of the promising starts.
    for_each_item(
        starts.size(), [&] { return Icp<PointToPlane>(rest_cfg); },
        [&](Icp<PointToPlane>& icp, std::size_t i) {
          Start& st = starts[i];
          if (!st.valid) return;
          const Target<S>& tg = models_[st.model].target;
          if (st.early.rmse > cfg_.hopeless_factor * best_early || st.early.inliers < 6) {
            st.stopped = true;
            st.transform = st.early.transform;
            return;
          }
          st.transform = icp.align(tg, coarse_span, st.early.transform).transform;
          st.score = truncated_rms(tg, coarse, st.transform, true);
        });
    // Stage 3, per model: its best starts refined on the closest-point field, the best kept.
    out.ranking.resize(models_.size());
    for_each_item(
        models_.size(), [&] { return Icp<PointToPlane>(approx_cfg); },
        [&](Icp<PointToPlane>& icp, std::size_t mi) {
          const Target<S>& tg = models_[mi].target;
          ModelMatch& match = out.ranking[mi];
          match.name = models_[mi].name;
          match.model = mi;
          std::vector<std::pair<double, std::size_t>> order;  // coarse score, start
          for (std::size_t i = 0; i < starts.size(); ++i) {
            if (starts[i].model != mi) continue;
            ++match.starts;
            if (!starts[i].valid) continue;
            if (starts[i].stopped) ++match.starts_stopped_early;
            order.emplace_back(starts[i].score, i);
          }
          std::sort(order.begin(), order.end());
          match.score = std::numeric_limits<double>::infinity();
          const std::size_t refined =
              std::min<std::size_t>(order.size(), static_cast<std::size_t>(cfg_.refine_best));
          for (std::size_t k = 0; k < refined; ++k) {
            const IcpResult res = icp.align(tg, fine_span, starts[order[k].second].transform);
            const double s = truncated_rms(tg, fine, res.transform, true);
            if (s < match.score) {
              match.score = s;
              match.transform = res.transform;
            }
          }
        });
    // The leading models refined exactly; every model scored exactly on the whole cloud.
    std::stable_sort(out.ranking.begin(), out.ranking.end(),
                     [](const ModelMatch& a, const ModelMatch& b) { return a.score < b.score; });
    for_each_item(
        out.ranking.size(), [&] { return Icp<PointToPlane>(cfg_.refine); },
        [&](Icp<PointToPlane>& icp, std::size_t k) {
          ModelMatch& match = out.ranking[k];
          const Target<S>& tg = models_[match.model].target;
          if (k < static_cast<std::size_t>(cfg_.exact_models)) {
            const IcpResult res = icp.align(tg, fine_span, match.transform);
            match.transform = res.transform;
            match.rmse = res.rmse;
            match.inlier_fraction = res.inlier_fraction;
            match.icp_status = res.status;
            match.exact = true;
          }
          match.score = truncated_rms(tg, pts, match.transform, false);
        });
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

  // Calls item(workspace, i) for every i in [0, n) on up to cfg_.threads threads, each thread
  // with one workspace made by make() and handed items one at a time.
  template <class Make, class Item>
  void for_each_item(std::size_t n, Make&& make, Item&& item) const {
    const std::size_t workers = std::min<std::size_t>(resolve_threads(cfg_.threads), n);
    std::atomic<std::size_t> next{0};
    parallel_for(workers, static_cast<unsigned>(workers), [&](std::size_t) {
      auto workspace = make();
      for (std::size_t i; (i = next.fetch_add(1, std::memory_order_relaxed)) < n;) {
        item(workspace, i);
      }
    });
  }

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
