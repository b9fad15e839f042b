// SPDX-License-Identifier: MIT
// The FusionPolicy concept: how a fused point starts from a contact and absorbs later ones.
#pragma once

#include <concepts>
#include <cstdint>
#include <utility>

#include "taxel/core/contact.hpp"
#include "taxel/core/types.hpp"

namespace taxel::fusion {

/// A fusion policy: a small stateless-by-instance type with
/// - `Scalar`, a nested aggregate `Config`, and the per-point `State` it updates;
/// - `kMerges`: false for policies that never merge (each contact becomes a point, `Raw`);
/// - `init(contact) -> State`: the state of a new point;
/// - `fuse(state, contact, n) -> bool`: absorbs `contact` into a point observed `n` times
///   before; returns false (state untouched) when the policy's own gate refuses the contact;
/// - `mean(state)` [m] and `covariance(state)` [m^2] of the fused point.
/// `contact` is already validated (finite, symmetric positive definite covariance).
template <class P>
concept FusionPolicy = requires(const P& policy, typename P::State& state,
                                const Contact<typename P::Scalar>& contact, std::uint32_t n) {
  requires Scalar<typename P::Scalar>;
  requires Configurable<P>;
  { P::kMerges } -> std::convertible_to<bool>;
  { policy.init(contact) } -> std::same_as<typename P::State>;
  { policy.fuse(state, contact, n) } -> std::same_as<bool>;
  { policy.mean(std::as_const(state)) } -> std::convertible_to<Vec3<typename P::Scalar>>;
  { policy.covariance(std::as_const(state)) } -> std::convertible_to<Mat3<typename P::Scalar>>;
};

}  // namespace taxel::fusion
