// SPDX-License-Identifier: MIT
// Tests of taxel/core: contact covariance helpers, validation, status, assertions, errors.
#include <Eigen/Eigenvalues>
#include <atomic>
#include <catch2/catch.hpp>
#include <cmath>
#include <limits>
#include <random>
#include <stdexcept>
#include <taxel/core.hpp>
#include <taxel/core/parallel.hpp>

using Catch::Matchers::Contains;

TEMPLATE_TEST_CASE("pad_covariance has sigma_n^2 along the normal and sigma_t^2 across it", "",
                   float, double) {
  using S = TestType;
  std::mt19937 rng(7);
  std::normal_distribution<S> g;
  const S tol = std::is_same_v<S, float> ? S(1e-4) : S(1e-10);
  for (int trial = 0; trial < 50; ++trial) {
    const taxel::Vec3<S> raw(g(rng), g(rng), g(rng));
    const taxel::Vec3<S> n = raw.normalized();
    const S sn = S(2e-3), st = S(0.98e-3);
    // The helper normalises; pass a scaled normal to check that too.
    const taxel::Mat3<S> c = taxel::pad_covariance<S>(raw * S(3), sn, st);
    const Eigen::SelfAdjointEigenSolver<taxel::Mat3<S>> es(c);
    // Eigenvalues ascending: st^2, st^2, sn^2 (sn > st).
    CHECK(es.eigenvalues()(0) == Approx(st * st).epsilon(tol));
    CHECK(es.eigenvalues()(1) == Approx(st * st).epsilon(tol));
    CHECK(es.eigenvalues()(2) == Approx(sn * sn).epsilon(tol));
    // The largest eigenvector is the normal (up to sign), and n'Cn = sn^2 directly.
    CHECK(std::abs(es.eigenvectors().col(2).dot(n)) == Approx(1).epsilon(tol));
    CHECK(n.dot(c * n) == Approx(sn * sn).epsilon(tol));
    // Any tangent direction sees st^2.
    const taxel::Vec3<S> t = n.unitOrthogonal();
    CHECK(t.dot(c * t) == Approx(st * st).epsilon(tol));
    CHECK(taxel::is_symmetric_positive_definite(c));
  }
}

TEST_CASE("pad_covariance rejects a zero normal and non-positive sigmas") {
  using V = taxel::Vec3d;
  CHECK_THROWS_WITH(taxel::pad_covariance(V(0, 0, 0), 1e-3, 1e-3), Contains("normal"));
  CHECK_THROWS_WITH(taxel::pad_covariance(V(0, 0, std::nan("")), 1e-3, 1e-3), Contains("normal"));
  CHECK_THROWS_WITH(taxel::pad_covariance(V(0, 0, 1), 0.0, 1e-3), Contains("sigma"));
  CHECK_THROWS_WITH(taxel::pad_covariance(V(0, 0, 1), 1e-3, -1.0), Contains("sigma"));
  CHECK_THROWS_AS(taxel::pad_covariance(V(0, 0, 1), 1e-3, std::numeric_limits<double>::infinity()),
                  std::invalid_argument);
  CHECK_THROWS_AS(taxel::isotropic_covariance(0.0), std::invalid_argument);
  CHECK(taxel::isotropic_covariance(2.0)(1, 1) == 4.0);
}

TEST_CASE("tactel_sigma is the standard deviation of a uniform distribution over one pitch") {
  // Var of U(0, a) = a^2 / 12.
  CHECK(taxel::tactel_sigma(3.4e-3) == Approx(3.4e-3 / std::sqrt(12.0)));
  CHECK(taxel::tactel_sigma(3.4e-3) == Approx(0.98149e-3).epsilon(1e-4));
}

TEST_CASE("check_contact names each defect of a contact") {
  taxel::Contact<double> c;
  c.position = {0.1, -0.2, 0.3};
  REQUIRE(taxel::check_contact(c) == taxel::ContactDefect::ok);

  auto with = [&](auto&& edit) {
    taxel::Contact<double> d = c;
    edit(d);
    return taxel::check_contact(d);
  };
  using D = taxel::ContactDefect;
  constexpr double nan = std::numeric_limits<double>::quiet_NaN();
  constexpr double inf = std::numeric_limits<double>::infinity();
  CHECK(with([&](auto& d) { d.position.x() = nan; }) == D::non_finite_position);
  CHECK(with([&](auto& d) { d.position.z() = -inf; }) == D::non_finite_position);
  CHECK(with([&](auto& d) { d.covariance(1, 2) = nan; }) == D::non_finite_covariance);
  CHECK(with([&](auto& d) { d.covariance(0, 1) = 1e-7; }) == D::asymmetric_covariance);
  CHECK(with([&](auto& d) { d.covariance(2, 2) = -1e-6; }) == D::indefinite_covariance);
  CHECK(with([&](auto& d) { d.covariance.setZero(); }) == D::indefinite_covariance);
  // Symmetric with positive diagonal but indefinite (off-diagonal too large).
  CHECK(with([&](auto& d) {
          d.covariance(0, 1) = 2e-6;
          d.covariance(1, 0) = 2e-6;
        }) == D::indefinite_covariance);
  CHECK(with([&](auto& d) { d.normal = taxel::Vec3d(0, 0, 2); }) == D::bad_normal);
  CHECK(with([&](auto& d) { d.normal = taxel::Vec3d(0, 0, 1); }) == D::ok);
  CHECK(with([&](auto& d) { d.normal = taxel::Vec3d(nan, 0, 1); }) == D::bad_normal);
  CHECK(with([&](auto& d) { d.normal = taxel::Vec3d(0, inf, 0); }) == D::bad_normal);
  CHECK(with([&](auto& d) { d.normal = taxel::Vec3d(1e200, 0, 0); }) == D::bad_normal);
  CHECK(with([&](auto& d) { d.normal = taxel::Vec3d(0, 0, 0); }) == D::bad_normal);
  // The unit-length tolerance is 1e-3 on |n|, either side.
  CHECK(with([&](auto& d) { d.normal = taxel::Vec3d(0, 0.6 * 1.0009, 0.8 * 1.0009); }) == D::ok);
  CHECK(with([&](auto& d) { d.normal = taxel::Vec3d(0, 0, 0.9991); }) == D::ok);
  CHECK(with([&](auto& d) { d.normal = taxel::Vec3d(0, 0.6 * 1.0011, 0.8 * 1.0011); }) ==
        D::bad_normal);
  CHECK(with([&](auto& d) { d.normal = taxel::Vec3d(0, 0, 0.9989); }) == D::bad_normal);
  // Rounding-level asymmetry is tolerated.
  CHECK(with([&](auto& d) { d.covariance(0, 1) = 1e-22; }) == D::ok);
  CHECK(taxel::to_string(D::indefinite_covariance) == "covariance is not positive definite");
}

TEST_CASE("Result carries a status and a message") {
  auto ok = taxel::Result<int>::success(42);
  CHECK(ok.ok());
  CHECK(static_cast<bool>(ok));
  CHECK(ok.value == 42);
  auto bad = taxel::Result<int>::failure(taxel::Status::degenerate, "collinear points");
  CHECK_FALSE(bad.ok());
  CHECK(bad.status == taxel::Status::degenerate);
  CHECK(bad.message == "collinear points");
  CHECK(taxel::to_string(taxel::Status::not_converged) == "not_converged");
  CHECK(taxel::to_string(taxel::Status::invalid_input) == "invalid_input");
}

namespace {
struct Caught {
  std::string expression, message;
  int line = 0;
};
Caught last_assert;
[[noreturn]] void recording_handler(const char* e, const char* m, const char*, int line) {
  last_assert = {e, m, line};
  throw std::runtime_error("recorded");
}
}  // namespace

TEST_CASE("TAXEL_ASSERT throws AssertionError by default and calls a replaced handler") {
  REQUIRE(TAXEL_ASSERTS_ACTIVE == 1);
  CHECK_THROWS_AS([] { TAXEL_ASSERT(1 + 1 == 3, "arithmetic"); }(), taxel::AssertionError);
  CHECK_THROWS_WITH([] { TAXEL_ASSERT(false, "the reason"); }(), Contains("the reason"));
  CHECK_NOTHROW([] { TAXEL_ASSERT(true, "never"); }());

  const auto previous = taxel::set_assert_handler(&recording_handler);
  CHECK_THROWS_WITH([] { TAXEL_ASSERT(2 < 1, "order"); }(), "recorded");
  CHECK(last_assert.expression == "2 < 1");
  CHECK(last_assert.message == "order");
  CHECK(last_assert.line > 0);
  taxel::set_assert_handler(previous);
  CHECK_THROWS_AS([] { TAXEL_ASSERT(false, "restored"); }(), taxel::AssertionError);
  taxel::set_assert_handler(nullptr);
  CHECK_THROWS_AS([] { TAXEL_ASSERT(false, "default"); }(), taxel::AssertionError);
}

TEST_CASE("IoError and ProtocolError say where the input was wrong") {
  const taxel::IoError line_err("cloud.ply", "expected 'end_header'", 12);
  CHECK(std::string(line_err.what()) == "cloud.ply:12: expected 'end_header'");
  CHECK(line_err.line() == 12u);
  CHECK_FALSE(line_err.byte_offset().has_value());
  const taxel::IoError byte_err("cloud.ply", "truncated vertex", std::nullopt, 4096);
  CHECK(std::string(byte_err.what()) == "cloud.ply: byte 4096: truncated vertex");
  const taxel::ProtocolError p("/dev/ttyUSB0", "CRC mismatch", 0x00);
  CHECK(std::string(p.what()) == "/dev/ttyUSB0: CRC mismatch");
  CHECK(p.packet_id() == 0);
}

TEST_CASE("PointCloud validates its size invariants and transforms points and normals") {
  taxel::PointCloud<double> c;
  c.points = {{1, 0, 0}, {0, 1, 0}};
  CHECK(c.validate().ok());
  CHECK_FALSE(c.has_normals());
  c.normals = {{0, 0, 1}};
  CHECK(c.validate().status == taxel::Status::invalid_input);
  c.normals.push_back({0, 0, 1});
  CHECK(c.has_normals());
  auto& f = c.field_or_add("observations");
  CHECK(f.values.size() == 2);
  f.values = {3, 4};
  REQUIRE(c.field("observations") != nullptr);
  CHECK(c.field("observations")->values[1] == 4);
  CHECK(c.field("missing") == nullptr);
  c.fields[0].values.pop_back();
  CHECK_THAT(c.validate().message, Contains("observations"));
  c.fields[0].values.push_back(4);
  c.points[1].y() = std::nan("");
  CHECK_THAT(c.validate().message, Contains("point 1"));
  c.points[1].y() = 1;

  taxel::Isometry3d T = taxel::Isometry3d::Identity();
  T.linear() = Eigen::AngleAxisd(M_PI / 2, taxel::Vec3d::UnitZ()).toRotationMatrix();
  T.translation() = taxel::Vec3d(0, 0, 5);
  const auto t = taxel::transformed(c, T);
  CHECK(t.points[0].isApprox(taxel::Vec3d(0, 1, 5)));
  CHECK(t.normals[0].isApprox(taxel::Vec3d(0, 0, 1)));
}

TEST_CASE("the version header matches the CMake project version") {
  CHECK(std::string(TAXEL_VERSION_STRING) == TAXEL_EXPECTED_VERSION);
}

TEST_CASE("parallel_for calls every item once and rethrows the lowest failing item",
          "[core][threads]") {
  for (const unsigned threads : {0u, 1u, 2u, 7u}) {
    std::vector<int> hits(1000, 0);
    taxel::parallel_for(hits.size(), threads, [&](std::size_t i) { hits[i] += 1; });
    CHECK(std::count(hits.begin(), hits.end(), 1) == 1000);
  }
  taxel::parallel_for(0, 4, [](std::size_t) { FAIL("no item"); });
  // Items 3 and 5 throw; whichever thread meets which first, item 3's exception comes out when
  // it ran, and no item runs twice.
  std::vector<std::atomic<int>> ran(50);
  try {
    taxel::parallel_for(ran.size(), 2, [&](std::size_t i) {
      ran[i].fetch_add(1);
      if (i == 3 || i == 5) throw std::runtime_error("item " + std::to_string(i));
    });
    FAIL("no exception");
  } catch (const std::runtime_error& e) {
    CHECK(std::string(e.what()) == "item 3");
  }
  for (const auto& r : ran) CHECK(r.load() <= 1);
  CHECK(taxel::resolve_threads(3) == 3);
  CHECK(taxel::resolve_threads(0) >= 1);
}
