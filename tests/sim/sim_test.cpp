// SPDX-License-Identifier: MIT
// Tests of taxel::sim shapes (against closed forms and brute-force surface samples) and of the
// sliding exploration stream.
#include <catch2/catch.hpp>
#include <random>
#include <taxel/sim.hpp>

namespace ts = taxel::sim;

namespace {
// Checks the shape laws at random points: the closest point lies on the surface (sd = 0), its
// distance equals |sd|, and the normal is a unit vector pointing from the surface to outside.
template <class Sh>
void check_shape_laws(const Sh& shape, double scale) {
  std::mt19937 rng(21);
  std::normal_distribution<double> g(0.0, scale);
  for (int i = 0; i < 2000; ++i) {
    const taxel::Vec3d p(g(rng), g(rng), g(rng));
    const taxel::Vec3d c = shape.closest_point(p);
    const double sd = shape.signed_distance(p);
    CHECK(std::abs(shape.signed_distance(c)) < 1e-12);
    CHECK((p - c).norm() == Approx(std::abs(sd)).margin(1e-12));
    const taxel::Vec3d n = shape.normal(p);
    CHECK(n.norm() == Approx(1.0));
    CHECK(shape.signed_distance(c + 1e-6 * n) == Approx(1e-6).margin(1e-9));
  }
}
}  // namespace

TEST_CASE("shapes: closest points lie on the surface at the signed distance") {
  check_shape_laws(ts::Sphere(0.04), 0.05);
  check_shape_laws(ts::Cylinder(0.03, 0.05), 0.05);
  check_shape_laws(ts::Box(), 0.05);
  CHECK(ts::Box().signed_distance({0, 0, 0}) == Approx(-0.02));
  CHECK(ts::Box().signed_distance({0.05, 0.04, 0}) == Approx(std::hypot(0.01, 0.01)));
  CHECK(ts::Cylinder(0.03, 0.05).signed_distance({0, 0, 0.07}) == Approx(0.02));
  CHECK(ts::Sphere(0.04).signed_distance({0, 0.1, 0}) == Approx(0.06));
  CHECK_THROWS_AS(ts::Sphere(-1), std::invalid_argument);
}

TEST_CASE("sliding exploration is deterministic and stays on the surface within its noise") {
  const ts::Sphere sphere(0.04);
  const auto a = ts::sliding_exploration(sphere, 3000, {.seed = 5});
  const auto b = ts::sliding_exploration(sphere, 3000, {.seed = 5});
  const auto c = ts::sliding_exploration(sphere, 3000, {.seed = 6});
  REQUIRE(a.size() == 3000);
  CHECK(a[2999].position == b[2999].position);
  CHECK(a[2999].position != c[2999].position);
  for (const auto& contact : a) {
    CHECK(taxel::check_contact(contact) == taxel::ContactDefect::ok);
  }
  const auto err = ts::surface_error(sphere, [&] {
    std::vector<taxel::Vec3d> p;
    for (const auto& x : a) p.push_back(x.position);
    return p;
  }());
  // Normal noise 1 mm, position noise 0.2 mm, tilt lever arms < 0.3 mm: RMS about 1.1 mm.
  CHECK(err.rms > 0.7e-3);
  CHECK(err.rms < 1.6e-3);
  CHECK(a.back().time > a.front().time);
}
