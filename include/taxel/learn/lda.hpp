// SPDX-License-Identifier: MIT
// Linear discriminant analysis with a shared (pooled) covariance, optional shrinkage towards a
// scaled identity (fixed, or Ledoit-Wolf's estimate), and a pseudo-inverse for singular data.
#pragma once

#include <Eigen/Core>
#include <Eigen/Eigenvalues>
#include <algorithm>
#include <cmath>
#include <limits>
#include <span>
#include <stdexcept>
#include <string>
#include <vector>

#include "taxel/core/deferred.hpp"
#include "taxel/core/status.hpp"
#include "taxel/learn/dataset.hpp"

namespace taxel::learn {

/// Options of Lda.
struct LdaConfig {
  /// Weight of the identity target: Sigma = (1 - s) S + s (tr S / d) I with s in [0, 1];
  /// a negative value picks s by Ledoit and Wolf (2004) from the data.
  double shrinkage = 0.0;
  bool empirical_priors = true;  ///< class priors from class frequencies (else uniform)
};

/// Gaussian classes with one shared covariance: decision_k(x) = x' S^+ mu_k - mu_k' S^+ mu_k / 2
/// + log prior_k. Directions where the pooled covariance vanishes (constant features) are left
/// out through the pseudo-inverse. Models Classifier.
class Lda {
 public:
  /// Throws std::invalid_argument for a shrinkage above 1 or NaN.
  explicit Lda(LdaConfig cfg = {}) : cfg_(cfg) {
    if (!(cfg.shrinkage <= 1.0)) {
      throw std::invalid_argument("LdaConfig: shrinkage = " + std::to_string(cfg.shrinkage) +
                                  " is outside the allowed range [0, 1] (or < 0 for automatic)");
    }
  }

  /// Trains on `d`; the outcome says ok, not_converged or why it could not (Classifier).
  template <class D = void>
  Outcome fit(const Deferred<DatasetView, D>& d) {
    using MatrixXd = Deferred<Eigen::MatrixXd, D>;
    using VectorXd = Deferred<Eigen::VectorXd, D>;
    Outcome o = validate_training_set(d, "Lda");
    if (!o) return o;
    std::vector<int> classes = class_order(d.y);
    const auto k = static_cast<Eigen::Index>(classes.size());
    const Eigen::Index n = d.rows();
    const Eigen::Index dims = d.dims();
    MatrixXd means = MatrixXd::Zero(k, dims);
    VectorXd count = VectorXd::Zero(k);
    std::vector<int> cls(static_cast<std::size_t>(n));
    for (Eigen::Index i = 0; i < n; ++i) {
      const int c = class_index(classes, d.y[static_cast<std::size_t>(i)]);
      cls[static_cast<std::size_t>(i)] = c;
      means.row(c) += d.x.row(i);
      count(c) += 1.0;
    }
    for (Eigen::Index c = 0; c < k; ++c) means.row(c) /= count(c);
    MatrixXd centred(n, dims);
    for (Eigen::Index i = 0; i < n; ++i)
      centred.row(i) = d.x.row(i) - means.row(cls[static_cast<std::size_t>(i)]);
    MatrixXd s = MatrixXd::Zero(dims, dims);
    s.template selfadjointView<Eigen::Lower>().rankUpdate(centred.transpose(),
                                                          1.0 / static_cast<double>(n));
    s = s.template selfadjointView<Eigen::Lower>();
    const double mu = s.trace() / static_cast<double>(dims);
    double shrink = cfg_.shrinkage;
    if (shrink < 0.0) {
      const double d2 = (s - mu * MatrixXd::Identity(dims, dims)).squaredNorm();
      double b2 = 0.0;
      for (Eigen::Index i = 0; i < n; ++i) b2 += std::pow(centred.row(i).squaredNorm(), 2);
      b2 = (b2 / static_cast<double>(n) - s.squaredNorm()) / static_cast<double>(n);
      shrink = d2 > 0.0 ? std::clamp(b2 / d2, 0.0, 1.0) : 1.0;
    }
    // Unbiased pooled covariance, then shrinkage.
    if (n > k) s *= static_cast<double>(n) / static_cast<double>(n - k);
    const double mu_u = s.trace() / static_cast<double>(dims);
    s = (1.0 - shrink) * s;
    s.diagonal().array() += shrink * mu_u;
    Eigen::SelfAdjointEigenSolver<MatrixXd> eig(s);
    const VectorXd& ev = eig.eigenvalues();
    const double top = ev.maxCoeff();
    if (!(top > 0.0)) {
      return {Status::degenerate, "Lda: every feature is constant within the classes"};
    }
    VectorXd inv(ev.size());
    for (Eigen::Index j = 0; j < ev.size(); ++j) inv(j) = ev(j) > 1e-10 * top ? 1.0 / ev(j) : 0.0;
    const MatrixXd proj = means * eig.eigenvectors();  // k x dims
    w_ = proj * inv.asDiagonal() * eig.eigenvectors().transpose();
    b_.resize(k);
    for (Eigen::Index c = 0; c < k; ++c) {
      const double prior =
          cfg_.empirical_priors ? count(c) / static_cast<double>(n) : 1.0 / static_cast<double>(k);
      b_(c) = -0.5 * w_.row(c).dot(means.row(c)) + std::log(prior);
    }
    classes_ = std::move(classes);
    means_ = std::move(means);
    shrinkage_ = shrink;
    return o;
  }

  /// One decision value per class of sample `x` into `out`, in classes() order (Classifier).
  template <class D = void>
  void decision(const Deferred<SampleRef, D>& x, Eigen::Ref<Eigen::VectorXd> out) const {
    detail::check_sample(x, dims(), "Lda");
    out = w_ * x + b_;
  }
  /// The label of sample `x` (Classifier).
  template <class D = void>
  [[nodiscard]] int predict(const Deferred<SampleRef, D>& x) const {
    detail::check_sample(x, dims(), "Lda");
    Eigen::Index best = 0;
    double best_v = -std::numeric_limits<double>::infinity();
    for (Eigen::Index c = 0; c < w_.rows(); ++c) {
      const double v = w_.row(c).dot(x) + b_(c);
      if (v > best_v) {
        best_v = v;
        best = c;
      }
    }
    return classes_[static_cast<std::size_t>(best)];
  }
  /// Labels in the model's order (Classifier); empty before fit.
  [[nodiscard]] std::span<const int> classes() const noexcept { return classes_; }
  /// Number of features a sample has; 0 before fit (Classifier).
  [[nodiscard]] Eigen::Index dims() const noexcept { return w_.cols(); }
  /// Class means, one row per class.
  [[nodiscard]] const Eigen::MatrixXd& means() const noexcept { return means_; }
  /// The shrinkage used by the last fit (the Ledoit-Wolf estimate when automatic).
  [[nodiscard]] double shrinkage() const noexcept { return shrinkage_; }

  /// Visits the options and what fit learned (encode_model / decode_model in model_file.hpp).
  template <class Ar>
  void state(Ar& ar) {
    ar.value(cfg_.shrinkage, "shrinkage");
    ar.value(cfg_.empirical_priors, "empirical_priors");
    ar.vector(classes_, "classes");
    ar.matrix(w_, "weights");
    ar.matrix(b_, "offsets");
    ar.matrix(means_, "means");
    ar.value(shrinkage_, "fitted shrinkage");
    ar.verify([&]() -> std::string {
      (void)Lda(cfg_);
      std::string e = detail::classes_error(classes_);
      if (!e.empty()) return e;
      const auto k = static_cast<Eigen::Index>(classes_.size());
      if (w_.rows() != k || b_.size() != k ||
          (k > 0 && (means_.rows() != k || means_.cols() != w_.cols())))
        return "classes, weights, offsets and means disagree";
      return {};
    });
  }

 private:
  LdaConfig cfg_;
  std::vector<int> classes_;
  Eigen::MatrixXd w_;
  Eigen::VectorXd b_;
  Eigen::MatrixXd means_;
  double shrinkage_ = 0.0;
};

}  // namespace taxel::learn
