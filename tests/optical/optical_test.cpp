// SPDX-License-Identifier: MIT
// Tests of the optical layer: the transforms against their direct sums, Poisson integration
// against exact heights, contact circles, and a calibration on rendered ball presses that
// reconstructs held-out presses of a ball, a cylinder and an edge against the rendering's truth.
#include <algorithm>
#include <catch2/catch.hpp>
#include <cmath>
#include <cstring>
#include <filesystem>
#include <limits>
#include <numbers>
#include <random>
#include <string>
#include <taxel/optical.hpp>
#include <taxel/sim/optical.hpp>
#include <vector>

namespace to = taxel::optical;
namespace ts = taxel::sim;
namespace image = taxel::image;

namespace {

constexpr int kRows = 240, kCols = 320;
constexpr double kPixel = 0.0634e-3;  // a GelSight Mini's mm per pixel, in metres
constexpr double kBall = 2e-3;        // calibration ball radius [m]

to::Plane random_plane(int rows, int cols, std::mt19937_64& rng) {
  std::uniform_real_distribution<double> u(-1.0, 1.0);
  to::Plane p(rows, cols);
  for (int r = 0; r < rows; ++r) {
    for (int c = 0; c < cols; ++c) p(r, c) = u(rng);
  }
  return p;
}

// A rendered set-up: the model's background, ball presses and a calibration from them.
struct Rig {
  to::ShadingModel model;
  to::Colour background;
  to::RgbFrame background_frame;
  std::vector<to::RgbFrame> presses;
  std::vector<to::Circle> truth;
  std::mt19937_64 rng{7};

  explicit Rig(int presses_count) {
    background = to::render_background(model, kRows, kCols);
    const to::Plane zero = to::Plane::Zero(kRows, kCols);
    background_frame = to::render(zero, zero, background, model, 2.0, rng);
    std::uniform_real_distribution<double> u(0.0, 1.0);
    for (int i = 0; i < presses_count; ++i) {
      const double d = 0.3e-3 + 0.4e-3 * u(rng), cx = 40 + 240 * u(rng), cy = 40 + 160 * u(rng);
      presses.push_back(frame(ts::press_ball(kRows, kCols, kPixel, kBall, d, cx, cy)));
      truth.push_back({cx, cy, std::sqrt(kBall * kBall - (kBall - d) * (kBall - d)) / kPixel});
    }
  }
  to::RgbFrame frame(const ts::GelPress& g) {
    return to::render(g.gx, g.gy, background, model, 2.0, rng);
  }
};

}  // namespace

TEST_CASE("optical: the DST-I and DCT-II by FFT equal their direct sums", "[optical]") {
  std::mt19937_64 rng(1);
  for (const auto& [rows, cols] : {std::pair{7, 9}, std::pair{6, 8}, std::pair{3, 3}}) {
    to::PoissonSolver solver(rows, cols);
    const to::Plane a = random_plane(rows, cols, rng);
    to::Plane dst = a, dct = a, back = a;
    solver.dst_rows(dst);
    solver.dct_rows(dct);
    solver.dct_cols(back);
    solver.idct_cols(back);
    const double pi = std::numbers::pi;
    for (int r = 0; r < rows; ++r) {
      for (int k = 0; k < cols; ++k) {
        double s = 0, c = 0;
        for (int j = 0; j < cols; ++j) {
          s += a(r, j) * std::sin(pi * (j + 1) * (k + 1) / (cols + 1));
          c += a(r, j) * std::cos(pi * k * (2 * j + 1) / (2.0 * cols));
        }
        CHECK(dst(r, k) == Approx(s).margin(1e-12));
        CHECK(dct(r, k) == Approx(c).margin(1e-12));
        CHECK(back(r, k) == Approx(a(r, k)).margin(1e-12));
      }
    }
  }
}

TEST_CASE("optical: Poisson integration recovers heights from their exact gradients", "[optical]") {
  // A Gaussian bump, 0.4 mm high and 12 px wide, inside a 120 x 160 frame, and a tilted
  // plane's ramp that runs off the frame: the free border recovers both (up to the constant
  // it sets on the untouched pixels); the zero border only the bump, which vanishes there.
  const int rows = 120, cols = 160;
  const double pixel = 0.05e-3, amp = 0.4e-3, w = 12.0;
  to::Plane h(rows, cols), gx(rows, cols), gy(rows, cols);
  for (int r = 0; r < rows; ++r) {
    for (int c = 0; c < cols; ++c) {
      const double x = c - 80.0, y = r - 60.0;
      const double e = amp * std::exp(-(x * x + y * y) / (2 * w * w));
      h(r, c) = e;
      gx(r, c) = -x / (w * w) * e / pixel;
      gy(r, c) = -y / (w * w) * e / pixel;
    }
  }
  to::PoissonSolver solver(rows, cols);
  const to::Plane zero_border = solver.integrate(gx, gy, pixel, to::PoissonBorder::zero);
  const to::Plane free_border = solver.integrate(gx, gy, pixel);
  // (Free: the whole frame averages 0, so compare after removing the mean.)
  const double mean = h.mean();
  CHECK((zero_border - h).abs().maxCoeff() < 0.01 * amp);
  CHECK((free_border - (h - mean)).abs().maxCoeff() < 0.01 * amp);
  // A ramp along x, 0.2 mm over the frame, plus the bump: the free border keeps it.
  to::Plane gr = gx + 0.2e-3 / (cols * pixel);
  to::Plane ramp(rows, cols);
  for (int r = 0; r < rows; ++r) {
    for (int c = 0; c < cols; ++c) ramp(r, c) = h(r, c) + 0.2e-3 * c / cols;
  }
  const to::Plane free_ramp = solver.integrate(gr, gy, pixel);
  CHECK((free_ramp - (ramp - ramp.mean())).abs().maxCoeff() < 0.01 * amp);
  CHECK_THROWS_WITH(solver.integrate(to::Plane::Zero(3, 3), gy, pixel),
                    Catch::Contains("gx is 3 x 3, the solver's planes are 120 x 160"));
  CHECK_THROWS_WITH(solver.integrate(gx, gy, 0.0), Catch::Contains("pixel size"));
  CHECK_THROWS_WITH(to::PoissonSolver(2, 5), Catch::Contains("at least 3 x 3"));
}

TEST_CASE("optical: a ball press's contact circle is found to a fifth of a pixel", "[optical]") {
  Rig rig(6);
  for (std::size_t i = 0; i < rig.presses.size(); ++i) {
    const to::Colour change = to::colour_change(rig.presses[i], rig.background);
    const to::Circle c = to::find_contact_circle(change);
    CAPTURE(i, c.cx, c.cy, c.radius, rig.truth[i].radius);
    CHECK(std::abs(c.cx - rig.truth[i].cx) < 0.2);
    CHECK(std::abs(c.cy - rig.truth[i].cy) < 0.2);
    CHECK(std::abs(c.radius - rig.truth[i].radius) < 0.2);
    // The search for real gels (drape, lighting): its centre from the change's oddness, its
    // radius at the ring of strongest change, which on a rendered press is the contact's last
    // ring of pixels.
    const to::Circle p = to::find_press_circle(change, {}, kBall / kPixel);
    CAPTURE(p.cx, p.cy, p.radius);
    CHECK(std::abs(p.cx - rig.truth[i].cx) <= 0.5);
    CHECK(std::abs(p.cy - rig.truth[i].cy) <= 0.5);
    CHECK(p.radius <= rig.truth[i].radius + 0.2);
    CHECK(p.radius > rig.truth[i].radius - 1.5);
  }
  // No contact: the background frame itself.
  CHECK_THROWS_WITH(
      to::find_contact_circle(to::colour_change(rig.background_frame, rig.background)),
      Catch::Contains("no contact"));
}

TEST_CASE(
    "optical: a calibration from rendered presses reconstructs a ball, a cylinder and an "
    "edge",
    "[optical]") {
  Rig rig(12);
  const to::Calibration cal =
      to::calibrate(rig.presses, rig.background_frame, {.ball_radius = kBall, .pixel = kPixel});
  REQUIRE(cal.circles.size() == 12);
  // Held-out gradient errors of both maps, and the better one kept.
  CAPTURE(cal.heldout_polynomial, cal.heldout_table);
  CHECK(cal.heldout() == std::min(cal.heldout_polynomial, cal.heldout_table));
  CHECK(cal.heldout() < 0.08);
  to::PoissonSolver solver(kRows, kCols);
  // Held-out balls (not among the presses): radius from the fitted sphere, height against the
  // truth inside the contact.
  for (const double cx : {90.0, 160.0, 250.0}) {
    const ts::GelPress g = ts::press_ball(kRows, kCols, kPixel, kBall, 0.5e-3, cx, 120.0);
    const to::HeightMap map = to::reconstruct(rig.frame(g), cal, solver);
    const to::BallFit fit = to::fit_ball(map, kPixel);
    double e = 0, n = 0;
    for (int r = 0; r < kRows; ++r) {
      for (int c = 0; c < kCols; ++c) {
        if (g.height(r, c) <= 0) continue;
        e += (map.height(r, c) - g.height(r, c)) * (map.height(r, c) - g.height(r, c));
        n += 1;
      }
    }
    CAPTURE(cx, fit.radius, std::sqrt(e / n));
    CHECK(std::abs(fit.radius - kBall) < 0.1 * kBall);  // measured: 3-5 % small
    CHECK(std::abs(fit.cx - cx) < 1.0);
    CHECK(std::sqrt(e / n) < 0.03e-3);  // measured: 0.008-0.014 mm
    CHECK(map.height.maxCoeff() == Approx(0.5e-3).epsilon(0.06));
    // The contact mask: the deformed pixels at least 0.3 of the deepest height, which on a
    // rendered ball (no drape) is the part of the contact at least 0.15 mm deep.
    int wrong = 0, inside = 0;
    for (int r = 0; r < kRows; ++r) {
      for (int c = 0; c < kCols; ++c) {
        const bool truth = g.height(r, c) >= 0.3 * 0.5e-3;
        inside += truth;
        // (pixels within 0.02 mm of the share's height may fall either way)
        if (std::abs(g.height(r, c) - 0.3 * 0.5e-3) > 0.02e-3 &&
            truth != (map.contact(r, c) != 0)) {
          ++wrong;
        }
        if (map.contact(r, c)) CHECK(map.mask(r, c));
      }
    }
    CAPTURE(wrong, inside);
    CHECK(wrong < inside / 100);
  }
  // A cylinder across the whole frame (its contact reaches the border) and an edge.
  for (const bool edge : {false, true}) {
    const ts::GelPress g =
        edge ? ts::press_edge(kRows, kCols, kPixel, 0.4, 0.3e-3, 160, 120, 0.3)
             : ts::press_cylinder(kRows, kCols, kPixel, 3e-3, 0.4e-3, 160, 120, 0.5);
    const to::HeightMap map = to::reconstruct(rig.frame(g), cal, solver);
    double e = 0, n = 0, outside = 0, m = 0;
    for (int r = 0; r < kRows; ++r) {
      for (int c = 0; c < kCols; ++c) {
        const double d = map.height(r, c) - g.height(r, c);
        if (g.height(r, c) > 0) {
          e += d * d;
          n += 1;
        } else {
          outside += d * d;
          m += 1;
        }
      }
    }
    CAPTURE(edge, std::sqrt(e / n), std::sqrt(outside / m));
    CHECK(std::sqrt(e / n) < (edge ? 0.02e-3 : 0.04e-3));  // measured 0.010 and 0.024 mm
    CHECK(std::sqrt(outside / m) < 0.015e-3);
  }
}

TEST_CASE("optical: contacts of a height map lie on the pressed surface in the world",
          "[optical]") {
  Rig rig(8);
  const to::Calibration cal =
      to::calibrate(rig.presses, rig.background_frame, {.ball_radius = kBall, .pixel = kPixel});
  to::PoissonSolver solver(kRows, kCols);
  const ts::GelPress g = ts::press_ball(kRows, kCols, kPixel, kBall, 0.5e-3, 160, 120);
  const to::HeightMap map = to::reconstruct(rig.frame(g), cal, solver);
  Eigen::Isometry3d pose = Eigen::Isometry3d::Identity();
  pose.translation() = taxel::Vec3d(0.1, -0.2, 0.3);
  pose.linear() = Eigen::AngleAxisd(0.7, taxel::Vec3d(1, 2, 3).normalized()).toRotationMatrix();
  std::vector<taxel::Contact<double>> contacts;
  const std::size_t n = to::height_contacts(map, kPixel, pose, 1.5, 0.02e-3, 0.05, 4, contacts);
  REQUIRE(n == contacts.size());
  REQUIRE(n > 50);
  // The ball's centre in the sensor frame: above pixel (160, 120) at z = R - d (the sensing
  // face looks along +z, into the ball).
  const taxel::Vec3d centre =
      pose * taxel::Vec3d((160 - 0.5 * (kCols - 1)) * kPixel, (120 - 0.5 * (kRows - 1)) * kPixel,
                          kBall - 0.5e-3);
  double worst = 0, worst_normal = 0;
  for (const auto& c : contacts) {
    CHECK(taxel::check_contact(c) == taxel::ContactDefect::ok);
    CHECK(c.time == 1.5);
    const double dist = (c.position - centre).norm() - kBall;
    worst = std::max(worst, std::abs(dist));
    worst_normal = std::max(
        worst_normal, std::acos(std::min(1.0, -c.normal->dot((centre - c.position).normalized()))));
  }
  CHECK(worst < 0.06e-3);
  CHECK(worst_normal < 0.25);
  CHECK_THROWS_WITH(to::height_contacts(map, kPixel, pose, 0, 0.02e-3, 0.05, 0, contacts),
                    Catch::Contains("stride"));
}

TEST_CASE("optical: the running maximum of the marker search equals the brute-force one",
          "[optical]") {
  std::mt19937 rng(3);
  std::uniform_real_distribution<double> u(0.0, 1.0);
  for (int t = 0; t < 500; ++t) {
    const int n = 1 + int(rng() % 40), reach = 1 + int(rng() % 8);
    std::vector<double> x(static_cast<std::size_t>(n));
    for (double& v : x) v = u(rng);
    // One row: the running maximum along it.
    to::Plane row(1, n);
    for (int i = 0; i < n; ++i) row(0, i) = x[static_cast<std::size_t>(i)];
    const to::Plane out = to::detail::running_max_2d(row, reach);
    for (int i = 0; i < n; ++i) {
      double m = -1;
      for (int k = std::max(0, i - reach); k <= std::min(n - 1, i + reach); ++k) {
        m = std::max(m, x[static_cast<std::size_t>(k)]);
      }
      REQUIRE(out(0, i) == m);
    }
  }
}

TEST_CASE("optical: marker dots are found, left out of calibration and filled in", "[optical]") {
  // The rig's frames with a printed grid of dots (3 px radius, 25 px apart, 70 % darker).
  Rig rig(12);
  const auto dots = ts::marker_grid(kRows, kCols, 25.0);
  const auto mark = [&](to::RgbFrame f) {
    ts::draw_markers(f, dots, 3.0, 0.7);
    return f;
  };
  // Found: every dot pixel of a press, and few others (the mask grows each dot by a pixel).
  const to::RgbFrame press = mark(rig.presses[0]);
  const auto found = to::marker_mask(press);
  double in_dots = 0, hit = 0, outside = 0, false_hit = 0;
  for (int r = 0; r < kRows; ++r) {
    for (int c = 0; c < kCols; ++c) {
      double nearest = 1e9;
      for (const auto& d : dots) nearest = std::min(nearest, std::hypot(c - d.x(), r - d.y()));
      if (nearest <= 3.0) {
        in_dots += 1;
        hit += found(r, c) != 0;
      } else if (nearest > 5.0) {
        outside += 1;
        false_hit += found(r, c) != 0;
      }
    }
  }
  CAPTURE(hit / in_dots, false_hit / outside);
  CHECK(hit / in_dots > 0.97);
  CHECK(false_hit / outside < 0.001);
  // Calibration with the dots left out beats it with them in, on held-out presses.
  std::vector<to::RgbFrame> presses;
  for (const auto& p : rig.presses) presses.push_back(mark(p));
  const to::RgbFrame background = mark(rig.background_frame);
  const to::Calibration with =
      to::calibrate(presses, background, {.ball_radius = kBall, .pixel = kPixel});
  const to::Calibration without =
      to::calibrate(presses, background, {.ball_radius = kBall, .pixel = kPixel, .markers = false});
  CAPTURE(with.heldout(), without.heldout());
  CHECK(with.heldout() < 0.07);  // measured 0.056 (the table), 0.089 with the dots in
  CHECK(with.heldout() < 0.8 * without.heldout());
  // A held-out ball with dots: radius and heights as without them.
  to::PoissonSolver solver(kRows, kCols);
  const ts::GelPress g = ts::press_ball(kRows, kCols, kPixel, kBall, 0.5e-3, 160.0, 120.0);
  const to::HeightMap map = to::reconstruct(mark(rig.frame(g)), with, solver);
  const to::BallFit fit = to::fit_ball(map, kPixel);
  CAPTURE(fit.radius);
  CHECK(std::abs(fit.radius - kBall) < 0.1 * kBall);
  CHECK(map.height.maxCoeff() == Approx(0.5e-3).epsilon(0.06));
  // Filling: a constant plane's holes take the constant; a hole between two levels lies
  // between them.
  to::Plane plane = to::Plane::Constant(20, 30, 2.5);
  image::Mask holes = image::Mask::Zero(20, 30);
  holes.block(5, 5, 6, 7).setOnes();
  plane.block(5, 5, 6, 7).setConstant(-100.0);
  to::fill_holes(plane, holes);
  CHECK((plane - 2.5).abs().maxCoeff() < 1e-12);
  to::Plane ramp(20, 30);
  for (int r = 0; r < 20; ++r) {
    for (int c = 0; c < 30; ++c) ramp(r, c) = c;
  }
  to::Plane filled = ramp;
  filled.block(5, 5, 6, 7).setConstant(1e9);
  to::fill_holes(filled, holes);
  CHECK(filled.block(5, 5, 6, 7).minCoeff() >= 4.0);
  CHECK(filled.block(5, 5, 6, 7).maxCoeff() <= 12.0);
  CHECK_THROWS_WITH(to::fill_holes(filled, image::Mask::Zero(3, 3)),
                    Catch::Contains("differ in size"));
  CHECK_THROWS_WITH(to::marker_mask(press, {.dark = 1.5}), Catch::Contains("dark in (0, 1)"));
}

TEST_CASE("optical: a background from frames that mostly show the untouched gel", "[optical]") {
  // Seven frames: four of the untouched gel with noise, three presses at different places.
  // The per-pixel median is the gel: within the noise of the model's background everywhere,
  // the presses included.
  Rig rig(3);
  std::vector<to::RgbFrame> frames = rig.presses;
  const to::Plane zero = to::Plane::Zero(kRows, kCols);
  for (int i = 0; i < 4; ++i)
    frames.push_back(to::render(zero, zero, rig.background, rig.model, 2.0, rig.rng));
  const to::Colour est = to::colour_planes(to::median_background(frames));
  double worst = 0;
  for (std::size_t k = 0; k < 3; ++k)
    worst = std::max(worst, (est[k] - rig.background[k]).abs().maxCoeff());
  CHECK(worst < 8.0);  // 2 levels of noise, rounding: the median of 7 stays within 4 sigma
  CHECK_THROWS_WITH(to::median_background({}), Catch::Contains("no frames"));
  frames.push_back(to::RgbFrame(10, 10, 0));
  CHECK_THROWS_WITH(to::median_background(frames), Catch::Contains("frame 7 is 10 x 10"));
}

TEST_CASE("optical: a calibration file round-trips and damaged ones are refused", "[optical]") {
  Rig rig(6);
  for (const bool markers : {true, false}) {
    const to::Calibration cal =
        to::calibrate(rig.presses, rig.background_frame,
                      {.ball_radius = kBall, .pixel = kPixel, .markers = markers});
    const std::string bytes = to::encode_calibration(cal);
    const to::Calibration back = to::decode_calibration(bytes);
    CHECK(back.rows == cal.rows);
    CHECK(back.method == cal.method);
    CHECK(back.heldout() == cal.heldout());
    CHECK(back.circles.size() == cal.circles.size());
    CHECK(back.polynomial == cal.polynomial);
    CHECK(back.table == cal.table);
    CHECK(back.background_markers.size() == cal.background_markers.size());
    // The same heights from either.
    to::PoissonSolver solver(kRows, kCols);
    const to::RgbFrame frame =
        rig.frame(ts::press_ball(kRows, kCols, kPixel, kBall, 0.5e-3, 150, 110));
    CHECK((to::reconstruct(frame, back, solver).height - to::reconstruct(frame, cal, solver).height)
              .abs()
              .maxCoeff() == 0.0);
    // A file, written and read.
    const auto path =
        (std::filesystem::temp_directory_path() / "taxel_optical_test.txcal").string();
    to::save_calibration(path, cal);
    CHECK(to::encode_calibration(to::load_calibration(path)) == bytes);
    std::filesystem::remove(path);
  }
  const to::Calibration cal =
      to::calibrate(rig.presses, rig.background_frame, {.ball_radius = kBall, .pixel = kPixel});
  const std::string bytes = to::encode_calibration(cal);
  CHECK_THROWS_WITH(to::decode_calibration("PNG\r\n"),
                    Catch::Contains("not a taxel optical calibration"));
  std::string v2 = bytes;
  v2[7] = 2;
  CHECK_THROWS_WITH(to::decode_calibration(v2), Catch::Contains("version 2 is not supported"));
  for (const std::size_t cut :
       {std::size_t{12}, std::size_t{40}, bytes.size() / 2, bytes.size() - 3}) {
    CHECK_THROWS_WITH(to::decode_calibration(bytes.substr(0, cut)), Catch::Contains("cut short"));
  }
  CHECK_THROWS_WITH(to::decode_calibration(bytes + "x"), Catch::Contains("1 bytes after"));
  std::string nan_pixel = bytes;
  const double nan = std::numeric_limits<double>::quiet_NaN();
  std::memcpy(nan_pixel.data() + 16, &nan, 8);
  CHECK_THROWS_WITH(to::decode_calibration(nan_pixel), Catch::Contains("pixel is not finite"));
  CHECK_THROWS_WITH(to::load_calibration("/nonexistent/x.txcal"),
                    Catch::Contains("/nonexistent/x.txcal"));

  // The JSON form: readable members, the binary form inside, and the same calibration back.
  const std::string json = to::encode_calibration_json(cal);
  CHECK_THAT(json, Catch::Contains("\"format\": \"taxel optical calibration\""));
  CHECK_THAT(json, Catch::Contains("\"rows\": 240"));
  CHECK(to::encode_calibration(to::decode_calibration_any(json)) == bytes);
  CHECK(to::encode_calibration(to::decode_calibration_any(bytes)) == bytes);
  const auto json_path =
      (std::filesystem::temp_directory_path() / "taxel_optical_test_cal.json").string();
  to::save_calibration(json_path, cal);
  CHECK(taxel::io::read_file(json_path).front() == '{');
  CHECK(to::encode_calibration(to::load_calibration(json_path)) == bytes);
  std::filesystem::remove(json_path);
  // Base64 against RFC 4648's test vectors, both ways.
  const std::pair<const char*, const char*> vectors[] = {
      {"", ""},        {"f", "Zg=="},        {"fo", "Zm8="},
      {"foo", "Zm9v"}, {"foob", "Zm9vYg=="}, {"foobar", "Zm9vYmFy"}};
  for (const auto& [plain, coded] : vectors) {
    CHECK(to::detail::base64(plain) == coded);
    std::string back;
    CHECK(to::detail::unbase64(coded, back));
    CHECK(back == plain);
  }
  std::string junk;
  CHECK_FALSE(to::detail::unbase64("Zm9", junk));
  CHECK_FALSE(to::detail::unbase64("Zm=v", junk));
  CHECK_FALSE(to::detail::unbase64("Z!9v", junk));
  // Damaged JSON: another document, no or bad "txcal", readable members edited alone.
  CHECK_THROWS_WITH(to::decode_calibration_any("{\"format\": \"other\"}"),
                    Catch::Contains("not a taxel optical calibration"));
  std::string no_data = json;
  no_data.replace(no_data.find("\"txcal\""), 7, "\"other\"");
  CHECK_THROWS_WITH(to::decode_calibration_any(no_data),
                    Catch::Contains("\"txcal\" string is missing"));
  std::string bad_data = json;
  bad_data[bad_data.find("\"txcal\": \"") + 10] = '!';
  CHECK_THROWS_WITH(to::decode_calibration_any(bad_data), Catch::Contains("not base64"));
  std::string edited = json;
  edited.replace(edited.find("\"rows\": 240"), 12, "\"rows\": 480");
  CHECK_THROWS_WITH(to::decode_calibration_any(edited), Catch::Contains("disagree"));
  std::string cut = json.substr(0, json.size() / 2);
  CHECK_THROWS(to::decode_calibration_any(cut));
}

TEST_CASE("optical: frames from NPY arrays of uint8 RGB, one or a stack, C or Fortran order",
          "[optical]") {
  // A 3 x 4 frame and a stack of two, each value its row-major index.
  const std::size_t one[] = {3, 4, 3}, two[] = {2, 3, 4, 3};
  std::vector<std::uint8_t> v(72);
  for (std::size_t i = 0; i < v.size(); ++i) v[i] = static_cast<std::uint8_t>(i);
  const std::vector<to::RgbFrame> a =
      to::decode_npy_frames(taxel::io::encode_npy_u8(one, {v.data(), 36}));
  REQUIRE(a.size() == 1);
  CHECK(a[0].rows == 3);
  CHECK(a[0].cols == 4);
  CHECK(a[0].data == std::vector<std::uint8_t>(v.begin(), v.begin() + 36));
  const std::vector<to::RgbFrame> b = to::decode_npy_frames(taxel::io::encode_npy_u8(two, v));
  REQUIRE(b.size() == 2);
  CHECK(b[1].data == std::vector<std::uint8_t>(v.begin() + 36, v.end()));
  // The same stack in Fortran order, where the first index varies fastest in the file.
  std::string fortran = taxel::io::encode_npy_u8(two, v);
  fortran.replace(fortran.find("False"), 5, "True ");
  const std::size_t data_at = fortran.size() - v.size();
  for (std::size_t i = 0; i < v.size(); ++i) {
    const std::size_t f = i / 36, r = i / 12 % 3, c = i / 3 % 4, ch = i % 3;
    fortran[data_at + f + 2 * (r + 3 * (c + 4 * ch))] = static_cast<char>(v[i]);
  }
  const std::vector<to::RgbFrame> fb = to::decode_npy_frames(fortran);
  REQUIRE(fb.size() == 2);
  CHECK(fb[0].data == b[0].data);
  CHECK(fb[1].data == b[1].data);
  // Float frames and grey frames are refused.
  const std::size_t grey[] = {3, 4};
  CHECK_THROWS_WITH(to::decode_npy_frames(taxel::io::encode_npy_f64(one, std::vector<double>(36))),
                    Catch::Contains("must be uint8"));
  CHECK_THROWS_WITH(to::decode_npy_frames(taxel::io::encode_npy_u8(grey, {v.data(), 12})),
                    Catch::Contains("shape (rows, cols, 3)"));
}

TEST_CASE("optical: bad frames, presses and options are refused with the reason", "[optical]") {
  Rig rig(4);
  const to::CalibrationOptions o{.ball_radius = kBall, .pixel = kPixel};
  // A press of another size.
  std::vector<to::RgbFrame> mixed = rig.presses;
  mixed[2] = to::RgbFrame(120, 160, 0);
  CHECK_THROWS_WITH(to::calibrate(mixed, rig.background_frame, o),
                    Catch::Contains("press 2 is 120 x 160, the background 240 x 320"));
  // A press with no contact.
  std::vector<to::RgbFrame> blank = rig.presses;
  blank[1] = rig.background_frame;
  CHECK_THROWS_WITH(to::calibrate(blank, rig.background_frame, o),
                    Catch::Contains("press 1: find_contact_circle: no contact"));
  // A ball radius given in millimetres: the "ball" is narrower than a pixel.
  CHECK_THROWS_WITH(
      to::calibrate(rig.presses, rig.background_frame, {.ball_radius = 2e-6, .pixel = kPixel}),
      Catch::Contains("the ball's radius is 0.032 px"));
  // Circles given by hand that are wider than the ball.
  CHECK_THROWS_WITH(to::calibrate(rig.presses, rig.background_frame, o,
                                  std::vector<to::Circle>(rig.presses.size(), {80, 60, 500})),
                    Catch::Contains("press 0: its contact circle (500 px) is wider than the ball"));
  CHECK_THROWS_WITH(to::calibrate({rig.presses[0]}, rig.background_frame, o),
                    Catch::Contains("at least two presses"));
  CHECK_THROWS_WITH(to::calibrate(rig.presses, rig.background_frame, {.pixel = kPixel}),
                    Catch::Contains("ball_radius"));
  const to::Calibration cal = to::calibrate(rig.presses, rig.background_frame, o);
  to::PoissonSolver solver(kRows, kCols);
  // A frame of another resolution than the calibration's.
  CHECK_THROWS_WITH(to::reconstruct(to::RgbFrame(480, 640, 0), cal, solver),
                    Catch::Contains("the frame is 480 x 640, the calibration is for 240 x 320"));
  // An all-black frame.
  CHECK_THROWS_WITH(to::reconstruct(to::RgbFrame(kRows, kCols, 0), cal, solver),
                    Catch::Contains("no gel in view"));
  // A truncated buffer.
  to::RgbFrame cut = rig.presses[0];
  cut.data.resize(cut.data.size() - 1);
  CHECK_THROWS_WITH(to::reconstruct(cut, cal, solver), Catch::Contains("rows * cols * 3 bytes"));
  to::PoissonSolver other(kRows, kCols + 1);
  CHECK_THROWS_WITH(to::reconstruct(rig.presses[0], cal, other),
                    Catch::Contains("the solver is for another frame size"));
}

TEST_CASE("optical: marker dots are tracked as a displacement field through lost and new dots",
          "[optical]") {
  to::ShadingModel model;
  const to::Colour background = to::render_background(model, kRows, kCols);
  const to::Plane flat = to::Plane::Zero(kRows, kCols);
  std::mt19937_64 rng(5);
  // A lattice 20 px apart, reaching two pitches beyond the frame so that dots can enter.
  const double pitch = 20.0, xc = 0.5 * (kCols - 1), yc = 0.5 * (kRows - 1);
  std::vector<Eigen::Vector2d> lattice;
  for (double y = -30; y < kRows + 40; y += pitch) {
    for (double x = -30; x < kCols + 40; x += pitch) lattice.emplace_back(x + 0.3, y + 0.7);
  }
  // The gel sheared, turned and shifted a little more every frame.
  const auto displaced = [&](const Eigen::Vector2d& p, int k) {
    const double s = 0.006 * k, t = 1.0 * k;
    return Eigen::Vector2d(p.x() + s * (p.y() - yc) + t, p.y() - 0.5 * s * (p.x() - xc));
  };
  const auto inside = [&](const Eigen::Vector2d& p) {
    return p.x() >= 4 && p.y() >= 4 && p.x() <= kCols - 5 && p.y() <= kRows - 5;
  };
  const auto draw = [&](int k, double drop) {
    std::vector<Eigen::Vector2d> centres;
    std::uniform_real_distribution<double> u(0.0, 1.0);
    for (const Eigen::Vector2d& p : lattice) {
      const Eigen::Vector2d q = displaced(p, k);
      if (inside(q) && u(rng) >= drop) centres.push_back(q);
    }
    to::RgbFrame f = to::render(flat, flat, background, model, 2.0, rng);
    ts::draw_markers(f, centres, 3.0, 0.7);
    return f;
  };
  // The reference: every dot found, each within 0.15 px of its centre.
  const std::vector<to::Dot> ref = to::find_dots(draw(0, 0.0));
  std::size_t expected = 0;
  for (const Eigen::Vector2d& p : lattice) expected += inside(p);
  REQUIRE(ref.size() == expected);
  // The lattice point a position belongs to at frame k (its nearest displaced point).
  const auto truth = [&](double x, double y, int k) {
    std::size_t best = 0;
    double d = 1e300;
    for (std::size_t i = 0; i < lattice.size(); ++i) {
      const double e = (displaced(lattice[i], k) - Eigen::Vector2d(x, y)).norm();
      if (e < d) {
        d = e;
        best = i;
      }
    }
    return std::pair{best, d};
  };
  for (const to::Dot& d : ref) CHECK(truth(d.x, d.y, 0).second < 0.15);
  to::MarkerTracker tracker(ref);
  CHECK(tracker.max_step() == Approx(0.4 * pitch).epsilon(0.02));
  std::vector<std::size_t> identity;  // each reference track's lattice point
  for (const to::Dot& d : ref) identity.push_back(truth(d.x, d.y, 0).first);
  double worst_seen = 0, worst_lost = 0, worst_new = 0;
  std::size_t lost = 0, fresh = 0;
  for (int k = 1; k <= 16; ++k) {
    tracker.update(to::find_dots(draw(k, 0.1)));  // a tenth of the dots hidden every frame
    const auto& tracks = tracker.tracks();
    for (std::size_t i = 0; i < tracks.size(); ++i) {
      const to::MarkerTrack& t = tracks[i];
      if (i < identity.size()) {
        // A reference dot: at its own lattice point's displaced place (no swaps), or predicted
        // near it when hidden or gone out of the frame.
        const Eigen::Vector2d want = displaced(lattice[identity[i]], k);
        const double e = (Eigen::Vector2d(t.x, t.y) - want).norm();
        if (t.seen) {
          worst_seen = std::max(worst_seen, e);
        } else if (inside(want)) {
          worst_lost = std::max(worst_lost, e);
          ++lost;
        }
      } else if (t.seen) {
        // A dot that entered: its reference is where its lattice point was at rest.
        const auto [at, d] = truth(t.x, t.y, k);
        worst_new = std::max(worst_new, (Eigen::Vector2d(t.x0, t.y0) - lattice[at]).norm());
        CHECK(d < 0.3);
        ++fresh;
      }
    }
  }
  CAPTURE(worst_seen, worst_lost, worst_new, lost, fresh);
  CHECK(worst_seen < 0.35);  // measured 0.27 px: a rendered dot is whole pixels
  CHECK(worst_lost < 1.0);   // measured 0.23 px
  CHECK(worst_new < 1.0);
  CHECK(lost > 100);
  CHECK(fresh > 10);
  // The dense field at the lattice points inside, against the truth.
  to::Plane fx, fy;
  tracker.field(kRows, kCols, fx, fy);
  double worst_field = 0;
  for (const Eigen::Vector2d& p : lattice) {
    const Eigen::Vector2d q = displaced(p, 16);
    if (!inside(q)) continue;
    const auto r = static_cast<int>(std::lround(q.y())), c = static_cast<int>(std::lround(q.x()));
    // The field is sampled where the gel point now is; compare with its displacement.
    worst_field = std::max(worst_field, std::hypot(fx(r, c) - (q - p).x(), fy(r, c) - (q - p).y()));
  }
  CHECK(worst_field < 1.0);  // measured 0.40 px
  // A dark frame has no dots; the tracks are then all lost, none found.
  CHECK(to::find_dots(to::RgbFrame(kRows, kCols, 0)).empty());
  to::MarkerTracker blind(ref);
  CHECK(blind.update({}) == 0);
  CHECK_THROWS_WITH(to::MarkerTracker(std::vector<to::Dot>(1)), Catch::Contains("fewer than two"));
  CHECK_THROWS_WITH(to::find_dots(draw(0, 0.0), {}, 5, 2), Catch::Contains("min_area"));
}

TEST_CASE("optical: a slow drift of the lighting is followed by the background", "[optical]") {
  Rig rig(8);
  const to::Calibration cal =
      to::calibrate(rig.presses, rig.background_frame, {.ball_radius = kBall, .pixel = kPixel});
  to::Calibration tracked = cal;
  to::PoissonSolver solver(kRows, kCols);
  const to::Plane zero = to::Plane::Zero(kRows, kCols);
  const ts::GelPress press = ts::press_ball(kRows, kCols, kPixel, kBall, 0.5e-3, 150, 110);
  // The lamp brightens by 0.15 % a frame, 25 % over 150 frames; a ball is pressed in every
  // tenth frame.
  for (int k = 1; k <= 150; ++k) {
    to::Colour lit = rig.background;
    for (to::Plane& p : lit) p *= 1.0 + 0.0015 * k;
    const bool pressed = k % 10 == 0;
    const to::RgbFrame f = to::render(pressed ? press.gx : zero, pressed ? press.gy : zero, lit,
                                      rig.model, 2.0, rig.rng);
    const to::HeightMap map = to::reconstruct(f, tracked, solver);
    to::track_background(tracked, f, map);
    if (k < 150) continue;
    // The last frame is pressed: with the background followed, the heights hold.
    double e = 0, n = 0;
    for (int r = 0; r < kRows; ++r) {
      for (int c = 0; c < kCols; ++c) {
        if (press.height(r, c) <= 0) continue;
        e += (map.height(r, c) - press.height(r, c)) * (map.height(r, c) - press.height(r, c));
        n += 1;
      }
    }
    const double touched = double(map.mask.cast<int>().sum()) / double(kRows * kCols);
    CAPTURE(std::sqrt(e / n), touched);
    CHECK(std::sqrt(e / n) < 0.03e-3);
    CHECK(touched < 0.1);
    // Without it the whole gel reads as deformed.
    const to::HeightMap stale = to::reconstruct(f, cal, solver);
    CHECK(double(stale.mask.cast<int>().sum()) / double(kRows * kCols) > 0.5);
  }
  CHECK_THROWS_WITH(to::track_background(tracked, rig.presses[0], to::HeightMap{}, 0.05),
                    Catch::Contains("differ in size"));
  const to::HeightMap any = to::reconstruct(rig.presses[0], cal, solver);
  CHECK_THROWS_WITH(to::track_background(tracked, rig.presses[0], any, 0.0),
                    Catch::Contains("rate in (0, 1]"));
}

TEST_CASE("optical: the touched mask against a brute-force threshold, speck removal and fill",
          "[optical]") {
  // Random blobs and rings of colour change on specks of noise. The oracle: threshold; specks
  // by a flood fill of each 8-connected region; holes by a flood fill of the complement from
  // the frame's border (4-connected).
  std::mt19937_64 rng(21);
  std::uniform_real_distribution<double> u(0.0, 1.0);
  const auto flood = [](const image::Mask& m, int r, int c, bool eight, std::uint8_t want,
                        std::vector<char>& seen) {
    const auto rows = int(m.rows()), cols = int(m.cols());
    std::vector<std::pair<int, int>> stack{{r, c}}, region;
    seen[std::size_t(r * cols + c)] = 1;
    while (!stack.empty()) {
      const auto [y, x] = stack.back();
      stack.pop_back();
      region.push_back({y, x});
      for (int dy = -1; dy <= 1; ++dy) {
        for (int dx = -1; dx <= 1; ++dx) {
          if ((dy == 0 && dx == 0) || (!eight && dy != 0 && dx != 0)) continue;
          const int yy = y + dy, xx = x + dx;
          if (yy < 0 || xx < 0 || yy >= rows || xx >= cols || m(yy, xx) != want) continue;
          if (seen[std::size_t(yy * cols + xx)]) continue;
          seen[std::size_t(yy * cols + xx)] = 1;
          stack.push_back({yy, xx});
        }
      }
    }
    return region;
  };
  for (int trial = 0; trial < 40; ++trial) {
    const int rows = 30 + int(40 * u(rng)), cols = 30 + int(40 * u(rng));
    to::Colour change;
    for (to::Plane& p : change) p = to::Plane::Zero(rows, cols);
    const int blobs = 1 + int(4 * u(rng));
    for (int b = 0; b < blobs; ++b) {
      const double cx = cols * u(rng), cy = rows * u(rng), outer = 2 + 10 * u(rng),
                   inner = u(rng) < 0.5 ? 0.0 : outer * u(rng);
      for (int r = 0; r < rows; ++r) {
        for (int c = 0; c < cols; ++c) {
          const double d = std::hypot(c - cx, r - cy);
          if (d < outer && d >= inner) change[0](r, c) = 40;
        }
      }
    }
    for (int r = 0; r < rows; ++r) {
      for (int c = 0; c < cols; ++c) {
        if (u(rng) < 0.02) change[1](r, c) = 30;  // specks
      }
    }
    const int min_area = trial % 2 == 0 ? 0 : 6;
    image::Mask expect(rows, cols);
    for (int r = 0; r < rows; ++r) {
      for (int c = 0; c < cols; ++c) {
        const double a = change[0](r, c), b = change[1](r, c);
        expect(r, c) = a * a + b * b > 144 ? 1 : 0;
      }
    }
    std::vector<char> seen(std::size_t(rows * cols), 0);
    for (int r = 0; r < rows; ++r) {
      for (int c = 0; c < cols; ++c) {
        if (!expect(r, c) || seen[std::size_t(r * cols + c)]) continue;
        const auto region = flood(expect, r, c, true, 1, seen);
        if (int(region.size()) < min_area) {
          for (const auto& [y, x] : region) expect(y, x) = 0;
        }
      }
    }
    std::fill(seen.begin(), seen.end(), 0);
    for (int r = 0; r < rows; ++r) {
      for (int c = 0; c < cols; ++c) {
        const bool edge = r == 0 || c == 0 || r == rows - 1 || c == cols - 1;
        if (edge && !expect(r, c) && !seen[std::size_t(r * cols + c)]) {
          (void)flood(expect, r, c, false, 0, seen);
        }
      }
    }
    for (int r = 0; r < rows; ++r) {
      for (int c = 0; c < cols; ++c) {
        if (!expect(r, c) && !seen[std::size_t(r * cols + c)]) expect(r, c) = 1;  // a hole
      }
    }
    CAPTURE(trial);
    CHECK((to::touched_mask(change, 12.0, min_area) == expect).all());
    if (min_area == 0) CHECK((to::contact_mask(change, 12.0) == expect).all());
  }
}

TEST_CASE("optical: the 2-D running maximum of the marker search equals the brute-force one",
          "[optical]") {
  std::mt19937 rng(4);
  std::uniform_real_distribution<double> u(0.0, 1.0);
  for (int t = 0; t < 60; ++t) {
    const int rows = 1 + int(rng() % 30), cols = 1 + int(rng() % 30), reach = 1 + int(rng() % 7);
    to::Plane x(rows, cols);
    for (int r = 0; r < rows; ++r) {
      for (int c = 0; c < cols; ++c) x(r, c) = u(rng);
    }
    const to::Plane m = to::detail::running_max_2d(x, reach);
    for (int r = 0; r < rows; ++r) {
      for (int c = 0; c < cols; ++c) {
        const int r0 = std::max(0, r - reach), r1 = std::min(rows - 1, r + reach);
        const int c0 = std::max(0, c - reach), c1 = std::min(cols - 1, c + reach);
        REQUIRE(m(r, c) == x.block(r0, c0, r1 - r0 + 1, c1 - c0 + 1).maxCoeff());
      }
    }
  }
}
