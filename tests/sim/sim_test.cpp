// SPDX-License-Identifier: MIT
// Tests of taxel::sim shapes (against closed forms and brute-force surface samples) and of the
// sliding exploration stream.
#include <catch2/catch.hpp>
#include <cmath>
#include <limits>
#include <numbers>
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

TEST_CASE("Reconstruction metrics: distances, coverage, compaction", "[sim][metrics]") {
  const taxel::sim::Sphere sphere(0.04);
  const auto dense = taxel::sim::sample_surface(sphere, 20000, 3);
  const auto full = taxel::sim::reconstruction_metrics(sphere, dense.points, 100000);
  CHECK(full.error.max < 1e-12);
  CHECK(full.coverage == 1.0);
  CHECK(full.points == 20000);
  CHECK(full.compaction == Approx(5.0));
  // The upper half only, 1 mm off the surface: half covered (within the 5 mm radius, a thin
  // band beyond the equator too), and every distance 1 mm.
  std::vector<taxel::Vec3d> half;
  for (const auto& p : dense.points) {
    if (p.z() > 0) half.push_back(p * (0.041 / 0.04));
  }
  const auto m = taxel::sim::reconstruction_metrics(sphere, half, half.size());
  CHECK(m.error.mean == Approx(1e-3).epsilon(1e-9));
  CHECK(m.error.max == Approx(1e-3).epsilon(1e-9));
  CHECK(m.coverage > 0.5);
  CHECK(m.coverage < 0.5 + 0.1);
  CHECK(m.compaction == 1.0);
  const auto empty = taxel::sim::reconstruction_metrics(sphere, {}, 0);
  CHECK(empty.coverage == 0.0);
  CHECK(empty.compaction == 0.0);
  CHECK_THROWS_AS(taxel::sim::reconstruction_metrics(sphere, half, 1, {.coverage_radius = 0.0}),
                  std::invalid_argument);
}

TEST_CASE("Cone: exact closest point, signed distance, normals, uniform sampling",
          "[sim][shapes]") {
  const taxel::sim::Cone cone(0.03, 0.06);
  // Dense surface samples as a brute-force oracle: no sample is nearer than the exact distance,
  // and the nearest sample is within the sampling spacing of it.
  const auto samples = taxel::sim::sample_surface(cone, 200000, 5);
  for (const auto& p : samples.points) REQUIRE(std::abs(cone.signed_distance(p)) < 1e-12);
  std::mt19937_64 rng(8);
  std::uniform_real_distribution<double> u(-0.06, 0.06);
  for (int q = 0; q < 300; ++q) {
    const taxel::Vec3d p(u(rng), u(rng), u(rng));
    const double d = cone.signed_distance(p);
    const taxel::Vec3d c = cone.closest_point(p);
    REQUIRE(std::abs(cone.signed_distance(c)) < 1e-12);            // on the surface
    REQUIRE((p - c).norm() == Approx(std::abs(d)).margin(1e-12));  // at the distance
    double nearest = 1e9;
    for (const auto& s : samples.points) nearest = std::min(nearest, (s - p).norm());
    REQUIRE(nearest >= std::abs(d) - 1e-12);
    REQUIRE(nearest <= std::abs(d) + 1.5e-3);
    const taxel::Vec3d n = cone.normal(p);
    REQUIRE(n.norm() == Approx(1.0).epsilon(1e-12));
    if (std::abs(d) > 1e-9) {  // away from the surface, the normal points from c towards p
      REQUIRE(n.dot(p - c) * (d > 0 ? 1.0 : -1.0) > 0.0);
    }
  }
  CHECK(cone.signed_distance(taxel::Vec3d(0, 0, 0)) < 0);                 // inside
  CHECK(cone.signed_distance(taxel::Vec3d(0, 0, 0.04)) == Approx(0.01));  // above the apex
  CHECK(cone.normal(taxel::Vec3d(0.001, 0, -0.05)) == taxel::Vec3d(0, 0, -1));
  // Area-uniform sampling: the base holds pi R^2 / area of the samples.
  std::size_t on_base = 0;
  for (const auto& p : samples.points) on_base += p.z() < -0.03 + 1e-12 ? 1 : 0;
  const double expected = 3.14159265358979 * 0.03 * 0.03 / taxel::sim::surface_area(cone);
  CHECK(static_cast<double>(on_base) / static_cast<double>(samples.size()) ==
        Approx(expected).margin(0.01));
  CHECK_THROWS_AS(taxel::sim::Cone(0.0, 1.0), std::invalid_argument);
}

namespace {
// Brute force against dense area-uniform samples: no sample nearer than the exact distance, the
// nearest within the sampling spacing; the normal points from the closest point to the query.
template <class Sh>
void check_against_samples(const Sh& shape, double extent, double spacing) {
  const auto samples = taxel::sim::sample_surface(shape, 200000, 5);
  for (const auto& p : samples.points) REQUIRE(std::abs(shape.signed_distance(p)) < 1e-12);
  for (std::size_t i = 0; i < samples.size(); i += 997) {  // sampled normals are the shape's
    REQUIRE((shape.normal(samples.points[i]) - samples.normals[i]).norm() < 1e-9);
  }
  std::mt19937_64 rng(8);
  std::uniform_real_distribution<double> u(-extent, extent);
  for (int q = 0; q < 300; ++q) {
    const taxel::Vec3d p(u(rng), u(rng), u(rng));
    const double d = shape.signed_distance(p);
    const taxel::Vec3d c = shape.closest_point(p);
    REQUIRE(std::abs(shape.signed_distance(c)) < 1e-12);
    REQUIRE((p - c).norm() == Approx(std::abs(d)).margin(1e-12));
    double nearest = 1e9;
    for (const auto& s : samples.points) nearest = std::min(nearest, (s - p).norm());
    REQUIRE(nearest >= std::abs(d) - 1e-12);
    REQUIRE(nearest <= std::abs(d) + spacing);
    const taxel::Vec3d n = shape.normal(p);
    REQUIRE(n.norm() == Approx(1.0).epsilon(1e-12));
    if (std::abs(d) > 1e-9) REQUIRE(n.dot(p - c) * (d > 0 ? 1.0 : -1.0) > 0.0);
  }
}
}  // namespace

TEST_CASE("Ellipsoid: closest point against brute force, area, uniform sampling", "[sim][shapes]") {
  const taxel::sim::Ellipsoid el(taxel::Vec3d(0.05, 0.035, 0.025));
  check_shape_laws(el, 0.05);
  check_against_samples(el, 0.07, 1.5e-3);
  // Closed forms: on the axes, and a point on a symmetry plane inside (the mirror case).
  CHECK(el.signed_distance(taxel::Vec3d(0.08, 0, 0)) == Approx(0.03));
  CHECK(el.signed_distance(taxel::Vec3d(0, 0, 0)) == Approx(-0.025));
  CHECK(el.closest_point(taxel::Vec3d(0, 0, 0.01)).z() == Approx(0.025));
  // The sphere as a special case, and the area against the sphere's and a prolate spheroid's
  // closed form 2 pi a^2 (1 + c / (a e) asin e), e^2 = 1 - a^2 / c^2.
  CHECK(taxel::sim::surface_area(taxel::sim::Ellipsoid(taxel::Vec3d(0.02, 0.02, 0.02))) ==
        Approx(4 * 3.14159265358979 * 4e-4).epsilon(1e-6));
  const double a = 0.02, c = 0.05, e = std::sqrt(1 - a * a / (c * c));
  CHECK(taxel::sim::surface_area(taxel::sim::Ellipsoid(taxel::Vec3d(a, a, c))) ==
        Approx(2 * 3.14159265358979 * a * a * (1 + c / (a * e) * std::asin(e))).epsilon(1e-6));
  // Area-uniform: the fraction of samples with |z| > c / 2 against the area quadrature of that
  // band, done by brute force over a fine (u, v) grid of the same ellipsoid.
  const auto samples = taxel::sim::sample_surface(el, 100000, 9);
  std::size_t high = 0;
  for (const auto& p : samples.points) high += std::abs(p.z()) > 0.0125 ? 1 : 0;
  double band = 0.0, total = 0.0;
  const int n = 400;
  for (int i = 0; i < n; ++i) {
    const double u = (i + 0.5) * 3.14159265358979 / n;
    for (int j = 0; j < n; ++j) {
      const double v = (j + 0.5) * 2 * 3.14159265358979 / n;
      const taxel::Vec3d du(0.05 * std::cos(u) * std::cos(v), 0.035 * std::cos(u) * std::sin(v),
                            -0.025 * std::sin(u));
      const taxel::Vec3d dv(-0.05 * std::sin(u) * std::sin(v), 0.035 * std::sin(u) * std::cos(v),
                            0.0);
      const double dA = du.cross(dv).norm();
      total += dA;
      band += std::abs(0.025 * std::cos(u)) > 0.0125 ? dA : 0.0;
    }
  }
  CHECK(double(high) / double(samples.size()) == Approx(band / total).margin(0.006));
  CHECK_THROWS_AS(taxel::sim::Ellipsoid(taxel::Vec3d(0.01, 0, 0.01)), std::invalid_argument);
}

TEST_CASE("Torus: closest point against brute force, area, uniform sampling", "[sim][shapes]") {
  const taxel::sim::Torus torus(0.04, 0.015);
  check_shape_laws(torus, 0.05);
  check_against_samples(torus, 0.06, 1.5e-3);
  CHECK(torus.signed_distance(taxel::Vec3d(0, 0, 0)) == Approx(0.025));
  CHECK(torus.signed_distance(taxel::Vec3d(0.04, 0, 0)) == Approx(-0.015));
  CHECK(torus.signed_distance(taxel::Vec3d(0, 0.04, 0.02)) == Approx(0.005));
  CHECK(taxel::sim::surface_area(torus) == Approx(4 * 9.8696044010894 * 0.04 * 0.015));
  // Area-uniform: the outer half (distance from the axis > R) holds (pi R + 2 r) / (2 pi R) of
  // the area (integral of R + r cos theta over |theta| < pi / 2).
  const auto samples = taxel::sim::sample_surface(torus, 100000, 9);
  std::size_t outer = 0;
  for (const auto& p : samples.points) outer += std::hypot(p.x(), p.y()) > 0.04 ? 1 : 0;
  CHECK(
      double(outer) / double(samples.size()) ==
      Approx((3.14159265358979 * 0.04 + 2 * 0.015) / (2 * 3.14159265358979 * 0.04)).margin(0.006));
  CHECK_THROWS_AS(taxel::sim::Torus(0.01, 0.02), std::invalid_argument);
}

TEST_CASE(
    "TriangleMesh: exact on its own surface, within the chord error of the shape it "
    "approximates",
    "[sim][shapes][mesh]") {
  const taxel::sim::Sphere sphere(0.04);
  const taxel::sim::TriangleMesh mesh = taxel::sim::icosphere(0.04, 3);
  REQUIRE(mesh.triangles().size() == 1280);
  // Chord error: the largest gap between the sphere and the faces (at the face centres).
  double chord = 0.0;
  for (std::size_t f = 0; f < mesh.triangles().size(); ++f) {
    const auto& v = mesh.vertices()[mesh.triangles()[f][0]];
    chord = std::max(chord, 0.04 - std::abs(mesh.face_normal(f).dot(v)));
    REQUIRE(mesh.face_normal(f).dot(v) > 0.0);  // counter-clockwise from outside
  }
  const auto samples = taxel::sim::sample_surface(mesh, 50000, 2);
  std::mt19937_64 rng(4);
  std::uniform_real_distribution<double> u(-0.06, 0.06);
  for (int q = 0; q < 200; ++q) {
    const taxel::Vec3d p(u(rng), u(rng), u(rng));
    const double d = mesh.signed_distance(p);
    const taxel::Vec3d c = mesh.closest_point(p);
    REQUIRE(std::abs(mesh.signed_distance(c)) < 1e-12);
    REQUIRE((p - c).norm() == Approx(std::abs(d)).margin(1e-12));
    double nearest = 1e9;
    for (const auto& s : samples.points) nearest = std::min(nearest, (s - p).norm());
    REQUIRE(nearest >= std::abs(d) - 1e-12);
    REQUIRE(std::abs(d - sphere.signed_distance(p)) <= chord + 1e-12);
    if (std::abs(sphere.signed_distance(p)) > chord)
      REQUIRE((d > 0) == (sphere.signed_distance(p) > 0));
    REQUIRE(mesh.normal(p).dot(sphere.normal(p)) > 0.9);
  }
  CHECK(taxel::sim::surface_area(mesh) == Approx(taxel::sim::surface_area(sphere)).epsilon(0.02));
  CHECK_THROWS_WITH(taxel::sim::TriangleMesh({taxel::Vec3d::Zero()}, {{0, 0, 1}}),
                    Catch::Matchers::Contains("refers to vertex 1 of 1"));
  CHECK_THROWS_WITH(
      taxel::sim::TriangleMesh({taxel::Vec3d::Zero(), taxel::Vec3d::UnitX(), taxel::Vec3d::UnitX()},
                               {{0, 1, 2}}),
      Catch::Matchers::Contains("no area"));
}

namespace {

// The closest point over every triangle by brute force: each triangle is a mesh of its own
// (where the hierarchy has one leaf), the lowest index winning ties, as documented.
struct BruteHit {
  taxel::Vec3d point;
  double d2 = std::numeric_limits<double>::infinity();
  std::size_t face = 0;
};
BruteHit brute_closest(const std::vector<taxel::sim::TriangleMesh>& single, const taxel::Vec3d& p) {
  BruteHit best;
  for (std::size_t f = 0; f < single.size(); ++f) {
    const taxel::Vec3d c = single[f].closest_point(p);
    const double d2 = (p - c).squaredNorm();
    if (d2 < best.d2) best = {c, d2, f};
  }
  return best;
}
std::vector<taxel::sim::TriangleMesh> one_mesh_per_triangle(const taxel::sim::TriangleMesh& m) {
  std::vector<taxel::sim::TriangleMesh> out;
  for (const auto& t : m.triangles()) {
    out.emplace_back(
        std::vector<taxel::Vec3d>{m.vertices()[t[0]], m.vertices()[t[1]], m.vertices()[t[2]]},
        std::vector<taxel::sim::TriangleMesh::Triangle>{{0, 1, 2}});
  }
  return out;
}

}  // namespace

TEST_CASE("TriangleMesh's hierarchy finds the same closest point as a scan of every triangle",
          "[sim][mesh]") {
  std::mt19937_64 rng(17);
  std::normal_distribution<double> jitter(0.0, 0.002);
  // An icosphere with its vertices moved about (uneven triangles), a cylinder with long thin
  // side facets and fans on the caps, and a box of twelve triangles.
  taxel::sim::TriangleMesh ico = taxel::sim::icosphere(0.03, 3);
  std::vector<taxel::Vec3d> moved = ico.vertices();
  for (auto& v : moved) v += taxel::Vec3d(jitter(rng), jitter(rng), jitter(rng));
  const std::vector<taxel::sim::TriangleMesh> meshes{
      taxel::sim::TriangleMesh(moved, ico.triangles()),
      taxel::sim::cylinder_mesh(taxel::sim::Cylinder(0.02, 0.05), 48),
      taxel::sim::box_mesh(taxel::sim::Box(taxel::Vec3d(0.04, 0.01, 0.02)))};
  std::uniform_real_distribution<double> u(-0.08, 0.08);
  for (const auto& mesh : meshes) {
    CAPTURE(mesh.triangles().size());
    CHECK(mesh.hierarchy_nodes() > 0);
    const auto single = one_mesh_per_triangle(mesh);
    std::vector<taxel::Vec3d> queries;
    for (int i = 0; i < 600; ++i) queries.emplace_back(u(rng), u(rng), u(rng));
    for (int i = 0; i < 100; ++i) queries.push_back(taxel::Vec3d(u(rng), u(rng), u(rng)) * 100.0);
    for (const auto& v : mesh.vertices()) queries.push_back(v);  // ties between faces
    for (const auto& q : queries) {
      const BruteHit b = brute_closest(single, q);
      const taxel::Vec3d c = mesh.closest_point(q);
      CAPTURE(q.transpose());
      REQUIRE((q - c).squaredNorm() == b.d2);
      CHECK(c == b.point);
    }
  }
}

TEST_CASE("box_mesh is the box, and cylinder_mesh is within its chord error of the cylinder",
          "[sim][mesh]") {
  const taxel::sim::Box box(taxel::Vec3d(0.04, 0.03, 0.02));
  const taxel::sim::TriangleMesh bm = taxel::sim::box_mesh(box);
  CHECK(bm.triangles().size() == 12);
  CHECK(taxel::sim::surface_area(bm) == Approx(taxel::sim::surface_area(box)).epsilon(1e-12));
  const taxel::sim::Cylinder cyl(0.03, 0.05);
  const int n = 64;
  const taxel::sim::TriangleMesh cm = taxel::sim::cylinder_mesh(cyl, n);
  const double chord = cyl.radius * (1.0 - std::cos(std::numbers::pi / n));
  std::mt19937_64 rng(3);
  std::uniform_real_distribution<double> u(-0.1, 0.1);
  double worst = 0.0;
  for (int i = 0; i < 2000; ++i) {
    const taxel::Vec3d q(u(rng), u(rng), u(rng));
    CHECK(bm.signed_distance(q) == Approx(box.signed_distance(q)).margin(1e-12));
    worst = std::max(worst, std::abs(cm.signed_distance(q) - cyl.signed_distance(q)));
  }
  CHECK(worst <= chord + 1e-12);
  CHECK(worst > 0.2 * chord);  // the facets are really not the cylinder
  CHECK_THROWS_WITH(taxel::sim::cylinder_mesh(cyl, 2), Catch::Matchers::Contains("segments"));
}

TEST_CASE("sample_surface_spacing: one point per spacing^2, area-uniform over uneven triangles",
          "[sim][mesh]") {
  const taxel::sim::Box box(taxel::Vec3d(0.04, 0.03, 0.02));
  const double area = taxel::sim::surface_area(box);  // 0.0208 m^2
  const auto cloud = taxel::sim::sample_surface_spacing(taxel::sim::box_mesh(box), 1e-3);
  CHECK(cloud.size() == static_cast<std::size_t>(std::ceil(area / 1e-6)));
  // Points per face (by their normal) against the face's share of the area: each within five
  // binomial standard deviations.
  const double n = static_cast<double>(cloud.size());
  const double face_area[3] = {4 * 0.03 * 0.02, 4 * 0.04 * 0.02, 4 * 0.04 * 0.03};  // +-x, y, z
  for (int axis = 0; axis < 3; ++axis) {
    for (const double sign : {-1.0, 1.0}) {
      double count = 0;
      for (std::size_t i = 0; i < cloud.size(); ++i) {
        if (cloud.normals[i][axis] == sign) ++count;
      }
      const double p = face_area[axis] / area;
      CAPTURE(axis, sign, count, n * p);
      CHECK(std::abs(count - n * p) < 5.0 * std::sqrt(n * p * (1 - p)));
    }
  }
  CHECK_THROWS_WITH(
      taxel::sim::sample_surface_spacing(box, 1e-6),
      Catch::Matchers::Contains("more than 4194304") && Catch::Matchers::Contains("millimetres"));
  CHECK_THROWS_WITH(taxel::sim::sample_surface_spacing(box, 0.0),
                    Catch::Matchers::Contains("spacing must be"));
}
