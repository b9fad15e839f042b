// SPDX-License-Identifier: MIT
// The simulated objects of the command-line tools (taxel-simulate, taxel-explore): one of the
// simulator's shapes by name with its lengths, or a closed triangle mesh read from a PLY file.
#pragma once

#include <exception>
#include <optional>
#include <stdexcept>
#include <string>
#include <taxel/io/ply.hpp>
#include <taxel/sim/shapes.hpp>
#include <utility>
#include <vector>

#include "cli.hpp"

namespace taxel_cli {

/// The simulator's shapes by name, as --shape takes them.
inline constexpr const char* kShapeNames = "sphere|cylinder|box|cone|ellipsoid|torus";

/// The lengths of each shape when --size is not given [m]: radius; radius and half height;
/// half extents; base radius and height; semi-axes; ring and tube radius.
struct ShapeSizes {
  std::vector<double> sphere{0.03}, cylinder{0.025, 0.04}, box{0.04, 0.03, 0.02}, cone{0.03, 0.06},
      ellipsoid{0.045, 0.035, 0.025}, torus{0.035, 0.012};
};

/// Returns f(shape) for the shape `name` (one of kShapeNames) of lengths `size`, or of
/// `defaults` when `size` is empty. A `size` of the wrong count fails with usage (exit 2); a
/// shape constructor's std::invalid_argument (a length out of range) passes through.
template <class F>
decltype(auto) with_shape(const std::string& name, const std::vector<double>& size,
                          const ShapeSizes& defaults, const Args& args, F&& f) {
  namespace ts = taxel::sim;
  const auto dims = [&](const std::vector<double>& fallback) {
    if (size.empty()) return fallback;
    if (size.size() != fallback.size()) {
      args.fail("--size for a " + name + " takes " + std::to_string(fallback.size()) +
                " length(s), got " + std::to_string(size.size()));
    }
    return size;
  };
  if (name == "sphere") return f(ts::Sphere(dims(defaults.sphere)[0]));
  if (name == "cylinder") {
    const auto d = dims(defaults.cylinder);
    return f(ts::Cylinder(d[0], d[1]));
  }
  if (name == "box") {
    const auto d = dims(defaults.box);
    return f(ts::Box(taxel::Vec3d(d[0], d[1], d[2])));
  }
  if (name == "cone") {
    const auto d = dims(defaults.cone);
    return f(ts::Cone(d[0], d[1]));
  }
  if (name == "ellipsoid") {
    const auto d = dims(defaults.ellipsoid);
    return f(ts::Ellipsoid(taxel::Vec3d(d[0], d[1], d[2])));
  }
  if (name != "torus") args.fail("--shape must be one of " + std::string(kShapeNames));
  const auto d = dims(defaults.torus);
  return f(ts::Torus(d[0], d[1]));
}

/// The closed triangle mesh in the PLY file `path` ('-': standard input), its coordinates
/// multiplied by `scale`. Warns when it looks like millimetres; a file that cannot be read, is
/// not a PLY or is not a closed mesh fails with exit 1.
inline taxel::sim::TriangleMesh read_mesh(const std::string& path, double scale, const char* tool,
                                          const Args& args) {
  taxel::io::PlyData ply;
  try {
    ply = taxel::io::parse_ply(read_input(path), input_name(path));
  } catch (const std::exception& e) {
    args.fail(e.what(), 1);
  }
  if (scale != 1.0) {
    for (auto& p : ply.cloud.points) p *= scale;
  }
  warn_if_millimetres(tool, input_name(path), largest_extent(ply.cloud.points));
  try {
    return taxel::sim::TriangleMesh(std::move(ply.cloud.points), std::move(ply.triangles));
  } catch (const std::invalid_argument& e) {  // a mesh TriangleMesh refuses is bad data
    args.fail(input_name(path) + ": " + e.what(), 1);
  }
}

}  // namespace taxel_cli
