// SPDX-License-Identifier: MIT
// Covariance kernels of the implicit-surface Gaussian process: stationary and isotropic, a
// function k(r) of the distance r between two points. Matern kernels with smoothness 3/2 and
// 5/2 (Rasmussen and Williams, "Gaussian Processes for Machine Learning", 2006, eq. 4.17):
//   Matern32: k(r) = s^2 (1 + a) exp(-a),           a = sqrt(3) r / l
//   Matern52: k(r) = s^2 (1 + a + a^2 / 3) exp(-a),  a = sqrt(5) r / l
// with s the prior standard deviation of the field and l the length scale. They are the kernels
// of scikit-learn's `ConstantKernel(s^2) * Matern(l, nu)`, which the tests use as the oracle.
#pragma once

#include <Eigen/Core>
#include <cmath>
#include <concepts>
#include <stdexcept>
#include <string>

#include "taxel/shape/lanes.hpp"

namespace taxel::shape {

/// A stationary isotropic covariance k(r): `operator()(r)` its value, `slope(r)` the derivative
/// k'(r) / r (finite at r = 0, so that the gradient k'(r) (x - y) / r needs no division), both
/// also for arrays of distances (`values`, `slopes`), and `variance()` = k(0).
/// `evaluate(r, k, s)` writes both for an array of distances with one exponential each.
template <class K>
concept Kernel = requires(const K& k, double r, const Eigen::ArrayXd& rs, Eigen::ArrayXd& out) {
  { k(r) } -> std::convertible_to<double>;
  { k.slope(r) } -> std::convertible_to<double>;
  { k.values(rs) } -> std::convertible_to<Eigen::ArrayXd>;
  { k.slopes(rs) } -> std::convertible_to<Eigen::ArrayXd>;
  k.evaluate(rs, out, out);
  { k.variance() } -> std::convertible_to<double>;
};

namespace detail {
inline void check_kernel(const char* name, double length_scale, double sigma) {
  if (!(length_scale > 0.0) || !std::isfinite(length_scale)) {
    throw std::invalid_argument(std::string(name) +
                                ": length_scale must be finite and > 0 [m], got " +
                                std::to_string(length_scale));
  }
  if (!(sigma > 0.0) || !std::isfinite(sigma)) {
    throw std::invalid_argument(std::string(name) + ": sigma must be finite and > 0 [m], got " +
                                std::to_string(sigma));
  }
}
}  // namespace detail

/// Settings of the Matern kernels. The field is a distance, so both are lengths.
struct MaternConfig {
  double length_scale = 0.02;  ///< l [m]: how far a touch informs the surface
  double sigma = 0.01;         ///< s [m]: the field's prior standard deviation
};

/// Matern kernel of smoothness 3/2: a once mean-square differentiable field, so the surface's
/// normal is defined everywhere. The default of the implicit surface.
struct Matern32 {
  /// Settings.
  using Config = MaternConfig;

  /// Throws std::invalid_argument unless both settings are finite and > 0.
  explicit Matern32(const Config& c = {})
      : config_(c), a_(std::sqrt(3.0) / c.length_scale), s2_(c.sigma * c.sigma) {
    detail::check_kernel("Matern32", c.length_scale, c.sigma);
  }
  /// k(r).
  [[nodiscard]] double operator()(double r) const {
    const double a = a_ * r;
    return s2_ * (1.0 + a) * std::exp(-a);
  }
  /// k'(r) / r.
  [[nodiscard]] double slope(double r) const { return -s2_ * a_ * a_ * std::exp(-a_ * r); }
  /// k(r) for each distance.
  [[nodiscard]] Eigen::ArrayXd values(const Eigen::ArrayXd& r) const {
    const Eigen::ArrayXd a = a_ * r;
    return s2_ * (1.0 + a) * (-a).exp();
  }
  /// k'(r) / r for each distance.
  [[nodiscard]] Eigen::ArrayXd slopes(const Eigen::ArrayXd& r) const {
    return -s2_ * a_ * a_ * (-a_ * r).exp();
  }
  /// k(r) into `k` and k'(r) / r into `slope`, for each distance (one exponential each).
  template <class R, class V, class S>
  void evaluate(const R& r, V& k, S& slope) const {
    slope = (-a_ * r).exp();
    k = s2_ * (1.0 + a_ * r) * slope;
    slope *= -s2_ * a_ * a_;
  }
#if TAXEL_SHAPE_LANES
  /// evaluate() on SIMD lanes of distances (shape/lanes.hpp).
  template <class V>
  [[gnu::always_inline]] void evaluate_lanes(const V& r, V& k, V& slope) const {
    const V ar = a_ * r;
    detail::lanes::exp_nonpositive(V{} - ar, slope);
    k = s2_ * (1.0 + ar) * slope;
    slope *= -s2_ * a_ * a_;
  }
#endif
  /// k(0) = s^2.
  [[nodiscard]] double variance() const noexcept { return s2_; }
  /// The settings.
  [[nodiscard]] const Config& config() const noexcept { return config_; }

 private:
  Config config_;
  double a_, s2_;
};

/// Matern kernel of smoothness 5/2: a twice differentiable field, smoother surfaces between
/// touches, sharper loss of detail at creases.
struct Matern52 {
  /// Settings.
  using Config = MaternConfig;

  /// Throws std::invalid_argument unless both settings are finite and > 0.
  explicit Matern52(const Config& c = {})
      : config_(c), a_(std::sqrt(5.0) / c.length_scale), s2_(c.sigma * c.sigma) {
    detail::check_kernel("Matern52", c.length_scale, c.sigma);
  }
  /// k(r).
  [[nodiscard]] double operator()(double r) const {
    const double a = a_ * r;
    return s2_ * (1.0 + a + a * a / 3.0) * std::exp(-a);
  }
  /// k'(r) / r.
  [[nodiscard]] double slope(double r) const {
    const double a = a_ * r;
    return -s2_ * a_ * a_ / 3.0 * (1.0 + a) * std::exp(-a);
  }
  /// k(r) for each distance.
  [[nodiscard]] Eigen::ArrayXd values(const Eigen::ArrayXd& r) const {
    const Eigen::ArrayXd a = a_ * r;
    return s2_ * (1.0 + a + a.square() / 3.0) * (-a).exp();
  }
  /// k'(r) / r for each distance.
  [[nodiscard]] Eigen::ArrayXd slopes(const Eigen::ArrayXd& r) const {
    const Eigen::ArrayXd a = a_ * r;
    return -s2_ * a_ * a_ / 3.0 * (1.0 + a) * (-a).exp();
  }
  /// k(r) into `k` and k'(r) / r into `slope`, for each distance (one exponential each).
  template <class R, class V, class S>
  void evaluate(const R& r, V& k, S& slope) const {
    slope = (-a_ * r).exp();
    k = s2_ * (1.0 + a_ * r + (a_ * a_ / 3.0) * r.square()) * slope;
    slope *= -s2_ * a_ * a_ / 3.0 * (1.0 + a_ * r);
  }
#if TAXEL_SHAPE_LANES
  /// evaluate() on SIMD lanes of distances (shape/lanes.hpp).
  template <class V>
  [[gnu::always_inline]] void evaluate_lanes(const V& r, V& k, V& slope) const {
    const V ar = a_ * r;
    detail::lanes::exp_nonpositive(V{} - ar, slope);
    k = s2_ * (1.0 + ar + ar * ar / 3.0) * slope;
    slope *= -s2_ * a_ * a_ / 3.0 * (1.0 + ar);
  }
#endif
  /// k(0) = s^2.
  [[nodiscard]] double variance() const noexcept { return s2_; }
  /// The settings.
  [[nodiscard]] const Config& config() const noexcept { return config_; }

 private:
  Config config_;
  double a_, s2_;
};

}  // namespace taxel::shape
