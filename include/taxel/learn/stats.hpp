// SPDX-License-Identifier: MIT
// Statistics for comparing classifiers: Student's t distribution (CDF and quantile, through the
// regularised incomplete beta function), Dietterich's 5x2cv paired t statistic, and white
// Gaussian noise at a given signal-to-noise ratio.
#pragma once

#include <Eigen/Core>
#include <array>
#include <cmath>
#include <limits>
#include <random>
#include <stdexcept>
#include <string>

#include "taxel/core/status.hpp"
#include "taxel/learn/dataset.hpp"

namespace taxel::learn {

namespace detail {
// Continued fraction of the incomplete beta function (modified Lentz).
inline double beta_continued_fraction(double a, double b, double x) {
  constexpr double kTiny = 1e-300;
  constexpr double kEps = 1e-16;
  double c = 1.0;
  double d = 1.0 - (a + b) * x / (a + 1.0);
  if (std::fabs(d) < kTiny) d = kTiny;
  d = 1.0 / d;
  double h = d;
  for (int m = 1; m <= 10000; ++m) {
    const double m2 = 2.0 * m;
    double aa = m * (b - m) * x / ((a + m2 - 1.0) * (a + m2));
    d = 1.0 + aa * d;
    if (std::fabs(d) < kTiny) d = kTiny;
    c = 1.0 + aa / c;
    if (std::fabs(c) < kTiny) c = kTiny;
    d = 1.0 / d;
    h *= d * c;
    aa = -(a + m) * (a + b + m) * x / ((a + m2) * (a + m2 + 1.0));
    d = 1.0 + aa * d;
    if (std::fabs(d) < kTiny) d = kTiny;
    c = 1.0 + aa / c;
    if (std::fabs(c) < kTiny) c = kTiny;
    d = 1.0 / d;
    const double del = d * c;
    h *= del;
    if (std::fabs(del - 1.0) < kEps) break;
  }
  return h;
}
}  // namespace detail

/// The regularised incomplete beta function I_x(a, b) for a, b > 0 and 0 <= x <= 1.
inline double incomplete_beta(double a, double b, double x) {
  if (!(a > 0.0) || !(b > 0.0) || !(x >= 0.0 && x <= 1.0)) {
    throw std::invalid_argument("incomplete_beta: need a > 0, b > 0 and 0 <= x <= 1");
  }
  if (x == 0.0 || x == 1.0) return x;
  const double front = std::exp(std::lgamma(a + b) - std::lgamma(a) - std::lgamma(b) +
                                a * std::log(x) + b * std::log1p(-x));
  if (x < (a + 1.0) / (a + b + 2.0)) return front * detail::beta_continued_fraction(a, b, x) / a;
  return 1.0 - front * detail::beta_continued_fraction(b, a, 1.0 - x) / b;
}

/// Student's t cumulative distribution function with `dof` > 0 degrees of freedom.
inline double student_t_cdf(double t, double dof) {
  if (!(dof > 0.0) || std::isnan(t)) {
    throw std::invalid_argument("student_t_cdf: need dof > 0 and a number t");
  }
  if (std::isinf(t)) return t > 0 ? 1.0 : 0.0;
  const double tail = 0.5 * incomplete_beta(0.5 * dof, 0.5, dof / (dof + t * t));
  return t > 0.0 ? 1.0 - tail : tail;
}

/// The t with student_t_cdf(t, dof) = p, for 0 < p < 1 (bisection to full precision).
inline double student_t_quantile(double p, double dof) {
  if (!(p > 0.0 && p < 1.0) || !(dof > 0.0)) {
    throw std::invalid_argument("student_t_quantile: need 0 < p < 1 and dof > 0");
  }
  double lo = -1.0;
  double hi = 1.0;
  while (student_t_cdf(lo, dof) > p) lo *= 2.0;
  while (student_t_cdf(hi, dof) < p) hi *= 2.0;
  for (int i = 0; i < 200 && hi - lo > 1e-15 * (1.0 + std::fabs(lo)); ++i) {
    const double mid = 0.5 * (lo + hi);
    (student_t_cdf(mid, dof) < p ? lo : hi) = mid;
  }
  return 0.5 * (lo + hi);
}

/// Error-rate differences p_i(j) = err_A - err_B of replication i (0..4), fold j (0..1).
using FiveByTwoDifferences = std::array<std::array<double, 2>, 5>;

/// Dietterich's (1998) 5x2cv paired t test of two classifiers.
struct FiveByTwoResult : Outcome {
  FiveByTwoDifferences differences{};  ///< error of A minus error of B per replication and fold
  double t = 0.0;                      ///< p_1(1) / sqrt(sum s_i^2 / 5)
  double p_value = 1.0;                ///< two-sided, Student t with 5 degrees of freedom
  double alpha = 0.05;                 ///< significance level
  double critical = 0.0;               ///< |t| above this rejects (2.571 at 0.05, 2.015 at 0.10)
  bool reject = false;                 ///< the null hypothesis (equal error rates) is rejected
  double mean_error_a = 0.0;           ///< mean error rate of A over the ten folds
  double mean_error_b = 0.0;           ///< mean error rate of B over the ten folds
};

/// The 5x2cv t statistic, p-value and decision from the ten differences. When every s_i^2 is
/// zero the statistic is undefined: `degenerate` with t = 0, p = 1, no rejection.
inline FiveByTwoResult five_by_two_t_test(const FiveByTwoDifferences& diff, double alpha = 0.05) {
  if (!(alpha > 0.0 && alpha < 1.0)) {
    throw std::invalid_argument("five_by_two_t_test: alpha = " + std::to_string(alpha) +
                                " is outside (0, 1)");
  }
  FiveByTwoResult r;
  r.differences = diff;
  r.alpha = alpha;
  r.critical = student_t_quantile(1.0 - alpha / 2.0, 5.0);
  double sum_s2 = 0.0;
  for (const auto& d : diff) {
    if (!std::isfinite(d[0]) || !std::isfinite(d[1])) {
      r.status = Status::invalid_input;
      r.message = "five_by_two_t_test: a difference is not finite";
      return r;
    }
    const double mean = 0.5 * (d[0] + d[1]);
    sum_s2 += (d[0] - mean) * (d[0] - mean) + (d[1] - mean) * (d[1] - mean);
  }
  if (!(sum_s2 > 0.0)) {
    r.status = Status::degenerate;
    r.message =
        "five_by_two_t_test: the differences do not vary within any replication, so "
        "the variance estimate is zero and t is undefined";
    return r;
  }
  r.t = diff[0][0] / std::sqrt(sum_s2 / 5.0);
  r.p_value = 2.0 * (1.0 - student_t_cdf(std::fabs(r.t), 5.0));
  r.reject = std::fabs(r.t) > r.critical;
  return r;
}

/// Where feature noise goes in an evaluation.
enum class NoiseTarget {
  test_only,  ///< the classifier trains on clean features (default; the second paper does not say)
  both,       ///< training and test features are both noisy
};

/// Adds white Gaussian noise to every row of `x` at `snr_db` decibels, measured per row as
/// MATLAB's `awgn(x, snr, 'measured')`: noise variance = mean(row^2) / 10^(snr/10). Rows of zero
/// power stay unchanged. Throws std::invalid_argument for a NaN snr.
template <class Rng>
void add_white_noise(Eigen::Ref<FeatureMatrix> x, double snr_db, Rng& rng) {
  if (std::isnan(snr_db)) throw std::invalid_argument("add_white_noise: snr_db is NaN");
  if (std::isinf(snr_db) && snr_db > 0) return;
  std::normal_distribution<double> gauss(0.0, 1.0);
  const double ratio = std::pow(10.0, snr_db / 10.0);
  for (Eigen::Index r = 0; r < x.rows(); ++r) {
    const double power = x.row(r).squaredNorm() / static_cast<double>(x.cols());
    const double sd = std::sqrt(power / ratio);
    if (!(sd > 0.0) || !std::isfinite(sd)) continue;
    for (Eigen::Index c = 0; c < x.cols(); ++c) x(r, c) += sd * gauss(rng);
  }
}

}  // namespace taxel::learn
