// SPDX-License-Identifier: MIT
// Tests of the shape layer: the Gaussian process against scikit-learn's and closed forms, its
// incremental updates against refits, local experts against the exact process, marching
// tetrahedra against analytic fields with closed-form error bounds, and touch scoring against
// a brute-force refit.
#include <algorithm>
#include <catch2/catch.hpp>
#include <cmath>
#include <map>
#include <numbers>
#include <random>
#include <set>
#include <taxel/shape.hpp>
#include <taxel/sim/exploration.hpp>
#include <utility>
#include <vector>

namespace sh = taxel::shape;
using taxel::Vec3d;

namespace {

// From tests/shape/gp_golden.py (scikit-learn 1.2, GaussianProcessRegressor with
// ConstantKernel(1e-4) * Matern(0.01, nu) and alpha = kNoise).
const std::vector<double> kX{
    0.005003818664186678,  0.015888552038783022,   0.011027427609807742,  -0.010991712400376327,
    -0.007993348603550983, 0.014942137815850475,   -0.019789387817377012, 0.012849136735310653,
    0.01188277715008185,   -0.0012826018862511675, -0.00787870292722746,  -0.008862975515969066,
    -0.009805216493835017, -0.0021969477646941356, 0.0001819303583181324, 0.0021398940829796993,
    0.019820011337375706,  0.011706476768550123,   0.004887169177646505,  0.019558405907275398,
    -0.011387652070576041, -0.013591518645686218,  0.0045015841709212315, -0.018242319681544664,
    -0.018572788849056155, 0.000595552810854813,   -0.001351758986988437};
const std::vector<double> kY{
    -0.0021547715833865463, -0.00019400378160428793, 0.00045323594401323024,
    -0.0061205430620215745, -0.0019110131041357226,  -0.003914076312226558,
    -0.0032353489577023973, 0.004243594493544315,    -0.003230138701327586};
const std::vector<double> kNoise{
    1.1456354400309623e-08, 3.3371861462268076e-07, 7.023982161396153e-08,
    1.1436372877987631e-07, 3.5332954005252316e-07, 2.0881841584868504e-07,
    3.4038859608268903e-07, 2.594896951075852e-07,  2.9929066947112425e-07};
const std::vector<double> kQ{-0.020425219746847717, 0.002057191068824439,   0.00038861181501749845,
                             0.01856696883464403,   -0.0069367970492921205, 0.004909203360360652,
                             -0.02203741788272482,  -0.005618409944463564,  -0.00884818268708967,
                             -0.017490013546477407, 0.015816905190953787,   -0.0060276914224843756,
                             0.023937394220561084,  0.004499584650530512,   0.005252812691492564};
const std::vector<double> kMean32{-0.002871272555846579, -0.0005236437313627953,
                                  -0.0010882571142340946, -0.00010332696034696075,
                                  -0.0002886658080566378};
const std::vector<double> kStd32{0.004082281432179515, 0.009950164856068694, 0.008704798757976737,
                                 0.009445963317350313, 0.009939141340032036};
const std::vector<double> kMean52{-0.0030358251442730777, -0.0004411235586072563,
                                  -0.0012553280180660894, -7.462590633732164e-05,
                                  -0.00016007955208475919};
const std::vector<double> kStd52{0.0033552675663112053, 0.009957670540687443, 0.008465270443994725,
                                 0.009407441642183526, 0.009938569793988335};

Vec3d at(const std::vector<double>& v, std::size_t i) {
  return {v[3 * i], v[3 * i + 1], v[3 * i + 2]};
}

template <class K>
void check_against_sklearn(const std::vector<double>& mean, const std::vector<double>& stdev) {
  sh::GaussianProcess<K> gp(K({.length_scale = 0.01, .sigma = 0.01}));
  for (std::size_t i = 0; i < kY.size(); ++i) REQUIRE(gp.add(at(kX, i), kY[i], kNoise[i]));
  for (std::size_t q = 0; q < mean.size(); ++q) {
    const sh::FieldPrediction p = gp.predict(at(kQ, q));
    CHECK(p.mean == Approx(mean[q]).epsilon(1e-9).margin(1e-15));
    CHECK(std::sqrt(p.variance) == Approx(stdev[q]).epsilon(1e-9));
  }
}

Vec3d random_point(std::mt19937_64& rng, double half) {
  std::uniform_real_distribution<double> u(-half, half);
  return {u(rng), u(rng), u(rng)};
}

// Predictions of two processes agree at random points.
template <class A, class B>
void same_predictions(const A& a, const B& b, std::mt19937_64& rng, double half, double tol) {
  for (int i = 0; i < 20; ++i) {
    const Vec3d x = random_point(rng, half);
    const sh::FieldPrediction pa = a.predict(x), pb = b.predict(x);
    CHECK(pa.mean == Approx(pb.mean).margin(tol));
    CHECK(pa.variance == Approx(pb.variance).margin(tol * 1e-2));
    CHECK((pa.gradient - pb.gradient).norm() < 1e3 * tol);
  }
}

}  // namespace

TEST_CASE("Matern kernels: slopes are k'(r) / r by finite differences", "[shape][kernel]") {
  const sh::Matern32 k32({.length_scale = 0.007, .sigma = 0.02});
  const sh::Matern52 k52({.length_scale = 0.007, .sigma = 0.02});
  for (const double r : {1e-4, 2e-3, 7e-3, 0.02}) {
    const double h = 1e-8;
    CHECK(k32.slope(r) * r == Approx((k32(r + h) - k32(r - h)) / (2 * h)).epsilon(1e-6));
    CHECK(k52.slope(r) * r == Approx((k52(r + h) - k52(r - h)) / (2 * h)).epsilon(1e-6));
  }
  CHECK(k32(0.0) == Approx(4e-4));
  CHECK(k52.variance() == Approx(4e-4));
  const Eigen::ArrayXd r = Eigen::ArrayXd::LinSpaced(7, 0.0, 0.03);
  for (Eigen::Index i = 0; i < r.size(); ++i) {
    CHECK(k32.values(r)(i) == Approx(k32(r(i))));
    CHECK(k52.slopes(r)(i) == Approx(k52.slope(r(i))));
  }
  CHECK_THROWS_WITH(sh::Matern32({.length_scale = 0.0, .sigma = 1.0}),
                    Catch::Contains("length_scale must be finite and > 0"));
  CHECK_THROWS_WITH(sh::Matern52({.length_scale = 1.0, .sigma = NAN}),
                    Catch::Contains("sigma must be finite and > 0"));
}

#if TAXEL_SHAPE_LANES
TEMPLATE_TEST_CASE("lanes: the SIMD kernel sums equal plain sums with std::exp", "[shape][kernel]",
                   sh::Matern32, sh::Matern52) {
  namespace ln = sh::detail::lanes;
  // The exponential alone, over its whole range and beyond the clamp.
  for (const double x :
       {0.0, -1e-12, -0.3465, -0.3466, -1.0, -5.5, -37.0, -699.0, -700.0, -745.0, -1e6}) {
    ln::D2 v = ln::D2{} + x, e;
    ln::exp_nonpositive(v, e);
    const double expected = std::exp(std::max(x, -700.0));
    CHECK(std::abs(e[0] - expected) <= 1e-15 * expected);
  }
  // Sums of every length from 0 to 11 (all remainders of both widths), queries on an
  // observation (r = 0), near and far.
  const TestType kernel({.length_scale = 0.02, .sigma = 0.01});
  std::mt19937_64 rng(7);
  std::uniform_real_distribution<double> u(-0.03, 0.03);
  for (std::size_t n = 0; n <= 11; ++n) {
    std::vector<double> xs(n), ys(n), zs(n), w(n);
    for (std::size_t i = 0; i < n; ++i) {
      xs[i] = u(rng);
      ys[i] = u(rng);
      zs[i] = u(rng);
      w[i] = 1e3 * u(rng);
    }
    const double* p[3] = {xs.data(), ys.data(), zs.data()};
    std::vector<Vec3d> queries{Vec3d(0.001, -0.002, 0.003), Vec3d(2.0, 0.0, -1.0)};
    if (n > 0) queries.emplace_back(xs[0], ys[0], zs[0]);
    for (const Vec3d& q : queries) {
      double sum = 0.0, scale = 0.0;
      Vec3d grad = Vec3d::Zero();
      for (std::size_t i = 0; i < n; ++i) {
        const Vec3d d = q - Vec3d(xs[i], ys[i], zs[i]);
        sum += w[i] * kernel(d.norm());
        grad += w[i] * kernel.slope(d.norm()) * d;
        scale += std::abs(w[i]) * kernel.variance();
      }
      std::vector<double (*)(const TestType&, std::size_t, const double* const*, const double*,
                             const double*, double*)>
          paths{&ln::kernel_sum_sse2<true, TestType>};
      if (ln::cpu_has_avx2_fma()) paths.push_back(&ln::kernel_sum_avx2<true, TestType>);
      for (const auto path : paths) {
        Vec3d g = Vec3d::Constant(NAN);
        const double got = path(kernel, n, p, q.data(), w.data(), g.data());
        CHECK(std::abs(got - sum) <= 1e-14 * scale);
        CHECK((g - grad).norm() <= 1e-13 * scale / 0.02);
      }
    }
  }
}
#endif

TEST_CASE("GaussianProcess: mean and variance equal scikit-learn's", "[shape][gp]") {
  check_against_sklearn<sh::Matern32>(kMean32, kStd32);
  check_against_sklearn<sh::Matern52>(kMean52, kStd52);
}

TEST_CASE("GaussianProcess: one observation in closed form", "[shape][gp]") {
  const sh::Matern32 k({.length_scale = 0.01, .sigma = 0.005});
  sh::GaussianProcess gp(k);
  const double noise = 1e-6, y = 0.003;
  REQUIRE(gp.add(Vec3d(0.001, 0.0, 0.0), y, noise));
  const Vec3d x(0.004, 0.002, -0.001);
  const double kx = k((x - Vec3d(0.001, 0.0, 0.0)).norm());
  const sh::FieldPrediction p = gp.predict(x);
  CHECK(p.mean == Approx(kx * y / (k.variance() + noise)));
  CHECK(p.variance == Approx(k.variance() - kx * kx / (k.variance() + noise)));
  // The gradient by central differences.
  for (int a = 0; a < 3; ++a) {
    const double h = 1e-7;
    const Vec3d e = h * Vec3d::Unit(a);
    CHECK(p.gradient[a] == Approx((gp.mean(x + e) - gp.mean(x - e)) / (2 * h)).margin(1e-9));
  }
}

TEST_CASE("GaussianProcess: adds and removals equal a refit", "[shape][gp]") {
  std::mt19937_64 rng(3);
  std::normal_distribution<double> g(0.0, 0.003);
  const sh::Matern52 kernel({.length_scale = 0.008, .sigma = 0.01});
  std::vector<Vec3d> x;
  std::vector<double> y, noise;
  for (int i = 0; i < 40; ++i) {
    x.push_back(random_point(rng, 0.02));
    y.push_back(g(rng));
    noise.push_back(1e-7 * (1 + i % 3));
  }
  sh::GaussianProcess gp(kernel);
  for (std::size_t i = 0; i < x.size(); ++i) REQUIRE(gp.add(x[i], y[i], noise[i]));
  // Remove the first, a middle one and the last; compare with a process built without them.
  for (const std::size_t drop : {std::size_t{0}, std::size_t{17}, std::size_t{37}}) {
    gp.remove(drop);
    x.erase(x.begin() + static_cast<std::ptrdiff_t>(drop));
    y.erase(y.begin() + static_cast<std::ptrdiff_t>(drop));
    noise.erase(noise.begin() + static_cast<std::ptrdiff_t>(drop));
  }
  sh::GaussianProcess fresh(kernel);
  for (std::size_t i = 0; i < x.size(); ++i) REQUIRE(fresh.add(x[i], y[i], noise[i]));
  REQUIRE(gp.size() == fresh.size());
  same_predictions(gp, fresh, rng, 0.025, 1e-12);
  // New values: equal to a process fitted to them.
  Eigen::VectorXd values(static_cast<Eigen::Index>(x.size()));
  sh::GaussianProcess refit(kernel);
  for (std::size_t i = 0; i < x.size(); ++i) {
    values(static_cast<Eigen::Index>(i)) = g(rng);
    REQUIRE(refit.add(x[i], values(static_cast<Eigen::Index>(i)), noise[i]));
  }
  gp.set_values(values);
  same_predictions(gp, refit, rng, 0.025, 1e-12);
  // Batched predictions equal single ones.
  Eigen::Matrix3Xd q(3, 6);
  for (int i = 0; i < 6; ++i) q.col(i) = random_point(rng, 0.02);
  Eigen::VectorXd mean(6), var;
  gp.predict(q, mean, &var);
  for (int i = 0; i < 6; ++i) {
    CHECK(mean(i) == Approx(gp.predict(q.col(i)).mean).margin(1e-15));
    CHECK(var(i) == Approx(gp.predict(q.col(i)).variance).margin(1e-15));
  }
  CHECK_THROWS_AS(gp.remove(gp.size()), std::out_of_range);
  CHECK_THROWS_AS(gp.set_values(Eigen::VectorXd(2)), std::invalid_argument);
}

TEST_CASE("GaussianProcess: bad observations are refused and change nothing", "[shape][gp]") {
  sh::GaussianProcess gp;
  REQUIRE(gp.add(Vec3d::Zero(), 0.001, 0.0));
  const double before = gp.mean(Vec3d(0.001, 0, 0));
  CHECK_FALSE(gp.add(Vec3d(NAN, 0, 0), 0.0, 1e-6));
  CHECK_FALSE(gp.add(Vec3d::Zero(), INFINITY, 1e-6));
  CHECK_FALSE(gp.add(Vec3d::Ones(), 0.0, -1.0));
  CHECK_FALSE(gp.add(Vec3d::Zero(), 0.002, 0.0));  // a noiseless repeat: singular
  CHECK(gp.size() == 1);
  CHECK(gp.mean(Vec3d(0.001, 0, 0)) == before);
}

TEST_CASE("ImplicitSurface: points on the prior sphere leave the prior exact", "[shape][surface]") {
  // Every observation agrees with the prior m(x) = |x - c| - r (the off-surface ones at +-d
  // along the radial normal too), so the residuals are 0 and the posterior mean is the sphere's
  // signed distance everywhere: a closed form.
  const Vec3d c(0.003, -0.002, 0.001);
  const double r = 0.03;
  sh::ImplicitSurface surface({.expert_size = 0.01, .prior_centre = c, .prior_radius = r});
  std::mt19937_64 rng(5);
  std::normal_distribution<double> g;
  for (int i = 0; i < 300; ++i) {
    const Vec3d n = Vec3d(g(rng), g(rng), g(rng)).normalized();
    REQUIRE(surface.insert(c + r * n, n, 1e-8));
  }
  for (int i = 0; i < 50; ++i) {
    const Vec3d x = c + random_point(rng, 0.04);
    const sh::FieldPrediction p = surface.predict(x);
    CHECK(p.mean == Approx((x - c).norm() - r).margin(1e-12));
    CHECK((p.gradient - (x - c).normalized()).norm() < 1e-9);
  }
}

TEST_CASE("ImplicitSurface: a touched plane away from the prior", "[shape][surface]") {
  // The plane z = 0, touched densely over 30 x 30 mm, under a prior sphere of radius 0 at
  // (0, 0, -0.05): the posterior's zero level and normal follow the plane inside the touched
  // patch, and the variance there is far below the prior's.
  sh::ImplicitSurface surface({.expert_size = 0.01, .prior_centre = Vec3d(0, 0, -0.05)});
  for (int i = -15; i <= 15; ++i)
    for (int j = -15; j <= 15; ++j)
      REQUIRE(surface.insert(Vec3d(i * 1e-3, j * 1e-3, 0.0), Vec3d::UnitZ(), 1e-8));
  for (const Vec3d& x : {Vec3d(0, 0, 0), Vec3d(0.005, -0.004, 0), Vec3d(-0.008, 0.009, 0)}) {
    const sh::FieldPrediction p = surface.predict(x);
    CHECK(std::abs(p.mean) < 2e-5);
    CHECK(p.gradient.normalized().dot(Vec3d::UnitZ()) > std::cos(2.0 * std::numbers::pi / 180));
    CHECK(std::sqrt(p.variance) < 0.05 * surface.kernel().config().sigma);
    CHECK(surface.mean(x + Vec3d(0, 0, 0.002)) == Approx(0.002).margin(2e-4));
  }
  // Far from the patch the prior comes back, with the prior's variance.
  const sh::FieldPrediction far = surface.predict(Vec3d(0.2, 0.2, 0.0));
  CHECK(far.mean == Approx(surface.prior(Vec3d(0.2, 0.2, 0.0))));
  CHECK(far.variance == Approx(surface.kernel().variance()));
}

TEST_CASE("ImplicitSurface: experts equal the exact process when they hold every point",
          "[shape][surface]") {
  const double L = 0.02;
  sh::SurfaceConfig cfg{.expert_size = L,
                        .normal_offset = 0.002,
                        .inside_offset = 0.0015,
                        .min_sigma = 1e-4,
                        .prior_centre = Vec3d(0.01, 0.01, 0.0),
                        .prior_radius = 0.004};
  sh::ImplicitSurface surface(cfg);
  sh::GaussianProcess exact(surface.kernel());
  std::mt19937_64 rng(11);
  // Points in the lower half of cell 0 along every axis: experts -1 and 0 on each axis hold
  // them all, and answer every query within (1 - blend) L of the origin.
  std::uniform_real_distribution<double> u(0.001, 0.5 * L - 0.001);
  std::uniform_real_distribution<double> uq(-0.85 * L, 0.85 * L);
  std::normal_distribution<double> g;
  for (int i = 0; i < 12; ++i) {
    const Vec3d p(u(rng), u(rng), u(rng));
    const Vec3d n = Vec3d(g(rng), g(rng), g(rng)).normalized();
    const double var = (i % 3) * 1e-8;
    REQUIRE(surface.insert(p, n, var));
    const double nv = std::max(var, 1e-8);
    for (const double s : {0.0, cfg.normal_offset, -cfg.inside_offset}) {
      const Vec3d x = p + s * n;
      REQUIRE(exact.add(x, s - surface.prior(x), nv));
    }
  }
  CHECK(surface.expert_count() == 8);
  for (int i = 0; i < 30; ++i) {
    const Vec3d x(uq(rng), uq(rng), uq(rng));
    const sh::FieldPrediction p = surface.predict(x), e = exact.predict(x);
    CHECK(p.mean == Approx(e.mean + surface.prior(x)).margin(1e-12));
    CHECK(p.variance == Approx(e.variance).margin(1e-14));
    const Vec3d prior_grad = (x - cfg.prior_centre).normalized();
    CHECK((p.gradient - e.gradient - prior_grad).norm() < 1e-9);
  }
}

TEST_CASE("ImplicitSurface: moved and erased points equal a surface built from the final ones",
          "[shape][surface]") {
  sh::SurfaceConfig cfg{.expert_size = 0.008, .prior_radius = 0.02};
  sh::ImplicitSurface moved(cfg), fresh(cfg);
  std::mt19937_64 rng(13);
  std::normal_distribution<double> g;
  std::vector<std::pair<Vec3d, Vec3d>> pts;
  for (int i = 0; i < 60; ++i) {
    const Vec3d n = Vec3d(g(rng), g(rng), g(rng)).normalized();
    pts.emplace_back(0.02 * n + 0.001 * Vec3d(g(rng), g(rng), g(rng)), n);
    REQUIRE(moved.insert(pts.back().first, n, 1e-8) == std::size_t(i));
  }
  for (int i = 0; i < 60; i += 3) {  // move every third point, some across cells
    pts[std::size_t(i)].first += 0.004 * Vec3d(g(rng), g(rng), g(rng));
    REQUIRE(
        moved.update(std::size_t(i), pts[std::size_t(i)].first, pts[std::size_t(i)].second, 1e-8));
  }
  for (int i = 1; i < 60; i += 7) moved.erase(std::size_t(i));
  for (int i = 0; i < 60; ++i) {
    if (i % 7 == 1) continue;
    // The same order of observations within each expert is not needed: a process does not
    // depend on the order of its observations.
    REQUIRE(fresh.insert(pts[std::size_t(i)].first, pts[std::size_t(i)].second, 1e-8));
  }
  CHECK(moved.size() == fresh.size());
  same_predictions(moved, fresh, rng, 0.03, 1e-10);
  CHECK_THROWS_AS(moved.erase(1), std::out_of_range);
  CHECK_THROWS_AS(moved.update(1000, Vec3d::Zero(), Vec3d::UnitZ(), 0.0), std::out_of_range);
  CHECK_FALSE(moved.insert(Vec3d(NAN, 0, 0), Vec3d::UnitZ(), 0.0));
  CHECK_FALSE(moved.insert(Vec3d::Zero(), Vec3d::Zero(), 0.0));
  CHECK_FALSE(moved.insert(Vec3d::Zero(), Vec3d::UnitZ(), -1.0));
  CHECK_FALSE(moved.insert(Vec3d(1e300, 0, 0), Vec3d::UnitZ(), 0.0));
  CHECK_FALSE(moved.update(0, Vec3d::Zero(), Vec3d::UnitZ(), NAN));
  CHECK(moved.size() == fresh.size());
}

TEST_CASE("ImplicitSurface: the blended field is continuous and its gradient exact",
          "[shape][surface]") {
  sh::ImplicitSurface surface({.expert_size = 0.006, .prior_radius = 0.015});
  std::mt19937_64 rng(17);
  std::normal_distribution<double> g;
  for (int i = 0; i < 80; ++i) {
    const Vec3d n = Vec3d(g(rng), g(rng), g(rng)).normalized();
    REQUIRE(surface.insert((0.018 + 0.001 * g(rng)) * n, n, 1e-8));
  }
  for (int i = 0; i < 40; ++i) {
    const Vec3d x = random_point(rng, 0.025);
    const sh::FieldPrediction p = surface.predict(x);
    Vec3d grad = Vec3d::Zero();
    CHECK(surface.mean(x, grad) == Approx(p.mean).margin(1e-15));
    CHECK((grad - p.gradient).norm() < 1e-12);
    for (int a = 0; a < 3; ++a) {
      const double h = 1e-8;
      const Vec3d e = h * Vec3d::Unit(a);
      CHECK(p.gradient[a] ==
            Approx((surface.mean(x + e) - surface.mean(x - e)) / (2 * h)).margin(1e-5));
    }
  }
  // Across an expert boundary the field does not jump.
  const double L = surface.config().expert_size;
  for (int i = 0; i < 20; ++i) {
    Vec3d x = random_point(rng, 0.02);
    x.x() = L * std::round(x.x() / L);
    const double below = surface.mean(x - Vec3d(1e-12, 0, 0));
    const double above = surface.mean(x + Vec3d(1e-12, 0, 0));
    CHECK(below == Approx(above).margin(1e-10));
  }
  // Sampled grids and batched evaluation agree with single queries.
  const sh::Grid grid = sh::Grid::covering(Vec3d::Constant(-0.02), Vec3d::Constant(0.02), 0.004);
  const std::vector<double> field = surface.sample(grid);
  for (int k = 0; k < grid.nodes[2]; k += 3) {
    for (int j = 0; j < grid.nodes[1]; j += 2) {
      for (int i = 0; i < grid.nodes[0]; ++i) {
        CHECK(field[grid.index(i, j, k)] == Approx(surface.mean(grid.node(i, j, k))).margin(1e-14));
      }
    }
  }
  Eigen::Matrix3Xd q(3, 25);
  for (int i = 0; i < 25; ++i) q.col(i) = random_point(rng, 0.02);
  std::vector<double> mean(25), var(25);
  surface.evaluate(q, mean.data(), var.data());
  for (int i = 0; i < 25; ++i) {
    const sh::FieldPrediction p = surface.predict(q.col(i));
    CHECK(mean[std::size_t(i)] == Approx(p.mean).margin(1e-14));
    CHECK(var[std::size_t(i)] == Approx(p.variance).margin(1e-16));
  }
}

TEST_CASE("ImplicitSurface: invalid settings are refused", "[shape][surface]") {
  CHECK_THROWS_WITH(sh::ImplicitSurface<>({.expert_size = 0.0}),
                    Catch::Contains("expert_size must be finite and > 0"));
  CHECK_THROWS_WITH(sh::ImplicitSurface<>({.normal_offset = -1.0}),
                    Catch::Contains("normal_offset"));
  CHECK_THROWS_WITH(sh::ImplicitSurface<>({.min_sigma = 0.0}), Catch::Contains("min_sigma"));
  CHECK_THROWS_WITH(sh::ImplicitSurface<>({.prior_radius = NAN}), Catch::Contains("prior_radius"));
  sh::ImplicitSurface<> s;
  CHECK_THROWS_WITH(s.set_prior(Vec3d(NAN, 0, 0), 0.01), Catch::Contains("prior_centre"));
}

namespace {

// Every undirected edge in exactly two triangles, every directed edge in exactly one (a closed,
// consistently oriented mesh).
void check_closed(const sh::Mesh& mesh) {
  std::map<std::pair<std::uint32_t, std::uint32_t>, int> directed;
  for (const auto& t : mesh.triangles)
    for (int e = 0; e < 3; ++e) ++directed[{t[std::size_t(e)], t[std::size_t((e + 1) % 3)]}];
  bool ok = true;
  for (const auto& [edge, count] : directed) {
    const auto back = directed.find({edge.second, edge.first});
    ok = ok && count == 1 && back != directed.end() && back->second == 1;
  }
  CHECK(ok);
}

}  // namespace

TEST_CASE("marching_tetrahedra: a sphere within the closed-form bound", "[shape][marching]") {
  // On an exact signed-distance field, a vertex on a tetrahedron edge of length <= sqrt(3) h
  // lies within kappa * 3 h^2 / 8 of the surface, kappa bounding the field's curvature along
  // the edge: 1 / (R - sqrt(3) h) for a sphere of radius R.
  const double R = 0.02, h = 0.002;
  const Vec3d c(0.0007, -0.0003, 0.0011);
  const sh::Grid grid = sh::Grid::covering(Vec3d::Constant(-0.025), Vec3d::Constant(0.025), h);
  std::vector<double> f(grid.size());
  for (int k = 0; k < grid.nodes[2]; ++k)
    for (int j = 0; j < grid.nodes[1]; ++j)
      for (int i = 0; i < grid.nodes[0]; ++i)
        f[grid.index(i, j, k)] = (grid.node(i, j, k) - c).norm() - R;
  const sh::Mesh mesh = sh::marching_tetrahedra(grid, f);
  REQUIRE(mesh.triangles.size() > 1000);
  const double bound = 3.0 * h * h / 8.0 / (R - std::sqrt(3.0) * h);
  double worst = 0.0;
  for (const Vec3d& v : mesh.vertices) worst = std::max(worst, std::abs((v - c).norm() - R));
  CHECK(worst <= bound);
  check_closed(mesh);
  // Outward orientation, and the area near 4 pi R^2 (inscribed facets: a little less).
  int inward = 0;
  for (const auto& t : mesh.triangles) {
    const Vec3d& a = mesh.vertices[t[0]];
    const Vec3d n = (mesh.vertices[t[1]] - a).cross(mesh.vertices[t[2]] - a);
    inward += n.dot(a - c) < 0.0;
  }
  CHECK(inward == 0);
  CHECK(mesh.area() == Approx(4 * std::numbers::pi * R * R).epsilon(0.02));
}

TEST_CASE("marching_tetrahedra: a torus within the closed-form bound, closed at the border",
          "[shape][marching]") {
  // Torus of radii Rt (to the tube's centre) and r: the distance to the core circle minus r.
  // Its level sets' curvatures near the surface are at most 1 / (r - sqrt(3) h) around the
  // tube and 1 / (Rt - r - sqrt(3) h) around the axis.
  const double Rt = 0.02, r = 0.007, h = 0.0015;
  const sh::Grid grid = sh::Grid::covering(Vec3d(-0.03, -0.03, -0.01), Vec3d(0.03, 0.03, 0.01), h);
  std::vector<double> f(grid.size());
  const auto sdf = [&](const Vec3d& p) {
    return std::hypot(std::hypot(p.x(), p.y()) - Rt, p.z()) - r;
  };
  for (int k = 0; k < grid.nodes[2]; ++k)
    for (int j = 0; j < grid.nodes[1]; ++j)
      for (int i = 0; i < grid.nodes[0]; ++i) f[grid.index(i, j, k)] = sdf(grid.node(i, j, k));
  const sh::Mesh mesh = sh::marching_tetrahedra(grid, f, 0.0, true);
  const double s3h = std::sqrt(3.0) * h;
  const double bound = 3.0 * h * h / 8.0 * std::max(1.0 / (r - s3h), 1.0 / (Rt - r - s3h));
  double worst = 0.0;
  for (const Vec3d& v : mesh.vertices) worst = std::max(worst, std::abs(sdf(v)));
  CHECK(worst <= bound);
  check_closed(mesh);
  CHECK(mesh.area() == Approx(4 * std::numbers::pi * std::numbers::pi * Rt * r).epsilon(0.02));
  // Cut by the border: z in [-0.01, 0.01] holds the tube (r = 7 mm), so nothing is cut; a
  // field negative everywhere is closed at the border into the grid's box.
  std::vector<double> inside(grid.size(), -1.0);
  const sh::Mesh box = sh::marching_tetrahedra(grid, inside, 0.0, true);
  check_closed(box);
  CHECK(sh::marching_tetrahedra(grid, inside).triangles.empty());
  CHECK_THROWS_WITH(sh::marching_tetrahedra(grid, std::vector<double>(3)),
                    Catch::Contains("3 values for a grid of"));
  inside[5] = NAN;
  CHECK_THROWS_WITH(sh::marching_tetrahedra(grid, inside), Catch::Contains("not finite"));
}

TEST_CASE("first_crossing: rays meet a sampled sphere where the exact sphere is", "[shape][grid]") {
  const double R = 0.02, h = 0.001;
  const sh::Grid grid = sh::Grid::covering(Vec3d::Constant(-0.03), Vec3d::Constant(0.03), h);
  std::vector<double> f(grid.size());
  for (int k = 0; k < grid.nodes[2]; ++k)
    for (int j = 0; j < grid.nodes[1]; ++j)
      for (int i = 0; i < grid.nodes[0]; ++i)
        f[grid.index(i, j, k)] = grid.node(i, j, k).norm() - R;
  std::mt19937_64 rng(19);
  std::normal_distribution<double> g;
  for (int i = 0; i < 30; ++i) {
    const Vec3d u = Vec3d(g(rng), g(rng), g(rng)).normalized();
    const Vec3d origin = 0.1 * u, aim = 0.005 * Vec3d(g(rng), g(rng), g(rng));
    const Vec3d d = (aim - origin).normalized();
    // The exact hit: |origin + t d| = R.
    const double b = origin.dot(d), c = origin.squaredNorm() - R * R;
    const auto hit = sh::first_crossing(grid, f, origin, d, 1.0);
    if (b * b - c < 0) {
      CHECK_FALSE(hit);
      continue;
    }
    REQUIRE(hit);
    const double t = -b - std::sqrt(b * b - c);
    // Trilinear interpolation of |x| errs by at most 3 h^2 / (8 (R - sqrt(3) h)) / |cos| along the
    // ray.
    CHECK(((*hit) - (origin + t * d)).norm() < 0.2 * h);
  }
  CHECK_FALSE(sh::first_crossing(grid, f, Vec3d(0.1, 0.1, 0.1), Vec3d(1, 0, 0), 1.0));
  CHECK_FALSE(sh::first_crossing(grid, f, Vec3d(0.1, 0, 0), Vec3d(-1, 0, 0), 0.05));
}

TEST_CASE("score_touches: the gain equals a brute-force refit", "[shape][touch]") {
  // Points in one cell, so the expert nearest the contact holds them all; the gain must equal
  // the drop of the expert's variance summed over the targets within the radius, computed by
  // adding the predicted observations and predicting again.
  const double L = 0.02;
  sh::ImplicitSurface surface(
      {.expert_size = L, .prior_centre = Vec3d(0.01, 0.01, -0.02), .prior_radius = 0.026});
  for (int i = 0; i < 6; ++i) {
    const Vec3d p(0.004 + 0.002 * i, 0.012, 0.006);
    REQUIRE(surface.insert(p, Vec3d::UnitZ(), 1e-8));
  }
  const sh::Grid grid =
      sh::Grid::covering(Vec3d(-0.01, -0.01, -0.02), Vec3d(0.03, 0.03, 0.03), 0.001);
  const std::vector<double> field = surface.sample(grid);
  std::vector<Vec3d> targets;
  for (int i = -5; i <= 15; ++i)
    for (int j = -5; j <= 15; ++j) targets.emplace_back(0.002 * i, 0.002 * j, 0.006);
  std::vector<sh::TouchCandidate> cands;
  for (const Vec3d& xy : {Vec3d(0.009, 0.012, 0), Vec3d(0.009, 0.002, 0), Vec3d(0.003, 0.006, 0)})
    cands.push_back({xy + Vec3d(0, 0, 0.05), Vec3d(0, 0, -1), 0.2});
  cands.push_back({Vec3d(0.5, 0.5, 0.5), Vec3d(1, 0, 0), 0.2});  // misses the grid
  const sh::ScoringConfig cfg{.noise_sigma = 0.4e-3,
                              .radius = 0.008,
                              .patch_points = 3,
                              .patch_radius = 0.002,
                              .target_spacing = 0.0};
  const auto scores = sh::score_touches(surface, grid, field, targets, cands, cfg);
  REQUIRE(scores.size() == 4);
  CHECK_FALSE(scores[3].contact);
  CHECK(scores[3].gain == 0.0);
  for (std::size_t c = 0; c < 3; ++c) {
    const auto& s = scores[c];
    REQUIRE(s.contact);
    const auto* e = surface.find(surface.nearest_expert(s.point));
    REQUIRE(e != nullptr);
    auto after = e->process;
    for (const Vec3d& o : sh::touch_patch(s.point, s.normal, cfg))
      REQUIRE(after.add(o, 0.0, cfg.noise_sigma * cfg.noise_sigma));
    double brute = 0.0;
    int counted = 0;
    for (const Vec3d& q : targets) {
      if ((q - s.point).norm() > cfg.radius) continue;
      brute += e->process.predict(q).variance - after.predict(q).variance;
      ++counted;
    }
    REQUIRE(counted > 3);
    CHECK(s.gain == Approx(brute).epsilon(1e-9));
  }
  // A touch 10 mm beside the touched strip teaches more than one on its middle.
  CHECK(scores[1].gain > scores[0].gain);
  CHECK_THROWS_WITH(sh::score_touches(surface, grid, field, targets, cands,
                                      sh::ScoringConfig{.noise_sigma = 0.0}),
                    Catch::Contains("noise_sigma"));
  CHECK_THROWS_WITH(sh::score_touches(surface, grid, std::vector<double>(3), targets, cands),
                    Catch::Contains("does not fit"));
}

TEST_CASE("ImplicitSurface: the outside and inside offsets place their observations",
          "[shape][surface]") {
  const Vec3d p(0.004, 0.003, 0.002), n = Vec3d(1.0, 2.0, 2.0) / 3.0;
  for (const auto& [out, in] : {std::pair{0.003, 0.001}, std::pair{0.002, 0.0},
                                std::pair{0.0, 0.0015}, std::pair{0.0, 0.0}}) {
    sh::ImplicitSurface surface(
        {.expert_size = 0.01, .normal_offset = out, .inside_offset = in, .min_sigma = 1e-7});
    REQUIRE(surface.insert(p, n, 0.0));
    const std::size_t per_point = 1 + (out > 0.0) + (in > 0.0);
    surface.for_each_expert(p, [&](const auto* e, double, const Vec3d&) {
      REQUIRE(e != nullptr);
      CHECK(e->process.size() == per_point);
    });
    // Each observation is all but noise-free, so the mean passes through it.
    CHECK(surface.mean(p) == Approx(0.0).margin(1e-9));
    if (out > 0.0) CHECK(surface.mean(Vec3d(p + out * n)) == Approx(out).margin(1e-9));
    if (in > 0.0) CHECK(surface.mean(Vec3d(p - in * n)) == Approx(-in).margin(1e-9));
  }
  CHECK_THROWS_WITH(sh::ImplicitSurface({.inside_offset = -1e-3}),
                    Catch::Contains("inside_offset must be finite and >= 0"));
}

TEST_CASE("ImplicitSurface: free-space points observe the field's value", "[shape][surface]") {
  sh::ImplicitSurface surface({.expert_size = 0.01, .min_sigma = 1e-6, .prior_radius = 0.02});
  const Vec3d x(0.005, 0.001, 0.012);
  const double before = surface.mean(x);
  const auto id = surface.insert_free(x, 0.004, 1e-12);
  REQUIRE(id);
  CHECK(surface.mean(x) == Approx(0.004).margin(1e-6));
  CHECK(surface.predict(x).variance < 1e-9);
  CHECK_FALSE(surface.update(*id, x, Vec3d::UnitZ(), 0.0));
  CHECK_FALSE(surface.insert_free(x, NAN, 1e-6));
  CHECK_FALSE(surface.insert_free(x, 0.001, -1.0));
  surface.erase(*id);
  CHECK(surface.mean(x) == Approx(before).margin(1e-15));
}

TEST_CASE("Explorer: the incrementally resampled field equals a fresh sample",
          "[shape][explorer]") {
  sh::Explorer<> ex({.workspace_min = Vec3d::Constant(-0.03),
                     .workspace_max = Vec3d::Constant(0.03),
                     .grid_spacing = 0.003});
  std::mt19937_64 rng(23);
  std::normal_distribution<double> g;
  const auto batch = [&](double z, int n) {
    std::vector<taxel::Contact<double>> out;
    for (int i = 0; i < n; ++i) {
      taxel::Contact<double> c;
      c.position = Vec3d(0.004 * g(rng), 0.004 * g(rng), z + 1e-4 * g(rng));
      c.normal = Vec3d::UnitZ();
      c.covariance = taxel::Mat3d(Eigen::Vector3d(1e-6, 1e-6, 1e-8).asDiagonal());
      out.push_back(c);
    }
    return out;
  };
  const auto first = batch(0.015, 200);
  CHECK(ex.add_contacts(first) > 10);
  CHECK(ex.surface().size() == ex.cloud().size());
  const std::vector<double> before = ex.field();
  const auto second = batch(0.015, 100);
  CHECK(ex.add_contacts(second) > 0);
  CHECK(ex.add_free_space(Vec3d(0.0, 0.0, -0.05), Vec3d(0.0, 0.0, 0.01)) > 0);
  const std::vector<double> now = ex.field();
  const std::vector<double> fresh = ex.surface().sample(ex.grid());
  double worst = 0.0;
  for (std::size_t i = 0; i < now.size(); ++i) worst = std::max(worst, std::abs(now[i] - fresh[i]));
  CHECK(worst < 1e-12);
  CHECK(now != before);
  // Every fused point is in the surface at its fused position.
  for (std::size_t i = 0; i < ex.cloud().size(); ++i) {
    bool found = false;
    for (std::size_t s = 0; s < ex.surface().id_count() && !found; ++s) {
      const auto& p = ex.surface().point(s);
      found = p.alive && !p.free &&
              (p.position - ex.cloud().mean(static_cast<taxel::index::PointId>(i))).norm() < 1e-15;
    }
    CHECK(found);
  }
  // The estimate passes through the touched patch, with a small sigma there.
  const sh::SurfaceMesh& mesh = ex.estimate();
  REQUIRE_FALSE(mesh.mesh.triangles.empty());
  double near_sigma = 1.0;
  for (std::size_t v = 0; v < mesh.mesh.vertices.size(); ++v) {
    if ((mesh.mesh.vertices[v] - Vec3d(0, 0, 0.015)).norm() < 0.003)
      near_sigma = std::min(near_sigma, mesh.sigma[v]);
  }
  CHECK(near_sigma < 1e-3);
  CHECK_THROWS_WITH(sh::Explorer<>({.free_cap = 0.0}), Catch::Contains("free_cap"));

  // Rebuilt from its parts, it answers and goes on as the original.
  std::vector<std::optional<std::size_t>> ids(ex.cloud().size());
  for (std::size_t i = 0; i < ids.size(); ++i)
    ids[i] = ex.surface_id(static_cast<taxel::index::PointId>(i));
  sh::Explorer<> twin(ex.config(), ex.cloud(), ex.surface(), ids);
  CHECK(twin.field() == ex.field());
  auto wrong = ids;
  wrong.pop_back();
  CHECK_THROWS_WITH(sh::Explorer<>(ex.config(), ex.cloud(), ex.surface(), wrong),
                    Catch::Contains("surface ids for"));
  wrong = ids;
  wrong[1] = wrong[0];
  CHECK_THROWS_WITH(sh::Explorer<>(ex.config(), ex.cloud(), ex.surface(), wrong),
                    Catch::Contains("is not a live surface point of its own"));
  const auto third = batch(0.016, 50);
  CHECK(twin.add_contacts(third) == ex.add_contacts(third));
  CHECK(twin.field() == ex.field());
}

TEST_CASE("sim::poke meets the surface where the ray does, and misses cleanly", "[shape][sim]") {
  const taxel::sim::Sphere ball(0.03);
  taxel::sim::ExplorationConfig cfg;
  std::mt19937_64 rng(29);
  std::vector<taxel::Contact<double>> contacts;
  const Vec3d origin(0.01, 0.0, 0.1), dir(0.0, 0.0, -1.0);
  const auto hit = taxel::sim::poke(ball, cfg, origin, dir, 0.2, rng, contacts);
  REQUIRE(hit);
  CHECK((*hit - Vec3d(0.01, 0.0, std::sqrt(0.03 * 0.03 - 0.01 * 0.01))).norm() < 1e-8);
  REQUIRE(contacts.size() > 20);
  for (const auto& c : contacts) CHECK(std::abs(c.position.norm() - 0.03) < 0.002);
  contacts.clear();
  CHECK_FALSE(taxel::sim::poke(ball, cfg, Vec3d(0.05, 0.0, 0.1), dir, 0.2, rng, contacts));
  CHECK(contacts.empty());
  CHECK_FALSE(taxel::sim::poke(ball, cfg, origin, dir, 0.05, rng, contacts));  // too short
  CHECK_THROWS_WITH(taxel::sim::poke(ball, cfg, origin, Vec3d::Zero(), 0.2, rng, contacts),
                    Catch::Contains("direction of length > 0"));
}

TEST_CASE("confidence_region: with no touch, the prior sphere widened by k prior sigmas",
          "[shape][surface]") {
  // No observations: mean = |x| - r, sigma = s_f everywhere, so the shells are spheres of
  // radius r - k s_f and r + k s_f (a closed form).
  const double r = 0.03, sf = 0.005, k = 2.0, h = 0.002;
  sh::ImplicitSurface surface({.prior_radius = r},
                              sh::Matern32({.length_scale = 0.02, .sigma = sf}));
  const sh::Grid grid = sh::Grid::covering(Vec3d::Constant(-0.05), Vec3d::Constant(0.05), h);
  const sh::ConfidenceRegion region = sh::confidence_region(surface, grid, k);
  const auto radii = [](const sh::Mesh& m, double want) {
    double worst = 0.0;
    for (const Vec3d& v : m.vertices) worst = std::max(worst, std::abs(v.norm() - want));
    return worst;
  };
  REQUIRE_FALSE(region.inner.triangles.empty());
  REQUIRE_FALSE(region.outer.triangles.empty());
  CHECK(radii(region.inner, r - k * sf) <= 3 * h * h / 8 / (r - k * sf - std::sqrt(3.0) * h));
  CHECK(radii(region.outer, r + k * sf) <= 3 * h * h / 8 / (r + k * sf - std::sqrt(3.0) * h));
  CHECK_THROWS_WITH(sh::confidence_region(surface, grid, 0.0), Catch::Contains("k must be"));
}

TEST_CASE("score_touches: with no observations the gain is the prior's closed form",
          "[shape][touch]") {
  // One observation at the contact o against the prior: gain(q) = k(q, o)^2 / (k(0) + s^2).
  sh::ImplicitSurface surface({.prior_radius = 0.02});
  const sh::Grid grid = sh::Grid::covering(Vec3d::Constant(-0.04), Vec3d::Constant(0.04), 0.002);
  const std::vector<Vec3d> targets{{0.0, 0.003, 0.02}, {0.004, 0.0, 0.0195}, {0.0, 0.0, 0.02}};
  const sh::ScoringConfig cfg{.target_spacing = 0.0};
  const auto r = sh::score_touches(surface, grid, surface.sample(grid), targets,
                                   {{Vec3d(0, 0, 0.1), Vec3d(0, 0, -1), 1.0}}, cfg);
  REQUIRE(r[0].contact);
  const auto& k = surface.kernel();
  double want = 0.0;
  for (const Vec3d& q : targets) {
    const double c = k((q - r[0].point).norm());
    want += c * c / (k.variance() + cfg.noise_sigma * cfg.noise_sigma);
  }
  CHECK(r[0].gain == Approx(want).epsilon(1e-12));
}
