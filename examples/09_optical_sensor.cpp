// SPDX-License-Identifier: MIT
// A camera-based tactile sensor (GelSight-Mini class: 240 x 320 pixels of 0.0634 mm, marker
// dots) from calibration to a fused cloud, on rendered frames:
//  1. ball presses (2 mm radius) rendered with the shading model, and the calibration from them
//     (circles found, held-out slope errors);
//  2. a held-out press reconstructed: the ball's radius fitted to its heights;
//  3. the sensor pressed along a path over a 15 mm sphere: every frame rendered, reconstructed,
//     its contacts taken into the world through the sensor's pose and fused by ContactCloud;
//     the fused points' error against the sphere.
// With --out DIR it also writes the background, the presses, a held-out press, a dark frame and
// six frames of the gel sliding 0.6 px per frame (PNG when built with libpng, else NPY) for
// taxel-optical.
//
//   ./09_optical_sensor [--quick] [--out DIR]
#include <cmath>
#include <cstdio>
#include <cstring>
#include <filesystem>
#include <numbers>
#include <random>
#include <string>
#include <string_view>
#include <taxel/io/npy.hpp>
#include <taxel/optical.hpp>
#include <taxel/sim/optical.hpp>
#include <taxel/taxel.hpp>
#include <vector>

#ifdef TAXEL_EXAMPLES_HAVE_PNG
#include <taxel/io/png.hpp>
#endif

namespace {

namespace to = taxel::optical;
namespace ts = taxel::sim;

constexpr int kRows = 240, kCols = 320;
constexpr double kPixel = 0.0634e-3;  // [m]
constexpr double kBall = 2e-3;        // calibration ball radius [m]

struct Renderer {
  to::ShadingModel model;
  to::Colour background = to::render_background(model, kRows, kCols);
  std::vector<Eigen::Vector2d> dots = ts::marker_grid(kRows, kCols, 24.0);
  std::mt19937_64 rng{11};

  to::RgbFrame frame(const ts::GelPress& g) {
    to::RgbFrame f = to::render(g.gx, g.gy, background, model, 2.0, rng);
    ts::draw_markers(f, dots, 3.0, 0.7);
    return f;
  }
};

void save(const std::filesystem::path& dir, const std::string& stem, const to::RgbFrame& f) {
#ifdef TAXEL_EXAMPLES_HAVE_PNG
  taxel::io::write_png((dir / (stem + ".png")).string(), f);
#else
  const std::size_t shape[] = {std::size_t(f.rows), std::size_t(f.cols), 3};
  taxel::io::write_file((dir / (stem + ".npy")).string(), taxel::io::encode_npy_u8(shape, f.data));
#endif
}

}  // namespace

int main(int argc, char** argv) try {
  bool quick = false;
  std::string out;
  for (int i = 1; i < argc; ++i) {
    const std::string_view a = argv[i];
    if (a == "--quick") {
      quick = true;
    } else if (a == "--out" && i + 1 < argc) {
      out = argv[++i];
    } else {
      std::fputs(
          "usage: 09_optical_sensor [--quick] [--out DIR]\n"
          "Calibrates a rendered GelSight-class sensor from ball presses, reconstructs a\n"
          "held-out press, and fuses frames pressed along a 15 mm sphere into a cloud.\n",
          a == "--help" || a == "-h" ? stdout : stderr);
      return a == "--help" || a == "-h" ? 0 : 2;
    }
  }
  Renderer render;
  const ts::GelPress flat{to::Plane::Zero(kRows, kCols), to::Plane::Zero(kRows, kCols),
                          to::Plane::Zero(kRows, kCols)};
  const to::RgbFrame background = render.frame(flat);

  // 1. Ball presses at random places and depths.
  std::uniform_real_distribution<double> u(0.0, 1.0);
  std::vector<to::RgbFrame> presses;
  const int count = quick ? 6 : 12;
  for (int i = 0; i < count + 1; ++i) {  // the last one is held out
    const double d = 0.3e-3 + 0.4e-3 * u(render.rng), cx = 50 + 220 * u(render.rng),
                 cy = 50 + 140 * u(render.rng);
    presses.push_back(render.frame(ts::press_ball(kRows, kCols, kPixel, kBall, d, cx, cy)));
  }
  const to::RgbFrame held_out = presses.back();
  presses.pop_back();
  const to::Calibration cal =
      to::calibrate(presses, background, {.ball_radius = kBall, .pixel = kPixel});
  std::printf(
      "calibration: %d presses, %d x %d px of %.4f mm; held-out slope RMS: polynomial %.3f, "
      "lookup table %.3f; kept: %s\n",
      count, kRows, kCols, kPixel * 1e3, cal.heldout_polynomial, cal.heldout_table,
      cal.method == to::Calibration::Method::polynomial ? "polynomial" : "lookup table");

  // 2. The held-out press.
  to::PoissonSolver solver(kRows, kCols);
  const to::HeightMap map = to::reconstruct(held_out, cal, solver);
  const to::BallFit fit = to::fit_ball(map, kPixel);
  std::printf("held-out press: ball radius %.3f mm fitted (true %.3f mm, %+.1f %%)\n",
              fit.radius * 1e3, kBall * 1e3, 100.0 * (fit.radius - kBall) / kBall);

  // 3. Pressed along a great circle of a 15 mm sphere, 0.4 mm deep, the contact at the
  // frame's centre: the sensor's +z looks at the sphere's centre.
  const double R = 15e-3, depth = 0.4e-3;
  const ts::Sphere sphere(R);
  const int frames = quick ? 24 : 120;
  taxel::fusion::ContactCloud<taxel::fusion::Surfel<double>, taxel::index::VoxelHash<double>> cloud(
      {.association_radius = 1.0e-3});
  std::vector<taxel::Contact<double>> contacts;
  std::size_t total = 0;
  for (int k = 0; k < frames; ++k) {
    const double a = 0.9 * std::numbers::pi * k / frames;
    const Eigen::Vector3d n(std::cos(a), 0.0, std::sin(a));  // outward normal at the contact
    const to::RgbFrame f = render.frame(
        ts::press_ball(kRows, kCols, kPixel, R, depth, 0.5 * (kCols - 1), 0.5 * (kRows - 1)));
    const to::HeightMap m = to::reconstruct(f, cal, solver);
    Eigen::Isometry3d T = Eigen::Isometry3d::Identity();
    const Eigen::Vector3d z = -n, y = Eigen::Vector3d::UnitY(), x = y.cross(z);
    T.linear().col(0) = x;
    T.linear().col(1) = y;
    T.linear().col(2) = z;
    // The sphere's centre lies R - depth along +z from the frame's centre.
    T.translation() = -T.linear() * Eigen::Vector3d(0.0, 0.0, R - depth);
    contacts.clear();
    total += to::height_contacts(m, kPixel, T, 1e-2 * k, 0.01e-3, std::max(cal.heldout(), 1e-3), 4,
                                 contacts);
    for (const auto& c : contacts) (void)cloud.insert(c);
  }
  const auto pc = cloud.to_point_cloud();
  const auto err = ts::surface_error(sphere, pc.points);
  std::printf(
      "sliding over a %.0f mm sphere: %d frames, %zu contacts -> %zu points; RMS %.4f mm, signed "
      "%+.4f mm\n",
      R * 1e3, frames, total, pc.size(), err.rms * 1e3, err.signed_mean * 1e3);

  if (!out.empty()) {
    const std::filesystem::path dir(out);
    std::filesystem::create_directories(dir);
    save(dir, "background", background);
    for (std::size_t i = 0; i < presses.size(); ++i) {
      char stem[32];
      std::snprintf(stem, sizeof stem, "press_%02zu", i);
      save(dir, stem, presses[i]);
    }
    save(dir, "held_out", held_out);
    save(dir, "dark", to::RgbFrame(kRows, kCols, 0));  // the lights off: refused by depth
    // The flat gel sliding 0.6 px to the right per frame: dots for taxel-optical track.
    for (int k = 0; k < 6; ++k) {
      std::vector<Eigen::Vector2d> moved = render.dots;
      for (Eigen::Vector2d& d : moved) d.x() += 0.6 * k;
      to::RgbFrame f =
          to::render(flat.gx, flat.gy, render.background, render.model, 2.0, render.rng);
      ts::draw_markers(f, moved, 3.0, 0.7);
      char stem[32];
      std::snprintf(stem, sizeof stem, "slide_%02d", k);
      save(dir, stem, f);
    }
    std::printf("frames written to %s\n", out.c_str());
  }
  return 0;
} catch (const std::exception& e) {
  std::fprintf(stderr, "09_optical_sensor: %s\n", e.what());
  return 1;
}
