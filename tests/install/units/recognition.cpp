// SPDX-License-Identifier: MIT
// Registration, tactile images and learning.
#include <Eigen/Geometry>
#include <cmath>
#include <span>
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

int unit_image() {
  taxel::image::ImageD img = taxel::image::ImageD::Zero(32, 32);
  img.block(10, 10, 6, 6).setConstant(100.0);
  img.block(12, 12, 2, 2).setConstant(200.0);
  taxel::image::Recognizer<> rec(32, 32);
  const auto& r = rec.recognize(img);
  return r.ok() ? 0 : 1;
}

int unit_learn() {
  taxel::learn::FeatureMatrix x(4, 2);
  x << 0, 0, 0, 1, 5, 5, 5, 6;
  const std::vector<int> y{1, 1, 2, 2};
  taxel::learn::Lda lda;
  taxel::learn::LinearSvm svm;
  const taxel::learn::DatasetView d{x, y};
  if (!lda.fit(d) || !svm.fit(d)) return 1;
  const Eigen::VectorXd probe = Eigen::Vector2d(5.0, 5.5);
  return lda.predict(probe) == 2 && svm.predict(probe) == 2 ? 0 : 1;
}
