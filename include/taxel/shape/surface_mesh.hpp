// SPDX-License-Identifier: MIT
// The estimated surface as a mesh with its uncertainty: the zero level set of an implicit
// surface's posterior mean, each vertex with the field's posterior standard deviation (about
// the surface's uncertainty along its normal, in metres, since the field is about a distance)
// and the mean's normalised gradient as its normal.
#pragma once

#include <cmath>
#include <stdexcept>
#include <vector>

#include "taxel/core/point_cloud.hpp"
#include "taxel/shape/implicit_surface.hpp"
#include "taxel/shape/marching.hpp"

namespace taxel::shape {

/// A mesh of the estimated surface with per-vertex uncertainty.
struct SurfaceMesh {
  Mesh mesh;                   ///< the zero level set of the posterior mean
  std::vector<double> sigma;   ///< per vertex: posterior standard deviation of the field [m]
  std::vector<Vec3d> normals;  ///< per vertex: the mean's normalised gradient

  /// The vertices as a cloud with normals and the field "sigma" (for io::write_ply together
  /// with mesh.triangles).
  [[nodiscard]] PointCloud<double> to_point_cloud() const {
    PointCloud<double> out;
    out.points = mesh.vertices;
    out.normals = normals;
    out.fields.push_back({"sigma", sigma});
    return out;
  }
  /// Mean of sigma over the vertices, weighted by the area around each (a third of each
  /// triangle's), so that it does not depend on how finely the mesh is cut; 0 for no triangles.
  [[nodiscard]] double mean_sigma() const {
    double sum = 0.0, area = 0.0;
    for (const auto& t : mesh.triangles) {
      const auto& v = mesh.vertices;
      const double a = 0.5 * (v[t[1]] - v[t[0]]).cross(v[t[2]] - v[t[0]]).norm();
      sum += a * (sigma[t[0]] + sigma[t[1]] + sigma[t[2]]) / 3.0;
      area += a;
    }
    return area > 0.0 ? sum / area : 0.0;
  }
};

/// The mesh of `surface`'s zero level set on `grid` (closed at the grid's border), from the
/// sampled posterior mean `field` (ImplicitSurface::sample), with every vertex's standard
/// deviation and normal. Throws std::invalid_argument for a field that does not fit the grid.
template <Kernel K>
[[nodiscard]] SurfaceMesh extract_surface(const ImplicitSurface<K>& surface, const Grid& grid,
                                          const std::vector<double>& field) {
  SurfaceMesh out;
  out.mesh = marching_tetrahedra(grid, field, 0.0, true);
  const auto m = static_cast<Eigen::Index>(out.mesh.vertices.size());
  Eigen::Matrix3Xd at(3, m);
  for (Eigen::Index i = 0; i < m; ++i) at.col(i) = out.mesh.vertices[static_cast<std::size_t>(i)];
  std::vector<double> mean(out.mesh.vertices.size());
  out.sigma.resize(out.mesh.vertices.size());
  surface.evaluate(at, mean.data(), out.sigma.data());
  out.normals.resize(out.mesh.vertices.size());
  for (std::size_t i = 0; i < out.sigma.size(); ++i) {
    out.sigma[i] = std::sqrt(out.sigma[i]);
    Vec3d g = Vec3d::Zero();
    (void)surface.mean(out.mesh.vertices[i], g);
    out.normals[i] = g.norm() > 0.0 ? Vec3d(g.normalized()) : Vec3d::UnitZ();
  }
  return out;
}

/// The confidence region of the surface: between `inner`, where mean + k sigma = 0, and
/// `outer`, where mean - k sigma = 0 (sigma the field's posterior standard deviation). With the
/// field about a distance, the surface lies between them with the probability of k sigmas of
/// a normal distribution (about 95 % for k = 2) at each point.
struct ConfidenceRegion {
  Mesh inner;      ///< the level set mean + k sigma = 0 (inside the estimate)
  Mesh outer;      ///< the level set mean - k sigma = 0 (outside it)
  double k = 2.0;  ///< the number of standard deviations
};

/// The confidence region of `surface` on `grid` (see ConfidenceRegion), both meshes closed at
/// the grid's border. Costs a variance per grid node. Throws std::invalid_argument for an
/// invalid grid or k not finite and > 0.
template <Kernel K>
[[nodiscard]] ConfidenceRegion confidence_region(const ImplicitSurface<K>& surface,
                                                 const Grid& grid, double k = 2.0) {
  if (!(k > 0.0) || !std::isfinite(k))
    throw std::invalid_argument("confidence_region: k must be finite and > 0");
  grid.validate();
  Eigen::Matrix3Xd nodes(3, static_cast<Eigen::Index>(grid.size()));
  for (int c = 0; c < grid.nodes[2]; ++c) {
    for (int b = 0; b < grid.nodes[1]; ++b) {
      for (int a = 0; a < grid.nodes[0]; ++a)
        nodes.col(static_cast<Eigen::Index>(grid.index(a, b, c))) = grid.node(a, b, c);
    }
  }
  std::vector<double> mean(grid.size()), var(grid.size());
  surface.evaluate(nodes, mean.data(), var.data());
  std::vector<double> lo(grid.size()), hi(grid.size());
  for (std::size_t i = 0; i < grid.size(); ++i) {
    const double s = k * std::sqrt(var[i]);
    lo[i] = mean[i] + s;
    hi[i] = mean[i] - s;
  }
  ConfidenceRegion out;
  out.k = k;
  out.inner = marching_tetrahedra(grid, lo, 0.0, true);
  out.outer = marching_tetrahedra(grid, hi, 0.0, true);
  return out;
}

/// As above, sampling the field itself.
template <Kernel K>
[[nodiscard]] SurfaceMesh extract_surface(const ImplicitSurface<K>& surface, const Grid& grid) {
  return extract_surface(surface, grid, surface.sample(grid));
}

}  // namespace taxel::shape
