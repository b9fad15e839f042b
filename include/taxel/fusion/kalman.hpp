// SPDX-License-Identifier: MIT
// Kalman: one static-state 3-D Kalman filter per fused point (Meier et al. 2011, Sec. II).
#pragma once

#include <cmath>
#include <cstdint>
#include <optional>
#include <stdexcept>
#include <string>

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
  /// The floating-point type of positions and covariances (float or double).
  using Scalar = S;
  /// Configuration; defaults: no process noise, no gate, P0 = the first contact's R.
  struct Config {
    S process_noise = S(0);            ///< q [m] per update, >= 0 (Q = q^2 I)
    std::optional<S> gate_chi2{};      ///< Mahalanobis gate threshold (e.g. kChi2Dof3P99), > 0
    std::optional<S> initial_sigma{};  ///< if set, P0 = sigma^2 I [m] instead of the contact's R
  };
  /// A fused point: the filter's mean and covariance.
  struct State {
    Vec3<S> mean;        ///< Estimated surface position [m], world frame.
    Mat3<S> covariance;  ///< Covariance of the position [m^2].
  };
  /// Calls f(values, count) on each part of a state, in a fixed order: what a state is made
  /// of, for saving and restoring a cloud (ContactCloud::restore).
  template <class Fn>
  static void for_each_field(State& s, Fn&& f) {
    f(s.mean.data(), 3);
    f(s.covariance.data(), 9);
  }

  static constexpr bool kMerges =
      true;  ///< Contacts fuse into points (FusionPolicy; false only for Raw).

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
  /// Written in scalars on the symmetric 3x3 entries: the innovation covariance is inverted
  /// by its adjugate, the gain is scaled by 1/det last (so the division overlaps the
  /// product), and of the Joseph form only the upper triangle is formed, then mirrored.
  bool fuse(State& s, const Contact<S>& c, std::uint32_t) const {
    return update(s, c.position, c.covariance);
  }
  /// The same update from a measured position [m] and its covariance r [m^2] (all that `fuse`
  /// reads of a contact).
  bool update(State& s, const Vec3<S>& position, const Mat3<S>& r) const {
    Mat3<S>& pm = s.covariance;
    const S q2 = config_.process_noise * config_.process_noise;
    // Predicted covariance P- (symmetric: the upper triangle is read).
    S p[3][3];
    for (int i = 0; i < 3; ++i) {
      for (int j = i; j < 3; ++j) p[i][j] = p[j][i] = pm(i, j) + (i == j ? q2 : S(0));
    }
    // Innovation covariance (symmetric), its adjugate and determinant.
    const S a = p[0][0] + r(0, 0), b = p[0][1] + r(0, 1), cc = p[0][2] + r(0, 2);
    const S d = p[1][1] + r(1, 1), e = p[1][2] + r(1, 2), f = p[2][2] + r(2, 2);
    const S adj[3][3] = {{d * f - e * e, cc * e - b * f, b * e - cc * d},
                         {cc * e - b * f, a * f - cc * cc, b * cc - a * e},
                         {b * e - cc * d, b * cc - a * e, a * d - b * b}};
    const S inv_det = S(1) / (a * adj[0][0] + b * adj[0][1] + cc * adj[0][2]);
    const S v[3] = {position.x() - s.mean.x(), position.y() - s.mean.y(),
                    position.z() - s.mean.z()};
    if (config_.gate_chi2) {
      S m2 = S(0);
      for (int i = 0; i < 3; ++i) {
        m2 += v[i] * (adj[i][0] * v[0] + adj[i][1] * v[1] + adj[i][2] * v[2]);
      }
      if (m2 * inv_det > *config_.gate_chi2) return false;
    }
    // Gain K = P- adj / det (the product runs alongside the division).
    S k[3][3];
    for (int i = 0; i < 3; ++i) {
      for (int j = 0; j < 3; ++j) {
        k[i][j] = (p[i][0] * adj[0][j] + p[i][1] * adj[1][j] + p[i][2] * adj[2][j]) * inv_det;
      }
    }
    for (int i = 0; i < 3; ++i) s.mean[i] += k[i][0] * v[0] + k[i][1] * v[1] + k[i][2] * v[2];
    // Joseph form (I - K) P- (I - K)' + K R K', upper triangle: with T = (I - K) P- and
    // U = K R, entry (i, j) is T(i, j) + (U - T).row(i) . K.row(j).
    S t[3][3], w[3][3];
    for (int i = 0; i < 3; ++i) {
      for (int j = 0; j < 3; ++j) {
        t[i][j] = p[i][j] - (k[i][0] * p[0][j] + k[i][1] * p[1][j] + k[i][2] * p[2][j]);
        w[i][j] = k[i][0] * r(0, j) + k[i][1] * r(1, j) + k[i][2] * r(2, j) - t[i][j];
      }
    }
    for (int i = 0; i < 3; ++i) {
      for (int j = i; j < 3; ++j) {
        const S val = t[i][j] + w[i][0] * k[j][0] + w[i][1] * k[j][1] + w[i][2] * k[j][2];
        pm(i, j) = val;
        pm(j, i) = val;
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
