// SPDX-License-Identifier: MIT
// A cloud saved point by point (state, observations, last time) and restored into a new cloud
// goes on exactly as the original: what Python's pickling of ContactCloud relies on.
#include <catch2/catch.hpp>
#include <random>
#include <taxel/fusion.hpp>
#include <taxel/index.hpp>
#include <taxel/sim/contact_stream.hpp>

namespace {

using namespace taxel;

template <class F>
std::size_t field_doubles() {
  typename F::State s{};
  std::size_t n = 0;
  F::for_each_field(s, [&](double*, std::size_t k) { n += k; });
  return n;
}

template <class F, class I>
void restores(const std::vector<Contact<double>>& stream) {
  using Cloud = fusion::ContactCloud<F, I>;
  Cloud a({.association_radius = 4e-3});
  const std::size_t half = stream.size() / 2;
  for (std::size_t i = 0; i < half; ++i) (void)a.insert(stream[i]);
  Cloud b({.association_radius = 4e-3});
  for (std::size_t i = 0; i < a.size(); ++i) {
    const auto id = static_cast<index::PointId>(i);
    // Through the fields, as a saved file would hold them.
    typename F::State saved = a.state(id), loaded{};
    std::vector<double> flat;
    F::for_each_field(saved, [&](double* v, std::size_t k) { flat.insert(flat.end(), v, v + k); });
    std::size_t at = 0;
    F::for_each_field(loaded, [&](double* v, std::size_t k) {
      std::copy(flat.begin() + static_cast<std::ptrdiff_t>(at),
                flat.begin() + static_cast<std::ptrdiff_t>(at + k), v);
      at += k;
    });
    CHECK(b.restore(loaded, a.observations(id), a.last_time(id)) == id);
  }
  for (std::size_t i = half; i < stream.size(); ++i) {
    const auto ra = a.insert(stream[i]);
    const auto rb = b.insert(stream[i]);
    REQUIRE(ra.status == rb.status);
    REQUIRE(ra.id == rb.id);
  }
  REQUIRE(a.size() == b.size());
  for (std::size_t i = 0; i < a.size(); ++i) {
    const auto id = static_cast<index::PointId>(i);
    CHECK(a.mean(id) == b.mean(id));
    CHECK(a.covariance(id) == b.covariance(id));
    CHECK(a.observations(id) == b.observations(id));
  }
}

}  // namespace

TEST_CASE("ContactCloud::restore: a restored cloud fuses on exactly as the original",
          "[fusion][restore]") {
  // Every double of a state is a field (a member left out would not be saved).
  CHECK(field_doubles<fusion::Kalman<double>>() * 8 == sizeof(fusion::Kalman<double>::State));
  CHECK(field_doubles<fusion::Average<double>>() * 8 == sizeof(fusion::Average<double>::State));
  CHECK(field_doubles<fusion::Raw<double>>() * 8 == sizeof(fusion::Raw<double>::State));
  CHECK(field_doubles<fusion::Surfel<double>>() * 8 == sizeof(fusion::Surfel<double>::State));

  sim::ContactStreamConfig cfg;
  cfg.contacts = 6000;
  cfg.seed = 3;
  const auto stream = sim::contact_stream(sim::Sphere(0.02), cfg);
  restores<fusion::Surfel<double>, index::VoxelHash<double>>(stream);
  restores<fusion::Kalman<double>, index::DynamicKdTree<double>>(stream);
  restores<fusion::Average<double>, index::BruteForce<double>>(stream);
  restores<fusion::Raw<double>, index::VoxelHash<double>>(stream);

  fusion::ContactCloud<fusion::Kalman<double>, index::VoxelHash<double>> c;
  fusion::Kalman<double>::State bad{Vec3d(0, 0, std::nan("")), Mat3d::Identity()};
  CHECK_THROWS_WITH(c.restore(bad, 1, 0.0), Catch::Contains("finite mean"));
  bad.mean.setZero();
  CHECK_THROWS_WITH(c.restore(bad, 0, 0.0), Catch::Contains("at least one observation"));
  bad.mean = Vec3d(1e300, 0, 0);
  CHECK_THROWS_WITH(c.restore(bad, 1, 0.0), Catch::Contains("index's range"));
  CHECK(c.size() == 0);
}
