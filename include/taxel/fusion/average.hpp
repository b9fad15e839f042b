// SPDX-License-Identifier: MIT
// Average: the "sliding average" update of Meier et al. 2011, cumulative or exponential.
#pragma once

#include <cmath>
#include <cstdint>
#include <stdexcept>
#include <string>

#include "taxel/core/contact.hpp"

namespace taxel::fusion {

/// Averages contacts into a point, ignoring their covariances when weighting.
/// - `cumulative` (default): the arithmetic mean of all contacts, mu += (m - mu) / (n + 1);
///   independent of the order of the contacts.
/// - `exponential`: mu += alpha (m - mu), a moving average that forgets old contacts (a window
///   of W contacts corresponds to alpha = 2 / (W + 1)).
/// The covariance is that of the weighted mean of independent contacts:
/// sum_i w_i^2 R_i, updated as C <- (1 - w)^2 C + w^2 R. State: 96 bytes (double).
template <Scalar S>
struct Average {
  /// The floating-point type of positions and covariances (float or double).
  using Scalar = S;
  /// Which average.
  enum class Mode { cumulative, exponential };
  /// Configuration; defaults give the cumulative mean.
  struct Config {
    Mode mode = Mode::cumulative;  ///< Cumulative or exponential mean.
    S alpha = S(0.1);  ///< weight of the newest contact in `exponential` mode, in (0, 1]
  };
  /// A fused point.
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

  Average() = default;
  /// Throws std::invalid_argument when alpha is outside (0, 1] in exponential mode.
  explicit Average(const Config& config) : config_(config) {
    if (config.mode == Mode::exponential && !(config.alpha > S(0) && config.alpha <= S(1))) {
      throw std::invalid_argument("Average::Config::alpha must be in (0, 1], got " +
                                  std::to_string(config.alpha));
    }
  }

  /// A point at the contact.
  State init(const Contact<S>& c) const { return {c.position, c.covariance}; }
  /// Moves the mean towards the contact; always true (no gate).
  bool fuse(State& s, const Contact<S>& c, std::uint32_t n) const {
    const S w =
        config_.mode == Mode::cumulative ? S(1) / (static_cast<S>(n) + S(1)) : config_.alpha;
    s.mean += w * (c.position - s.mean);
    s.covariance = (S(1) - w) * (S(1) - w) * s.covariance + (w * w) * c.covariance;
    return true;
  }
  /// The averaged position [m].
  const Vec3<S>& mean(const State& s) const noexcept { return s.mean; }
  /// The covariance of the average [m^2].
  const Mat3<S>& covariance(const State& s) const noexcept { return s.covariance; }

 private:
  Config config_{};
};

}  // namespace taxel::fusion
