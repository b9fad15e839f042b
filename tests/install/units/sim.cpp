// SPDX-License-Identifier: MIT
#include <cmath>
#include <taxel/taxel.hpp>

#include "units.hpp"

int unit_sim() {
  const taxel::sim::Sphere s(0.04);
  const taxel::sim::Box b(taxel::Vec3d(0.01, 0.02, 0.03));
  const double ds = s.signed_distance(taxel::Vec3d(0.05, 0.0, 0.0));
  const double db = b.signed_distance(taxel::Vec3d(0.0, 0.0, 0.05));
  return std::abs(ds - 0.01) < 1e-12 && std::abs(db - 0.02) < 1e-12 ? 0 : 1;
}
