// SPDX-License-Identifier: MIT
// Tests of the tactile pad model (sensor.hpp) and the explorations built on it
// (exploration.hpp): readings against closed-form indentation, contacts against the surface
// they came from, the stated covariance against the measured scatter, determinism, and bad
// parameters.
#include <Eigen/Eigenvalues>
#include <algorithm>
#include <catch2/catch.hpp>
#include <cmath>
#include <limits>
#include <numbers>
#include <random>
#include <taxel/sim.hpp>

namespace ts = taxel::sim;
using taxel::Vec3d;

namespace {

ts::SensorModel noiseless() {
  ts::SensorModel m;
  m.sigma_normal = 0.0;
  m.sigma_position = 0.0;
  m.sigma_tilt = 0.0;
  return m;
}

// A pad facing down onto the top face (z = 0.02) of the default box, pressed `depth` in.
Eigen::Isometry3d on_box_top(double depth, double x = 0.0, double y = 0.0) {
  Eigen::Isometry3d T = Eigen::Isometry3d::Identity();
  T.linear() = Eigen::AngleAxisd(M_PI, Vec3d::UnitX()).matrix();  // pad z -> world -z
  T.translation() = Vec3d(x, y, 0.02 - depth);
  return T;
}

}  // namespace

TEST_CASE("pad readings follow the indentation, contacts lie on the pressed surface",
          "[sim][sensor]") {
  const ts::Box box;
  ts::SensorModel m = noiseless();
  std::mt19937_64 rng(1);
  const double depth = 1.0e-3;
  const ts::PadReading r = ts::read_pad(box, m, on_box_top(depth), rng);
  REQUIRE(r.counts.rows() == 14);
  REQUIRE(r.counts.cols() == 6);
  const auto expected = static_cast<std::uint16_t>(std::lround(depth / m.full_scale_depth * 4095));
  CHECK((r.counts == expected).all());
  CHECK(r.believed_pose.isApprox(r.true_pose));

  std::vector<taxel::Contact<double>> contacts;
  CHECK(ts::pad_contacts(r, m, ts::ContactMode::per_tactel, 0.5, contacts) == 84);
  const double quantum = m.full_scale_depth / 4095;
  for (const auto& c : contacts) {
    CHECK(std::abs(c.position.z() - 0.02) <= quantum);  // the undeformed face of the box
    CHECK(c.normal->isApprox(Vec3d::UnitZ()));
    CHECK(c.time == 0.5);
    CHECK(taxel::check_contact(c) == taxel::ContactDefect::ok);
    // In-plane variance: quantisation over one tactel; along the normal: depth quantisation
    // and the normal's own uncertainty over the tactel's footprint (a few per cent here).
    const Eigen::SelfAdjointEigenSolver<taxel::Mat3d> eig(c.covariance);
    CHECK(eig.eigenvalues()(2) == Approx(std::pow(3.4e-3, 2) / 12).epsilon(1e-9));
    CHECK(c.covariance(2, 2) >= quantum * quantum / 12);
    // Corner tactels fit their normal to four depths: var g = 2 * vd / pitch^2 per axis.
    CHECK(c.covariance(2, 2) <= (1.0 + 1.0 / 6.0) * quantum * quantum / 12 * (1 + 1e-9));
  }
  // The tactel grid: x spans 5 pitches, y spans 13.
  double xmin = 1, xmax = -1, ymin = 1, ymax = -1;
  for (const auto& c : contacts) {
    xmin = std::min(xmin, c.position.x());
    xmax = std::max(xmax, c.position.x());
    ymin = std::min(ymin, c.position.y());
    ymax = std::max(ymax, c.position.y());
  }
  CHECK(xmax - xmin == Approx(5 * 3.4e-3));
  CHECK(ymax - ymin == Approx(13 * 3.4e-3));

  SECTION("one pressure-weighted contact per pad") {
    std::vector<taxel::Contact<double>> one;
    CHECK(ts::pad_contacts(r, m, ts::ContactMode::per_pad, 0.5, one) == 1);
    CHECK(one[0].position.isApprox(Vec3d(0, 0, 0.02), 1e-3));
    CHECK(std::abs(one[0].position.z() - 0.02) <= quantum);
    CHECK(one[0].pressure == 84.0 * expected);
  }
  SECTION("half the pad over the edge: only the tactels on the face read") {
    // Pad centre at x = 0.04 (the edge): columns with x > 0 hang in the air.
    const ts::PadReading half = ts::read_pad(box, m, on_box_top(depth, 0.04), rng);
    CHECK((half.counts.leftCols(3) == expected).all());
    CHECK((half.counts.rightCols(3) == std::uint16_t{0}).all());
  }
  SECTION("saturated tactels give no per-tactel contact, lifted pads none at all") {
    const ts::PadReading deep = ts::read_pad(box, m, on_box_top(5e-3), rng);
    CHECK((deep.counts == std::uint16_t{4095}).all());
    std::vector<taxel::Contact<double>> none;
    CHECK(ts::pad_contacts(deep, m, ts::ContactMode::per_tactel, 0, none) == 0);
    CHECK(ts::pad_contacts(deep, m, ts::ContactMode::per_pad, 0, none) == 0);
    const ts::PadReading lifted = ts::read_pad(box, m, on_box_top(-1e-3), rng);
    CHECK_FALSE(lifted.touching());
    CHECK(ts::pad_contacts(lifted, m, ts::ContactMode::per_tactel, 0, none) == 0);
  }
  SECTION("below the threshold a tactel reads zero") {
    const ts::PadReading light = ts::read_pad(box, m, on_box_top(0.5 * m.threshold * quantum), rng);
    CHECK_FALSE(light.touching());
  }
}

TEST_CASE("pad on a sphere: contacts on the surface", "[sim][sensor]") {
  const ts::Sphere sphere(0.04);
  const ts::SensorModel m = noiseless();
  std::mt19937_64 rng(2);
  Eigen::Isometry3d T = Eigen::Isometry3d::Identity();
  T.linear() = Eigen::AngleAxisd(M_PI, Vec3d::UnitX()).matrix();
  T.translation() = Vec3d(0, 0, 0.04 - 1.5e-3);
  const ts::PadReading r = ts::read_pad(sphere, m, T, rng);
  std::vector<taxel::Contact<double>> contacts;
  const std::size_t n = ts::pad_contacts(r, m, ts::ContactMode::per_tactel, 0, contacts);
  // The touching disc: tactels within sqrt(2 R d) = 11 mm of the pad centre (less the threshold).
  std::size_t inside = 0;
  for (int row = 0; row < 14; ++row)
    for (int col = 0; col < 6; ++col)
      inside += m.geometry.tactel(row, col).head<2>().norm() < 0.0105 ? 1 : 0;
  CHECK(n >= inside);
  CHECK(n <= 84);
  for (const auto& c : contacts) {
    // Compression is measured along the pad normal: the contact lies on the sphere up to the
    // depth quantum.
    CHECK(std::abs(sphere.signed_distance(c.position)) < 1e-6);
  }
}

TEST_CASE("pad noise: the scatter along the normal matches the stated covariance",
          "[sim][sensor]") {
  const ts::Box box;
  ts::SensorModel m;  // default noise: 0.3 mm depth, 0.2 mm position, 0.02 rad tilt
  std::mt19937_64 rng(3);
  double sum_ratio = 0.0, sum_angle2 = 0.0;
  std::size_t count = 0;
  for (int frame = 0; frame < 3000; ++frame) {
    const ts::PadReading r = ts::read_pad(box, m, on_box_top(1.5e-3), rng);
    std::vector<taxel::Contact<double>> contacts;
    ts::pad_contacts(r, m, ts::ContactMode::per_tactel, 0, contacts);
    for (const auto& c : contacts) {
      const Vec3d n = *c.normal;
      const double e = c.position.z() - 0.02;  // the error: the face is at z = 0.02
      // Variance the contact claims along the true normal (+z), against the squared error.
      sum_ratio += e * e / Vec3d::UnitZ().dot(c.covariance * Vec3d::UnitZ());
      ++count;
      // Normals from the depth map: the whole pad is pressed, so they come from the pad-wide
      // quadric, whose slope noise (0.3 mm over 84 tactels) is small beside the pose's 0.02
      // rad tilt (a 3x3 plane's would be about 0.04 rad per axis inside, 0.09 at the corners).
      const double angle = std::acos(std::min(1.0, n.z()));
      sum_angle2 += angle * angle;
      CHECK(angle < 0.45);
    }
  }
  REQUIRE(count > 100000);
  CHECK(sum_ratio / double(count) == Approx(1.0).margin(0.06));
  CHECK(std::sqrt(sum_angle2 / double(count)) < 0.03);  // about 0.024
  CHECK(std::sqrt(sum_angle2 / double(count)) > 0.018);
}

TEST_CASE("explorations: deterministic, timed, on the surface, at the object's pose",
          "[sim][exploration]") {
  ts::ExplorationConfig cfg;
  cfg.sensor = noiseless();
  cfg.object_pose.linear() = Eigen::AngleAxisd(0.7, Vec3d(1, 2, 3).normalized()).matrix();
  cfg.object_pose.translation() = Vec3d(0.1, -0.2, 0.3);
  const ts::Cylinder cyl(0.03, 0.05);
  const auto check = [&](const auto& ex, std::size_t min_contacts) {
    INFO("frames " << ex.frames.size());
    REQUIRE(ex.contact_count() >= min_contacts);
    // Noise-free, contacts lie on the placed surface up to the depth quantum (0.73 um).
    double worst = 0.0;
    for (std::size_t f = 0; f < ex.frames.size(); ++f) {
      CHECK(ex.frames[f].time == Approx(double(f) / cfg.frame_rate));
      for (const auto& c : ex.frames[f].contacts) {
        REQUIRE(c.time == ex.frames[f].time);
        const double d = std::abs(ex.truth.signed_distance(c.position));
        worst = std::max(worst, d);
      }
    }
    CHECK(worst < 1e-6);
    // The contacts are on the placed shape, not on the shape at the origin.
    CHECK(std::abs(cyl.signed_distance(ex.contacts().front().position)) > 0.05);
  };
  const auto slide = ts::explore_sliding(cyl, cfg, {.slides = 2, .frames = 300});
  CHECK(slide.frames.size() == 600);
  check(slide, 600);
  const auto grasp = ts::explore_grasps(cyl, cfg, {.grasps = 4});
  check(grasp, 100);
  const auto palp = ts::explore_palpation(cyl, cfg, {.touches = 10});
  check(palp, 10);

  SECTION("a grasp: every pad in every frame, by a stable id, most touching in the hold") {
    // 3 fingers x 2 pads 5 cm apart on a 10 cm cylinder.
    for (const auto& f : grasp.frames) {
      REQUIRE(f.pads.size() == 6);
      for (int i = 0; i < 6; ++i) CHECK(f.pads[std::size_t(i)].pad == i);
    }
    const auto& hold = grasp.frames.back();
    int touching = 0;
    for (const auto& p : hold.pads) touching += p.touching() ? 1 : 0;
    CHECK(touching >= 4);
  }
  SECTION("per-pad contacts: one per pad and frame, one per tactel under six active") {
    ts::ExplorationConfig per_pad = cfg;
    per_pad.contacts.mode = ts::ContactMode::per_pad;
    const auto g = ts::explore_grasps(cyl, per_pad, {.grasps = 4});
    std::size_t merged = 0;  // frames where some pad gave one contact for several tactels
    for (const auto& f : g.frames) {
      std::size_t at_least = 0, at_most = 0;
      for (const auto& p : f.pads) {
        const auto active = static_cast<std::size_t>(
            ((p.counts >= static_cast<std::uint16_t>(per_pad.sensor.threshold)) &&
             (p.counts < static_cast<std::uint16_t>(per_pad.sensor.levels - 1)))
                .count());
        at_least += active >= 6 ? 1 : active;
        at_most += active;
      }
      CHECK(f.contacts.size() >= at_least);
      CHECK(f.contacts.size() <= at_most);
      if (f.contacts.size() < at_most) ++merged;
    }
    CHECK(merged > 0);
    CHECK(g.contact_count() > 0);
  }
  SECTION("equal seeds give equal streams, other seeds other streams") {
    ts::ExplorationConfig noisy;
    noisy.seed = 9;
    const auto a = ts::explore_palpation(ts::Sphere(0.04), noisy, {.touches = 5});
    const auto b = ts::explore_palpation(ts::Sphere(0.04), noisy, {.touches = 5});
    noisy.seed = 10;
    const auto c = ts::explore_palpation(ts::Sphere(0.04), noisy, {.touches = 5});
    const auto ca = a.contacts(), cb = b.contacts(), cc = c.contacts();
    REQUIRE(ca.size() == cb.size());
    for (std::size_t i = 0; i < ca.size(); ++i) REQUIRE(ca[i].position == cb[i].position);
    CHECK((ca.size() != cc.size() || ca[0].position != cc[0].position));
  }
}

TEST_CASE("explorations and sensor model refuse bad parameters", "[sim][exploration]") {
  const ts::Sphere s(0.04);
  ts::ExplorationConfig cfg;
  CHECK_THROWS_AS(ts::explore_sliding(s, cfg, {.slides = 0}), std::invalid_argument);
  CHECK_THROWS_AS(ts::explore_grasps(s, cfg, {.fingers = 0}), std::invalid_argument);
  CHECK_THROWS_AS(ts::explore_palpation(s, cfg, {.press_speed = 0}), std::invalid_argument);
  cfg.indentation = std::nan("");
  CHECK_THROWS_AS(ts::explore_sliding(s, cfg), std::invalid_argument);
  // A length in millimetres given as metres, and frame rates beyond any tactile sensor's.
  cfg.indentation = 1.5;
  CHECK_THROWS_WITH(ts::explore_sliding(s, cfg),
                    Catch::Contains("indentation must be in (0, 1] m"));
  cfg = {};
  for (const double rate : {0.0, 2e6, 1e300, std::numeric_limits<double>::infinity()}) {
    cfg.frame_rate = rate;
    CHECK_THROWS_WITH(ts::explore_palpation(s, cfg), Catch::Contains("frame_rate must be in"));
  }
  // Pressing in so slowly that it would take more than a million frames (at 1e-300 m/s the
  // frame count overflowed an int, and at 1e-9 m/s the exploration ran for hours): refused
  // before any frame, naming the parameters to change.
  cfg = {};
  for (const double speed : {1e-300, 1e-9}) {
    CHECK_THROWS_WITH(ts::explore_palpation(s, cfg, {.touches = 1, .press_speed = speed}),
                      Catch::Contains("PalpationParams: pressing") &&
                          Catch::Contains("more than a million frames"));
    CHECK_THROWS_WITH(ts::explore_grasps(s, cfg, {.grasps = 1, .closing_speed = speed}),
                      Catch::Contains("GraspParams: pressing"));
  }
  CHECK_THROWS_WITH(ts::explore_palpation(s, cfg, {.hold_frames = 1000001}),
                    Catch::Contains("hold_frames in [0, 1e6]"));
  CHECK_THROWS_WITH(ts::explore_grasps(s, cfg, {.hold_frames = std::numeric_limits<int>::max()}),
                    Catch::Contains("hold_frames in [0, 1e6]"));
  // A press within the bound: 1 mm at 0.01 m/s and 1 kHz is 100 frames, and the two before.
  const ts::Exploration<ts::Sphere> quick =
      ts::explore_palpation(s, cfg, {.touches = 1, .press_speed = 0.01, .hold_frames = 0});
  CHECK(quick.frames.size() == 102);
  cfg = {};
  cfg.sensor.geometry.pitch = -1;
  CHECK_THROWS_WITH(ts::explore_palpation(s, cfg), Catch::Contains("pitch"));
  cfg = {};
  cfg.sensor.threshold = cfg.sensor.levels;
  CHECK_THROWS_WITH(ts::explore_palpation(s, cfg), Catch::Contains("threshold"));
  cfg = {};
  cfg.frame_rate = 0;
  CHECK_THROWS_WITH(ts::explore_grasps(s, cfg), Catch::Contains("frame_rate"));
}

TEST_CASE("footprint integration: a tactel reads its mean indentation over its square",
          "[sim][sensor]") {
  // A 5x5 pad of 3.4 mm tactels pressed 1 mm into the top of a 15 mm sphere, fine levels and no
  // noise, so that a reading is the indentation to 46 nm.
  const double R = 0.015, depth = 1e-3, a = 3.4e-3;
  const ts::Sphere sphere{R};
  ts::SensorModel m = noiseless();
  m.geometry.rows = m.geometry.cols = 5;
  m.geometry.pitch = a;
  m.levels = 65536;
  m.threshold = 1;
  const double quantum = m.depth_per_count();
  Eigen::Isometry3d T = Eigen::Isometry3d::Identity();
  T.linear() = Eigen::AngleAxisd(M_PI, Vec3d::UnitX()).matrix();  // pad z -> world -z
  T.translation() = Vec3d(0, 0, R - depth);
  // The oracle: the compression sqrt(R^2 - x^2 - y^2) - (R - depth) averaged over the tactel's
  // square by brute force (a 400 x 400 midpoint grid).
  // Also says whether the whole square touches.
  const auto mean_indentation = [&](double x0, double y0, bool& whole) {
    const int n = 400;
    double sum = 0.0;
    whole = true;
    for (int i = 0; i < n; ++i) {
      for (int j = 0; j < n; ++j) {
        const double x = x0 + a * ((i + 0.5) / n - 0.5), y = y0 + a * ((j + 0.5) / n - 0.5);
        const double d = std::sqrt(R * R - x * x - y * y) - (R - depth);
        whole = whole && d > 0;
        sum += std::max(0.0, d);
      }
    }
    return sum / (n * n);
  };
  std::mt19937_64 rng(3);
  const ts::PadReading centre = ts::read_pad(sphere, m, T, rng, 0, 1);
  const ts::PadReading area2 = ts::read_pad(sphere, m, T, rng, 0, 2);
  const ts::PadReading area4 = ts::read_pad(sphere, m, T, rng, 0, 4);
  // The middle tactel, fully touching: it reads pitch^2 / (12 R) less than at its centre
  // (64 um here; the closed form of a paraboloid, within its quartic term, 0.2 um).
  const double at_centre = centre.counts(2, 2) * quantum, over_area = area4.counts(2, 2) * quantum;
  CHECK(at_centre == Approx(depth).margin(quantum));
  CHECK(at_centre - over_area == Approx(a * a / (12 * R)).margin(0.3e-6));
  // Every tactel against the oracle. Where the whole square touches, the four-point rule is
  // exact to the quantum and the two-point one within 1 um; where only part of it touches (the
  // diagonal tactels here), the indentation has a kink and both are within 4 um.
  int whole_squares = 0;
  for (int r = 1; r <= 3; ++r) {
    for (int c = 1; c <= 3; ++c) {
      const Vec3d p = T * m.geometry.tactel(r, c);
      bool whole = false;
      const double want = mean_indentation(p.x(), p.y(), whole);
      whole_squares += whole ? 1 : 0;
      CAPTURE(r, c, want, whole);
      CHECK(area4.counts(r, c) * quantum == Approx(want).margin(whole ? 2 * quantum : 4e-6));
      CHECK(area2.counts(r, c) * quantum == Approx(want).margin(whole ? 1e-6 : 4e-6));
    }
  }
  CHECK(whole_squares == 5);  // the middle and its four neighbours
  // A tactel whose centre is off the object but part of its square is on it reads that part.
  const double R2 = 0.0035;  // a 3.5 mm sphere under the 5x5 pad: the ring of tactels at 3.4 mm
  const ts::Sphere small{R2};
  Eigen::Isometry3d T2 = T;
  T2.translation() = Vec3d(0, 0, R2 - depth);
  const ts::PadReading edge1 = ts::read_pad(small, m, T2, rng, 0, 1);
  const ts::PadReading edge4 = ts::read_pad(small, m, T2, rng, 0, 4);
  CHECK(edge1.counts(2, 3) == 0);  // its centre is outside the sphere
  CHECK(edge4.counts(2, 3) > 0);
  CHECK_THROWS_AS(ts::read_pad(sphere, m, T, rng, 0, 5), std::invalid_argument);
  CHECK_THROWS_AS(ts::read_pad(sphere, m, T, rng, 0, 0), std::invalid_argument);
}

TEST_CASE(
    "contact_stream: stated covariances that match the scatter, unstated normal and pose "
    "noise",
    "[sim][stream]") {
  const ts::Box box(Vec3d(0.06, 0.05, 0.04));
  ts::ContactStreamConfig cfg;
  cfg.contacts = 20000;
  cfg.seed = 5;
  cfg.normal_noise = 0.0;
  cfg.pose_position = 0.0;
  cfg.pose_angle = 0.0;
  const auto a = ts::contact_stream(box, cfg);
  REQUIRE(a.size() == 20000);
  CHECK(ts::contact_stream(box, cfg)[12345].position == a[12345].position);  // deterministic
  // Along the normal the scatter is the stated 0.3 mm, centred on the surface (flat faces; the
  // contacts within 2 mm of an edge are left out).
  double sum = 0, sum2 = 0;
  std::size_t n = 0, exact_normals = 0;
  for (const auto& c : a) {
    REQUIRE(c.normal);
    CHECK(c.normal_sigma == 0.0);  // not stated
    Eigen::SelfAdjointEigenSolver<Eigen::Matrix3d> es(c.covariance);
    CHECK(es.eigenvalues()(0) == Approx(cfg.sigma_normal * cfg.sigma_normal).epsilon(1e-9));
    CHECK(es.eigenvalues()(2) == Approx(cfg.sigma_lateral * cfg.sigma_lateral).epsilon(1e-9));
    const Vec3d d = box.half_extents - c.position.cwiseAbs();
    int near_edge = 0;
    for (int k = 0; k < 3; ++k) near_edge += d[k] < 2e-3 ? 1 : 0;
    if (near_edge != 1) continue;
    const double s = box.signed_distance(c.position);
    sum += s;
    sum2 += s * s;
    ++n;
    exact_normals += (c.normal->cwiseAbs().maxCoeff() == 1.0) ? 1 : 0;
  }
  REQUIRE(n > 10000);
  const double mean = sum / double(n), sd = std::sqrt(sum2 / double(n) - mean * mean);
  CHECK(std::abs(mean) < 3 * cfg.sigma_normal / std::sqrt(double(n)));
  CHECK(sd == Approx(cfg.sigma_normal).epsilon(0.03));
  CHECK(exact_normals == n);  // without normal noise, a face's normal exactly
  // Normal noise and a pose error, neither stated: the normals turn by about
  // sqrt(2 normal_noise^2 + 2/3 pose_angle^2) on average (0.073 rad here).
  cfg.normal_noise = 0.05;
  cfg.pose_angle = 0.02;
  cfg.pose_position = 0.2e-3;
  const auto b = ts::contact_stream(box, cfg);
  double angle = 0;
  std::size_t m = 0;
  for (const auto& c : b) {
    const Vec3d d = box.half_extents - c.position.cwiseAbs();
    if ((d.array() < 3e-3).count() != 1) continue;
    angle += std::acos(std::clamp(c.normal->dot(box.normal(c.position)), -1.0, 1.0));
    ++m;
    CHECK(c.normal_sigma == 0.0);
  }
  const double expected = std::sqrt(std::numbers::pi / 2) *
                          std::sqrt(2 * 0.05 * 0.05 + 2.0 / 3.0 * 0.02 * 0.02) / std::sqrt(2.0);
  CHECK(angle / double(m) == Approx(expected).epsilon(0.1));
  cfg.sigma_lateral = -1e-3;
  CHECK_THROWS_WITH(ts::contact_stream(box, cfg), Catch::Contains("sigma_lateral"));
  cfg.sigma_lateral = 1e-3;
  cfg.footprint = 5;
  CHECK_THROWS_WITH(ts::contact_stream(box, cfg), Catch::Contains("footprint"));
  cfg.footprint = 1;
  cfg.normal_smoothing = -1;
  CHECK_THROWS_WITH(ts::contact_stream(box, cfg), Catch::Contains("normal_smoothing"));
}

TEST_CASE("contact_stream: stated normal noise, depth-map normals, footprint, no lateral scatter",
          "[sim][stream]") {
  ts::ContactStreamConfig cfg;
  cfg.contacts = 5000;
  cfg.seed = 9;
  SECTION("normal_sigma stated: the per-axis tilt of normal noise and pose error") {
    cfg.state_normal_sigma = true;
    for (const auto& c : ts::contact_stream(ts::Sphere(0.03), cfg)) {
      CHECK(c.normal_sigma == Approx(std::sqrt(0.05 * 0.05 + 0.02 * 0.02 / 3)));
    }
  }
  SECTION("no lateral scatter: positions on the surface across the normal") {
    cfg.sigma_lateral = 0;
    cfg.sigma_normal = 1e-9;
    cfg.pose_position = cfg.pose_angle = 0;
    const ts::Sphere sphere(0.03);
    for (const auto& c : ts::contact_stream(sphere, cfg)) {
      CHECK(std::abs(sphere.signed_distance(c.position)) < 1e-8);
      // Stated isotropic at sigma_normal.
      CHECK(c.covariance.isApprox(Eigen::Matrix3d::Identity() * 1e-18, 1e-6));
    }
  }
  SECTION("depth-map normals round a box's edges, and are exact on its faces") {
    const ts::Box box(Vec3d(0.06, 0.05, 0.04));
    cfg.normal_noise = cfg.pose_angle = cfg.pose_position = 0;
    cfg.sigma_lateral = 0;
    cfg.sigma_normal = 1e-9;
    cfg.normal_smoothing = 1e-3;
    std::size_t rounded = 0, on_faces = 0;
    for (const auto& c : ts::contact_stream(box, cfg)) {
      const Vec3d d = box.half_extents - c.position.cwiseAbs();
      const bool face = (d.array() < 1.5e-3).count() == 1;  // > 1.5 mm from every edge
      const bool exact = c.normal->cwiseAbs().maxCoeff() == 1.0;
      if (face) {
        ++on_faces;
        CHECK(exact);
      }
      if (!exact) {
        ++rounded;
        CHECK((d.array() < 1.1e-3).count() >= 2);  // within the smoothing of an edge
      }
    }
    CHECK(on_faces > 1000);
    CHECK(rounded > 20);
  }
  SECTION("footprint: fully touching sites sit inside a sphere by pitch^2 / (12 R)") {
    // A small pad pressed 2.5 mm deep into a 40 mm sphere: every site touches over its whole
    // footprint, and reads the mean compression, pitch^2 / (12 R) less than at its centre
    // (exact for a paraboloid with 2 x 2 Gauss points); at footprint 1 it reads its centre.
    const double R = 0.04;
    const ts::Sphere sphere(R);
    cfg.rows = cfg.cols = 3;
    cfg.indentation = 2.5e-3;
    cfg.sigma_lateral = 0;
    cfg.sigma_normal = 1e-9;
    cfg.normal_noise = cfg.pose_angle = cfg.pose_position = 0;
    for (const int footprint : {1, 2, 3}) {
      cfg.footprint = footprint;
      double sum = 0;
      const auto contacts = ts::contact_stream(sphere, cfg);
      for (const auto& c : contacts) sum += sphere.signed_distance(c.position);
      const double mean = sum / double(contacts.size());
      CAPTURE(footprint, mean);
      if (footprint == 1) {
        CHECK(std::abs(mean) < 1e-9);
      } else {
        CHECK(mean == Approx(-cfg.pitch * cfg.pitch / (12 * R)).epsilon(0.05));
      }
    }
  }
}
