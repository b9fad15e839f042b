// SPDX-License-Identifier: MIT
#include <taxel/taxel.hpp>

#include "units.hpp"

int unit_all() {
  // The same calls as other units make: their instantiations must merge at link time.
  const taxel::sim::Sphere s(0.04);
  taxel::learn::FeatureMatrix x(4, 1);
  x << 0, 1, 5, 6;
  const std::vector<int> y{1, 1, 2, 2};
  taxel::learn::LinearSvm svm;  // as in learn.cpp; its Lda here too would double this compile
  if (!svm.fit(taxel::learn::DatasetView{x, y})) return 1;
  return s.closest_point(taxel::Vec3d(0.0, 0.0, 1.0)).z() == 0.04 ? 0 : 1;
}
