// SPDX-License-Identifier: MIT
// 04: recognise objects by touch. Each trial explores one of seven objects with a few short
// slides of a tactile pad, fuses the contacts with Kalman filters, places the cloud at a random
// pose, and asks an ObjectLibrary of the seven models which object it was. Prints the
// confusion matrix, top-1 accuracy and time per recognition; writes the models and one cloud
// per object as PLY (inputs for taxel-recognize).
//   ./04_recognize_objects [--quick] [--trials N] [--out DIR]
#include <charconv>
#include <chrono>
#include <cstdio>
#include <filesystem>
#include <functional>
#include <random>
#include <string>
#include <string_view>
#include <taxel/taxel.hpp>
#include <vector>

#include "cli.hpp"

namespace {

using namespace taxel;
namespace tr = taxel::registration;

struct Object {
  std::string name;
  std::function<PointCloud<double>(std::size_t, std::uint64_t)> model;
  std::function<sim::TriangleMesh()> mesh;
  std::function<std::vector<Contact<double>>(std::size_t, const sim::SlidingConfig&)> explore;
};

// Meshes of very different vertex density: 12 triangles for a box, 2 562 vertices for a
// sphere, 514 for a cylinder.
sim::TriangleMesh mesh_of(const sim::Sphere& s) { return sim::icosphere(s.radius, 4); }
sim::TriangleMesh mesh_of(const sim::Cylinder& c) { return sim::cylinder_mesh(c, 256); }
sim::TriangleMesh mesh_of(const sim::Box& b) { return sim::box_mesh(b); }

template <class Shape>
Object make(std::string name, Shape shape) {
  return {
      std::move(name),
      [shape](std::size_t n, std::uint64_t seed) { return sim::sample_surface(shape, n, seed); },
      [shape] { return mesh_of(shape); },
      [shape](std::size_t n, const sim::SlidingConfig& c) {
        return sim::sliding_exploration(shape, n, c);
      }};
}

constexpr const char* kUsage =
    "usage: 04_recognize_objects [--quick] [--trials N] [--out DIR]\n"
    "Explores seven simulated objects by touch, fuses the contacts with Kalman filters and\n"
    "recognises each cloud among the seven models by multi-start ICP.\n";

}  // namespace

int main(int argc, char** argv) try {
  taxel_cli::check_stdout_at_exit("04_recognize_objects");
  int trials = 5;
  const taxel_cli::StudyOptions opt =
      taxel_cli::parse_study_options("04_recognize_objects", kUsage, "recognize-objects", argc,
                                     argv, [&](std::string_view a, taxel_cli::Args& args) {
                                       if (a != "--trials") return false;
                                       trials = args.number<int>(1, 1000);
                                       return true;
                                     });
  if (opt.quick) trials = 1;
  const std::filesystem::path out = opt.out;
  const std::vector<Object> objects{
      make("sphere-40", sim::Sphere(0.04)),
      make("sphere-25", sim::Sphere(0.025)),
      make("cylinder-30x100", sim::Cylinder(0.03, 0.05)),
      make("cylinder-20x60", sim::Cylinder(0.02, 0.03)),
      make("box-80x60x40", sim::Box(Vec3d(0.04, 0.03, 0.02))),
      make("cube-50", sim::Box(Vec3d(0.025, 0.025, 0.025))),
      make("bar-120x40x20", sim::Box(Vec3d(0.06, 0.02, 0.01))),
  };
  std::filesystem::create_directories(out / "models");
  std::filesystem::create_directories(out / "clouds");
  std::filesystem::create_directories(out / "meshes");
  tr::ObjectLibrary<double> lib;
  for (const auto& o : objects) {
    const PointCloud<double> m = o.model(10000, 1);
    lib.add(o.name, m);
    io::write_ply((out / "models" / (o.name + ".ply")).string(), m);
    const sim::TriangleMesh mesh = o.mesh();
    PointCloud<double> vertices;
    vertices.points = mesh.vertices();
    io::write_ply((out / "meshes" / (o.name + ".ply")).string(), vertices,
                  io::PlyFormat::binary_little_endian, mesh.triangles());
  }

  const std::size_t n = objects.size();
  std::vector<std::vector<int>> confusion(n, std::vector<int>(n + 1, 0));  // last: unknown
  std::mt19937_64 rng(7);
  std::normal_distribution<double> g(0.0, 1.0);
  double seconds = 0.0;
  int right = 0;
  for (int t = 0; t < trials; ++t) {
    for (std::size_t o = 0; o < n; ++o) {
      // Five short slides (about 30 mm each) from random places, fused with Kalman filters.
      fusion::ContactCloud<fusion::Kalman<double>, index::VoxelHash<double>> fused(
          {.association_radius = 3.4e-3});
      for (int s = 0; s < 5; ++s) {
        const auto c = objects[o].explore(3000, {.speed = 0.1,
                                                 .sigma_tilt = 0.1,
                                                 .seed = 1000 * static_cast<std::uint64_t>(t) +
                                                         10 * o + static_cast<std::uint64_t>(s)});
        (void)fused.insert(std::span(c));
      }
      Isometry3d pose = Isometry3d::Identity();
      pose.linear() =
          Eigen::Quaterniond(Eigen::Vector4d(g(rng), g(rng), g(rng), g(rng)).normalized())
              .toRotationMatrix();
      pose.translation() = 0.1 * Vec3d(g(rng), g(rng), g(rng));
      const PointCloud<double> cloud = transformed(fused.to_point_cloud(), pose);
      if (t == 0) io::write_ply((out / "clouds" / (objects[o].name + ".ply")).string(), cloud);
      const auto t0 = std::chrono::steady_clock::now();
      const tr::ObjectRecognition r = lib.recognize(cloud);
      seconds += std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
      std::size_t answer = n;
      for (std::size_t k = 0; k < n && !r.unknown; ++k) {
        if (objects[k].name == r.best) answer = k;
      }
      ++confusion[o][answer];
      right += answer == o ? 1 : 0;
    }
    std::fprintf(stderr, "\r  trial %d/%d ", t + 1, trials);
  }
  std::fputs("\r\033[K", stderr);

  std::printf("Confusion matrix (rows: true object, columns: answer), %d trial(s) per object\n",
              trials);
  std::printf("%-20s", "");
  for (std::size_t k = 0; k < n; ++k) std::printf(" %4zu", k + 1);
  std::printf(" %7s\n", "unknown");
  for (std::size_t o = 0; o < n; ++o) {
    std::printf("%zu %-18s", o + 1, objects[o].name.c_str());
    for (std::size_t k = 0; k < n; ++k) std::printf(" %4d", confusion[o][k]);
    std::printf(" %7d\n", confusion[o][n]);
  }
  const int total = trials * static_cast<int>(n);
  std::printf("top-1 %d / %d = %.1f %%, %.1f ms per recognition among %zu models\n", right, total,
              100.0 * right / total, 1e3 * seconds / total, n);
  std::printf(
      "wrote %s/models/*.ply, %s/meshes/*.ply and %s/clouds/*.ply (try: taxel-recognize "
      "%s/clouds/cube-50.ply %s/meshes)\n",
      out.c_str(), out.c_str(), out.c_str(), out.c_str(), out.c_str());
  return 0;
} catch (const std::exception& e) {
  std::fprintf(stderr, "04_recognize_objects: %s\n", e.what());
  return 1;
}
