// SPDX-License-Identifier: MIT
// Kalman: one static-state 3-D Kalman filter per fused point (Meier et al. 2011, Sec. II).
#pragma once

#include <cmath>
#include <cstdint>
#include <optional>
#include <stdexcept>
#include <string>

#include <Eigen/LU>

#include "taxel/core/contact.hpp"

namespace taxel::fusion {

/// Chi-square thresholds with 3 degrees of freedom for the Mahalanobis gate.
inline constexpr double kChi2Dof3P95 = 7.814727903251178;   ///< 95 %
inline constexpr double kChi2Dof3P99 = 11.344866730144373;  ///< 99 %

/// Fuses contacts into a point with a Kalman filter on a static 3-D state: identity process
/// and measurement models, measurement covariance R = the contact's covariance.
///   predict: P- = P + q^2 I
///   gain:    K = P- (P- + R)^-1
///   update:  mu += K (m - mu);  P = (I - K) P- (I - K)' + K R K'   (Joseph form)
/// The Joseph form keeps P symmetric positive definite under rounding. With q = 0 and one
/// isotropic R for every contact the mean equals the cumulative average (K = I / (n + 1));
/// the filter gains over averaging when R is anisotropic or varies (pad orientation,
/// pressure). Optional Mahalanobis gate: refuse a contact when
/// (m - mu)' (P- + R)^-1 (m - mu) > gate_chi2. State: 96 bytes (double), 48 (float).
/// No allocation.
template <Scalar S>
struct Kalman {
  using Scalar = S;
  /// Configuration; defaults: no process noise, no gate, P0 = the first contact's R.
  struct Config {
    S process_noise = S(0);            ///< q [m] per update, >= 0 (Q = q^2 I)
    std::optional<S> gate_chi2{};      ///< Mahalanobis gate threshold (e.g. kChi2Dof3P99), > 0
    std::optional<S> initial_sigma{};  ///< if set, P0 = sigma^2 I [m] instead of the contact's R
  };
  /// A fused point: the filter's mean and covariance.
  struct State {
    Vec3<S> mean;
    Mat3<S> covariance;
  };
  static constexpr bool kMerges = true;

  Kalman() = default;
  /// Throws std::invalid_argument naming the field that is out of range.
  explicit Kalman(const Config& config) : config_(config) {
    if (!(config.process_noise >= S(0)) || !std::isfinite(config.process_noise)) {
      throw std::invalid_argument("Kalman::Config::process_noise must be finite and >= 0, got " +
                                  std::to_string(config.process_noise));
    }
    if (config.gate_chi2 && !(*config.gate_chi2 > S(0))) {
      throw std::invalid_argument("Kalman::Config::gate_chi2 must be > 0, got " +
                                  std::to_string(*config.gate_chi2));
    }
    if (config.initial_sigma &&
        (!(*config.initial_sigma > S(0)) || !std::isfinite(*config.initial_sigma))) {
      throw std::invalid_argument("Kalman::Config::initial_sigma must be finite and > 0, got " +
                                  std::to_string(*config.initial_sigma));
    }
  }

  /// A point at the contact with covariance R (or initial_sigma^2 I).
  State init(const Contact<S>& c) const {
    if (config_.initial_sigma) {
      const S s = *config_.initial_sigma;
      return {c.position, Mat3<S>::Identity() * (s * s)};
    }
    return {c.position, c.covariance};
  }

  /// One Kalman update; false (state untouched) when the Mahalanobis gate refuses.
  bool fuse(State& s, const Contact<S>& c, std::uint32_t) const {
    Mat3<S> p_pred = s.covariance;
    if (config_.process_noise > S(0)) {
      p_pred.diagonal().array() += config_.process_noise * config_.process_noise;
    }
    const Mat3<S> innovation_cov_inv = (p_pred + c.covariance).inverse();
    const Vec3<S> innovation = c.position - s.mean;
    if (config_.gate_chi2 && innovation.dot(innovation_cov_inv * innovation) > *config_.gate_chi2) {
      return false;
    }
    const Mat3<S> gain = p_pred * innovation_cov_inv;
    s.mean += gain * innovation;
    const Mat3<S> i_minus_k = Mat3<S>::Identity() - gain;
    const Mat3<S> joseph =
        i_minus_k * p_pred * i_minus_k.transpose() + gain * c.covariance * gain.transpose();
    s.covariance = S(0.5) * (joseph + joseph.transpose());
    return true;
  }
  /// The filter mean [m].
  const Vec3<S>& mean(const State& s) const noexcept { return s.mean; }
  /// The filter covariance [m^2].
  const Mat3<S>& covariance(const State& s) const noexcept { return s.covariance; }

 private:
  Config config_{};
};

}  // namespace taxel::fusion
