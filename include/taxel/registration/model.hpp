// SPDX-License-Identifier: MIT
// The cloud a model file stands for: its surface when it has faces, its vertices otherwise.
#pragma once

#include <cstddef>
#include <cstdint>
#include <stdexcept>
#include <string>
#include <utility>
#include <vector>

#include "taxel/core/deferred.hpp"
#include "taxel/core/point_cloud.hpp"
#include "taxel/io/ply.hpp"
#include "taxel/sim/sampling.hpp"
#include "taxel/sim/shapes.hpp"

namespace taxel::registration {

/// How a model with faces becomes points.
struct ModelSampling {
  /// About one point per spacing^2 of surface [m], > 0. The default suits tactile objects of a
  /// few centimetres (a 10 cm cube: 60 000 points); 0 keeps the vertices even when there are
  /// faces.
  double spacing = 1e-3;
  std::uint64_t seed = 1;                         ///< of the area-uniform draw
  std::size_t max_points = std::size_t{1} << 22;  ///< more is refused (a spacing too fine)
};

/// A model cloud and what it was made of.
struct ModelCloud {
  PointCloud<double> cloud;    ///< The points (and normals) of the model.
  bool from_surface = false;   ///< sampled from the faces (else: the vertices as read)
  std::size_t triangles = 0;   ///< faces used
  std::size_t degenerate = 0;  ///< faces of zero area, skipped
  double spacing = 0.0;        ///< the sampling spacing when from_surface [m]

  /// One line for a user: "12 triangles: 5000 points sampled area-uniformly at 0.001 m spacing"
  /// or "1000 vertices (no faces)".
  [[nodiscard]] std::string describe() const {
    if (!from_surface) {
      return std::to_string(cloud.size()) + " vertices" + (triangles == 0 ? " (no faces)" : "");
    }
    std::string s = std::to_string(triangles) + " triangles: " + std::to_string(cloud.size()) +
                    " points sampled area-uniformly at " + std::to_string(spacing) + " m spacing";
    if (degenerate > 0) s += " (" + std::to_string(degenerate) + " faces of zero area skipped)";
    return s;
  }
};

/// The cloud a model stands for. With faces (and a spacing > 0), points drawn uniformly over
/// the surface by area, about one per spacing^2, with the normals of their faces: so a finely
/// meshed model and a coarsely meshed one weigh alike in ICP and recognition, whatever the
/// density of their vertices. Without faces, the vertices (and normals) as read. Faces of zero
/// area are skipped and counted. Throws std::invalid_argument for a non-finite vertex, a face
/// naming a missing vertex, a surface of zero area, or a spacing too fine for max_points.
template <class D = void>
ModelCloud model_cloud(Deferred<io::PlyData, D> ply, const ModelSampling& sampling = {}) {
  ModelCloud out;
  if (ply.triangles.empty() || sampling.spacing == 0.0) {
    out.triangles = ply.triangles.size();
    out.cloud = std::move(ply.cloud);
    return out;
  }
  if (!(sampling.spacing > 0.0)) {
    throw std::invalid_argument("ModelSampling: spacing must be >= 0 (0: use the vertices)");
  }
  std::vector<sim::TriangleMesh::Triangle> faces;
  faces.reserve(ply.triangles.size());
  const auto& v = ply.cloud.points;
  for (const auto& t : ply.triangles) {
    for (const auto i : t) {
      if (i >= v.size()) {
        throw std::invalid_argument("a face names vertex " + std::to_string(i) + " of " +
                                    std::to_string(v.size()));
      }
    }
    if ((v[t[1]] - v[t[0]]).cross(v[t[2]] - v[t[0]]).norm() > 0.0) {
      faces.push_back(t);
    } else {
      ++out.degenerate;
    }
  }
  if (faces.empty()) throw std::invalid_argument("every face has zero area");
  out.triangles = faces.size();
  const sim::TriangleMesh mesh(std::move(ply.cloud.points), std::move(faces));
  out.cloud =
      sim::sample_surface_spacing(mesh, sampling.spacing, sampling.seed, sampling.max_points);
  out.from_surface = true;
  out.spacing = sampling.spacing;
  return out;
}

}  // namespace taxel::registration
