// SPDX-License-Identifier: MIT
// A tiny program using the installed taxel; exits 0 when the pad covariance is as documented.
#include <cmath>
#include <cstdio>
#include <taxel/taxel.hpp>

int main() {
  const taxel::Vec3d n(0.0, 0.0, 1.0);
  const taxel::Mat3d c = taxel::pad_covariance(n, 2e-3, 1e-3);
  const bool ok = std::abs(c(2, 2) - 4e-6) < 1e-18 && std::abs(c(0, 0) - 1e-6) < 1e-18;
  std::printf("taxel %s consumer: %s\n", TAXEL_VERSION_STRING, ok ? "ok" : "WRONG");
  return ok ? 0 : 1;
}
