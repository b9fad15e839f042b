// SPDX-License-Identifier: MIT
#include <Eigen/Geometry>
#include <cmath>
#include <vector>

#include <taxel/taxel.hpp>

#include "units.hpp"

int unit_registration() {
  // A 1 mm shift of a corner of a grid recovered by point-to-point ICP.
  std::vector<taxel::Vec3d> model;
  for (int i = 0; i < 10; ++i) {
    for (int j = 0; j < 10; ++j) {
      model.emplace_back(0.01 * i, 0.01 * j, 0.0);
      model.emplace_back(0.01 * i, 0.0, 0.01 * j);
      model.emplace_back(0.0, 0.01 * i, 0.01 * j);
    }
  }
  taxel::registration::Target<double> target(taxel::PointCloud<double>{model});
  std::vector<taxel::Vec3d> source;
  for (const auto& p : model) source.push_back(p + taxel::Vec3d(1e-3, 0.0, 0.0));
  taxel::registration::Icp<taxel::registration::PointToPoint> icp;
  const auto r = icp.align(target, std::span<const taxel::Vec3d>(source));
  return r.ok() && std::abs(r.transform.translation().x() + 1e-3) < 1e-6 ? 0 : 1;
}
