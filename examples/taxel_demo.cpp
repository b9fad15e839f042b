// SPDX-License-Identifier: MIT
// taxel-demo: the end-to-end demonstration of what taxel does so far. It grows with each
// capability. Today: contact-stream fusion of simulated sliding explorations with the three
// policies, the accuracy/compaction table, and the fused clouds written as ASCII PLY.
//   taxel-demo [--quick] [output-folder]
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <string>
#include <string_view>
#include <taxel/taxel.hpp>

namespace {

namespace tf = taxel::fusion;

// Minimal ASCII PLY writer for the demo (a full reader/writer is planned in taxel::io).
bool write_ply(const std::filesystem::path& path, const taxel::PointCloud<double>& cloud) {
  std::ofstream out(path);
  out << "ply\nformat ascii 1.0\nelement vertex " << cloud.size()
      << "\nproperty double x\nproperty double y\nproperty double z\n";
  for (const auto& f : cloud.fields) out << "property double " << f.name << "\n";
  out << "end_header\n";
  out.precision(9);
  for (std::size_t i = 0; i < cloud.size(); ++i) {
    out << cloud.points[i].x() << ' ' << cloud.points[i].y() << ' ' << cloud.points[i].z();
    for (const auto& f : cloud.fields) out << ' ' << f.values[i];
    out << '\n';
  }
  return static_cast<bool>(out);
}

template <class Policy, class Shape>
bool fuse_row(const char* shape_name, const char* policy_name, const Shape& shape,
              const std::vector<taxel::Contact<double>>& contacts,
              const std::filesystem::path& dir) {
  tf::ContactCloud<Policy> cloud({.association_radius = 3.4e-3});
  cloud.insert(std::span(contacts));
  const auto pc = cloud.to_point_cloud();
  const auto err = taxel::sim::surface_error(shape, pc.points);
  std::printf("| %-9s | %-8s | %8zu | %7.1fx | %6.3f | %6.3f | %6.2f |\n", shape_name, policy_name,
              cloud.size(),
              static_cast<double>(contacts.size()) / static_cast<double>(cloud.size()),
              err.mean * 1e3, err.rms * 1e3, err.max * 1e3);
  const auto file = dir / (std::string(shape_name) + "_" + policy_name + ".ply");
  if (!write_ply(file, pc)) {
    std::fprintf(stderr, "taxel-demo: cannot write %s\n", file.c_str());
    return false;
  }
  return true;
}

template <class Shape>
bool shape_rows(const char* name, const Shape& shape, std::size_t n,
                const std::filesystem::path& dir) {
  const auto contacts = taxel::sim::sliding_exploration(shape, n, {.sigma_tilt = 0.2, .seed = 3});
  return fuse_row<tf::Raw<double>>(name, "raw", shape, contacts, dir) &&
         fuse_row<tf::Average<double>>(name, "average", shape, contacts, dir) &&
         fuse_row<tf::Kalman<double>>(name, "kalman", shape, contacts, dir);
}

}  // namespace

int main(int argc, char** argv) {
  bool quick = false;
  std::filesystem::path dir = "taxel-demo-output";
  for (int i = 1; i < argc; ++i) {
    const std::string_view arg = argv[i];
    if (arg == "--quick") {
      quick = true;
    } else if (arg == "--help" || arg == "-h") {
      std::puts(
          "usage: taxel-demo [--quick] [output-folder]   (default taxel-demo-output)\n"
          "Fuses simulated sliding explorations of a sphere, a cylinder and a box with the\n"
          "raw, averaging and Kalman policies, prints accuracy and compaction, and writes\n"
          "the fused clouds as PLY files.");
      return 0;
    } else if (!arg.empty() && arg[0] == '-') {
      std::fprintf(stderr, "taxel-demo: unknown option '%s' (try --help)\n", argv[i]);
      return 2;
    } else {
      dir = arg;
    }
  }
  std::error_code ec;
  std::filesystem::create_directories(dir, ec);
  if (ec) {
    std::fprintf(stderr, "taxel-demo: cannot create %s: %s\n", dir.c_str(), ec.message().c_str());
    return 1;
  }
  const std::size_t n = quick ? 20000 : 200000;
  std::printf("taxel %s demo: %zu contacts per object, 3.4 mm pad, 2 mm association radius\n\n",
              TAXEL_VERSION_STRING, n);
  std::puts("| object    | policy   |   points | compact | mean mm | rms mm | max mm |");
  std::puts("|-----------|----------|----------|---------|---------|--------|--------|");
  const bool ok = shape_rows("sphere", taxel::sim::Sphere(0.04), n, dir) &&
                  shape_rows("cylinder", taxel::sim::Cylinder(0.03, 0.05), n, dir) &&
                  shape_rows("box", taxel::sim::Box(), n, dir);
  if (!ok) return 1;
  std::printf("\nPLY clouds written to %s/\n", dir.c_str());
  return 0;
}
