// SPDX-License-Identifier: MIT
// Synthetic data sets for the learn tests.
#pragma once

#include <cmath>
#include <random>
#include <taxel/learn/dataset.hpp>

namespace taxel_test {

/// `per_class` Gaussian samples (sd 1) around `classes` centres `separation` apart on random
/// directions, with labels 1..classes (or -1/+1 for two classes when `pm_one`).
inline taxel::learn::Dataset blobs(int per_class, int classes, int dims, double separation,
                                   unsigned seed, bool pm_one = false) {
  std::mt19937_64 rng(seed);
  std::normal_distribution<double> g(0.0, 1.0);
  taxel::learn::FeatureMatrix centres(classes, dims);
  for (int c = 0; c < classes; ++c) {
    Eigen::VectorXd v(dims);
    for (int j = 0; j < dims; ++j) v(j) = g(rng);
    centres.row(c) = separation * v.normalized().transpose();
  }
  taxel::learn::Dataset d;
  d.x.resize(per_class * classes, dims);
  // Interleave classes (c0, c1, ..., c0, c1, ...), label order = 1..classes.
  for (int i = 0; i < per_class * classes; ++i) {
    const int c = i % classes;
    for (int j = 0; j < dims; ++j) d.x(i, j) = centres(c, j) + g(rng);
    d.y.push_back(pm_one ? (c == 0 ? -1 : 1) : c + 1);
    d.groups.push_back(i / classes % 10);
  }
  return d;
}

/// XOR of two features' signs (plus `extra` noise features): not linearly separable.
inline taxel::learn::Dataset xor_set(int n, int extra, unsigned seed) {
  std::mt19937_64 rng(seed);
  std::uniform_real_distribution<double> u(-1.0, 1.0);
  taxel::learn::Dataset d;
  d.x.resize(n, 2 + extra);
  for (int i = 0; i < n; ++i) {
    double a = 0.0;
    double b = 0.0;
    do {
      a = u(rng);
      b = u(rng);
    } while (std::fabs(a) < 0.1 || std::fabs(b) < 0.1);
    d.x(i, 0) = a;
    d.x(i, 1) = b;
    for (int j = 0; j < extra; ++j) d.x(i, 2 + j) = 0.1 * u(rng);
    d.y.push_back((a > 0) == (b > 0) ? 1 : 2);
  }
  return d;
}

}  // namespace taxel_test
