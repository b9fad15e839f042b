// SPDX-License-Identifier: MIT
#include <taxel/taxel.hpp>

#include "units.hpp"

int unit_fusion() {
  taxel::fusion::ContactCloud<taxel::fusion::Surfel<double>, taxel::index::VoxelHash<double>> cloud(
      {.association_radius = 3e-3});
  taxel::Contact<double> c;
  c.position = {0.01, 0.0, 0.0};
  c.covariance = taxel::pad_covariance<double>({0, 0, 1}, 1e-3, 2e-3);
  cloud.insert(c);
  c.position = {0.011, 0.0, 0.0};
  cloud.insert(c);
  return cloud.size() == 1 ? 0 : 1;  // the second contact is within the radius: fused
}
