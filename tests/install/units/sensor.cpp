// SPDX-License-Identifier: MIT
#include <cmath>
#include <taxel/taxel.hpp>

#include "units.hpp"

int unit_sensor() {
  // A reading exactly at the threshold: the truncated-normal mean lies sigma * phi(0) /
  // (1 - Phi(0)) = sigma * sqrt(2 / pi) above the true depth.
  const double sigma = 3e-4;
  const double bias = taxel::sensor::truncation_bias(1e-3, 1e-3, sigma);
  return std::abs(bias - sigma * std::sqrt(2.0 / 3.141592653589793)) < 1e-15 ? 0 : 1;
}
