// SPDX-License-Identifier: MIT
// Fusion, spatial index, file formats, shapes and the sensor model.
#include <cmath>
#include <vector>

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

int unit_index() {
  std::vector<taxel::Vec3d> pts{{0, 0, 0}, {1, 0, 0}, {0, 2, 0}};
  taxel::index::KdTree<double> tree(pts);
  const auto hit = tree.knn({0.9, 0.1, 0.0}, 1);
  return hit.size() == 1 && hit[0].id == 1 ? 0 : 1;
}

int unit_io() {
  const auto data = taxel::io::parse_ply(
      "ply\nformat ascii 1.0\nelement vertex 2\nproperty float x\nproperty float y\n"
      "property float z\nend_header\n0 0 0\n1 2 3\n",
      "inline.ply");
  return data.cloud.size() == 2 && data.cloud.points[1].z() == 3.0 ? 0 : 1;
}

int unit_sim() {
  const taxel::sim::Sphere s(0.04);
  const taxel::sim::Box b(taxel::Vec3d(0.01, 0.02, 0.03));
  const double ds = s.signed_distance(taxel::Vec3d(0.05, 0.0, 0.0));
  const double db = b.signed_distance(taxel::Vec3d(0.0, 0.0, 0.05));
  return std::abs(ds - 0.01) < 1e-12 && std::abs(db - 0.02) < 1e-12 ? 0 : 1;
}

int unit_sensor() {
  // A reading exactly at the threshold: the truncated-normal mean lies sigma * phi(0) /
  // (1 - Phi(0)) = sigma * sqrt(2 / pi) above the true depth.
  const double sigma = 3e-4;
  const double bias = taxel::sensor::truncation_bias(1e-3, 1e-3, sigma);
  return std::abs(bias - sigma * std::sqrt(2.0 / 3.141592653589793)) < 1e-15 ? 0 : 1;
}
