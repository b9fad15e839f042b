// SPDX-License-Identifier: MIT
// An exact Gaussian process over points in 3-D with scalar observations y_i = f(x_i) + e_i,
// e_i ~ N(0, noise_i), zero prior mean (Rasmussen and Williams 2006, algorithm 2.1):
//   mean(x) = k(x)' alpha,  alpha = K^-1 y,  variance(x) = k(0) - v' v,  v = L^-1 k(x),
// with K = [k(|x_i - x_j|)] + diag(noise) = L L'. The Cholesky factor grows by one row per
// observation (a triangular solve, O(n^2)) and loses one by a rank-one update of its trailing
// block (O(n^2)), so that a stream of observations never refits.
#pragma once

#include <Eigen/Core>
#include <algorithm>
#include <cmath>
#include <cstddef>
#include <stdexcept>
#include <string>

#include "taxel/core/types.hpp"
#include "taxel/shape/kernels.hpp"

namespace taxel::shape {

/// The field at a point: its posterior mean, variance and the mean's gradient.
struct FieldPrediction {
  double mean = 0.0;               ///< posterior mean of the field
  double variance = 0.0;           ///< posterior variance of the field (latent, no noise)
  Vec3d gradient = Vec3d::Zero();  ///< gradient of the posterior mean
};

/// Exact Gaussian process regression with incremental Cholesky updates (see the file comment).
/// Copyable; not thread-safe for writes, concurrent const queries are safe.
template <Kernel K = Matern32>
class GaussianProcess {
 public:
  /// A process with no observations, whose prior covariance is `kernel`.
  explicit GaussianProcess(K kernel = K{}) : kernel_(std::move(kernel)) {}

  /// Number of observations.
  [[nodiscard]] std::size_t size() const noexcept { return n_; }
  /// The covariance kernel.
  [[nodiscard]] const K& kernel() const noexcept { return kernel_; }
  /// Observation positions (3 x size()).
  [[nodiscard]] auto positions() const {
    return x_.topRows(static_cast<Eigen::Index>(n_)).transpose();
  }
  /// Observed values.
  [[nodiscard]] auto values() const { return y_.head(static_cast<Eigen::Index>(n_)); }
  /// Noise variances of the observations.
  [[nodiscard]] auto noise() const { return noise_.head(static_cast<Eigen::Index>(n_)); }
  /// K^-1 y, the weights of the posterior mean.
  [[nodiscard]] auto weights() const { return alpha_.head(static_cast<Eigen::Index>(n_)); }

  /// Reserves room for `n` observations.
  void reserve(std::size_t n) {
    if (n > cap_) grow(n);
  }

  /// Adds observation `y` at `x` with noise variance `noise_variance` (>= 0). O(n^2). Returns
  /// false, and leaves the process unchanged, when the observation is not finite or would make
  /// the covariance singular (a noiseless repeat of what is already known).
  bool add(const Vec3d& x, double y, double noise_variance) {
    if (!x.allFinite() || !std::isfinite(y) || !(noise_variance >= 0.0) ||
        !std::isfinite(noise_variance))
      return false;
    const auto n = static_cast<Eigen::Index>(n_);
    if (n_ == cap_) grow(std::max<std::size_t>(16, 2 * cap_));
    Eigen::VectorXd l = covariances(x);
    if (n > 0) L_.topLeftCorner(n, n).triangularView<Eigen::Lower>().solveInPlace(l);
    const double d2 = kernel_.variance() + noise_variance - l.squaredNorm();
    if (!(d2 > 1e-12 * kernel_.variance())) return false;
    const double d = std::sqrt(d2);
    L_.row(n).head(n) = l.transpose();
    L_(n, n) = d;
    x_.row(n) = x.transpose();
    y_(n) = y;
    noise_(n) = noise_variance;
    z_(n) = (y - l.dot(z_.head(n))) / d;
    ++n_;
    solve_weights();
    return true;
  }

  /// Removes observation `i` (the later ones move down by one). O(n^2).
  void remove(std::size_t i) {
    if (i >= n_) throw std::out_of_range("GaussianProcess::remove: index out of range");
    const auto n = static_cast<Eigen::Index>(n_);
    const auto k = static_cast<Eigen::Index>(i);
    // The trailing block absorbs the removed column: L33 L33' + l32 l32'.
    Eigen::VectorXd v = L_.col(k).segment(k + 1, n - k - 1);
    for (Eigen::Index j = k + 1; j < n; ++j) {
      const double ljj = L_(j, j);
      const double r = std::hypot(ljj, v(j - k - 1));
      const double c = r / ljj, s = v(j - k - 1) / ljj;
      L_(j, j) = r;
      for (Eigen::Index a = j + 1; a < n; ++a) {
        L_(a, j) = (L_(a, j) + s * v(a - k - 1)) / c;
        v(a - k - 1) = c * v(a - k - 1) - s * L_(a, j);
      }
    }
    // Drop row and column k: entry (a, b) of the new factor is (old(a), old(b)), old(a) = a for
    // a < k and a + 1 beyond; every read is of an entry not yet overwritten.
    const auto old = [k](Eigen::Index a) { return a < k ? a : a + 1; };
    for (Eigen::Index b = 0; b + 1 < n; ++b) {
      for (Eigen::Index a = std::max(b, k); a + 1 < n; ++a) L_(a, b) = L_(old(a), old(b));
    }
    for (Eigen::Index a = k; a + 1 < n; ++a) {
      x_.row(a) = x_.row(a + 1);
      y_(a) = y_(a + 1);
      noise_(a) = noise_(a + 1);
    }
    --n_;
    solve_targets();
  }

  /// Replaces every observed value (positions and noise unchanged): O(n^2).
  void set_values(const Eigen::Ref<const Eigen::VectorXd>& y) {
    if (static_cast<std::size_t>(y.size()) != n_) {
      throw std::invalid_argument("GaussianProcess::set_values: expected " + std::to_string(n_) +
                                  " values, got " + std::to_string(y.size()));
    }
    if (!y.allFinite()) throw std::invalid_argument("GaussianProcess::set_values: not finite");
    y_.head(static_cast<Eigen::Index>(n_)) = y;
    solve_targets();
  }

  /// Posterior mean at `x`. O(n).
  [[nodiscard]] double mean(const Vec3d& x) const {
    Vec3d unused = Vec3d::Zero();
    return mean<false>(x, unused);
  }

  /// Posterior mean at `x` and its gradient. O(n).
  [[nodiscard]] double mean(const Vec3d& x, Vec3d& gradient) const {
    return mean<true>(x, gradient);
  }

  /// sum_i w_i k(|x - x_i|) for weights w (size() of them): the posterior mean when w = K^-1 y.
  /// O(n), no allocation.
  [[nodiscard]] double weighted_sum(const Vec3d& x,
                                    const Eigen::Ref<const Eigen::VectorXd>& w) const {
    Vec3d unused = Vec3d::Zero();
    return weighted_sum<false>(x, w.data(), unused);
  }

  /// Posterior mean, variance and gradient at `x`. O(n^2) (a triangular solve).
  [[nodiscard]] FieldPrediction predict(const Vec3d& x) const {
    FieldPrediction out;
    out.mean = mean(x, out.gradient);
    out.variance = kernel_.variance();
    if (n_ == 0) return out;
    out.variance = std::max(0.0, kernel_.variance() - whiten(x).squaredNorm());
    return out;
  }

  /// v = L^-1 k(X, x): the posterior covariance of the field at a and b is
  /// k(|a - b|) - v(a)' v(b).
  [[nodiscard]] Eigen::VectorXd whiten(const Vec3d& x) const {
    Eigen::VectorXd v = covariances(x);
    const auto n = static_cast<Eigen::Index>(n_);
    if (n > 0) L_.topLeftCorner(n, n).triangularView<Eigen::Lower>().solveInPlace(v);
    return v;
  }

  /// Posterior means (and, when `variance` is given, variances) at the columns of `points`,
  /// through one kernel matrix and one multi-column triangular solve.
  void predict(const Eigen::Ref<const Eigen::Matrix3Xd>& points, Eigen::Ref<Eigen::VectorXd> mean,
               Eigen::VectorXd* variance = nullptr) const {
    const Eigen::Index m = points.cols();
    if (n_ == 0) {
      mean.setZero();
      if (variance != nullptr) variance->setConstant(m, kernel_.variance());
      return;
    }
    Eigen::MatrixXd k = cross_covariances(points);
    mean.noalias() = k.transpose() * weights();
    if (variance == nullptr) return;
    const auto n = static_cast<Eigen::Index>(n_);
    L_.topLeftCorner(n, n).triangularView<Eigen::Lower>().solveInPlace(k);
    *variance =
        (kernel_.variance() - k.colwise().squaredNorm().array()).max(0.0).matrix().transpose();
  }

  /// The prior covariances k(|x_i - p_j|) of every observation i with every column j of
  /// `points` (size() x points.cols()).
  [[nodiscard]] Eigen::MatrixXd cross_covariances(
      const Eigen::Ref<const Eigen::Matrix3Xd>& points) const {
    const auto X = positions();
    Eigen::MatrixXd d2 = (-2.0 * X.transpose()) * points;
    d2.colwise() += X.colwise().squaredNorm().transpose();
    d2.rowwise() += points.colwise().squaredNorm();
    const Eigen::ArrayXd k = kernel_.values(d2.array().max(0.0).sqrt().reshaped());
    return Eigen::Map<const Eigen::MatrixXd>(k.data(), X.cols(), points.cols());
  }

  /// Replaces each column b of `m` (size() rows) by L^-T b (applied to whiten(x): K^-1 k(X, x)).
  template <class M>
  void solve_upper(M& m) const {
    const auto n = static_cast<Eigen::Index>(n_);
    if (n > 0)
      L_.topLeftCorner(n, n).transpose().template triangularView<Eigen::Upper>().solveInPlace(m);
  }

  /// The prior covariances k(|x_i - x|) of `x` with every observation.
  [[nodiscard]] Eigen::VectorXd covariances(const Vec3d& x) const {
    if (n_ == 0) return Eigen::VectorXd();
    return kernel_.values(distances(x)).matrix();
  }

 private:
  // The mean (and gradient) in blocks of at most 256 observations on the stack: no allocation,
  // one exponential per observation.
  template <bool Gradient>
  double mean(const Vec3d& x, Vec3d& gradient) const {
    return weighted_sum<Gradient>(x, alpha_.data(), gradient);
  }
  template <bool Gradient>
  double weighted_sum(const Vec3d& x, const double* weights, Vec3d& gradient) const {
#if TAXEL_SHAPE_LANES
    if constexpr (detail::lanes::LaneKernel<K>) {
      const double* p[3] = {x_.col(0).data(), x_.col(1).data(), x_.col(2).data()};
      return detail::lanes::kernel_sum<Gradient>(kernel_, n_, p, x.data(), weights,
                                                 gradient.data());
    }
#endif
    using Block = Eigen::Array<double, Eigen::Dynamic, 1, 0, 256, 1>;
    const auto n = static_cast<Eigen::Index>(n_);
    double out = 0.0;
    gradient.setZero();
    Block dx, dy, dz, r, k, s;
    for (Eigen::Index first = 0; first < n; first += 256) {
      const Eigen::Index c = std::min<Eigen::Index>(256, n - first);
      dx = x[0] - x_.col(0).segment(first, c).array();
      dy = x[1] - x_.col(1).segment(first, c).array();
      dz = x[2] - x_.col(2).segment(first, c).array();
      r = (dx.square() + dy.square() + dz.square()).sqrt();
      kernel_.evaluate(r, k, s);
      const auto a = Eigen::Map<const Eigen::ArrayXd>(weights + first, c);
      out += (k * a).sum();
      if constexpr (Gradient) {
        // d k(|x - x_i|) / dx = k'(r) / r (x - x_i)
        s *= a;
        gradient += Vec3d((s * dx).sum(), (s * dy).sum(), (s * dz).sum());
      }
    }
    return out;
  }
  Eigen::ArrayXd distances(const Vec3d& x) const {
    return (positions().colwise() - x).colwise().norm().transpose().array();
  }
  void grow(std::size_t cap) {
    const auto c = static_cast<Eigen::Index>(cap);
    L_.conservativeResize(c, c);
    x_.conservativeResize(c, 3);
    y_.conservativeResize(c);
    noise_.conservativeResize(c);
    z_.conservativeResize(c);
    alpha_.conservativeResize(c);
    cap_ = cap;
  }
  // z = L^-1 y, then the weights.
  void solve_targets() {
    const auto n = static_cast<Eigen::Index>(n_);
    z_.head(n) = y_.head(n);
    if (n > 0) L_.topLeftCorner(n, n).triangularView<Eigen::Lower>().solveInPlace(z_.head(n));
    solve_weights();
  }
  // alpha = L^-T z.
  void solve_weights() {
    const auto n = static_cast<Eigen::Index>(n_);
    alpha_.head(n) = z_.head(n);
    if (n > 0) {
      L_.topLeftCorner(n, n).transpose().triangularView<Eigen::Upper>().solveInPlace(
          alpha_.head(n));
    }
  }

  K kernel_;
  std::size_t n_ = 0, cap_ = 0;
  Eigen::MatrixXd L_;   // lower Cholesky factor of K in its top-left n x n corner
  Eigen::MatrixX3d x_;  // positions, one per row (each coordinate contiguous)
  Eigen::VectorXd y_, noise_, z_, alpha_;
};

}  // namespace taxel::shape
