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
  /// Written on the symmetric 3x3 entries: the innovation covariance is inverted by its
  /// adjugate, and of the Joseph form only the upper triangle is formed, then mirrored.
  bool fuse(State& s, const Contact<S>& c, std::uint32_t) const {
    Mat3<S> pp = s.covariance;
    if (config_.process_noise > S(0)) {
      pp.diagonal().array() += config_.process_noise * config_.process_noise;
    }
    const Mat3<S>& r = c.covariance;
    // Innovation covariance (symmetric) and its inverse.
    const S a = pp(0, 0) + r(0, 0), b = pp(0, 1) + r(0, 1), cc = pp(0, 2) + r(0, 2);
    const S d = pp(1, 1) + r(1, 1), e = pp(1, 2) + r(1, 2), f = pp(2, 2) + r(2, 2);
    const S i00 = d * f - e * e, i01 = cc * e - b * f, i02 = b * e - cc * d;
    const S i11 = a * f - cc * cc, i12 = b * cc - a * e, i22 = a * d - b * b;
    const S inv_det = S(1) / (a * i00 + b * i01 + cc * i02);
    Mat3<S> si;
    si << i00 * inv_det, i01 * inv_det, i02 * inv_det,  //
        i01 * inv_det, i11 * inv_det, i12 * inv_det,    //
        i02 * inv_det, i12 * inv_det, i22 * inv_det;
    const Vec3<S> innovation = c.position - s.mean;
    if (config_.gate_chi2 && innovation.dot(si * innovation) > *config_.gate_chi2) return false;
    const Mat3<S> gain = pp * si;
    s.mean += gain * innovation;
    // Joseph form (I - K) P- (I - K)' + K R K', upper triangle: with B = (I - K) P- and
    // C = K R, entry (i, j) is B(i, j) - B.row(i) . K.row(j) + C.row(i) . K.row(j).
    const Mat3<S> bm = pp - gain * pp;
    const Mat3<S> cm = gain * r;
    const Mat3<S> diff = cm - bm;  // (C - B)
    Mat3<S>& out = s.covariance;
    for (int i = 0; i < 3; ++i) {
      for (int j = i; j < 3; ++j) {
        const S v = bm(i, j) + diff.row(i).dot(gain.row(j));
        out(i, j) = v;
        out(j, i) = v;
      }
    }
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
