// SPDX-License-Identifier: MIT
// The program, and again some of the calls the other units make: their instantiations must
// merge at link time.
#include <cstdio>
#include <vector>

#include <taxel/taxel.hpp>

#include "units.hpp"

namespace {

int same_calls() {
  taxel::fusion::ContactCloud<taxel::fusion::Surfel<double>, taxel::index::VoxelHash<double>> cloud(
      {.association_radius = 3e-3});
  taxel::Contact<double> c;
  c.position = {0.01, 0.0, 0.0};
  c.covariance = taxel::pad_covariance<double>({0, 0, 1}, 1e-3, 2e-3);
  cloud.insert(c);
  const taxel::sim::Sphere s(0.04);
  taxel::learn::FeatureMatrix x(4, 1);
  x << 0, 1, 5, 6;
  const std::vector<int> y{1, 1, 2, 2};
  taxel::learn::LinearSvm svm;  // as in recognition.cpp; its Lda here too would double this compile
  if (!svm.fit(taxel::learn::DatasetView{x, y})) return 1;
  const bool ok = cloud.size() == 1 && s.closest_point(taxel::Vec3d(0.0, 0.0, 1.0)).z() == 0.04;
  return ok ? 0 : 1;
}

}  // namespace

int main() {
  const int failed = unit_fusion() + unit_index() + unit_io() + unit_sim() + unit_sensor() +
                     unit_registration() + unit_image() + unit_learn() + same_calls();
  std::printf("taxel %s, three translation units: %d failed checks\n", TAXEL_VERSION_STRING,
              failed);
  return failed == 0 ? 0 : 1;
}
