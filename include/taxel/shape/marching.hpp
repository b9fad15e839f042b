// SPDX-License-Identifier: MIT
// The level set of a sampled field as a triangle mesh, by marching tetrahedra: each grid cube
// is cut into six tetrahedra around its diagonal from node (0, 0, 0) to node (1, 1, 1), and in
// each tetrahedron the field is taken linear, so its level set is one triangle or a quad (two
// triangles). Neighbouring cubes cut their shared face along the same diagonal, and a vertex
// is shared by every triangle on its grid edge, so the mesh has no cracks: away from the grid's
// border every edge belongs to exactly two triangles. Chosen over the classic marching cubes
// (Lorensen and Cline 1987) because it has no ambiguous cases and its 16-case table derives
// from the tetrahedron's sign pattern, at the cost of about twice the triangles.
#pragma once

#include <array>
#include <cstdint>
#include <stdexcept>
#include <string>
#include <unordered_map>
#include <vector>

#include "taxel/core/types.hpp"
#include "taxel/shape/grid.hpp"

namespace taxel::shape {

/// A triangle mesh: triangles counter-clockwise seen from outside (the side where the field is
/// above the level).
struct Mesh {
  std::vector<Vec3d> vertices;                          ///< [m]
  std::vector<std::array<std::uint32_t, 3>> triangles;  ///< vertex indices

  /// Total area [m^2].
  [[nodiscard]] double area() const {
    double a = 0.0;
    for (const auto& t : triangles)
      a += 0.5 * (vertices[t[1]] - vertices[t[0]]).cross(vertices[t[2]] - vertices[t[0]]).norm();
    return a;
  }
};

/// The surface where `values` (sampled on `grid`, one per node) cross `level`. With `close`,
/// nodes on the grid's border count as above the level, so that a field below it at the border
/// still gives a closed mesh. Throws std::invalid_argument for an invalid grid, a value count
/// that does not match it, or a non-finite value or level.
template <class = void>
[[nodiscard]] Mesh marching_tetrahedra(const Grid& grid, const std::vector<double>& values,
                                       double level = 0.0, bool close = false) {
  grid.validate();
  if (values.size() != grid.size()) {
    throw std::invalid_argument("marching_tetrahedra: " + std::to_string(values.size()) +
                                " values for a grid of " + std::to_string(grid.size()) + " nodes");
  }
  if (!std::isfinite(level)) throw std::invalid_argument("marching_tetrahedra: level not finite");
  for (const double v : values) {
    if (!std::isfinite(v))
      throw std::invalid_argument("marching_tetrahedra: a value is not finite");
  }
  const auto& n = grid.nodes;
  const auto value = [&](int i, int j, int k) {
    const double v = values[grid.index(i, j, k)];
    if (close && (i == 0 || j == 0 || k == 0 || i == n[0] - 1 || j == n[1] - 1 || k == n[2] - 1))
      return std::max(v, level + 1e-9 * grid.spacing);
    return v;
  };
  static constexpr int kTets[6][4] = {{0, 1, 3, 7}, {0, 1, 5, 7}, {0, 2, 3, 7},
                                      {0, 2, 6, 7}, {0, 4, 5, 7}, {0, 4, 6, 7}};
  Mesh mesh;
  std::unordered_map<std::uint64_t, std::uint32_t> on_edge;
  std::array<std::size_t, 8> id{};
  std::array<double, 8> f{};
  std::array<Vec3d, 8> x;
  const auto vertex = [&](int a, int b) {
    if (id[static_cast<std::size_t>(a)] > id[static_cast<std::size_t>(b)]) std::swap(a, b);
    const auto ua = static_cast<std::size_t>(a), ub = static_cast<std::size_t>(b);
    const std::uint64_t edge = (std::uint64_t(id[ua]) << 32) | std::uint64_t(id[ub]);
    const auto [it, added] =
        on_edge.try_emplace(edge, static_cast<std::uint32_t>(mesh.vertices.size()));
    if (added) {
      const double t = std::clamp((level - f[ua]) / (f[ub] - f[ua]), 1e-6, 1.0 - 1e-6);
      mesh.vertices.push_back(x[ua] + t * (x[ub] - x[ua]));
    }
    return it->second;
  };
  const auto emit = [&](std::uint32_t p, std::uint32_t q, std::uint32_t r, const Vec3d& outward) {
    const Vec3d normal =
        (mesh.vertices[q] - mesh.vertices[p]).cross(mesh.vertices[r] - mesh.vertices[p]);
    if (normal.dot(outward) < 0.0) std::swap(q, r);
    mesh.triangles.push_back({p, q, r});
  };
  for (int k = 0; k + 1 < n[2]; ++k) {
    for (int j = 0; j + 1 < n[1]; ++j) {
      for (int i = 0; i + 1 < n[0]; ++i) {
        int below = 0;
        for (int c = 0; c < 8; ++c) {
          const int ci = i + (c & 1), cj = j + ((c >> 1) & 1), ck = k + ((c >> 2) & 1);
          const auto uc = static_cast<std::size_t>(c);
          f[uc] = value(ci, cj, ck);
          id[uc] = grid.index(ci, cj, ck);
          x[uc] = grid.node(ci, cj, ck);
          below += f[uc] < level;
        }
        if (below == 0 || below == 8) continue;
        for (const auto& tet : kTets) {
          std::array<int, 4> in{}, out{};
          int nin = 0, nout = 0;
          for (const int c : tet)
            (f[static_cast<std::size_t>(c)] < level ? in[nin++] : out[nout++]) = c;
          if (nin == 0 || nout == 0) continue;
          Vec3d outward = Vec3d::Zero();
          for (int a = 0; a < nout; ++a) outward += x[static_cast<std::size_t>(out[a])] / nout;
          for (int a = 0; a < nin; ++a) outward -= x[static_cast<std::size_t>(in[a])] / nin;
          if (nin == 1) {
            emit(vertex(in[0], out[0]), vertex(in[0], out[1]), vertex(in[0], out[2]), outward);
          } else if (nout == 1) {
            emit(vertex(in[0], out[0]), vertex(in[1], out[0]), vertex(in[2], out[0]), outward);
          } else {  // a quad: in[0]-out[0], in[0]-out[1], in[1]-out[1], in[1]-out[0]
            const std::uint32_t a = vertex(in[0], out[0]), b = vertex(in[0], out[1]),
                                c = vertex(in[1], out[1]), d = vertex(in[1], out[0]);
            emit(a, b, c, outward);
            emit(a, c, d, outward);
          }
        }
      }
    }
  }
  return mesh;
}

}  // namespace taxel::shape
