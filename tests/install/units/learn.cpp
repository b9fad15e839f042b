// SPDX-License-Identifier: MIT
#include <vector>

#include <taxel/taxel.hpp>

#include "units.hpp"

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
