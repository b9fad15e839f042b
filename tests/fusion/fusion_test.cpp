// SPDX-License-Identifier: MIT
// Tests of taxel::fusion: each policy against its defining property, and ContactCloud.
#include <Eigen/Eigenvalues>
#include <algorithm>
#include <atomic>
#include <catch2/catch.hpp>
#include <cstdlib>
#include <limits>
#include <new>
#include <random>
#include <span>
#include <taxel/fusion.hpp>
#include <taxel/index.hpp>
#include <taxel/io/ply.hpp>
#include <taxel/sim.hpp>
#include <vector>

namespace tf = taxel::fusion;
namespace ti = taxel::index;

#include "support/allocation_counter.hpp"

using taxel_test::g_allocations;

namespace {

template <class S>
taxel::Contact<S> contact_at(const taxel::Vec3<S>& p, const taxel::Mat3<S>& cov, double t = 0) {
  taxel::Contact<S> c;
  c.position = p;
  c.covariance = cov;
  c.time = t;
  return c;
}

// A random pad normal within `max_tilt` rad of +z.
taxel::Vec3d random_normal(std::mt19937& rng, double max_tilt) {
  std::uniform_real_distribution<double> u(0.0, 1.0);
  const double tilt = max_tilt * u(rng), azimuth = 2 * M_PI * u(rng);
  return {std::sin(tilt) * std::cos(azimuth), std::sin(tilt) * std::sin(azimuth), std::cos(tilt)};
}

// A contact of the true point `truth` seen by a pad with normal n: noise drawn from R.
taxel::Contact<double> noisy_contact(std::mt19937& rng, const taxel::Vec3d& truth,
                                     const taxel::Vec3d& n, double sn, double st) {
  std::normal_distribution<double> g(0.0, 1.0);
  const taxel::Vec3d a = n.unitOrthogonal(), b = n.cross(a);
  return contact_at<double>(truth + sn * g(rng) * n + st * g(rng) * a + st * g(rng) * b,
                            taxel::pad_covariance(n, sn, st));
}

template <class M>
bool symmetric_positive_definite(const M& m) {
  if ((m - m.transpose()).cwiseAbs().maxCoeff() != 0) return false;
  return Eigen::SelfAdjointEigenSolver<M>(m).eigenvalues().minCoeff() > 0;
}

}  // namespace

TEMPLATE_TEST_CASE("Raw, Average, Kalman and Surfel satisfy FusionPolicy", "[fusion]", float,
                   double) {
  STATIC_REQUIRE(tf::FusionPolicy<tf::Surfel<TestType>>);
  STATIC_REQUIRE(tf::Surfel<TestType>::kMerges);
  STATIC_REQUIRE(tf::FusionPolicy<tf::Raw<TestType>>);
  STATIC_REQUIRE(tf::FusionPolicy<tf::Average<TestType>>);
  STATIC_REQUIRE(tf::FusionPolicy<tf::Kalman<TestType>>);
  STATIC_REQUIRE_FALSE(tf::Raw<TestType>::kMerges);
  STATIC_REQUIRE(tf::Kalman<TestType>::kMerges);
}

TEST_CASE("Raw keeps every valid contact as its own point", "[fusion]") {
  const auto stream = taxel::sim::sliding_exploration(taxel::sim::Sphere(0.04), 5000);
  tf::ContactCloud<tf::Raw<double>> cloud;
  const auto r = cloud.insert(std::span(stream));
  CHECK(r.added == stream.size());
  CHECK(r.fused == 0);
  REQUIRE(cloud.size() == stream.size());
  for (std::size_t i = 0; i < stream.size(); i += 97) {
    CHECK(cloud.mean(static_cast<ti::PointId>(i)) == stream[i].position);
    CHECK(cloud.covariance(static_cast<ti::PointId>(i)) == stream[i].covariance);
  }
}

TEMPLATE_TEST_CASE("Average is the arithmetic mean and does not depend on order", "[fusion]", float,
                   double) {
  using S = TestType;
  std::mt19937 rng(3);
  std::normal_distribution<double> g(0.0, 0.3e-3);
  std::vector<taxel::Contact<S>> contacts;
  Eigen::Vector3d sum = Eigen::Vector3d::Zero();
  for (int i = 0; i < 200; ++i) {
    const Eigen::Vector3d p(0.01 + g(rng), -0.02 + g(rng), 0.005 + g(rng));
    sum += p;
    contacts.push_back(
        contact_at<S>(p.cast<S>(), taxel::isotropic_covariance<S>(S(1e-3)), i * 1e-3));
  }
  const Eigen::Vector3d mean = sum / 200.0;
  const double tol = std::is_same_v<S, float> ? 1e-6 : 1e-15;

  tf::ContactCloud<tf::Average<S>> cloud({.association_radius = S(5e-3)});
  const auto r = cloud.insert(std::span<const taxel::Contact<S>>(contacts));
  CHECK(r.added == 1);
  CHECK(r.fused == 199);
  REQUIRE(cloud.size() == 1);
  CHECK((cloud.mean(0).template cast<double>() - mean).norm() < tol);
  CHECK(cloud.observations(0) == 200);
  CHECK(cloud.last_time(0) == Approx(0.199));
  // The mean of 200 independent contacts with R = s^2 I has covariance s^2 I / 200.
  CHECK(cloud.covariance(0)(0, 0) == Approx(1e-6 / 200).epsilon(1e-4));

  std::shuffle(contacts.begin(), contacts.end(), rng);
  tf::ContactCloud<tf::Average<S>> shuffled({.association_radius = S(5e-3)});
  shuffled.insert(std::span<const taxel::Contact<S>>(contacts));
  REQUIRE(shuffled.size() == 1);
  CHECK((shuffled.mean(0).template cast<double>() - mean).norm() < tol);

  SECTION("the exponential variant weights the newest contact by alpha") {
    tf::Average<S> ema({.mode = tf::Average<S>::Mode::exponential, .alpha = S(0.25)});
    auto state = ema.init(contact_at<S>(taxel::Vec3<S>::Zero(), contacts[0].covariance));
    ema.fuse(state, contact_at<S>(taxel::Vec3<S>(S(4), S(0), S(0)), contacts[0].covariance), 1);
    CHECK(state.mean.x() == Approx(1.0));
    ema.fuse(state, contact_at<S>(taxel::Vec3<S>(S(4), S(0), S(0)), contacts[0].covariance), 2);
    CHECK(state.mean.x() == Approx(1.75));
  }
}

TEMPLATE_TEST_CASE("Kalman with Q = 0 and one isotropic R equals the cumulative average",
                   "[fusion]", float, double) {
  using S = TestType;
  std::mt19937 rng(11);
  std::normal_distribution<double> g(0.0, 1e-3);
  const taxel::Mat3<S> R = taxel::isotropic_covariance<S>(S(1e-3));
  tf::Kalman<S> kalman;
  tf::Average<S> average;
  const taxel::Contact<S> first = contact_at<S>(taxel::Vec3<S>::Zero(), R);
  auto k = kalman.init(first);
  auto a = average.init(first);
  for (std::uint32_t n = 1; n < 2000; ++n) {
    const auto c = contact_at<S>(Eigen::Vector3d(g(rng), g(rng), g(rng)).cast<S>(), R);
    REQUIRE(kalman.fuse(k, c, n));
    average.fuse(a, c, n);
  }
  const S tol = std::is_same_v<S, float> ? S(1e-8) : S(1e-16);
  CHECK((k.mean - a.mean).norm() < tol);
  // Both covariances are R / n.
  CHECK(k.covariance(1, 1) == Approx(1e-6 / 2000).epsilon(1e-3));
  CHECK(a.covariance(1, 1) == Approx(1e-6 / 2000).epsilon(1e-3));
}

TEST_CASE("Kalman beats Average with anisotropic pad covariances from several orientations",
          "[fusion]") {
  // Many trials: a true point observed by 20 contacts from pads tilted up to 60 degrees, 2 mm
  // noise along each pad normal, 0.5 mm across. The Kalman mean is the best linear unbiased
  // estimate; the average ignores the directions.
  tf::Kalman<double> kalman;
  tf::Average<double> average;
  double sum_k = 0, sum_a = 0;
  int kalman_wins = 0;
  const int trials = 400;
  for (int seed = 0; seed < trials; ++seed) {
    std::mt19937 rng(static_cast<unsigned>(seed));
    const taxel::Vec3d truth(0.01, 0.02, -0.03);
    auto first = noisy_contact(rng, truth, random_normal(rng, M_PI / 3), 2e-3, 0.5e-3);
    auto k = kalman.init(first);
    auto a = average.init(first);
    for (std::uint32_t n = 1; n < 20; ++n) {
      const auto c = noisy_contact(rng, truth, random_normal(rng, M_PI / 3), 2e-3, 0.5e-3);
      kalman.fuse(k, c, n);
      average.fuse(a, c, n);
    }
    const double ek = (k.mean - truth).norm(), ea = (a.mean - truth).norm();
    sum_k += ek;
    sum_a += ea;
    kalman_wins += ek < ea ? 1 : 0;
  }
  INFO("mean error Kalman " << sum_k / trials << " m, Average " << sum_a / trials << " m");
  CHECK(sum_k < 0.8 * sum_a);
  CHECK(kalman_wins > trials * 6 / 10);
}

TEMPLATE_TEST_CASE("Kalman covariance stays symmetric positive definite over 10^6 updates",
                   "[fusion]", float, double) {
  using S = TestType;
  const S q = GENERATE(S(0), S(1e-5));
  tf::Kalman<S> kalman({.process_noise = q});
  std::mt19937 rng(17);
  std::normal_distribution<double> g(0.0, 1.0);
  auto state = kalman.init(
      contact_at<S>(taxel::Vec3<S>::Zero(), taxel::pad_covariance<S>({0, 0, 1}, S(2e-3), S(1e-3))));
  for (std::uint32_t n = 1; n <= 1000000; ++n) {
    const taxel::Vec3d normal = random_normal(rng, M_PI / 2);
    const double sn = 1e-3 * (0.5 + std::abs(g(rng)));
    const auto c = contact_at<S>(Eigen::Vector3d(g(rng), g(rng), g(rng)).cast<S>() * S(1e-3),
                                 taxel::pad_covariance<S>(normal.cast<S>(), S(sn), S(0.98e-3)));
    kalman.fuse(state, c, n);
    if (n % 100000 == 0) {
      INFO("update " << n);
      REQUIRE(symmetric_positive_definite(state.covariance));
      REQUIRE(state.mean.allFinite());
    }
  }
  if (q == S(0)) {
    CHECK(state.covariance.trace() < S(1e-11));  // shrinks like 1/n
    CHECK(state.mean.norm() < S(1e-5));          // and the mean converges on the truth
  } else {
    CHECK(state.covariance.trace() > S(1e-10));  // process noise keeps it open
  }
}

TEMPLATE_TEST_CASE("Kalman update equals the textbook matrix form with correlated P and R",
                   "[fusion]", float, double) {
  // Oracle: the update written with general matrices in long double, Eigen's LU inverse.
  using S = TestType;
  using L = long double;
  using ML = Eigen::Matrix<L, 3, 3>;
  using VL = Eigen::Matrix<L, 3, 1>;
  std::mt19937 rng(29);
  std::normal_distribution<double> g(0.0, 1.0);
  auto random_spd = [&](double scale) {
    Eigen::Matrix3d a;
    for (int i = 0; i < 9; ++i) a.data()[i] = g(rng);
    const Eigen::Matrix3d m = (a * a.transpose() + 0.1 * Eigen::Matrix3d::Identity()) * scale;
    return taxel::Mat3<S>(m.cast<S>());
  };
  const S tol = std::is_same_v<S, float> ? S(2e-4) : S(1e-11);
  for (int trial = 0; trial < 200; ++trial) {
    const S q = trial % 2 ? S(0) : S(3e-4);
    tf::Kalman<S> kalman({.process_noise = q});
    typename tf::Kalman<S>::State s{taxel::Vec3<S>(S(g(rng)), S(g(rng)), S(g(rng))) * S(1e-2),
                                    random_spd(1e-6)};
    const auto c = contact_at<S>(s.mean + taxel::Vec3<S>(S(g(rng)), S(g(rng)), S(g(rng))) * S(1e-3),
                                 random_spd(1e-6));
    const ML pm = s.covariance.template cast<L>() + ML::Identity() * (L(q) * L(q));
    const ML r = c.covariance.template cast<L>();
    const ML k = pm * (pm + r).inverse();
    const VL mean =
        s.mean.template cast<L>() + k * (c.position.template cast<L>() - s.mean.template cast<L>());
    const ML a = ML::Identity() - k;
    const ML p = a * pm * a.transpose() + k * r * k.transpose();
    REQUIRE(kalman.fuse(s, c, 1));
    INFO("trial " << trial);
    CHECK((s.mean.template cast<L>() - mean).norm() <= L(tol) * (1e-2L + mean.norm()));
    CHECK((s.covariance.template cast<L>() - p).norm() <= L(tol) * p.norm());
    CHECK(s.covariance == s.covariance.transpose());
  }
}

TEMPLATE_TEST_CASE("the Mahalanobis gate compares the textbook distance with the threshold",
                   "[fusion]", float, double) {
  using S = TestType;
  const taxel::Mat3<S> p = taxel::pad_covariance<S>({0, 0, 1}, S(1e-3), S(2e-3));
  const taxel::Mat3<S> r =
      taxel::pad_covariance<S>(taxel::Vec3<S>(S(1), S(1), S(1)).normalized(), S(0.5e-3), S(1.5e-3));
  const auto c = contact_at<S>(taxel::Vec3<S>(S(2e-3), S(-1e-3), S(3e-3)), r);
  const double d2 = c.position.template cast<double>().dot(
      (p + r).template cast<double>().inverse() * c.position.template cast<double>());
  for (const double factor : {0.99, 1.01}) {
    tf::Kalman<S> kalman({.gate_chi2 = S(d2 * factor)});
    typename tf::Kalman<S>::State s{taxel::Vec3<S>::Zero(), p};
    const auto before = s.covariance;
    INFO("threshold " << factor << " x " << d2);
    CHECK(kalman.fuse(s, c, 1) == (factor > 1));
    if (factor < 1) CHECK((s.covariance == before && s.mean.isZero()));
  }
}

TEST_CASE("the Mahalanobis gate refuses contacts the covariance rules out", "[fusion]") {
  using Cloud = tf::ContactCloud<tf::Kalman<double>>;
  Cloud gated({.association_radius = 5e-3, .fusion = {.gate_chi2 = tf::kChi2Dof3P99}});
  Cloud plain({.association_radius = 5e-3});
  // 0.3 mm sigma along z: a contact 3 mm away along z is 10 sigma off, yet within 5 mm.
  const auto R = taxel::pad_covariance<double>({0, 0, 1}, 0.3e-3, 2e-3);
  for (Cloud* c : {&gated, &plain}) {
    REQUIRE(c->insert(contact_at<double>({0, 0, 0}, R)).status == tf::InsertStatus::added);
  }
  CHECK(gated.insert(contact_at<double>({0, 0, 3e-3}, R)).status == tf::InsertStatus::added);
  CHECK(plain.insert(contact_at<double>({0, 0, 3e-3}, R)).status == tf::InsertStatus::fused);
  // 3 mm in the plane is 1.5 sigma: accepted.
  CHECK(gated.insert(contact_at<double>({3e-3, 0, 0}, R)).status == tf::InsertStatus::fused);
}

TEMPLATE_TEST_CASE("ContactCloud gives identical clouds over every index", "[fusion]", float,
                   double) {
  using S = TestType;
  const auto stream64 = taxel::sim::sliding_exploration(taxel::sim::Box(), 20000, {.seed = 4});
  std::vector<taxel::Contact<S>> stream;
  for (const auto& c : stream64) stream.push_back(taxel::contact_cast<S>(c));
  // The stream's 1 mm of noise along the normal widens the 2 mm gate to 6 mm by default
  // (queries within 4 mm, then 6 mm); association_sigmas = 0 keeps it fixed.
  std::size_t points[2] = {0, 0};
  for (const S sigmas : {S(0), S(6)}) {
    CAPTURE(sigmas);
    const S r = S(2e-3);
    tf::ContactCloud<tf::Kalman<S>, ti::BruteForce<S>> brute({r, sigmas});
    tf::ContactCloud<tf::Kalman<S>, ti::VoxelHash<S>> voxel({r, sigmas});
    tf::ContactCloud<tf::Kalman<S>, ti::DynamicKdTree<S>> kd({r, sigmas});
    const std::span<const taxel::Contact<S>> all(stream);
    const auto rb = brute.insert(all);
    const auto rv = voxel.insert(all);
    const auto rk = kd.insert(all);
    CHECK(rb.added == rv.added);
    CHECK(rb.added == rk.added);
    CHECK(rb.fused == rv.fused);
    CHECK(rb.fused > rb.added);  // the stream is redundant: most contacts fuse
    REQUIRE(brute.size() == voxel.size());
    REQUIRE(brute.size() == kd.size());
    for (ti::PointId i = 0; i < brute.size(); ++i) {
      REQUIRE(brute.mean(i) == voxel.mean(i));
      REQUIRE(brute.mean(i) == kd.mean(i));
      REQUIRE(brute.observations(i) == voxel.observations(i));
      REQUIRE(brute.covariance(i) == kd.covariance(i));
    }
    points[sigmas > S(0) ? 1 : 0] = brute.size();
  }
  CHECK(points[1] * 5 < points[0]);  // the widened gate is at work: far fewer points
}

namespace {

// Inserts `frames` (consecutive spans of `stream`) one contact at a time and a frame at a time
// into clouds of policy P over index I, and requires the two clouds to be equal bit for bit.
template <class P, class I>
void require_frames_equal_one_by_one(const std::vector<taxel::Contact<double>>& stream,
                                     const std::vector<std::size_t>& ends) {
  tf::ContactCloud<P, I> one({.association_radius = 4e-3});
  tf::ContactCloud<P, I> framed({.association_radius = 4e-3});
  tf::BatchResult sum;
  for (const auto& c : stream) (void)one.insert(c);
  std::size_t begin = 0;
  for (const std::size_t end : ends) {
    const auto r = framed.insert(std::span(stream).subspan(begin, end - begin));
    sum.added += r.added;
    sum.fused += r.fused;
    sum.rejected += r.rejected;
    begin = end;
  }
  REQUIRE(framed.size() == one.size());
  CHECK(sum.added == one.size());
  CHECK(sum.added + sum.fused + sum.rejected == stream.size());
  for (ti::PointId i = 0; i < one.size(); ++i) {
    REQUIRE(framed.mean(i) == one.mean(i));
    REQUIRE(framed.covariance(i) == one.covariance(i));
    REQUIRE(framed.observations(i) == one.observations(i));
    REQUIRE(framed.last_time(i) == one.last_time(i));
  }
}

}  // namespace

TEST_CASE("a frame at a time equals one contact at a time over every policy and index",
          "[fusion]") {
  // Frames of the pad model (a sliding pad and a grasping hand, one contact per active tactel),
  // with a few defective contacts mixed in so that rejections inside a frame are covered.
  taxel::sim::ExplorationConfig cfg;
  cfg.seed = 9;
  std::vector<taxel::Contact<double>> stream;
  std::vector<std::size_t> ends;
  const auto add = [&](const auto& ex) {
    for (const auto& f : ex.frames) {
      if (f.contacts.empty()) continue;
      stream.insert(stream.end(), f.contacts.begin(), f.contacts.end());
      ends.push_back(stream.size());
    }
  };
  const taxel::sim::Sphere sphere(0.04);
  add(taxel::sim::explore_sliding(sphere, cfg, {.slides = 1, .frames = 150}));
  add(taxel::sim::explore_grasps(sphere, cfg, {.grasps = 1}));
  REQUIRE(ends.size() > 100);
  for (std::size_t i = 7; i < stream.size(); i += 997) {
    stream[i].position.x() = std::numeric_limits<double>::quiet_NaN();
  }
  using V = ti::VoxelHash<double>;
  using K = ti::DynamicKdTree<double>;
  using B = ti::BruteForce<double>;
  require_frames_equal_one_by_one<tf::Kalman<double>, V>(stream, ends);
  require_frames_equal_one_by_one<tf::Kalman<double>, K>(stream, ends);
  require_frames_equal_one_by_one<tf::Kalman<double>, B>(stream, ends);
  require_frames_equal_one_by_one<tf::Surfel<double>, V>(stream, ends);
  require_frames_equal_one_by_one<tf::Surfel<double>, K>(stream, ends);
  require_frames_equal_one_by_one<tf::Average<double>, V>(stream, ends);
  require_frames_equal_one_by_one<tf::Average<double>, B>(stream, ends);
  require_frames_equal_one_by_one<tf::Raw<double>, V>(stream, ends);
}

TEST_CASE("ContactCloud rejects invalid contacts and stays unchanged", "[fusion]") {
  tf::ContactCloud<> cloud({.association_radius = 3e-3});
  const auto R = taxel::pad_covariance<double>({0, 0, 1}, 1e-3, 1e-3);
  REQUIRE(cloud.insert(contact_at<double>({0, 0, 0}, R)).status == tf::InsertStatus::added);
  REQUIRE(cloud.insert(contact_at<double>({1e-3, 0, 0}, R)).status == tf::InsertStatus::fused);
  const auto before = cloud.to_point_cloud();
  const auto cov_before = cloud.covariance(0);

  const double nan = std::numeric_limits<double>::quiet_NaN();
  const double inf = std::numeric_limits<double>::infinity();
  std::vector<std::pair<taxel::Contact<double>, taxel::ContactDefect>> bad;
  bad.push_back({contact_at<double>({nan, 0, 0}, R), taxel::ContactDefect::non_finite_position});
  bad.push_back({contact_at<double>({0, inf, 0}, R), taxel::ContactDefect::non_finite_position});
  auto c = contact_at<double>({0, 0, 0}, R);
  c.covariance(2, 2) = inf;
  bad.push_back({c, taxel::ContactDefect::non_finite_covariance});
  c = contact_at<double>({0, 0, 0}, R);
  c.covariance(0, 1) = 5e-7;
  bad.push_back({c, taxel::ContactDefect::asymmetric_covariance});
  c = contact_at<double>({0, 0, 0}, R);
  c.covariance(1, 1) = -1e-6;
  bad.push_back({c, taxel::ContactDefect::indefinite_covariance});
  c = contact_at<double>({0, 0, 0}, taxel::Mat3d::Zero());
  bad.push_back({c, taxel::ContactDefect::indefinite_covariance});
  c = contact_at<double>({0, 0, 0}, R);
  c.time = nan;
  bad.push_back({c, taxel::ContactDefect::non_finite_time});
  c = contact_at<double>({0, 0, 0}, R);
  c.pressure = -inf;
  bad.push_back({c, taxel::ContactDefect::non_finite_pressure});
  for (const double sigma : {-0.1, nan, inf}) {
    c = contact_at<double>({0, 0, 0}, R);
    c.normal_sigma = sigma;
    bad.push_back({c, taxel::ContactDefect::bad_normal_sigma});
    c = contact_at<double>({0, 0, 0}, R);
    c.footprint_sigma = sigma;
    bad.push_back({c, taxel::ContactDefect::bad_footprint_sigma});
  }
  // Beyond the voxel hash's exact range (about 6400 km for this radius), where every point
  // would share a clamped border cell and inserts would turn quadratic.
  bad.push_back({contact_at<double>({0, 1e7, 0}, R), taxel::ContactDefect::out_of_range});

  for (const auto& [contact, defect] : bad) {
    const auto r = cloud.insert(contact);
    CHECK(r.status == tf::InsertStatus::rejected);
    CHECK(r.defect == defect);
  }
  const auto batch = cloud.insert(std::span<const taxel::Contact<double>>(
      std::vector<taxel::Contact<double>>{bad[0].first, bad[3].first}));
  CHECK(batch.rejected == 2);
  const auto after = cloud.to_point_cloud();
  REQUIRE(after.size() == before.size());
  CHECK(after.points == before.points);
  CHECK(after.fields[0].values == before.fields[0].values);
  CHECK(cloud.covariance(0) == cov_before);
}

TEST_CASE("ContactCloud rejects bad configuration naming the field", "[fusion]") {
  using Catch::Matchers::Contains;
  using KalmanCloud = tf::ContactCloud<tf::Kalman<double>>;
  CHECK_THROWS_WITH(tf::ContactCloud<>({.association_radius = 0}), Contains("association_radius"));
  CHECK_THROWS_WITH(tf::ContactCloud<>({.association_radius = std::nan("")}),
                    Contains("association_radius"));
  // A gate in millimetres: said, with the value in metres.
  CHECK_THROWS_WITH(tf::ContactCloud<>({.association_radius = 4.0}),
                    Contains("association_radius = 4.000000 m looks like millimetres") &&
                        Contains("4.000000 mm = 0.004000"));
  CHECK_NOTHROW(tf::ContactCloud<>({.association_radius = 1.0}));
  for (const double k : {-1.0, std::nan(""), std::numeric_limits<double>::infinity()}) {
    CHECK_THROWS_WITH(tf::ContactCloud<>({.association_sigmas = k}),
                      Contains("association_sigmas"));
  }
  CHECK_NOTHROW(tf::ContactCloud<>({.association_sigmas = 0}));
  CHECK_THROWS_WITH(KalmanCloud({.fusion = {.process_noise = -1}}), Contains("process_noise"));
  CHECK_THROWS_WITH(KalmanCloud({.fusion = {.gate_chi2 = 0.0}}), Contains("gate_chi2"));
  CHECK_THROWS_WITH(tf::ContactCloud<>({.fusion = {.kalman = {.process_noise = -1}}}),
                    Contains("process_noise"));
  CHECK_THROWS_WITH(tf::ContactCloud<>({.fusion = {.max_normal_angle = 2.0}}),
                    Contains("max_normal_angle"));
  CHECK_THROWS_WITH(tf::ContactCloud<>({.fusion = {.normal_sigma = 0.0}}),
                    Contains("normal_sigma"));
  CHECK_THROWS_WITH(tf::ContactCloud<>({.fusion = {.curvature_prior = -1.0}}),
                    Contains("curvature_prior"));
  // Beyond the bounds the ridge (normal_sigma / curvature_prior)^2 overflows (found by
  // fuzzing: a prior of 1e-250 / m gave NaN normals) or means nothing physical.
  for (const double v : {1e-250, 1e-7, 4.0, 1e300, std::nan("")}) {
    CHECK_THROWS_WITH(tf::ContactCloud<>({.fusion = {.normal_sigma = v}}),
                      Contains("normal_sigma must be in"));
  }
  for (const double v : {1e-250, 1e-7, 1e10, 1e300, std::nan("")}) {
    CHECK_THROWS_WITH(tf::ContactCloud<>({.fusion = {.curvature_prior = v}}),
                      Contains("curvature_prior must be in"));
  }
  CHECK_THROWS_WITH(tf::ContactCloud<tf::Average<double>>(
                        {.fusion = {.mode = tf::Average<double>::Mode::exponential, .alpha = 1.5}}),
                    Contains("alpha"));
}

TEST_CASE("Surfel at the bounds of its configuration fuses a curved patch into finite points",
          "[fusion]") {
  // In float and double, at every corner of the normal_sigma and curvature_prior ranges: finite
  // means and unit normals.
  const auto at_bounds = [](auto scalar) {
    using S = decltype(scalar);
    for (const S ns : {S(1e-6), S(3.141592653589793)}) {
      for (const S prior : {S(1e-6), S(1e9)}) {
        tf::ContactCloud<tf::Surfel<S>> cloud(
            {.association_radius = S(4e-3),
             .fusion = {.normal_sigma = ns, .curvature_prior = prior}});
        for (int i = 0; i < 200; ++i) {
          const S a = S(0.002) * S(i % 20), b = S(0.002) * S(i / 20);
          taxel::Contact<S> c;
          c.position = {a, b, (a * a + b * b) / S(0.08)};  // a 40 mm paraboloid
          c.covariance = taxel::Mat3<S>::Identity() * S(1e-8);
          c.normal = taxel::Vec3<S>(-a / S(0.04), -b / S(0.04), S(1)).normalized();
          REQUIRE(cloud.insert(c).status != tf::InsertStatus::rejected);
        }
        const auto pc = cloud.to_point_cloud();
        REQUIRE(pc.size() > 0);
        for (std::size_t i = 0; i < pc.size(); ++i) {
          CHECK(pc.points[i].allFinite());
          CHECK(std::abs(pc.normals[i].norm() - S(1)) < S(1e-3));
        }
      }
    }
  };
  at_bounds(0.0);
  at_bounds(0.0f);
}

TEST_CASE("ContactCloud exports, clears and fuses without allocating", "[fusion]") {
  const auto stream = taxel::sim::sliding_exploration(taxel::sim::Cylinder(), 30000);
  tf::ContactCloud<> cloud({.association_radius = 2e-3});
  cloud.reserve(30000);
  cloud.insert(std::span(stream).first(20000));

  // Replay contacts that land on existing points: every insert fuses; count allocations.
  long fused = 0, allocations = 0;
  for (std::size_t i = 20000; i < stream.size(); ++i) {
    const long before = g_allocations.load();
    const auto r = cloud.insert(stream[i]);
    const long delta = g_allocations.load() - before;
    if (r.status == tf::InsertStatus::fused) {
      ++fused;
      allocations += delta;
    }
  }
  CHECK(fused > 5000);
  if (TAXEL_TEST_COUNTS_ALLOCATIONS) {
    CHECK(allocations == 0);
  } else {
    WARN("allocation count not checked under AddressSanitizer");
  }

  const auto pc = cloud.to_point_cloud();
  CHECK(pc.validate().ok());
  CHECK(pc.size() == cloud.size());
  REQUIRE(pc.field("observations") != nullptr);
  double total = 0;
  for (double v : pc.field("observations")->values) total += v;
  CHECK(total == Approx(30000));  // every contact counted once
  CHECK(cloud.memory_bytes() > cloud.size() * sizeof(tf::Kalman<double>::State));
  cloud.clear();
  CHECK(cloud.empty());
  CHECK(cloud.insert(stream[0]).status == tf::InsertStatus::added);
}

TEST_CASE("fused clouds are compact and closer to the surface than raw contacts", "[fusion]") {
  const taxel::sim::Sphere sphere(0.04);
  const auto stream = taxel::sim::sliding_exploration(sphere, 50000, {.seed = 8});
  tf::ContactCloud<tf::Raw<double>> raw({.association_radius = 3.4e-3});
  tf::ContactCloud<tf::Kalman<double>> kalman({.association_radius = 3.4e-3});
  raw.insert(std::span(stream));
  kalman.insert(std::span(stream));
  const auto raw_err = taxel::sim::surface_error(sphere, raw.to_point_cloud().points);
  const auto k_err = taxel::sim::surface_error(sphere, kalman.to_point_cloud().points);
  INFO("raw " << raw.size() << " pts rms " << raw_err.rms << "; kalman " << kalman.size()
              << " pts rms " << k_err.rms);
  CHECK(kalman.size() * 10 < raw.size());
  CHECK(k_err.rms < raw_err.rms);
}

namespace {
// A contact on a sphere of radius R (centre at the origin) near the unit direction `at`,
// within `spread` of it, with its exact outward normal (tilted by up to `normal_noise` rad)
// and a pad covariance (sn along the normal, st across) whose tight axis follows that normal.
taxel::Contact<double> sphere_contact(std::mt19937& rng, double R, const taxel::Vec3d& at,
                                      double spread, double normal_noise, double sn, double st) {
  std::uniform_real_distribution<double> u(-1.0, 1.0);
  std::normal_distribution<double> g(0.0, 1.0);
  taxel::Vec3d d;
  do {
    d = spread * taxel::Vec3d(u(rng), u(rng), u(rng));
  } while (d.norm() > spread);
  const taxel::Vec3d p = (R * at + d).normalized() * R;
  const taxel::Vec3d n =
      (p.normalized() + normal_noise * taxel::Vec3d(g(rng), g(rng), g(rng)) / std::sqrt(3.0))
          .normalized();
  taxel::Contact<double> c = contact_at<double>(p, taxel::pad_covariance(n, sn, st));
  c.normal = n;
  c.footprint_sigma = st;  // an exact surface point: its lateral covariance is a footprint
  return c;
}
}  // namespace

TEST_CASE("Surfel lands on a curved surface where Kalman lands outside and Average inside",
          "[fusion]") {
  // 200 points on spheres of 40 and 15 mm, each fed 200 exact contacts from a 4 mm patch with
  // normals noisy by 0.1 rad: the closed forms say Average sits E[u'Hu]/2 inside (chord sag,
  // 0.080 / 0.213 mm here) and Kalman about (1 - 2 sn^2/st^2) of that outside.
  for (const double R : {0.04, 0.015}) {
    std::mt19937 rng(7);
    const tf::Surfel<double> surfel;
    const tf::Kalman<double> kalman;
    const tf::Average<double> average;
    double bias_s = 0, bias_k = 0, bias_a = 0, worst_s = 0;
    const int points = 200;
    for (int t = 0; t < points; ++t) {
      const taxel::Vec3d at = random_normal(rng, M_PI);
      auto c = sphere_contact(rng, R, at, 4e-3, 0.1, 0.3e-3, 1e-3);
      auto s = surfel.init(c);
      auto k = kalman.init(c);
      auto a = average.init(c);
      for (std::uint32_t i = 1; i < 200; ++i) {
        c = sphere_contact(rng, R, at, 4e-3, 0.1, 0.3e-3, 1e-3);
        REQUIRE(surfel.fuse(s, c, i));
        kalman.fuse(k, c, i);
        average.fuse(a, c, i);
      }
      const double e = surfel.mean(s).norm() - R;
      bias_s += e / points;
      worst_s = std::max(worst_s, std::abs(e));
      bias_k += (kalman.mean(k).norm() - R) / points;
      bias_a += (average.mean(a).norm() - R) / points;
    }
    const double sag = 0.5 * 2 * (16e-6 / 5) / R;  // E[u'Hu]/2 over a uniform 4 mm ball
    CAPTURE(R, bias_s, bias_k, bias_a, worst_s);
    CHECK(bias_a == Approx(-sag).epsilon(0.05));
    CHECK(bias_k > 0.7 * sag);
    CHECK(std::abs(bias_s) < 0.05 * sag);
    CHECK(worst_s < 0.25 * sag);
  }
}

TEST_CASE("Surfel equals Kalman on a plane with exact normals", "[fusion]") {
  // All contacts share the plane's normal: no turn, no curvature; with one covariance for all
  // the Kalman mean is the average, and so is the Surfel's point.
  std::mt19937 rng(9);
  std::normal_distribution<double> g(0.0, 1.0);
  const taxel::Vec3d n = random_normal(rng, 1.0);
  const taxel::Vec3d a = n.unitOrthogonal(), b = n.cross(a);
  const tf::Surfel<double> surfel;
  const tf::Kalman<double> kalman;
  const taxel::Mat3d R = taxel::pad_covariance(n, 0.3e-3, 1e-3);
  const auto make = [&] {
    auto c = contact_at<double>(taxel::Vec3d(0.01, 0.02, 0.03) + 1e-3 * g(rng) * a +
                                    1e-3 * g(rng) * b + 0.3e-3 * g(rng) * n,
                                R);
    c.normal = n;
    return c;
  };
  auto c = make();
  auto s = surfel.init(c);
  auto k = kalman.init(c);
  for (std::uint32_t i = 1; i < 500; ++i) {
    c = make();
    surfel.fuse(s, c, i);
    kalman.fuse(k, c, i);
  }
  double h[3];
  surfel.fit_curvature(s, h);
  CHECK(std::abs(h[0]) + std::abs(h[1]) + std::abs(h[2]) < 1e-9);
  CHECK((surfel.mean(s) - kalman.mean(k)).norm() < 1e-12);
  CHECK((surfel.covariance(s) - kalman.covariance(k)).norm() < 1e-18);
  SECTION("contacts without a normal: Kalman, up to rounding") {
    auto c0 = make();
    c0.normal.reset();
    auto s0 = surfel.init(c0);
    auto k0 = kalman.init(c0);
    for (std::uint32_t i = 1; i < 50; ++i) {
      auto ci = make();
      ci.normal.reset();
      surfel.fuse(s0, ci, i);
      kalman.fuse(k0, ci, i);
    }
    // Surfel keeps the filter in information form; Kalman in covariance form (Joseph).
    CHECK((surfel.mean(s0) - kalman.mean(k0)).norm() < 1e-15);
    CHECK(surfel.mean(s0) == surfel.filter_mean(s0));
    // No contact had a normal: the point has none (every member of a state starts at zero).
    CHECK(surfel.normal(s0) == taxel::Vec3d::Zero());
    CHECK((surfel.covariance(s0) - kalman.covariance(k0)).norm() <
          1e-12 * kalman.covariance(k0).norm());
  }
}

TEST_CASE("Surfel's filter in information form equals Kalman with process noise, gate and P0",
          "[fusion]") {
  // Contacts without a normal reach only the filter, so Surfel's covariance and mean must be
  // those of Kalman (covariance form, Joseph update) on the same stream, refusals included:
  // a gate of 7.8 (95 %) on anisotropic covariances of varying orientation, with a tenth of
  // the contacts 5 mm off.
  std::mt19937 rng(31);
  std::normal_distribution<double> g(0.0, 1.0);
  std::uniform_real_distribution<double> u(0.0, 1.0);
  for (const double q : {0.0, 2e-5}) {
    for (const int variant : {0, 1, 2}) {  // no gate; a gate; a gate and P0 = (2 mm)^2 I
      const bool gated = variant > 0;
      typename tf::Kalman<double>::Config kc{.process_noise = q};
      if (gated) kc.gate_chi2 = tf::kChi2Dof3P95;
      if (variant == 2) kc.initial_sigma = 2e-3;
      const tf::Kalman<double> kalman(kc);
      const tf::Surfel<double> surfel({.kalman = kc});
      const auto make = [&] {
        const taxel::Vec3d n = random_normal(rng, M_PI);
        const taxel::Vec3d off = u(rng) < 0.1 ? taxel::Vec3d(0, 0, 5e-3) : taxel::Vec3d::Zero();
        const taxel::Vec3d p(0.3e-3 * g(rng), 1e-3 * g(rng), 0.5e-3 * g(rng));
        return contact_at<double>(taxel::Vec3d(0.01, -0.02, 0.03) + p + off,
                                  taxel::pad_covariance(n, 0.2e-3 + 0.3e-3 * u(rng), 1e-3));
      };
      auto c = make();
      auto k = kalman.init(c);
      auto s = surfel.init(c);
      int refused = 0;
      for (std::uint32_t i = 1; i < 400; ++i) {
        c = make();
        const bool fk = kalman.fuse(k, c, i);
        REQUIRE(surfel.fuse(s, c, i) == fk);
        refused += fk ? 0 : 1;
      }
      CAPTURE(q, variant, refused);
      if (gated) CHECK(refused > 20);  // the gate is exercised
      if (!gated) CHECK(refused == 0);
      CHECK((surfel.mean(s) - kalman.mean(k)).norm() < 1e-12);
      CHECK((surfel.covariance(s) - kalman.covariance(k)).norm() <
            1e-9 * kalman.covariance(k).norm());
      CHECK((surfel.filter_mean(s) - kalman.mean(k)).norm() < 1e-12);
    }
  }
}

TEST_CASE("Surfel fits the curvature of a cylinder patch", "[fusion]") {
  // Contacts on a cylinder of radius 30 mm (axis z) around (R, 0, 0), exact normals: the fitted
  // curvature has 1/R across the axis and 0 along it.
  const double R = 0.03;
  std::mt19937 rng(11);
  std::uniform_real_distribution<double> u(-3e-3, 3e-3);
  const tf::Surfel<double> surfel;
  const auto make = [&] {
    const double phi = u(rng) / R, z = u(rng);
    const taxel::Vec3d n(std::cos(phi), std::sin(phi), 0);
    auto c =
        contact_at<double>(R * n + taxel::Vec3d(0, 0, z), taxel::pad_covariance(n, 3e-4, 1e-3));
    c.normal = n;
    c.footprint_sigma = 1e-3;  // an exact surface point
    return c;
  };
  auto s = surfel.init(make());
  for (std::uint32_t i = 1; i < 400; ++i) surfel.fuse(s, make(), i);
  double h[3];
  surfel.fit_curvature(s, h);
  // In the point's own tangent frame (t1, n0 x t1): H = (1/R) e e' with e the tangent across
  // the axis, so trace 1/R and determinant 0.
  CHECK(h[0] + h[2] == Approx(1 / R).epsilon(0.03));
  CHECK(std::abs(h[0] * h[2] - h[1] * h[1]) < 0.05 / (R * R));
  CHECK(std::abs(surfel.mean(s).head<2>().norm() - R) < 5e-6);
}

TEST_CASE("Surfel weights a guessed normal's slope down by the sigma it states", "[fusion]") {
  // The cylinder patch above, plus contacts on one side of it whose normals are wrong by 0.9
  // rad in one direction (a pad's normal where no neighbour measured the slope). Stated as
  // guesses (normal_sigma 1 rad) they barely move the fit; unstated, they bend it.
  const double R = 0.03;
  std::mt19937 rng(12);
  std::uniform_real_distribution<double> u(-3e-3, 3e-3);
  const auto make = [&](bool guessed, double sigma) {
    const double phi = (guessed ? std::abs(u(rng)) : u(rng)) / R, z = u(rng);
    const taxel::Vec3d n(std::cos(phi), std::sin(phi), 0);
    auto c =
        contact_at<double>(R * n + taxel::Vec3d(0, 0, z), taxel::pad_covariance(n, 3e-4, 1e-3));
    c.normal = guessed ? taxel::Vec3d(std::cos(phi + 0.9), std::sin(phi + 0.9), 0) : n;
    c.normal_sigma = guessed ? sigma : 0.02;
    c.footprint_sigma = 1e-3;  // an exact surface point
    return c;
  };
  const tf::Surfel<double> surfel;
  const auto fit = [&](double sigma) {
    rng.seed(12);
    auto s = surfel.init(make(false, sigma));
    for (std::uint32_t i = 1; i < 500; ++i) surfel.fuse(s, make(i % 5 == 0, sigma), i);
    double h[3];
    surfel.fit_curvature(s, h);
    return std::pair{h[0] + h[2], std::abs(surfel.mean(s).head<2>().norm() - R)};
  };
  const auto [trace_stated, off_stated] = fit(1.0);
  const auto [trace_unstated, off_unstated] = fit(0.0);
  CAPTURE(trace_stated * R, trace_unstated * R, off_stated, off_unstated);
  CHECK(trace_stated == Approx(1 / R).epsilon(0.05));
  CHECK(std::abs(trace_unstated - 1 / R) > 0.5 / R);
  CHECK(off_stated < 1e-5);
}

TEST_CASE("Surfel's normal is its fitted sphere's normal at the point it reports", "[fusion]") {
  // Contacts with exact normals on a patch of a sphere of radius 40 mm around +z. Those with
  // x > 0 are five times finer along the normal, so the point is reported above a centroid
  // shifted towards them, where the plain mean of the contacts' normals is not the normal
  // (about 1 mm away: 0.03 rad). A fifth of the contacts with x < 0 carry a guessed normal,
  // 0.8 rad off and stated so (normal_sigma 0.21 rad), which the plain mean takes in full.
  const double R = 0.04;
  std::mt19937 rng(5);
  std::uniform_real_distribution<double> u(-3e-3, 3e-3);
  std::normal_distribution<double> g(0.0, 1.0);
  const auto make = [&](std::uint32_t i, bool with_guesses) {
    const double x = u(rng), y = u(rng);
    const taxel::Vec3d n = taxel::Vec3d(x, y, R).normalized();
    const double sn = x > 0 ? 0.1e-3 : 0.5e-3;
    auto c = contact_at<double>(R * n + sn * g(rng) * n, taxel::pad_covariance(n, sn, 1e-3));
    c.normal = n;
    c.normal_sigma = 0.02;
    if (with_guesses && x < 0 && i % 5 == 0) {
      c.normal = (n + std::tan(0.8) * n.cross(taxel::Vec3d::UnitY()).normalized()).normalized();
      c.normal_sigma = 0.21;
    }
    return c;
  };
  const tf::Surfel<double> surfel;
  for (const bool with_guesses : {false, true}) {
    auto s = surfel.init(make(0, with_guesses));
    for (std::uint32_t i = 1; i < 2000; ++i) surfel.fuse(s, make(i, with_guesses), i);
    const taxel::Vec3d truth = surfel.mean(s).normalized();  // the sphere's normal there
    const double fitted = std::acos(std::min(1.0, truth.dot(surfel.normal(s))));
    const double plain = std::acos(std::min(1.0, truth.dot(s.unit_normal)));
    CAPTURE(with_guesses, fitted, plain);
    CHECK(surfel.normal(s).norm() == Approx(1.0).epsilon(1e-12));
    // With the guesses, their slopes' share ((0.05 / 0.21)^2 of a measured one's) still tilts
    // the fit by about 2 mrad; the plain mean is tilted 0.1 rad.
    CHECK(fitted < (with_guesses ? 5e-3 : 1e-3));
    CHECK(plain > 0.03);  // the plain mean would fail the check above
  }
  // A normal_sigma that is valid but so large that every slope's share underflows leaves the
  // fit no weight: the normal is then the plain mean, not 0 / 0.
  auto c = make(1, false);
  c.normal_sigma = 1e300;
  auto s = surfel.init(c);
  c.position.x() += 1e-3;
  c.normal = taxel::Vec3d(0.1, 0, 1).normalized();
  surfel.fuse(s, c, 1);
  CHECK(s.vweight < std::numeric_limits<double>::min());
  CHECK(surfel.normal(s).allFinite());
  CHECK((surfel.normal(s) - s.unit_normal).norm() == 0);
}

TEST_CASE("a valid contact whose Surfel weight overflows is refused, not added as NaN",
          "[fusion]") {
  // Found by fuzzing: a variance of 1e-320 along the normal is valid (the determinant,
  // 1e100 * 1e100 * 1e-320, is positive) but its information 1 / n'Rn overflows to infinity.
  taxel::Contact<double> c = contact_at<double>(
      {0.01, 0.02, 0.03}, taxel::Vec3d(1e100, 1e100, 1e-320).asDiagonal().toDenseMatrix());
  c.normal = taxel::Vec3d(0, 0, 1);
  REQUIRE(taxel::check_contact(c) == taxel::ContactDefect::ok);
  tf::ContactCloud<> cloud;
  const auto r = cloud.insert(c);
  CHECK(r.status == tf::InsertStatus::rejected);
  CHECK(r.defect == taxel::ContactDefect::overflow);
  CHECK(cloud.empty());
  // Without the normal too: Surfel's filter holds the information R^-1, which overflows.
  c.normal.reset();
  CHECK(cloud.insert(c).defect == taxel::ContactDefect::overflow);
  CHECK(cloud.empty());
  // Kalman, which holds the covariance, takes it as a finite point.
  tf::ContactCloud<tf::Kalman<double>> kalman;
  REQUIRE(kalman.insert(c).status == tf::InsertStatus::added);
  CHECK(kalman.mean(0).allFinite());
}

TEST_CASE("the association gate widens to association_sigmas of a coarse contact's noise",
          "[fusion][gate]") {
  using Cloud = tf::ContactCloud<tf::Surfel<double>>;
  const taxel::Vec3d up(0, 0, 1);
  // A fine contact (0.3 mm along its normal) and a coarse one (1.5 mm), both 1 mm across.
  taxel::Contact<double> fine =
      contact_at<double>({0, 0, 0}, taxel::pad_covariance(up, 0.3e-3, 1e-3));
  fine.normal = up;
  taxel::Contact<double> coarse = fine;
  coarse.covariance = taxel::pad_covariance(up, 1.5e-3, 1e-3);
  const Cloud cloud({.association_radius = 6e-3});
  CHECK(cloud.gate(fine) == 6e-3);  // 6 x 0.3 mm is inside the radius
  CHECK(cloud.gate(coarse) == Approx(9e-3).epsilon(1e-12));
  // The normal decides, not the trace: the same coarse covariance seen from the side.
  taxel::Contact<double> side = coarse;
  side.normal = taxel::Vec3d(1, 0, 0);
  CHECK(cloud.gate(side) == 6e-3);
  // Without a normal: the smallest eigenvalue, whatever the axes (a rotated covariance).
  taxel::Contact<double> bare = coarse;
  bare.normal.reset();
  const taxel::Mat3d rot =
      Eigen::AngleAxisd(0.7, taxel::Vec3d(1, 2, 3).normalized()).toRotationMatrix();
  bare.covariance = rot * taxel::pad_covariance(up, 2.0e-3, 3e-3) * rot.transpose();
  CHECK(cloud.gate(bare) == Approx(12e-3).epsilon(1e-9));
  CHECK(Cloud({.association_radius = 6e-3, .association_sigmas = 0}).gate(coarse) == 6e-3);
  CHECK(Cloud({.association_radius = 6e-3, .association_sigmas = 3}).gate(coarse) == 6e-3);

  // What the gate is for: coarse contacts on the plane z = 0, noise comparable to the radius.
  // With a fixed 6 mm gate a 3-4 sigma tail now and then lands beyond every point, starts a
  // point off the surface, and that point gathers the contacts on its side: it ends up
  // millimetres off while its covariance claims far less. The widened gate absorbs the tails.
  const auto run = [&](double sigmas) {
    std::mt19937_64 rng(21);
    std::normal_distribution<double> g(0.0, 1.0);
    std::uniform_real_distribution<double> u(-0.03, 0.03);
    Cloud c({.association_radius = 6e-3, .association_sigmas = sigmas});
    for (int i = 0; i < 60000; ++i) {
      taxel::Contact<double> k = coarse;
      k.position = {u(rng) + 1.44e-3 * g(rng), u(rng) + 1.44e-3 * g(rng), 1.5e-3 * g(rng)};
      REQUIRE(c.insert(k).status != tf::InsertStatus::rejected);
    }
    // Worst height among the points the confidence filter keeps, in units of their claimed
    // standard deviation along z.
    double worst = 0;
    for (std::size_t i = 0; i < c.size(); ++i) {
      const auto id = static_cast<taxel::index::PointId>(i);
      if (!c.confident(id, {3, std::numeric_limits<double>::infinity(), 0.3e-3})) continue;
      worst = std::max(worst, std::abs(c.mean(id).z()) / std::sqrt(c.covariance(id)(2, 2)));
    }
    return worst;
  };
  const double fixed = run(0), widened = run(6);
  CHECK(fixed > 6);      // tail points: far beyond what their covariance claims
  CHECK(widened < 4.5);  // every confident point within what its covariance says
}

TEST_CASE("to_point_cloud: full covariances, normals and confidence filters",
          "[fusion][confidence]") {
  namespace tf = taxel::fusion;
  taxel::sim::ExplorationConfig cfg;
  cfg.seed = 9;
  const auto contacts =
      taxel::sim::explore_palpation(taxel::sim::Sphere(0.03), cfg, {.touches = 6}).contacts();
  tf::ContactCloud<tf::Surfel<double>> cloud({.association_radius = 4e-3});
  cloud.insert(std::span<const taxel::Contact<double>>(contacts));
  REQUIRE(cloud.size() > 10);
  const auto all = cloud.to_point_cloud();
  REQUIRE(all.size() == cloud.size());
  REQUIRE(all.normals.size() == cloud.size());  // Surfel estimates normals
  const char* names[6] = {"cov_xx", "cov_xy", "cov_xz", "cov_yy", "cov_yz", "cov_zz"};
  const int rc[6][2] = {{0, 0}, {0, 1}, {0, 2}, {1, 1}, {1, 2}, {2, 2}};
  for (std::size_t i = 0; i < cloud.size(); ++i) {
    const auto id = static_cast<taxel::index::PointId>(i);
    const taxel::Mat3d c = cloud.covariance(id);
    for (int k = 0; k < 6; ++k) {
      CHECK(all.field(names[k])->values[i] == c(rc[k][0], rc[k][1]));
    }
    CHECK(all.field("observations")->values[i] == double(cloud.observations(id)));
    CHECK(all.normals[i].norm() == Approx(1.0));
    // The normal of a sphere point points away from the centre.
    CHECK(all.normals[i].dot(all.points[i].normalized()) > 0.9);
  }
  // Filters against brute force with Eigen's eigen-solver.
  for (const std::uint32_t min_obs : {1u, 5u, 50u}) {
    for (const double max_sigma : {1e-4, 3e-4, 1e-3, std::numeric_limits<double>::infinity()}) {
      const auto kept = cloud.to_point_cloud({min_obs, max_sigma});
      std::size_t expected = 0;
      for (std::size_t i = 0; i < cloud.size(); ++i) {
        const auto id = static_cast<taxel::index::PointId>(i);
        const double top =
            Eigen::SelfAdjointEigenSolver<taxel::Mat3d>(cloud.covariance(id)).eigenvalues()(2);
        const bool pass = cloud.observations(id) >= min_obs && std::sqrt(top) <= max_sigma;
        CHECK(cloud.confident(id, {min_obs, max_sigma}) == pass);
        if (pass) {
          REQUIRE(expected < kept.size());
          CHECK(kept.points[expected] == all.points[i]);
          ++expected;
        }
      }
      CHECK(kept.size() == expected);
    }
  }
  // The smallest standard deviation (across the surface), against the eigen-solver too; the
  // points' normal sigmas spread over the thresholds, so each keeps some and drops some.
  std::size_t some_kept = 0, some_dropped = 0;
  const double inf = std::numeric_limits<double>::infinity();
  for (const double max_normal : {0.03e-3, 0.05e-3, 0.1e-3, 0.3e-3}) {
    const auto kept = cloud.to_point_cloud({1, inf, max_normal});
    std::size_t expected = 0;
    for (std::size_t i = 0; i < cloud.size(); ++i) {
      const auto id = static_cast<taxel::index::PointId>(i);
      const double low =
          Eigen::SelfAdjointEigenSolver<taxel::Mat3d>(cloud.covariance(id)).eigenvalues()(0);
      const bool pass = std::sqrt(low) <= max_normal;
      CHECK(cloud.confident(id, {1, inf, max_normal}) == pass);
      expected += pass ? 1 : 0;
    }
    CHECK(kept.size() == expected);
    some_kept += expected > 0 ? 1 : 0;
    some_dropped += expected < cloud.size() ? 1 : 0;
  }
  CHECK(some_kept > 0);
  CHECK(some_dropped > 0);
  CHECK_THROWS_AS(cloud.to_point_cloud({1, inf, -1.0}), std::invalid_argument);
  CHECK_THROWS_AS(cloud.to_point_cloud({1, inf, std::nan("")}), std::invalid_argument);
  CHECK(cloud.to_point_cloud({1, 0.0}).size() == 0);
  CHECK_THROWS_AS(cloud.to_point_cloud({1, -1.0}), std::invalid_argument);
  CHECK_THROWS_AS(cloud.to_point_cloud({1, std::nan("")}), std::invalid_argument);
  // A single coarse contact does not pass a support filter, however tight its covariance.
  tf::ContactCloud<tf::Kalman<double>> one;
  taxel::Contact<double> c;
  c.position = taxel::Vec3d(0.1, 0, 0);
  c.covariance = 1e-10 * taxel::Mat3d::Identity();
  one.insert(c);
  CHECK(one.to_point_cloud().normals.empty());  // Kalman keeps no normal
  CHECK(one.to_point_cloud({3}).size() == 0);
  CHECK(one.to_point_cloud({1, 1e-4}).size() == 1);
  // The covariance fields survive a PLY round trip.
  const std::string ply = taxel::io::encode_ply(all, taxel::io::PlyFormat::binary_little_endian);
  const auto back = taxel::io::parse_ply(ply, "cloud.ply");
  for (int k = 0; k < 6; ++k)
    CHECK(back.cloud.field(names[k])->values == all.field(names[k])->values);
}

TEST_CASE(
    "Surfel removes the lift of the tangent-plane scatter contacts state, not of a footprint, "
    "on a sphere and a cylinder",
    "[fusion]") {
  // A dense, uniform stream over a 15 mm sphere (or a cylinder of 15 mm along x): each
  // contact is its true surface point moved along the tangent plane there by N(0, 1 mm^2) per
  // axis, and 0.3 mm along the normal, as its covariance states; exact normals. A point
  // gathers the contacts whose reported position lies within 2 mm of the top, as a cloud's gate
  // does. Tangent-plane scatter lifts each contact off the surface by e'He / 2: on average
  // sigma_t^2 / R on the sphere (67 um), sigma_t^2 / (2 R) on the cylinder (33 um). Told that
  // the lateral covariance is a footprint (footprint_sigma = sigma_t), Surfel follows its
  // contacts outward (by 75-80 % of the lift in this set-up, which varies with the draws);
  // told nothing (footprint_sigma = 0: scatter), it moves the point in by the lift, with the
  // curvature it fits. A stream of exact surface points stating the same footprint lands as
  // near the surface (0.2 of the lift inside, as the scattered stream with the lift removed);
  // stating it as scatter, it moves inward by the lift.
  const double R = 0.015, st = 1e-3, sn = 0.3e-3;
  for (const bool cylinder : {false, true}) {
    const auto normal_at = [&](const taxel::Vec3d& p) {
      return cylinder ? taxel::Vec3d(0, p.y(), p.z()).normalized() : taxel::Vec3d(p.normalized());
    };
    const auto distance = [&](const taxel::Vec3d& p) {
      return (cylinder ? std::hypot(p.y(), p.z()) : p.norm()) - R;
    };
    const tf::Surfel<double> surfel;
    // Fuses 40 000 contacts of the point's gate twice, stating their lateral sigma as a
    // footprint and as scatter; `exact`: the true surface points, moved along the normal only.
    const auto fuse = [&](bool exact) {
      std::mt19937_64 rng(11);
      std::normal_distribution<double> g(0.0, 1.0);
      std::uniform_real_distribution<double> u(-6e-3, 6e-3);
      tf::Surfel<double>::State foot{}, scatter{};
      std::uint32_t n = 0;
      while (n < 40000) {
        const double x = u(rng), y = u(rng);
        const double z = cylinder ? std::sqrt(R * R - y * y) : std::sqrt(R * R - x * x - y * y);
        const taxel::Vec3d q(x, y, z), nq = normal_at(q);
        const taxel::Vec3d t1 = nq.unitOrthogonal(), t2 = nq.cross(t1);
        taxel::Contact<double> c;
        c.position = q + sn * g(rng) * nq;
        const taxel::Vec3d across = st * (g(rng) * t1 + g(rng) * t2);
        if (!exact) c.position += across;
        if (std::hypot(c.position.x(), c.position.y()) > 2e-3) continue;  // the point's gate
        c.covariance = taxel::pad_covariance<double>(nq, sn, st);
        c.normal = nq;
        taxel::Contact<double> f = c;
        f.footprint_sigma = st;
        if (n == 0) {
          foot = surfel.init(f);
          scatter = surfel.init(c);
        } else {
          REQUIRE(surfel.fuse(foot, f, n));
          REQUIRE(surfel.fuse(scatter, c, n));
        }
        ++n;
      }
      return std::pair{distance(surfel.mean(foot)), distance(surfel.mean(scatter))};
    };
    const double lift = cylinder ? st * st / (2 * R) : st * st / R;
    const auto [foot, scatter] = fuse(false);
    const auto [on, bare] = fuse(true);
    CAPTURE(cylinder, foot, scatter, on, bare, lift);
    CHECK(foot > 0.5 * lift);
    CHECK(foot - scatter == Approx(lift).epsilon(0.1));
    CHECK(std::abs(scatter) < 0.35 * lift);
    CHECK(std::abs(on) < 0.35 * lift);
    CHECK(on - bare == Approx(lift).epsilon(0.1));
  }
}

namespace {
// Contacts on the faces of a convex solid near a crease or a corner: each face f is the plane
// n_f . x = 0 (outward unit normal n_f), and the solid is where every n_f . x <= 0. A contact
// is a point of one face on the solid, moved by 0.3 mm along the face's normal and by `lateral`
// across it, as its covariance states; its normal is the face's, turned by `noise` about each
// axis (not stated). Kept when its reported position lies within `spread` of `at`, as a
// cloud's gate keeps them.
std::vector<taxel::Contact<double>> face_contacts(const std::vector<taxel::Vec3d>& faces,
                                                  const taxel::Vec3d& at, double spread,
                                                  double lateral, double noise, int count,
                                                  std::uint64_t seed) {
  std::mt19937_64 rng(seed);
  std::normal_distribution<double> g(0.0, 1.0);
  const double reach = spread + 4 * lateral + 1.2e-3;
  std::uniform_real_distribution<double> u(-reach, reach);
  std::uniform_int_distribution<std::size_t> pick(0, faces.size() - 1);
  std::vector<taxel::Contact<double>> out;
  while (int(out.size()) < count) {
    const taxel::Vec3d& n = faces[pick(rng)];
    const taxel::Vec3d t1 = n.unitOrthogonal(), t2 = n.cross(t1);
    const taxel::Vec3d q = at - n * n.dot(at) + u(rng) * t1 + u(rng) * t2;
    bool on_solid = true;
    for (const auto& m : faces) on_solid = on_solid && m.dot(q) <= 1e-15;
    if (!on_solid) continue;
    taxel::Contact<double> c;
    c.position = q + 0.3e-3 * g(rng) * n + lateral * (g(rng) * t1 + g(rng) * t2);
    c.covariance = taxel::pad_covariance<double>(n, 0.3e-3, std::max(lateral, 0.3e-3));
    const Eigen::Matrix3d turn(Eigen::AngleAxisd(noise * g(rng), taxel::Vec3d::UnitX()) *
                               Eigen::AngleAxisd(noise * g(rng), taxel::Vec3d::UnitY()) *
                               Eigen::AngleAxisd(noise * g(rng), taxel::Vec3d::UnitZ()));
    c.normal = (turn * n).normalized();
    if ((c.position - at).norm() <= spread) out.push_back(c);
  }
  return out;
}

// Fuses `contacts` into one point of `policy` (no gate) and returns its state.
template <class Policy>
typename Policy::State fuse_all(const Policy& policy,
                                const std::vector<taxel::Contact<double>>& contacts) {
  auto s = policy.init(contacts.front());
  for (std::size_t i = 1; i < contacts.size(); ++i) {
    REQUIRE(policy.fuse(s, contacts[i], std::uint32_t(i)));
  }
  return s;
}
}  // namespace

TEST_CASE(
    "Surfel at a crease and a corner: the patch's point, or Kalman's where other faces dominate",
    "[fusion]") {
  const tf::Surfel<double> surfel;
  const tf::Kalman<double> kalman;
  const taxel::Vec3d x = taxel::Vec3d::UnitX(), y = taxel::Vec3d::UnitY(),
                     z = taxel::Vec3d::UnitZ();
  // A point near a box's edge (two faces) or corner (three), its first contact on the top face
  // (+z), its contacts spread 3 mm with 1 mm of lateral scatter and 0.05 rad of unstated normal
  // noise. The contacts of the other faces are 90 degrees off the patch's normal.
  for (const auto& faces : {std::vector<taxel::Vec3d>{z, x}, std::vector<taxel::Vec3d>{z, x, y}}) {
    for (const std::uint64_t seed : {1u, 2u, 3u}) {
      const auto all =
          face_contacts(faces, taxel::Vec3d(0.5e-3, 0.5e-3, 0.5e-3), 3e-3, 1e-3, 0.05, 4000, seed);
      std::vector<taxel::Contact<double>> top, others;
      for (const auto& c : all) (c.normal->dot(z) > 0.7 ? top : others).push_back(c);
      REQUIRE(top.size() > 100);
      REQUIRE(others.size() > 100);
      CAPTURE(faces.size(), seed);
      SECTION("the patch holds the majority: the mean is the patch's point") {
        // 300 top contacts, then 200 of the other faces (40 % apart): the mean is that of the
        // top contacts alone, to rounding.
        std::vector<taxel::Contact<double>> mixed(top.begin(), top.begin() + 300);
        mixed.insert(mixed.end(), others.begin(), others.begin() + 200);
        const auto s = fuse_all(surfel, mixed);
        const auto patch =
            fuse_all(surfel, std::vector<taxel::Contact<double>>(top.begin(), top.begin() + 300));
        CHECK(s.xcount == 200.0);
        CHECK(s.count == 300.0);
        CHECK((surfel.mean(s) - surfel.mean(patch)).norm() < 1e-12);
      }
      SECTION("other faces hold 80 % or more: the mean is Kalman's fusion") {
        // One top contact starts the point and its frame; every other contact is apart. With one
        // patch contact, the patch's point is that contact and its information is the
        // contact's, so the mean is exactly Kalman's.
        std::vector<taxel::Contact<double>> mixed{top.front()};
        mixed.insert(mixed.end(), others.begin(), others.begin() + 400);
        const auto s = fuse_all(surfel, mixed);
        const auto k = fuse_all(kalman, mixed);
        CHECK(s.xcount == 400.0);
        CHECK((surfel.mean(s) - kalman.mean(k)).norm() < 1e-9);
      }
    }
  }
}

TEST_CASE("Surfel: a crease inside the patch moves the point to Kalman's, a sphere's cap does not",
          "[fusion]") {
  const tf::Kalman<double> kalman;
  SECTION("two planes 0.5 rad apart, normals as good as stated") {
    // Every contact is within max_normal_angle (1.2 rad) of the others, so all enter the
    // curvature fit, whose slopes jump across the crease: the residual is far beyond the
    // stated 0.01 rad, and the point is Kalman's, whose tight planes meet on the crease.
    const tf::Surfel<double> sharp({.normal_sigma = 0.01});
    const taxel::Vec3d a(std::sin(-0.25), 0, std::cos(0.25)), b(std::sin(0.25), 0, std::cos(0.25));
    for (const std::uint64_t seed : {1u, 2u, 3u}) {
      const auto contacts =
          face_contacts({a, b}, taxel::Vec3d(0.3e-3, 0, 0), 3e-3, 1e-3, 0.01, 3000, seed);
      const auto s = fuse_all(sharp, contacts);
      const auto k = fuse_all(kalman, contacts);
      double h[3];
      sharp.fit_curvature(s, h);
      CAPTURE(seed);
      CHECK(s.xcount == 0.0);
      CHECK(sharp.crease_share(s, h) == 1.0);
      CHECK((sharp.mean(s) - kalman.mean(k)).norm() < 1e-9);
    }
  }
  SECTION("a 15 mm sphere's cap, normals turned by normal_sigma") {
    // The slopes follow H u: no crease, and the point stays on the sphere where Kalman's is
    // outside.
    for (const double noise : {0.01, 0.05}) {
      const tf::Surfel<double> p({.normal_sigma = noise});
      std::mt19937_64 rng(5);
      std::normal_distribution<double> g(0.0, 1.0);
      std::uniform_real_distribution<double> u(-3e-3, 3e-3);
      std::vector<taxel::Contact<double>> contacts;
      const double R = 0.015;
      for (int i = 0; i < 3000; ++i) {
        const double px = u(rng), py = u(rng);
        const taxel::Vec3d q(px, py, std::sqrt(R * R - px * px - py * py)), n = q / R;
        taxel::Contact<double> c;
        c.position = q + 0.3e-3 * g(rng) * n;
        c.covariance = taxel::pad_covariance<double>(n, 0.3e-3, 1e-3);
        c.footprint_sigma = 1e-3;  // an exact surface point
        const Eigen::Matrix3d turn(Eigen::AngleAxisd(noise * g(rng), taxel::Vec3d::UnitX()) *
                                   Eigen::AngleAxisd(noise * g(rng), taxel::Vec3d::UnitY()));
        c.normal = (turn * n).normalized();
        contacts.push_back(c);
      }
      const auto s = fuse_all(p, contacts);
      const auto k = fuse_all(kalman, contacts);
      double h[3];
      p.fit_curvature(s, h);
      CAPTURE(noise, p.mean(s).norm() - R, kalman.mean(k).norm() - R);
      CHECK(p.crease_share(s, h) == 0.0);
      CHECK(std::abs(p.mean(s).norm() - R) < 0.02e-3);
      CHECK(kalman.mean(k).norm() - R > 0.05e-3);
    }
  }
}

TEST_CASE("Surfel keeps a point from lying outside the plane of the contacts apart from it",
          "[fusion]") {
  // A point on a box's top face (+z) next to its edge along y (the solid is x <= 0, z <= 0):
  // its top contacts were reported past the edge, at x = 0.2-2.5 mm, as lateral scatter puts
  // them. 60 contacts of the side face (+x) are apart (14 %, too few for the blend). The patch
  // alone places the point beyond the edge; the side face's plane, through their Kalman mean,
  // bounds it.
  std::mt19937_64 rng(3);
  std::normal_distribution<double> g(0.0, 1.0);
  std::uniform_real_distribution<double> beyond(0.2e-3, 2.5e-3), along(-2e-3, 2e-3),
      down(-3e-3, 0.0);
  const taxel::Vec3d x = taxel::Vec3d::UnitX(), z = taxel::Vec3d::UnitZ();
  std::vector<taxel::Contact<double>> top, side;
  for (int i = 0; i < 360; ++i) {
    const bool on_top = i < 300;
    const taxel::Vec3d n = on_top ? z : x;
    taxel::Contact<double> c;
    c.position = on_top ? taxel::Vec3d(beyond(rng), along(rng), 0.3e-3 * g(rng))
                        : taxel::Vec3d(0.3e-3 * g(rng), along(rng), down(rng));
    c.covariance = taxel::pad_covariance<double>(n, 0.3e-3, 1e-3);
    c.normal = n;
    (on_top ? top : side).push_back(c);
  }
  std::vector<taxel::Contact<double>> all = top;
  all.insert(all.end(), side.begin(), side.end());
  const tf::Surfel<double> surfel;
  const auto s = fuse_all(surfel, all);
  const auto patch = fuse_all(surfel, top);
  const auto k = fuse_all(tf::Kalman<double>(), side);
  const double plane = tf::Kalman<double>().mean(k).x();
  CAPTURE(surfel.mean(patch).x(), surfel.mean(s).x(), plane);
  CHECK(s.xcount == 60.0);
  CHECK(surfel.mean(patch).x() > plane + 0.5e-3);
  CHECK(std::abs(surfel.mean(s).x() - plane) < 1e-12);
  // Only the component along the side's normal moves.
  CHECK(std::abs(surfel.mean(s).z() - surfel.mean(patch).z()) < 1e-12);
}
