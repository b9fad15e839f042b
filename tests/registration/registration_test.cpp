// SPDX-License-Identifier: MIT
#include <array>
#include <catch2/catch.hpp>
#include <cmath>
#include <limits>
#include <random>
#include <taxel/index/brute_force.hpp>
#include <taxel/index/uniform_grid.hpp>
#include <taxel/io/ply.hpp>
#include <taxel/registration.hpp>
#include <taxel/sim/sampling.hpp>
#include <utility>
#include <vector>

#include "../support/allocation_counter.hpp"

using namespace taxel;
using namespace taxel::registration;
using Catch::Matchers::Contains;

namespace {

// An asymmetric object: a box with a sphere and a tilted cylinder attached off-centre.
PointCloud<double> asymmetric(std::size_t n, std::uint64_t seed) {
  PointCloud<double> a = sim::sample_surface(sim::Box(Vec3d(0.04, 0.03, 0.02)), n / 2, seed);
  const PointCloud<double> b = sim::sample_surface(sim::Sphere(0.02), n / 4, seed + 1);
  const PointCloud<double> c =
      sim::sample_surface(sim::Cylinder(0.01, 0.03), n - n / 2 - n / 4, seed + 2);
  const Eigen::AngleAxisd tilt(0.7, Vec3d::UnitX());
  for (std::size_t i = 0; i < b.size(); ++i) {
    a.points.push_back(b.points[i] + Vec3d(0.03, 0.02, 0.02));
    a.normals.push_back(b.normals[i]);
  }
  for (std::size_t i = 0; i < c.size(); ++i) {
    a.points.push_back(tilt * c.points[i] + Vec3d(-0.03, 0.0, 0.03));
    a.normals.push_back(tilt * c.normals[i]);
  }
  return a;
}

Isometry3d pose(double angle, const Vec3d& axis, const Vec3d& t) {
  Isometry3d T = Isometry3d::Identity();
  T.linear() = Eigen::AngleAxisd(angle, axis.normalized()).toRotationMatrix();
  T.translation() = t;
  return T;
}

double rotation_error(const Isometry3d& a, const Isometry3d& b) {
  return Eigen::AngleAxisd(a.linear() * b.linear().transpose()).angle();
}

std::vector<Vec3d> moved(const Isometry3d& T, const std::vector<Vec3d>& pts) {
  std::vector<Vec3d> out;
  out.reserve(pts.size());
  for (const auto& p : pts) out.push_back(T * p);
  return out;
}

// n points drawn uniformly on a sphere shell of radius 30 mm (an ICP model: most grid cells
// empty), from the caller's generator and distribution.
template <class S>
std::vector<Vec3<S>> sphere_shell(int n, std::mt19937_64& rng,
                                  std::normal_distribution<double>& g) {
  std::vector<Vec3<S>> pts;
  for (int i = 0; i < n; ++i) {
    pts.push_back((0.03 * Vec3d(g(rng), g(rng), g(rng)).normalized()).template cast<S>());
  }
  return pts;
}

IcpConfig tight() {
  IcpConfig cfg;
  cfg.max_iterations = 300;
  cfg.translation_tolerance = 1e-14;
  cfg.rotation_tolerance = 1e-14;
  return cfg;
}

}  // namespace

TEST_CASE("symmetric_eigen: eigenpairs of symmetric 6x6 matrices against closed forms and Eigen",
          "[registration][icp]") {
  std::mt19937_64 rng(5);
  std::normal_distribution<double> g;
  // Known spectra in a random orthonormal basis: distinct, repeated, zero (a plane's three
  // free directions), spanning 12 decades, and negative.
  const std::vector<std::array<double, 6>> spectra = {{1, 2, 3, 4, 5, 6},
                                                      {0, 0, 0, 1, 1, 2},
                                                      {1e-12, 1e-9, 1e-6, 1e-3, 1, 1},
                                                      {-3, -1, 0, 2, 2, 7},
                                                      {5, 5, 5, 5, 5, 5}};
  SECTION("known spectra in random bases") {
    for (const auto& spectrum : spectra) {
      for (int trial = 0; trial < 20; ++trial) {
        Mat6d m;
        for (int i = 0; i < 36; ++i) m(i) = g(rng);
        const Mat6d q = Eigen::HouseholderQR<Mat6d>(m).householderQ();
        Vec6d want;
        for (int i = 0; i < 6; ++i) want(i) = spectrum[static_cast<std::size_t>(i)];
        Mat6d a = q * want.asDiagonal() * q.transpose();
        a = (0.5 * (a + a.transpose())).eval();
        Vec6d values;
        Mat6d vectors;
        registration::detail::symmetric_eigen(a, values, vectors);
        const double scale = a.norm();
        for (int i = 0; i < 6; ++i) CHECK(values(i) == Approx(want(i)).margin(1e-13 * scale));
        CHECK((vectors.transpose() * vectors - Mat6d::Identity()).norm() < 1e-13);
        CHECK((a * vectors - vectors * values.asDiagonal()).norm() < 1e-13 * scale);
        const Eigen::SelfAdjointEigenSolver<Mat6d> oracle(a);
        CHECK((values - oracle.eigenvalues()).norm() < 1e-13 * scale);
      }
    }
  }
  SECTION("a diagonal matrix needs no rotation, and is sorted") {
    const Vec6d d = (Vec6d() << 3, -1, 2, 0, 5, 4).finished();
    Vec6d values;
    Mat6d vectors;
    const Mat6d a = d.asDiagonal();
    registration::detail::symmetric_eigen(a, values, vectors);
    CHECK(values == (Vec6d() << -1, 0, 2, 3, 4, 5).finished());
    CHECK((a * vectors - vectors * values.asDiagonal()).norm() == 0.0);  // a permutation
    CHECK((vectors.transpose() * vectors - Mat6d::Identity()).norm() == 0.0);
  }
  SECTION("a NaN or infinite entry gives NaN eigenvalues") {
    for (const double bad :
         {std::numeric_limits<double>::quiet_NaN(), std::numeric_limits<double>::infinity()}) {
      for (const auto& [i, j] : {std::pair{1, 2}, std::pair{4, 4}}) {
        Mat6d a = Mat6d::Identity();
        a(i, j) = a(j, i) = bad;
        Vec6d values;
        Mat6d vectors;
        registration::detail::symmetric_eigen(a, values, vectors);
        CHECK(values.array().isNaN().all());
      }
    }
  }
}

TEST_CASE("UniformGrid answers exactly as brute force", "[registration][index]") {
  std::mt19937_64 rng(42);
  std::uniform_real_distribution<double> u(-0.05, 0.05);
  for (const double offset : {0.0, -1e3, 1e3}) {
    std::vector<Vec3d> pts;
    for (int i = 0; i < 600; ++i)
      pts.push_back(Vec3d(u(rng), u(rng), u(rng)) + Vec3d::Constant(offset));
    for (int i = 0; i < 40; ++i) pts.push_back(pts[static_cast<std::size_t>(i)]);  // duplicates
    // Points exactly on cell boundaries of a 10 mm grid anchored at the minimum.
    for (int i = 0; i < 20; ++i)
      pts.push_back(Vec3d(0.01 * i - 0.05, -0.05, 0.0) + Vec3d::Constant(offset));
    for (const double cell : {0.0, 0.01, 0.003}) {
      const index::UniformGrid<double> grid(pts, {cell});
      index::BruteForce<double> brute;
      for (std::size_t i = 0; i < pts.size(); ++i)
        brute.insert(static_cast<index::PointId>(i), pts[i]);
      for (int q = 0; q < 300; ++q) {
        const double spread = q % 3 == 0 ? 0.3 : 0.06;  // some queries far outside
        std::uniform_real_distribution<double> uq(-spread, spread);
        const Vec3d x = Vec3d(uq(rng), uq(rng), uq(rng)) + Vec3d::Constant(offset);
        const double r = q % 2 == 0 ? 0.004 : 0.02;
        REQUIRE(grid.nearest_within(x, r) == brute.nearest_within(x, r));
        // From a hint (any id, near or far, or out of range): the same answer.
        const auto nearest = brute.nearest_within(x, 1e9);
        for (const index::PointId hint : {nearest->id, static_cast<index::PointId>(q % pts.size()),
                                          static_cast<index::PointId>((7 * q + 3) % pts.size()),
                                          static_cast<index::PointId>(pts.size())}) {
          REQUIRE(grid.nearest_within(x, r, hint) == brute.nearest_within(x, r));
        }
        REQUIRE(grid.knn(x, 7) == brute.knn(x, 7));
        REQUIRE(grid.within(x, r) == brute.within(x, r));
      }
      CHECK(grid.knn(pts[3], pts.size() + 10) == brute.knn(pts[3], pts.size() + 10));
      CHECK(grid.nearest_within(pts[5], 0.0)->squared_distance == 0.0);
    }
  }
  const index::UniformGrid<double> empty(std::vector<Vec3d>{});
  CHECK_FALSE(empty.nearest_within(Vec3d::Zero(), 1.0));
  CHECK(empty.knn(Vec3d::Zero(), 3).empty());
  const index::UniformGrid<double> one(std::vector<Vec3d>{Vec3d(1, 2, 3)});
  CHECK(one.knn(Vec3d::Zero(), 5).size() == 1);
  CHECK_FALSE(one.nearest_within(Vec3d(std::nan(""), 0, 0), 10.0));
  CHECK_THROWS_WITH(index::UniformGrid<double>(std::vector<Vec3d>{Vec3d(0, 0, std::nan(""))}),
                    Contains("point 0 is not finite"));
}

TEMPLATE_TEST_CASE("UniformGrid is exact for queries off a sampled surface, at every range",
                   "[registration][index]", float, double) {
  // Points on a sphere shell, as an ICP model is: most cells are empty, and a query a cell or
  // more off the surface finds nothing in its own 2 x 2 x 2 block (the wider ball scans and
  // the shell search then answer it).
  using S = TestType;
  std::mt19937_64 rng(7);
  std::normal_distribution<double> g(0.0, 1.0);
  std::uniform_real_distribution<double> u(0.0, 1.0);
  const std::vector<Vec3<S>> pts = sphere_shell<S>(2000, rng, g);
  const index::UniformGrid<S> grid(pts);
  const double cell = static_cast<double>(grid.cell());
  index::BruteForce<S> brute;
  for (std::size_t i = 0; i < pts.size(); ++i) brute.insert(static_cast<index::PointId>(i), pts[i]);
  const S inf = std::numeric_limits<S>::infinity();
  for (int q = 0; q < 2000; ++q) {
    // 0 to 8 cells off the surface, inside or outside it.
    const double off = (q % 2 == 0 ? 1.0 : -0.5) * 8.0 * cell * u(rng) * u(rng);
    const Vec3d dir = Vec3d(g(rng), g(rng), g(rng)).normalized();
    const Vec3<S> x = ((0.03 + off) * dir).template cast<S>();
    const auto nearest = brute.nearest_within(x, inf);
    REQUIRE(nearest);
    const S exact = std::sqrt(nearest->squared_distance);
    for (const S r : {S(0.5 * cell), S(1.5 * cell), S(2.0 * cell), S(5.0 * cell), exact, inf}) {
      REQUIRE(grid.nearest_within(x, r) == brute.nearest_within(x, r));
      REQUIRE(grid.nearest_within(x, r, static_cast<index::PointId>(q % pts.size())) ==
              brute.nearest_within(x, r));
    }
  }
}

TEST_CASE("Target: PCA normals, exact nearest with the closest-point field, errors",
          "[registration]") {
  PointCloud<double> sphere = sim::sample_surface(sim::Sphere(0.04), 4000, 3);
  const std::vector<Vec3d> exact = sphere.normals;
  sphere.normals.clear();
  const Target<double> tg(sphere, TargetConfig{.normal_neighbors = 12, .field_cell = 2e-3});
  REQUIRE(tg.normals().size() == sphere.size());
  double worst = 1.0;
  for (std::size_t i = 0; i < exact.size(); ++i)
    worst = std::min(worst, tg.normals()[i].dot(exact[i]));
  CHECK(worst > 0.95);  // oriented outwards, close to the true normals
  CHECK(tg.centroid().norm() < 2e-3);
  CHECK(tg.radius() == Approx(0.04).margin(2e-3));
  REQUIRE(tg.has_field());
  // With the field's bounds the answer stays exact, near the surface and far from it.
  index::BruteForce<double> brute;
  for (std::size_t i = 0; i < sphere.size(); ++i)
    brute.insert(static_cast<index::PointId>(i), sphere.points[i]);
  std::mt19937_64 rng(9);
  std::normal_distribution<double> g(0.0, 1.0);
  for (int q = 0; q < 400; ++q) {
    const Vec3d dir = Vec3d(g(rng), g(rng), g(rng)).normalized();
    // A quarter beyond the field (which ends 20 mm outside the points' box).
    const Vec3d x = dir * (q % 4 == 3 ? 0.08 + 0.1 * std::abs(g(rng)) : 0.04 + 0.02 * g(rng));
    const auto nearest = brute.nearest_within(x, 1.0);
    for (const double r : {0.001, 0.005, 0.03, 0.1, 1.0}) {
      REQUIRE(tg.nearest_within(x, r) == brute.nearest_within(x, r));
      // Searched from a hint (the answer, a neighbour of it, any point): the same answer.
      for (const index::PointId hint :
           {nearest->id, (nearest->id + 1) % 4000u, static_cast<index::PointId>(q * 9 % 4000)}) {
        REQUIRE(tg.nearest_within(x, r, hint) == brute.nearest_within(x, r));
      }
    }
    const auto approx = tg.field_nearest(x);
    if (approx) {  // within half a field cell diagonal of exact
      const double d = (tg.points()[*approx] - x).norm();
      CHECK(d <= std::sqrt(brute.nearest_within(x, 1.0)->squared_distance) + std::sqrt(3.0) * 2e-3);
    }
  }
  CHECK_THROWS_WITH(Target<double>(PointCloud<double>{}), Contains("no points"));
  PointCloud<double> bad = sphere;
  bad.points[7].x() = std::nan("");
  CHECK_THROWS_WITH(Target<double>(bad), Contains("point 7 is not finite"));
  PointCloud<double> zero_normal = sim::sample_surface(sim::Sphere(0.04), 50, 1);
  zero_normal.normals[4].setZero();
  CHECK_THROWS_WITH(Target<double>(zero_normal), Contains("normal 4"));
  CHECK_THROWS_WITH(Target<double>(sphere, TargetConfig{.normal_neighbors = 2}),
                    Contains("normal_neighbors = 2"));
}

TEMPLATE_TEST_CASE("UniformGrid's stable radius: every query within it has the same nearest point",
                   "[registration][index]", float, double) {
  // Points on a sphere shell, and some exact duplicates (a tie: no radius). Oracles: the
  // radius never exceeds half the gap between the nearest and the second-nearest point (brute
  // force), and queries drawn inside the ball keep the answer.
  using S = TestType;
  std::mt19937_64 rng(11);
  std::normal_distribution<double> g(0.0, 1.0);
  std::uniform_real_distribution<double> u(0.0, 1.0);
  std::vector<Vec3<S>> pts = sphere_shell<S>(3000, rng, g);
  for (int i = 0; i < 100; ++i) pts.push_back(pts[static_cast<std::size_t>(7 * i)]);
  const index::UniformGrid<S> grid(pts);
  const double cell = static_cast<double>(grid.cell());
  index::BruteForce<S> brute;
  for (std::size_t i = 0; i < pts.size(); ++i) brute.insert(static_cast<index::PointId>(i), pts[i]);
  const S inf = std::numeric_limits<S>::infinity();
  int positive = 0, tied = 0, tied_zero = 0;
  for (int q = 0; q < 3000; ++q) {
    const double off = (q % 2 == 0 ? 1.0 : -0.5) * 2.0 * cell * u(rng) * u(rng);
    const Vec3d dir = Vec3d(g(rng), g(rng), g(rng)).normalized();
    const Vec3<S> x = ((0.03 + off) * dir).template cast<S>();
    const std::vector<index::Neighbor<S>> two = brute.knn(x, 2);
    REQUIRE(two.size() == 2);
    // Hints: the answer, a near point (the second), an arbitrary id, one out of range.
    for (const index::PointId hint : {two[0].id, two[1].id, static_cast<index::PointId>(q),
                                      static_cast<index::PointId>(pts.size())}) {
      for (const S r : {S(0.5 * cell), inf}) {
        const auto st = grid.nearest_stable(x, r, hint);
        const auto nb = brute.nearest_within(x, r);
        REQUIRE(st.has_value() == nb.has_value());
        if (!st) continue;
        REQUIRE(st->nearest == *nb);
        const double d1 = std::sqrt(static_cast<double>(two[0].squared_distance));
        const double d2 = std::sqrt(static_cast<double>(two[1].squared_distance));
        REQUIRE(st->radius >= 0.0);
        REQUIRE(st->radius <= 0.5 * (d2 - d1));
        if (two[0].squared_distance == two[1].squared_distance) {
          ++tied;
          tied_zero += st->radius == 0.0;
        }
        if (st->radius == 0.0) continue;
        ++positive;
        for (int k = 0; k < 8; ++k) {
          const Vec3d step = Vec3d(g(rng), g(rng), g(rng)).normalized() *
                             (k == 0 ? 0.999 : std::cbrt(u(rng))) * st->radius;
          const Vec3<S> y = (x.template cast<double>() + step).template cast<S>();
          REQUIRE(brute.nearest_within(y, inf)->id == st->nearest.id);
        }
      }
    }
  }
  INFO("positive radii " << positive << ", ties " << tied);
  CHECK(positive > 5000);  // not vacuous: most hinted answers near the surface have a radius
  CHECK(tied > 0);
  CHECK(tied_zero == tied);
}

TEMPLATE_TEST_CASE("ICP keeping stable matches gives the same result as searching every time",
                   "[registration][icp]", float, double) {
  using S = TestType;
  const PointCloud<double> model = asymmetric(8000, 5);
  PointCloud<S> cast;
  for (const Vec3d& p : model.points) cast.points.push_back(p.template cast<S>());
  for (const Vec3d& n : model.normals) cast.normals.push_back(n.template cast<S>());
  const Target<S> tg(cast);
  std::mt19937_64 rng(3);
  std::normal_distribution<double> g(0.0, 1.0);
  int compared = 0;
  for (int trial = 0; trial < 6; ++trial) {
    std::vector<Vec3d> own;
    for (std::size_t i = static_cast<std::size_t>(trial); i < model.size(); i += 5) {
      own.push_back(model.points[i] + 2e-4 * Vec3d(g(rng), g(rng), g(rng)));
    }
    const Isometry3d truth = pose(0.05 + 0.03 * trial, Vec3d(g(rng), g(rng), g(rng)),
                                  0.003 * Vec3d(g(rng), g(rng), g(rng)));
    std::vector<Vec3<S>> source;
    for (const Vec3d& p : moved(truth.inverse(), own)) source.push_back(p.template cast<S>());
    IcpConfig cfg;
    cfg.max_iterations = 30;
    cfg.translation_tolerance = 0.0;
    cfg.rotation_tolerance = 0.0;
    cfg.max_distance = trial % 2 == 0 ? 0.004 : std::numeric_limits<double>::infinity();
    cfg.trim_fraction = trial % 3 == 0 ? 0.1 : 0.0;
    IcpConfig searching = cfg;
    searching.keep_stable_matches = false;
    const auto same = [&](const IcpResult& a, const IcpResult& b) {
      CHECK(a.status == b.status);
      CHECK(a.iterations == b.iterations);
      CHECK(a.transform.matrix() == b.transform.matrix());
      CHECK(a.rmse == b.rmse);
      CHECK(a.inliers == b.inliers);
      CHECK(a.information == b.information);
      ++compared;
    };
    same(Icp<PointToPlane>(cfg).align(tg, std::span<const Vec3<S>>(source)),
         Icp<PointToPlane>(searching).align(tg, std::span<const Vec3<S>>(source)));
    same(Icp<PointToPoint>(cfg).align(tg, std::span<const Vec3<S>>(source)),
         Icp<PointToPoint>(searching).align(tg, std::span<const Vec3<S>>(source)));
  }
  CHECK(compared == 12);
}

TEST_CASE(
    "ICP recovers known transforms exactly without noise, point-to-plane needs fewer "
    "iterations",
    "[registration][icp]") {
  const PointCloud<double> model = asymmetric(6000, 1);
  const Target<double> tg(model);
  std::vector<Vec3d> own;  // a subset of the model's own points, so exact recovery is possible
  for (std::size_t i = 0; i < model.size(); i += 4) own.push_back(model.points[i]);
  const Isometry3d truth = pose(0.2, Vec3d(1, 2, 3), Vec3d(0.006, -0.004, 0.003));
  const std::vector<Vec3d> source = moved(truth.inverse(), own);

  Icp<PointToPoint> p2p(tight());
  Icp<PointToPlane> p2l(tight());
  const IcpResult a = p2p.align(tg, std::span<const Vec3d>(source));
  const IcpResult b = p2l.align(tg, std::span<const Vec3d>(source));
  for (const IcpResult* r : {&a, &b}) {
    INFO(r->message);
    CHECK(r->status == Status::ok);
    CHECK(rotation_error(r->transform, truth) < 1e-9);
    CHECK((r->transform.translation() - truth.translation()).norm() < 1e-9);
    CHECK(r->rmse < 1e-9);
    CHECK(r->inlier_fraction == 1.0);
    CHECK(r->information.allFinite());
    CHECK((r->information - r->information.transpose()).norm() == 0.0);
  }
  INFO("iterations p2p " << a.iterations << ", p2l " << b.iterations);
  CHECK(b.iterations < a.iterations);
  // A start from the truth converges at once.
  const IcpResult c = p2l.align(tg, std::span<const Vec3d>(source), truth);
  CHECK(c.iterations <= 2);
  // Coarse-to-fine (a subsample on the closest-point field first) ends exactly as well.
  const Target<double> with_field(model, TargetConfig{.field_cell = 1e-3});
  IcpConfig coarse_cfg = tight();
  coarse_cfg.coarse_points = 200;
  const IcpResult d =
      Icp<PointToPlane>(coarse_cfg).align(with_field, std::span<const Vec3d>(source));
  INFO(d.message);
  CHECK(d.status == Status::ok);
  CHECK(rotation_error(d.transform, truth) < 1e-9);
  CHECK((d.transform.translation() - truth.translation()).norm() < 1e-9);
}

TEST_CASE("ICP with noise: the pose error is within the statistical bound", "[registration][icp]") {
  const PointCloud<double> model = asymmetric(20000, 2);
  const Target<double> tg(model);
  const double sigma = 0.5e-3;
  std::mt19937_64 rng(5);
  std::normal_distribution<double> g(0.0, sigma);
  const Isometry3d truth = pose(0.1, Vec3d(-1, 0.5, 2), Vec3d(-0.003, 0.002, 0.004));
  // Source: model points displaced along their normals (the noise point-to-plane models).
  std::vector<Vec3d> noisy;
  for (std::size_t i = 0; i < model.size(); i += 10) {
    noisy.push_back(model.points[i] + g(rng) * model.normals[i]);
  }
  const std::vector<Vec3d> source = moved(truth.inverse(), noisy);
  Icp<PointToPlane> icp(tight());
  const IcpResult r = icp.align(tg, std::span<const Vec3d>(source));
  REQUIRE(r.status == Status::ok);
  // Error twist (rotation, translation) of T_est T_true^-1, and its Mahalanobis distance under
  // the estimate's covariance sigma^2 (J'J)^-1: chi-square with 6 degrees of freedom.
  const Isometry3d err = r.transform * truth.inverse();
  const Eigen::AngleAxisd aa(err.linear());
  Vec6d e;
  e.head<3>() = aa.angle() * aa.axis();
  e.tail<3>() = err.translation();
  const double mahalanobis = e.dot(r.information * e) / (sigma * sigma);
  INFO("pose error " << e.transpose() << ", Mahalanobis^2 " << mahalanobis);
  CHECK(mahalanobis < 22.46);  // chi2_6 at 0.999
  CHECK(r.rmse == Approx(sigma).epsilon(0.25));
}

TEST_CASE("ICP on symmetric shapes is judged modulo the symmetry", "[registration][icp]") {
  const Isometry3d truth = pose(0.3, Vec3d(0, 1, 1), Vec3d(0.004, 0.003, -0.002));
  SECTION("sphere: the centre is recovered, the rotation is free") {
    const Target<double> tg(sim::sample_surface(sim::Sphere(0.03), 8000, 4));
    const PointCloud<double> patch = sim::tactile_patches(
        sim::Sphere(0.03), {.patches = 3, .radius = 0.012, .points = 800, .sigma = 0.0}, 5);
    const std::vector<Vec3d> source = moved(truth.inverse(), patch.points);
    Icp<PointToPlane> icp(tight());
    const IcpResult r = icp.align(tg, std::span<const Vec3d>(source));
    CHECK(r.status == Status::degenerate);
    CHECK_THAT(r.message, Contains("3 of 6 pose directions"));
    CHECK(r.transform.matrix().allFinite());
    const Vec3d centre = r.transform * (truth.inverse() * Vec3d::Zero());
    CHECK(centre.norm() < 1e-4);
    CHECK(r.rmse < 1e-3);  // the patch and the model are independent samples
  }
  SECTION("cylinder: the axis is recovered up to its direction") {
    const sim::Cylinder cyl(0.02, 0.04);
    const Target<double> tg(sim::sample_surface(cyl, 8000, 6));
    const PointCloud<double> patch =
        sim::tactile_patches(cyl, {.patches = 5, .radius = 0.012, .points = 1500, .sigma = 0.0}, 7);
    const std::vector<Vec3d> source = moved(truth.inverse(), patch.points);
    Icp<PointToPlane> icp(tight());
    const IcpResult r = icp.align(tg, std::span<const Vec3d>(source));
    INFO(r.message);
    CHECK(r.status != Status::invalid_input);
    const Isometry3d err = r.transform * truth.inverse();
    // The error may only rotate about and slide along the axis (z) or flip it.
    CHECK(std::fabs((err.linear() * Vec3d::UnitZ()).z()) > 1.0 - 1e-6);
    CHECK(err.translation().head<2>().norm() < 1e-4);
  }
}

TEST_CASE("ICP degenerate and invalid inputs give their status, never NaN", "[registration][icp]") {
  const Target<double> tg(asymmetric(3000, 3));
  Icp<PointToPoint> p2p(tight());
  Icp<PointToPlane> p2l(tight());
  const auto finite = [](const IcpResult& r) {
    return r.transform.matrix().allFinite() && std::isfinite(r.rmse) && r.information.allFinite();
  };
  SECTION("fewer than 3 points") {
    const std::vector<Vec3d> two{Vec3d(0.04, 0, 0), Vec3d(0, 0.03, 0)};
    const IcpResult r = p2p.align(tg, std::span<const Vec3d>(two));
    CHECK(r.status == Status::degenerate);
    CHECK_THAT(r.message, Contains("2 finite source points"));
    CHECK(finite(r));
  }
  SECTION("collinear points, point-to-point") {
    std::vector<Vec3d> line;
    for (int i = 0; i < 50; ++i) line.emplace_back(-0.04 + 0.0016 * i, 0.03, 0.02);
    const IcpResult r = p2p.align(tg, std::span<const Vec3d>(line));
    CHECK(r.status == Status::degenerate);
    CHECK_THAT(r.message, Contains("collinear"));
    CHECK(finite(r));
  }
  SECTION("a planar patch, point-to-plane") {
    const Target<double> box(sim::sample_surface(sim::Box(Vec3d(0.04, 0.03, 0.02)), 6000, 3));
    std::vector<Vec3d> face;
    for (int i = 0; i < 20; ++i) {
      for (int j = 0; j < 20; ++j) face.emplace_back(-0.02 + 0.002 * i, -0.015 + 0.0015 * j, 0.02);
    }
    const IcpResult r =
        p2l.align(box, std::span<const Vec3d>(face), pose(0.0, Vec3d::UnitZ(), Vec3d(0, 0, 0.001)));
    CHECK(r.status == Status::degenerate);
    CHECK_THAT(r.message, Contains("3 of 6"));
    CHECK(finite(r));
    CHECK(r.rmse < 1.5e-3);  // in-plane distance to the random model samples
    CHECK(std::fabs(r.transform.translation().z()) < 1e-9);  // the constrained direction is fixed
  }
  SECTION("no correspondences within the gate") {
    IcpConfig cfg = tight();
    cfg.max_distance = 0.001;
    Icp<PointToPlane> gated(cfg);
    std::vector<Vec3d> far;
    for (int i = 0; i < 30; ++i) far.emplace_back(1.0 + 0.01 * i, 0.3 * (i % 3), 0.1 * (i % 5));
    const IcpResult r = gated.align(tg, std::span<const Vec3d>(far));
    CHECK(r.status == Status::degenerate);
    CHECK_THAT(r.message, Contains("0 correspondences within max_distance"));
    CHECK(finite(r));
    CHECK(r.inlier_fraction == 0.0);
  }
  SECTION("NaN source points are skipped") {
    std::vector<Vec3d> pts;
    for (std::size_t i = 0; i < tg.size(); i += 5) pts.push_back(tg.points()[i]);
    pts[3].y() = std::nan("");
    pts[10].z() = std::numeric_limits<double>::infinity();
    const IcpResult r = p2l.align(tg, std::span<const Vec3d>(pts));
    CHECK(r.ok());
    CHECK(r.skipped == 2);
    CHECK(finite(r));
    CHECK(r.rmse < 1e-9);
    std::vector<Vec3d> all_nan(10, Vec3d::Constant(std::nan("")));
    const IcpResult none = p2l.align(tg, std::span<const Vec3d>(all_nan));
    CHECK(none.status == Status::degenerate);
    CHECK(none.skipped == 10);
    CHECK(finite(none));
  }
  SECTION("a bad initial transform") {
    std::vector<Vec3d> pts(tg.points().begin(), tg.points().begin() + 100);
    Isometry3d bad = Isometry3d::Identity();
    bad.linear()(0, 0) = 2.0;
    CHECK(p2l.align(tg, std::span<const Vec3d>(pts), bad).status == Status::invalid_input);
    bad.setIdentity();
    bad.translation().x() = std::nan("");
    const IcpResult r = p2l.align(tg, std::span<const Vec3d>(pts), bad);
    CHECK(r.status == Status::invalid_input);
    CHECK(finite(r));
  }
  SECTION("bad configurations name the field") {
    CHECK_THROWS_WITH(Icp<>(IcpConfig{.max_iterations = 0}), Contains("max_iterations"));
    CHECK_THROWS_WITH(Icp<>(IcpConfig{.max_distance = -1.0}), Contains("max_distance"));
    CHECK_THROWS_WITH(Icp<>(IcpConfig{.trim_fraction = 1.0}), Contains("trim_fraction"));
  }
}

TEST_CASE("Robust kernels and trimming resist outliers", "[registration][icp]") {
  CHECK(Huber{0.01}.weight(0.005) == 1.0);
  CHECK(Huber{0.01}.weight(0.04) == Approx(0.25));
  CHECK(Cauchy{0.01}.weight(0.01) == Approx(0.5));
  CHECK(GemanMcClure{0.01}.weight(0.01) == Approx(0.25));
  CHECK(Tukey{0.01}.weight(0.0) == 1.0);
  CHECK(Tukey{0.01}.weight(0.005) == Approx(0.5625));
  CHECK(Tukey{0.01}.weight(0.02) == 0.0);
  CHECK(NoKernel::weight(1e9) == 1.0);

  const PointCloud<double> model = asymmetric(8000, 7);
  const Target<double> tg(model);
  const Isometry3d truth = pose(0.08, Vec3d(1, -1, 0.5), Vec3d(0.002, 0.001, -0.002));
  std::vector<Vec3d> pts;
  for (std::size_t i = 0; i < model.size(); i += 8) pts.push_back(model.points[i]);
  std::mt19937_64 rng(11);
  std::uniform_real_distribution<double> u(-0.02, 0.02);
  const std::size_t n = pts.size();
  for (std::size_t i = 0; i < n / 4; ++i) {  // 20 % outliers floating near the object
    pts.push_back(model.points[(i * 37) % model.size()] + Vec3d(u(rng), u(rng), u(rng)));
  }
  const std::vector<Vec3d> source = moved(truth.inverse(), pts);
  const auto error = [&](const IcpResult& r) {
    return rotation_error(r.transform, truth) * 0.05 +
           (r.transform.translation() - truth.translation()).norm();
  };
  IcpConfig cfg;
  cfg.max_iterations = 100;
  const double plain = error(Icp<PointToPlane>(cfg).align(tg, std::span<const Vec3d>(source)));
  const double tukey =
      error(Icp<PointToPlane, Tukey>(cfg, Tukey{0.003}).align(tg, std::span<const Vec3d>(source)));
  const double cauchy = error(
      Icp<PointToPlane, Cauchy>(cfg, Cauchy{0.001}).align(tg, std::span<const Vec3d>(source)));
  IcpConfig trimmed = cfg;
  trimmed.trim_fraction = 0.25;
  const double trim = error(Icp<PointToPlane>(trimmed).align(tg, std::span<const Vec3d>(source)));
  INFO("plain " << plain << ", tukey " << tukey << ", cauchy " << cauchy << ", trimmed " << trim);
  CHECK(tukey < 0.5 * plain);
  CHECK(cauchy < 0.5 * plain);
  CHECK(trim < 0.5 * plain);
  CHECK(tukey < 2e-4);
}

TEST_CASE("ICP iterations allocate nothing after the first alignment", "[registration][icp]") {
  const Target<double> tg(asymmetric(4000, 8));
  std::vector<Vec3d> pts;
  for (std::size_t i = 0; i < tg.size(); i += 4) pts.push_back(tg.points()[i]);
  const std::vector<Vec3d> source = moved(pose(0.1, Vec3d(0, 0, 1), Vec3d(0.002, 0, 0)), pts);
  Icp<PointToPlane, Huber> icp(IcpConfig{}, Huber{0.002});
  const IcpResult first = icp.align(tg, std::span<const Vec3d>(source));
  REQUIRE(first.iterations > 2);
  const long before = taxel_test::g_allocations.load();
  const IcpResult again = icp.align(tg, std::span<const Vec3d>(source));
  const long allocations = taxel_test::g_allocations.load() - before;
  CHECK(again.iterations == first.iterations);
  if (TAXEL_TEST_COUNTS_ALLOCATIONS) CHECK(allocations == 0);
}

TEST_CASE("ObjectLibrary recognises partial, noisy, randomly posed clouds",
          "[registration][recognition]") {
  ObjectLibrary<double> lib;
  struct Obj {
    const char* name;
    std::function<PointCloud<double>(std::size_t, std::uint64_t)> sample;
    std::function<PointCloud<double>(std::uint64_t)> touch;
  };
  std::vector<Obj> objects;
  const auto add = [&](const char* name, auto shape) {
    objects.push_back(
        {name, [shape](std::size_t n, std::uint64_t s) { return sim::sample_surface(shape, n, s); },
         [shape](std::uint64_t s) { return sim::tactile_patches(shape, sim::PatchConfig{}, s); }});
    lib.add(name, objects.back().sample(8000, 1));
  };
  add("sphere 40", sim::Sphere(0.04));
  add("sphere 25", sim::Sphere(0.025));
  add("cylinder 30 x 100", sim::Cylinder(0.03, 0.05));
  add("cylinder 20 x 60", sim::Cylinder(0.02, 0.03));
  add("box 80 x 60 x 40", sim::Box(Vec3d(0.04, 0.03, 0.02)));
  add("cube 50", sim::Box(Vec3d(0.025, 0.025, 0.025)));
  add("bar 120 x 40 x 20", sim::Box(Vec3d(0.06, 0.02, 0.01)));
  REQUIRE(lib.size() == 7);
  // The same models recognised on one thread and on three.
  ObjectLibrary<double> serial(LibraryConfig{.threads = 1});
  ObjectLibrary<double> threaded(LibraryConfig{.threads = 3});
  for (std::size_t m = 0; m < lib.size(); ++m) {
    serial.add(lib.name(m), objects[m].sample(8000, 1));
    threaded.add(lib.name(m), objects[m].sample(8000, 1));
  }

  std::mt19937_64 rng(2024);
  std::uniform_real_distribution<double> u(-0.2, 0.2);
  int right = 0;
  int total = 0;
  for (int trial = 0; trial < 4; ++trial) {
    for (std::size_t o = 0; o < objects.size(); ++o) {
      Eigen::Quaterniond q(Eigen::Vector4d(u(rng), u(rng), u(rng), u(rng)));
      q.normalize();
      Isometry3d T = Isometry3d::Identity();
      T.linear() = q.toRotationMatrix();
      T.translation() = Vec3d(u(rng), u(rng), u(rng));
      const PointCloud<double> cloud = transformed(objects[o].touch(100 + 13 * trial + o), T);
      const ObjectRecognition r = lib.recognize(cloud);
      REQUIRE(r.ok());
      if (trial < 2) {  // the same answer, to the bit, on one thread and on three
        const ObjectRecognition one = serial.recognize(cloud);
        const ObjectRecognition three = threaded.recognize(cloud);
        for (const ObjectRecognition* other : {&one, &three}) {
          REQUIRE(other->ranking.size() == r.ranking.size());
          CHECK(other->best == r.best);
          for (std::size_t k = 0; k < r.ranking.size(); ++k) {
            CHECK(other->ranking[k].model == r.ranking[k].model);
            CHECK(other->ranking[k].score == r.ranking[k].score);
            CHECK(other->ranking[k].starts_stopped_early == r.ranking[k].starts_stopped_early);
            CHECK(other->ranking[k].transform.matrix() == r.ranking[k].transform.matrix());
          }
        }
      }
      REQUIRE(r.ranking.size() == 7);
      CHECK(std::is_sorted(
          r.ranking.begin(), r.ranking.end(),
          [](const ModelMatch& a, const ModelMatch& b) { return a.score < b.score; }));
      CHECK(r.margin >= 0.0);
      ++total;
      right += r.best == objects[o].name ? 1 : 0;
      if (r.best == objects[o].name) {
        CHECK(r.ranking[0].exact);
        CHECK(r.ranking[0].score < 3e-3);  // about the 1 mm noise
      }
    }
  }
  INFO("top-1 " << right << " / " << total);
  CHECK(right >= static_cast<int>(std::ceil(0.95 * total)));

  // A cloud unlike every model: unknown.
  PointCloud<double> blob;
  std::uniform_real_distribution<double> v(-0.03, 0.03);
  for (int i = 0; i < 500; ++i) blob.points.emplace_back(v(rng), v(rng), v(rng));
  const ObjectRecognition none = lib.recognize(blob);
  CHECK(none.unknown);
  CHECK(none.best == "unknown");

  PointCloud<double> few;
  few.points = {Vec3d::Zero(), Vec3d::UnitX(), Vec3d(std::nan(""), 0, 0)};
  const ObjectRecognition bad = lib.recognize(few);
  CHECK(bad.status == Status::invalid_input);
  CHECK_THAT(bad.message, Contains("2 finite cloud points"));
  CHECK(ObjectLibrary<double>{}.recognize(blob).status == Status::invalid_input);
  CHECK_THROWS_WITH(lib.add("cube 50", objects[0].sample(100, 1)), Contains("'cube 50' exists"));
  CHECK_THROWS_WITH(ObjectLibrary<double>(LibraryConfig{.field_cell = -1.0}),
                    Contains("field_cell"));
  CHECK_THROWS_WITH(ObjectLibrary<double>(LibraryConfig{.rotation_starts = 30}),
                    Contains("rotation_starts"));
}

TEST_CASE("Registration works on float clouds", "[registration][icp]") {
  const PointCloud<double> model = asymmetric(4000, 12);
  PointCloud<float> mf;
  for (std::size_t i = 0; i < model.size(); ++i) {
    mf.points.push_back(model.points[i].cast<float>());
    mf.normals.push_back(model.normals[i].cast<float>());
  }
  const Target<float> tg(mf, TargetConfig{.field_cell = 2e-3});
  const Isometry3d truth = pose(0.1, Vec3d(0, 1, 0), Vec3d(0.002, 0.001, 0.0));
  std::vector<Vec3f> source;
  for (std::size_t i = 0; i < model.size(); i += 4)
    source.push_back((truth.inverse() * model.points[i]).cast<float>());
  const IcpResult r =
      Icp<PointToPlane>(IcpConfig{.coarse_points = 300}).align(tg, std::span<const Vec3f>(source));
  CHECK(r.ok());
  CHECK(rotation_error(r.transform, truth) < 1e-5);
  CHECK((r.transform.translation() - truth.translation()).norm() < 1e-5);
  ObjectLibrary<float> lib;
  lib.add("object", mf);
  PointCloud<float> cloud;
  cloud.points = source;
  CHECK(lib.recognize(cloud).best == "object");
}

TEST_CASE("Point-to-point ICP on 1-point, 2-point and collinear targets is degenerate",
          "[registration][icp][reliability]") {
  Icp<PointToPoint> p2p(IcpConfig{.max_iterations = 30});
  std::vector<Vec3d> source;
  for (int i = 0; i < 40; ++i) {
    source.emplace_back(0.01 * std::cos(0.3 * i), 0.008 * std::sin(0.5 * i), 0.002 * (i % 7));
  }
  const auto target_of = [](std::vector<Vec3d> pts) {
    PointCloud<double> c;
    c.points = std::move(pts);
    return Target<double>(std::move(c));
  };
  for (const auto& pts :
       {std::vector<Vec3d>{Vec3d(0, 0, 0)}, std::vector<Vec3d>{Vec3d(0, 0, 0), Vec3d(0.01, 0, 0)},
        std::vector<Vec3d>{Vec3d(0, 0, 0), Vec3d(0.01, 0, 0), Vec3d(0.02, 0, 0),
                           Vec3d(0.03, 0, 0)}}) {
    const Target<double> tg = target_of(pts);
    const IcpResult r = p2p.align(tg, std::span<const Vec3d>(source));
    CHECK(r.status == Status::degenerate);
    CHECK_THAT(r.message, Contains("target points are collinear or fewer than three"));
    CHECK(r.transform.matrix().allFinite());
  }
}

TEST_CASE("Target sizes its closest-point field to the model, never failing on a legal model",
          "[registration][reliability]") {
  // A model in millimetres (a 40 mm sphere written as radius 40) with the metre-scale default
  // cell: the field grows its cell to stay within field_max_cells.
  PointCloud<double> mm = sim::sample_surface(sim::Sphere(40.0), 2000, 5);
  const Target<double> tg(mm, TargetConfig{.field_cell = 2e-3, .field_max_cells = 1 << 18});
  CHECK(tg.has_field());
  CHECK(tg.field_cell() > 2e-3);
  // Exact queries stay exact.
  const index::BruteForce<double> brute = [&] {
    index::BruteForce<double> b;
    for (std::size_t i = 0; i < mm.points.size(); ++i) {
      b.insert(static_cast<index::PointId>(i), mm.points[i]);
    }
    return b;
  }();
  for (const Vec3d& q : {Vec3d(0, 0, 0), Vec3d(45, 3, -2), Vec3d(-10, 70, 5)}) {
    const auto a = tg.nearest_within(q, 1e9);
    const auto b = brute.nearest_within(q, 1e9);
    REQUIRE(a.has_value());
    CHECK(a->id == b->id);
  }
  // Float coordinates near the float limit: the field's counts never reach an int cast.
  PointCloud<float> huge;
  huge.points = {Vec3<float>(-1e37f, 0, 0), Vec3<float>(1e37f, 0, 0), Vec3<float>(0, 1e37f, 0),
                 Vec3<float>(0, 0, 1e37f)};
  const Target<float> big(huge, TargetConfig{.field_cell = 1e-3, .field_max_cells = 4096});
  CHECK(big.has_field());
  CHECK_THROWS_WITH(Target<double>(mm, TargetConfig{.field_cell = 1e-3, .field_max_cells = 0}),
                    Contains("field_max_cells"));
}

TEST_CASE("Meshes of uneven vertex density are recognised by their surface, not their vertices",
          "[registration][recognition][mesh]") {
  // A 12-triangle box (8 vertices), a cylinder of 514 vertices and an icosphere of 2 562: as
  // vertex clouds the sphere is dense everywhere and the box only at its corners. Each model
  // file holds the mesh (PLY: vertices and faces), read back as a user's would be.
  const sim::Box box(Vec3d(0.04, 0.03, 0.02));
  const sim::Cylinder cyl(0.03, 0.05);
  const sim::Sphere sphere(0.04);
  const std::vector<std::pair<std::string, sim::TriangleMesh>> meshes{
      {"box", sim::box_mesh(box)},
      {"cylinder", sim::cylinder_mesh(cyl, 256)},
      {"sphere", sim::icosphere(sphere.radius, 4)}};
  ObjectLibrary<double> by_surface;
  for (const auto& [name, mesh] : meshes) {
    PointCloud<double> vertices;
    vertices.points = mesh.vertices();
    const std::string bytes =
        io::encode_ply(vertices, io::PlyFormat::binary_little_endian, mesh.triangles());
    const ModelCloud m = model_cloud(io::parse_ply(bytes, name + ".ply"));
    CHECK(m.from_surface);
    CHECK(m.triangles == mesh.triangles().size());
    CHECK(m.cloud.size() ==
          static_cast<std::size_t>(std::ceil(sim::surface_area(mesh) / (m.spacing * m.spacing))));
    CHECK_THAT(m.describe(), Catch::Matchers::Contains("points sampled area-uniformly"));
    by_surface.add(name, m.cloud);
  }
  // Partial, noisy, posed touches of the true shapes.
  std::mt19937_64 rng(31);
  std::uniform_real_distribution<double> u(-0.2, 0.2);
  const auto touch = [&](const auto& shape, std::uint64_t seed) {
    Eigen::Quaterniond q(Eigen::Vector4d(u(rng), u(rng), u(rng), u(rng)));
    q.normalize();
    Isometry3d t = Isometry3d::Identity();
    t.linear() = q.toRotationMatrix();
    t.translation() = Vec3d(u(rng), u(rng), u(rng));
    return transformed(sim::tactile_patches(shape, sim::PatchConfig{}, seed), t);
  };
  for (int trial = 0; trial < 3; ++trial) {
    const auto seed = static_cast<std::uint64_t>(40 + trial);
    CHECK(by_surface.recognize(touch(box, seed)).best == "box");
    CHECK(by_surface.recognize(touch(cyl, seed)).best == "cylinder");
    CHECK(by_surface.recognize(touch(sphere, seed)).best == "sphere");
  }
  // Spacing 0 keeps the vertices; a face naming a missing vertex and a surface of zero area are
  // refused; faces of zero area are skipped and counted.
  io::PlyData flat;
  flat.cloud.points = {Vec3d::Zero(), Vec3d::UnitX(), Vec3d::UnitY(), Vec3d::UnitX()};
  flat.triangles = {{0, 1, 2}, {0, 1, 3}};
  const ModelCloud kept = model_cloud(flat, {.spacing = 0.0});
  CHECK((!kept.from_surface && kept.cloud.size() == 4 && kept.describe() == "4 vertices"));
  const ModelCloud skipped = model_cloud(flat, {.spacing = 0.1});
  CHECK((skipped.from_surface && skipped.triangles == 1 && skipped.degenerate == 1));
  CHECK(skipped.cloud.size() == 50);  // 0.5 m^2 / 0.01 m^2
  flat.triangles = {{0, 1, 3}};
  CHECK_THROWS_WITH(model_cloud(flat), Catch::Matchers::Contains("every face has zero area"));
  flat.triangles = {{0, 1, 7}};
  CHECK_THROWS_WITH(model_cloud(flat), Catch::Matchers::Contains("names vertex 7 of 4"));
}
