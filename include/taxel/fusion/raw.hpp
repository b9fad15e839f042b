// SPDX-License-Identifier: MIT
// Raw: the baseline that keeps every contact as its own point.
#pragma once

#include <cstdint>

#include "taxel/core/contact.hpp"

namespace taxel::fusion {

/// Never merges: every valid contact becomes a point with the contact's position and
/// measurement covariance (Meier et al. 2011, the "raw data" representation).
/// State: 96 bytes (double), 48 (float).
template <Scalar S>
struct Raw {
  /// The floating-point type of positions and covariances (float or double).
  using Scalar = S;
  /// Raw has nothing to configure.
  struct Config {};
  /// A stored contact.
  struct State {
    Vec3<S> position;    ///< The contact's position [m], world frame.
    Mat3<S> covariance;  ///< Covariance of the position [m^2].
  };
  /// Calls f(values, count) on each part of a state, in a fixed order: what a state is made
  /// of, for saving and restoring a cloud (ContactCloud::restore).
  template <class Fn>
  static void for_each_field(State& s, Fn&& f) {
    f(s.position.data(), 3);
    f(s.covariance.data(), 9);
  }

  static constexpr bool kMerges =
      false;  ///< Every contact stays a point of its own (FusionPolicy).

  Raw() = default;
  /// Raw has nothing to configure.
  explicit Raw(const Config&) {}

  /// The state of a contact.
  State init(const Contact<S>& c) const { return {c.position, c.covariance}; }
  /// Never merges; always false.
  bool fuse(State&, const Contact<S>&, std::uint32_t) const { return false; }
  /// The contact position [m].
  const Vec3<S>& mean(const State& s) const noexcept { return s.position; }
  /// The contact covariance [m^2].
  const Mat3<S>& covariance(const State& s) const noexcept { return s.covariance; }
};

}  // namespace taxel::fusion
