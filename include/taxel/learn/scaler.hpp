// SPDX-License-Identifier: MIT
// Feature scaling fitted on training data only: standardisation (z-score) and LIBSVM-style
// range scaling (svm-scale, default [-1, 1]); and `Scaled<Scaler, Classifier>`, a classifier
// that scales before it fits and predicts.
#pragma once

#include <Eigen/Core>
#include <cmath>
#include <concepts>
#include <span>
#include <stdexcept>
#include <string>

#include "taxel/core/deferred.hpp"
#include "taxel/core/status.hpp"
#include "taxel/learn/concepts.hpp"
#include "taxel/learn/dataset.hpp"

namespace taxel::learn {

/// An affine per-feature map `x' = (x - offset) * factor`, fitted on training features.
class AffineScaler {
 public:
  /// Applies the map to one sample. Throws std::invalid_argument on a length mismatch.
  template <class D = void>
  void transform(const Deferred<SampleRef, D>& x, Eigen::Ref<Eigen::VectorXd> out) const {
    check(x.size());
    out = (x - offset_).cwiseProduct(factor_);
  }
  /// Applies the map to every row, in place.
  template <class = void>
  void transform_in_place(Eigen::Ref<FeatureMatrix> x) const {
    check(x.cols());
    x = (x.rowwise() - offset_.transpose()).array().rowwise() * factor_.transpose().array();
  }
  /// Subtracted per feature.
  [[nodiscard]] const Eigen::VectorXd& offset() const noexcept { return offset_; }
  /// Multiplied per feature after the subtraction (0 for a feature constant in training).
  [[nodiscard]] const Eigen::VectorXd& factor() const noexcept { return factor_; }
  /// Features expected (0 before fit).
  [[nodiscard]] Eigen::Index dims() const noexcept { return offset_.size(); }

 protected:
  /// Throws unless the scaler is fitted and a sample has dims() features.
  template <class = void>
  void check(Eigen::Index n) const {
    if (dims() == 0) throw std::logic_error("scaler: transform before fit");
    if (n != dims()) {
      throw std::invalid_argument("scaler: the sample has " + std::to_string(n) +
                                  " features, the scaler was fitted on " + std::to_string(dims()));
    }
  }
  /// Why `x` cannot be fitted (empty, non-finite), or ok.
  template <class D = void>
  static Outcome check_fit(const Deferred<Eigen::Ref<const FeatureMatrix>, D>& x, const char* who) {
    if (x.rows() == 0 || x.cols() == 0)
      return {Status::invalid_input, std::string(who) + ": no data"};
    if (!x.allFinite()) return {Status::invalid_input, std::string(who) + ": non-finite feature"};
    return {};
  }
  Eigen::VectorXd offset_;  ///< Subtracted from each feature.
  Eigen::VectorXd factor_;  ///< Then multiplied with each feature.
};

/// Standardisation: each feature to zero mean and unit (population) standard deviation over
/// the training rows. A feature constant in training maps to 0.
class StandardScaler : public AffineScaler {
 public:
  /// Fits on the rows of `x`; `invalid_input` for empty or non-finite data.
  template <class D = void>
  Outcome fit(const Deferred<Eigen::Ref<const FeatureMatrix>, D>& x) {
    using VectorXd = Deferred<Eigen::VectorXd, D>;
    Outcome o = check_fit(x, "StandardScaler");
    if (!o) return o;
    offset_ = x.colwise().mean().transpose();
    const VectorXd var = (x.rowwise() - offset_.transpose()).colwise().squaredNorm().transpose() /
                         static_cast<double>(x.rows());
    factor_.resize(var.size());
    for (Eigen::Index j = 0; j < var.size(); ++j) {
      const double sd = std::sqrt(var(j));
      factor_(j) = sd > 1e-12 * (1.0 + std::fabs(offset_(j))) ? 1.0 / sd : 0.0;
    }
    return o;
  }
};

/// svm-scale: each feature linearly from its training [min, max] to [lower, upper]. A
/// feature constant in training maps to 0 (svm-scale leaves it out of its sparse output).
class RangeScaler : public AffineScaler {
 public:
  /// Throws std::invalid_argument unless lower < upper, both finite.
  explicit RangeScaler(double lower = -1.0, double upper = 1.0) : lower_(lower), upper_(upper) {
    if (!(lower < upper) || !std::isfinite(lower) || !std::isfinite(upper)) {
      throw std::invalid_argument("RangeScaler: lower = " + std::to_string(lower) +
                                  " must be below upper = " + std::to_string(upper));
    }
  }
  /// Fits on the rows of `x`; `invalid_input` for empty or non-finite data.
  template <class D = void>
  Outcome fit(const Deferred<Eigen::Ref<const FeatureMatrix>, D>& x) {
    using VectorXd = Deferred<Eigen::VectorXd, D>;
    Outcome o = check_fit(x, "RangeScaler");
    if (!o) return o;
    const VectorXd lo = x.colwise().minCoeff().transpose();
    const VectorXd hi = x.colwise().maxCoeff().transpose();
    offset_.resize(lo.size());
    factor_.resize(lo.size());
    for (Eigen::Index j = 0; j < lo.size(); ++j) {
      if (hi(j) > lo(j)) {
        factor_(j) = (upper_ - lower_) / (hi(j) - lo(j));
        offset_(j) = lo(j) - lower_ / factor_(j);
      } else {
        factor_(j) = 0.0;
        offset_(j) = lo(j);
      }
    }
    return o;
  }
  /// Smallest scaled value.
  [[nodiscard]] double lower() const noexcept { return lower_; }
  /// Largest scaled value.
  [[nodiscard]] double upper() const noexcept { return upper_; }

 private:
  double lower_;
  double upper_;
};

/// A scaler the Scaled pipeline can fit and apply.
template <class S>
concept FeatureScaler = std::copy_constructible<S> &&
    requires(S& s, const S& cs, const Eigen::Ref<const FeatureMatrix>& x, const SampleRef& v,
             Eigen::Ref<Eigen::VectorXd> out, Eigen::Ref<FeatureMatrix> m) {
  { s.fit(x) } -> std::convertible_to<Outcome>;
  cs.transform(v, out);
  cs.transform_in_place(m);
};

/// A classifier that fits its scaler on the training features, then the classifier on the
/// scaled features, and scales every sample it predicts. Models Classifier.
template <FeatureScaler S, Classifier C>
class Scaled {
 public:
  /// The pipeline of `scaler` then `classifier`.
  explicit Scaled(C classifier = C(), S scaler = S())
      : scaler_(std::move(scaler)), classifier_(std::move(classifier)) {}

  /// Trains on `d`; the outcome says ok, not_converged or why it could not (Classifier).
  Outcome fit(const DatasetView& d) {
    Outcome o = validate_training_set(d, "Scaled");
    if (!o) return o;
    S scaler = scaler_;
    o = scaler.fit(d.x);
    if (!o) return o;
    FeatureMatrix x = d.x;
    scaler.transform_in_place(x);
    C classifier = classifier_;
    o = classifier.fit(DatasetView{x, d.y, d.groups});
    if (o.status == Status::ok || o.status == Status::not_converged) {
      scaler_ = std::move(scaler);
      classifier_ = std::move(classifier);
    }
    return o;
  }
  /// The label of sample `x` (Classifier).
  [[nodiscard]] int predict(const SampleRef& x) const {
    Eigen::VectorXd s(x.size());
    scaler_.transform(x, s);
    return classifier_.predict(s);
  }
  /// One decision value per class of sample `x` into `out`, in classes() order (Classifier).
  void decision(const SampleRef& x, Eigen::Ref<Eigen::VectorXd> out) const {
    Eigen::VectorXd s(x.size());
    scaler_.transform(x, s);
    classifier_.decision(s, out);
  }
  /// Labels in the model's order (Classifier); empty before fit.
  [[nodiscard]] std::span<const int> classes() const noexcept { return classifier_.classes(); }
  /// Number of features a sample has; 0 before fit (Classifier).
  [[nodiscard]] Eigen::Index dims() const noexcept { return classifier_.dims(); }
  /// The scaler, as fitted.
  [[nodiscard]] const S& scaler() const noexcept { return scaler_; }
  /// The classifier, as trained.
  [[nodiscard]] const C& classifier() const noexcept { return classifier_; }
  /// The wrapped classifier's training threads, when it has them (ThreadedTraining).
  [[nodiscard]] unsigned threads() const noexcept requires ThreadedTraining<C> {
    return classifier_.threads();
  }
  /// Sets the wrapped classifier's training threads (ThreadedTraining).
  void set_threads(unsigned threads) noexcept requires ThreadedTraining<C> {
    classifier_.set_threads(threads);
  }

 private:
  S scaler_;
  C classifier_;
};

}  // namespace taxel::learn
