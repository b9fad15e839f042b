// SPDX-License-Identifier: MIT
// Exact k-nearest-neighbour classification by brute force (the feature vectors of tactile
// images have 11 to ~1000 dimensions, where trees do not beat a linear scan).
#pragma once

#include <Eigen/Core>
#include <algorithm>
#include <cmath>
#include <span>
#include <stdexcept>
#include <string>
#include <utility>
#include <vector>

#include "taxel/core/deferred.hpp"
#include "taxel/core/status.hpp"
#include "taxel/learn/dataset.hpp"

namespace taxel::learn {

/// Distance of Knn.
enum class KnnMetric { euclidean, manhattan };
/// Vote of each neighbour.
enum class KnnWeighting {
  uniform,   ///< one vote each
  distance,  ///< 1 / distance (an exact duplicate of the sample outvotes the rest)
};

/// Options of Knn.
struct KnnConfig {
  int k = 5;                                       ///< neighbours, >= 1
  KnnMetric metric = KnnMetric::euclidean;         ///< Distance between samples.
  KnnWeighting weighting = KnnWeighting::uniform;  ///< How neighbours vote.
};

/// k nearest neighbours; ties in distance go to the earlier training sample, ties in votes to
/// the class of the nearest neighbour among the tied. Decision values are vote shares.
/// Models Classifier.
class Knn {
 public:
  /// Throws std::invalid_argument for k < 1.
  explicit Knn(KnnConfig cfg = {}) : cfg_(cfg) {
    if (cfg.k < 1) {
      throw std::invalid_argument("KnnConfig: k = " + std::to_string(cfg.k) +
                                  " is outside the allowed range [1, inf)");
    }
  }

  /// Stores the training set. `invalid_input` when it has fewer than k samples.
  template <class D = void>
  Outcome fit(const Deferred<DatasetView, D>& d) {
    Outcome o = validate_training_set(d, "Knn", 1);
    if (!o) return o;
    if (d.rows() < cfg_.k) {
      return {Status::invalid_input, "Knn: k = " + std::to_string(cfg_.k) + " but only " +
                                         std::to_string(d.rows()) + " training samples"};
    }
    classes_ = class_order(d.y);
    x_ = d.x;
    sq_ = x_.rowwise().squaredNorm();
    cls_.resize(d.y.size());
    for (std::size_t i = 0; i < d.y.size(); ++i) cls_[i] = class_index(classes_, d.y[i]);
    return o;
  }

  /// One decision value per class of sample `x` into `out`, in classes() order (Classifier).
  template <class D = void>
  void decision(const Deferred<SampleRef, D>& x, Eigen::Ref<Eigen::VectorXd> out) const {
    detail::check_sample(x, dims(), "Knn");
    vote(x, out);
    out /= out.sum();
  }
  /// The label of sample `x` (Classifier).
  template <class D = void>
  [[nodiscard]] int predict(const Deferred<SampleRef, D>& x) const {
    using VectorXd = Deferred<Eigen::VectorXd, D>;
    detail::check_sample(x, dims(), "Knn");
    VectorXd votes(static_cast<Eigen::Index>(classes_.size()));
    const int nearest = vote(x, votes);
    const double top = votes.maxCoeff();
    if (votes(nearest) == top) return classes_[static_cast<std::size_t>(nearest)];
    Eigen::Index best = 0;
    votes.maxCoeff(&best);
    return classes_[static_cast<std::size_t>(best)];
  }
  /// Labels in the model's order (Classifier); empty before fit.
  [[nodiscard]] std::span<const int> classes() const noexcept { return classes_; }
  /// Number of features a sample has; 0 before fit (Classifier).
  [[nodiscard]] Eigen::Index dims() const noexcept { return x_.cols(); }

  /// Visits the options and the training set (encode_model / decode_model in model_file.hpp).
  template <class Ar>
  void state(Ar& ar) {
    ar.value(cfg_.k, "k");
    ar.enumeration(cfg_.metric, 2, "metric");
    ar.enumeration(cfg_.weighting, 2, "weighting");
    ar.vector(classes_, "classes");
    ar.matrix(x_, "training samples");
    ar.vector(cls_, "training classes");
    ar.verify([&]() -> std::string {
      (void)Knn(cfg_);
      std::string e = detail::classes_error(classes_);
      if (!e.empty()) return e;
      if (static_cast<std::size_t>(x_.rows()) != cls_.size())
        return "training samples and classes disagree";
      if (x_.rows() > 0 && (x_.rows() < cfg_.k || classes_.empty()))
        return "fewer training samples than k";
      for (int c : cls_) {
        if (c < 0 || static_cast<std::size_t>(c) >= classes_.size())
          return "a training class out of range";
      }
      return {};
    });
    sq_ = x_.rowwise().squaredNorm();
  }

 private:
  // Fills votes per class; returns the class of the nearest neighbour.
  template <class D = void>
  int vote(const Deferred<SampleRef, D>& x, Eigen::Ref<Eigen::VectorXd> votes) const {
    using VectorXd = Deferred<Eigen::VectorXd, D>;
    const Eigen::Index n = x_.rows();
    std::vector<std::pair<double, Eigen::Index>> dist(static_cast<std::size_t>(n));
    if (cfg_.metric == KnnMetric::euclidean) {
      const VectorXd dots = x_ * x;
      const double xx = x.squaredNorm();
      for (Eigen::Index i = 0; i < n; ++i) {
        dist[static_cast<std::size_t>(i)] = {std::max(0.0, sq_(i) + xx - 2.0 * dots(i)), i};
      }
    } else {
      for (Eigen::Index i = 0; i < n; ++i) {
        dist[static_cast<std::size_t>(i)] = {(x_.row(i).transpose() - x).cwiseAbs().sum(), i};
      }
    }
    const auto k = static_cast<std::size_t>(cfg_.k);
    std::partial_sort(dist.begin(), dist.begin() + static_cast<std::ptrdiff_t>(k), dist.end());
    votes.setZero();
    for (std::size_t j = 0; j < k; ++j) {
      double w = 1.0;
      if (cfg_.weighting == KnnWeighting::distance) {
        const double dd =
            cfg_.metric == KnnMetric::euclidean ? std::sqrt(dist[j].first) : dist[j].first;
        w = 1.0 / std::max(dd, 1e-300);
      }
      votes(cls_[static_cast<std::size_t>(dist[j].second)]) += w;
    }
    return cls_[static_cast<std::size_t>(dist[0].second)];
  }

  KnnConfig cfg_;
  std::vector<int> classes_;
  FeatureMatrix x_;
  Eigen::VectorXd sq_;
  std::vector<int> cls_;
};

}  // namespace taxel::learn
