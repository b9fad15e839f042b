// SPDX-License-Identifier: MIT
// Fuzzer helpers: a configuration value drawn by one input byte over the range it accepts.
#pragma once

#include <algorithm>
#include <cmath>
#include <cstdint>

namespace taxel::fuzz {

/// Log-uniform in [lo, hi] (0 < lo <= hi) by a byte: lo at 0, hi at 255, both ends exact.
inline double log_range(std::uint8_t b, double lo, double hi) {
  return std::clamp(lo * std::pow(hi / lo, b / 255.0), lo, hi);
}

}  // namespace taxel::fuzz
