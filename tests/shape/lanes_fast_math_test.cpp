// SPDX-License-Identifier: MIT
// The SIMD-lane kernel sums (shape/lanes.hpp) built with -ffast-math, as a user's project may
// build them. Their exponential rounds x / ln 2 to an integer; done by adding and subtracting
// 1.5 * 2^52, the optimiser folds that away under -ffast-math (errors of 40 %), so the header
// rounds through integer lanes. Checked against std::exp and plain sums.
#include <algorithm>
#include <catch2/catch.hpp>
#include <cmath>
#include <random>
#include <taxel/shape/kernels.hpp>
#include <vector>

#if TAXEL_SHAPE_LANES
namespace ln = taxel::shape::detail::lanes;

TEST_CASE("lanes under -ffast-math: the exponential keeps its rounding", "[shape][kernel]") {
  double worst = 0.0;
  for (double x = 0.0; x > -700.0; x -= 0.37) {
    ln::D2 v = ln::D2{} + x, e;
    ln::exp_nonpositive(v, e);
    worst = std::max(worst, std::abs(e[0] - std::exp(x)) / std::exp(x));
  }
  CHECK(worst < 1e-12);
}

TEST_CASE("lanes under -ffast-math: kernel sums equal plain sums", "[shape][kernel]") {
  const taxel::shape::Matern32 kernel({.length_scale = 0.02, .sigma = 0.01});
  std::mt19937_64 rng(3);
  std::uniform_real_distribution<double> u(-0.03, 0.03);
  const std::size_t n = 37;
  std::vector<double> xs(n), ys(n), zs(n), w(n);
  for (std::size_t i = 0; i < n; ++i) {
    xs[i] = u(rng);
    ys[i] = u(rng);
    zs[i] = u(rng);
    w[i] = u(rng);
  }
  const double* p[3] = {xs.data(), ys.data(), zs.data()};
  const double q[3] = {0.004, -0.01, 0.02};
  double sum = 0.0, scale = 0.0;
  for (std::size_t i = 0; i < n; ++i) {
    const double r = std::hypot(q[0] - xs[i], q[1] - ys[i], q[2] - zs[i]);
    sum += w[i] * kernel(r);
    scale += std::abs(w[i]) * kernel.variance();
  }
  double g[3];
  CHECK(std::abs(ln::kernel_sum_sse2<true>(kernel, n, p, q, w.data(), g) - sum) < 1e-12 * scale);
  if (ln::cpu_has_avx2_fma())
    CHECK(std::abs(ln::kernel_sum_avx2<true>(kernel, n, p, q, w.data(), g) - sum) < 1e-12 * scale);
}
#endif
