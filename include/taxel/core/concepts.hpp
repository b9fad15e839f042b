// SPDX-License-Identifier: MIT
// Concepts shared by every layer.
#pragma once

#include <concepts>
#include <type_traits>

namespace taxel {

/// The floating-point types taxel's algorithms are instantiated for.
template <class T>
concept Scalar = std::same_as<T, float> || std::same_as<T, double>;

/// A type with a nested aggregate `Config` that can be value-initialised.
template <class T>
concept Configurable =
    std::is_aggregate_v<typename T::Config> && std::default_initializable<typename T::Config>;

}  // namespace taxel
