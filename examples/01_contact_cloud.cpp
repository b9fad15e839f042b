// SPDX-License-Identifier: MIT
// 01: fuse a sliding exploration into a compact cloud; swap the fusion policy (and the index)
// with one template argument and compare point counts, surface errors and speed.
//   ./01_contact_cloud [--quick]
#include <chrono>
#include <cstdio>
#include <cstring>
#include <string_view>
#include <taxel/taxel.hpp>

namespace {

template <class Policy, class Index, class Shape>
void run(const char* policy, const char* index, const Shape& shape,
         const std::vector<taxel::Contact<double>>& contacts) {
  taxel::fusion::ContactCloud<Policy, Index> cloud({.association_radius = 3.4e-3});
  const auto start = std::chrono::steady_clock::now();
  const auto counts = cloud.insert(std::span(contacts));
  const double seconds =
      std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  const auto pc = cloud.to_point_cloud();
  const auto err = taxel::sim::surface_error(shape, pc.points);
  // Points seen at least 5 times: single outlying contacts start points of their own (the
  // gate selects them), so the confirmed points show what fusion does to the noise.
  std::vector<taxel::Vec3d> confirmed;
  for (std::size_t i = 0; i < pc.size(); ++i) {
    if (pc.field("observations")->values[i] >= 5) confirmed.push_back(pc.points[i]);
  }
  const auto conf = taxel::sim::surface_error(shape, confirmed);
  std::printf(
      "  %-8s %-13s %8zu points  %6.1fx  rms %5.3f mm  max %5.2f mm | n>=5: %6zu pts "
      "rms %5.3f mm | %5.0f ns/contact  rejected %zu\n",
      policy, index, cloud.size(),
      static_cast<double>(contacts.size()) / static_cast<double>(cloud.size()), err.rms * 1e3,
      err.max * 1e3, confirmed.size(), conf.rms * 1e3,
      seconds * 1e9 / static_cast<double>(contacts.size()), counts.rejected);
}

template <class Shape>
void study(const char* name, const Shape& shape, std::size_t n) {
  // A 3.4 mm-pitch pad sliding at 20 mm/s, 1 kHz, 1 mm noise along its normal, and 0.2 rad
  // of kinematic tilt noise, so that contacts reach a point from varied pad orientations.
  const auto contacts = taxel::sim::sliding_exploration(shape, n, {.sigma_tilt = 0.2, .seed = 7});
  std::printf("%s: %zu contacts\n", name, contacts.size());
  namespace tf = taxel::fusion;
  namespace ti = taxel::index;
  run<tf::Raw<double>, ti::VoxelHash<double>>("Raw", "VoxelHash", shape, contacts);
  run<tf::Average<double>, ti::VoxelHash<double>>("Average", "VoxelHash", shape, contacts);
  run<tf::Kalman<double>, ti::VoxelHash<double>>("Kalman", "VoxelHash", shape, contacts);
  run<tf::Kalman<double>, ti::DynamicKdTree<double>>("Kalman", "DynamicKdTree", shape, contacts);
}

}  // namespace

int main(int argc, char** argv) {
  bool quick = false;
  for (int i = 1; i < argc; ++i) {
    const std::string_view arg = argv[i];
    if (arg == "--quick") {
      quick = true;
    } else if (arg == "--help" || arg == "-h") {
      std::puts(
          "usage: 01_contact_cloud [--quick]\n"
          "Fuses simulated sliding explorations with Raw, Average and Kalman policies and\n"
          "prints point counts and distances to the true surface.");
      return 0;
    } else {
      std::fprintf(stderr, "01_contact_cloud: unknown argument '%s' (try --help)\n", argv[i]);
      return 2;
    }
  }
  const std::size_t n = quick ? 20000 : 200000;
  study("sphere r=40 mm", taxel::sim::Sphere(0.04), n);
  study("cylinder r=30 mm h=100 mm", taxel::sim::Cylinder(0.03, 0.05), n);
  study("box 80x60x40 mm", taxel::sim::Box(), n);
  return 0;
}
