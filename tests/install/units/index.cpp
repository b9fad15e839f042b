// SPDX-License-Identifier: MIT
#include <vector>

#include <taxel/taxel.hpp>

#include "units.hpp"

int unit_index() {
  std::vector<taxel::Vec3d> pts{{0, 0, 0}, {1, 0, 0}, {0, 2, 0}};
  taxel::index::KdTree<double> tree(pts);
  const auto hit = tree.knn({0.9, 0.1, 0.0}, 1);
  return hit.size() == 1 && hit[0].id == 1 ? 0 : 1;
}
