// SPDX-License-Identifier: MIT
#include <cstdio>
#include <taxel/taxel.hpp>

int main() {
  const auto c = taxel::pad_covariance(taxel::Vec3d(0, 0, 1), 2e-3, 1e-3);
  std::printf("taxel %s: pad covariance trace %.3g m^2\n", TAXEL_VERSION_STRING, c.trace());
  return taxel::is_symmetric_positive_definite(c) ? 0 : 1;
}
