// SPDX-License-Identifier: MIT
// A plain point cloud: positions, optional normals and named per-point scalar fields.
#pragma once

#include <algorithm>
#include <cstddef>
#include <string>
#include <string_view>
#include <utility>
#include <vector>

#include "taxel/core/status.hpp"
#include "taxel/core/types.hpp"

namespace taxel {

/// A named per-point scalar (e.g. "observations", "covariance_trace"); one value per point.
template <Scalar S>
struct ScalarField {
  std::string name;       ///< property name, as written to PLY
  std::vector<S> values;  ///< one value per point
};

/// A point cloud in one frame. Invariant (checked by `validate`): `normals` is empty or as long
/// as `points`, and every field has one value per point. Units: metres.
template <Scalar S>
struct PointCloud {
  std::vector<Vec3<S>> points;         ///< positions [m]
  std::vector<Vec3<S>> normals;        ///< unit normals, or empty
  std::vector<ScalarField<S>> fields;  ///< extra per-point scalars

  /// Number of points.
  [[nodiscard]] std::size_t size() const noexcept { return points.size(); }
  /// True when there are no points.
  [[nodiscard]] bool empty() const noexcept { return points.empty(); }
  /// True when every point has a normal.
  [[nodiscard]] bool has_normals() const noexcept {
    return !points.empty() && normals.size() == points.size();
  }

  /// The field called `name`, or nullptr.
  [[nodiscard]] const ScalarField<S>* field(std::string_view name) const noexcept {
    auto it = std::find_if(fields.begin(), fields.end(),
                           [&](const ScalarField<S>& f) { return f.name == name; });
    return it == fields.end() ? nullptr : &*it;
  }

  /// The field called `name`, created with `size()` zeros when missing.
  ScalarField<S>& field_or_add(std::string_view name) {
    for (auto& f : fields) {
      if (f.name == name) return f;
    }
    fields.push_back({std::string(name), std::vector<S>(points.size(), S(0))});
    return fields.back();
  }

  /// Checks the size invariants and that every coordinate is finite.
  [[nodiscard]] Outcome validate() const {
    if (!normals.empty() && normals.size() != points.size()) {
      return {Status::invalid_input, "normals: " + std::to_string(normals.size()) +
                                         " entries for " + std::to_string(points.size()) +
                                         " points"};
    }
    for (const auto& f : fields) {
      if (f.values.size() != points.size()) {
        return {Status::invalid_input,
                "field '" + f.name + "': " + std::to_string(f.values.size()) + " values for " +
                    std::to_string(points.size()) + " points"};
      }
    }
    for (std::size_t i = 0; i < points.size(); ++i) {
      if (!points[i].allFinite()) {
        return {Status::invalid_input, "point " + std::to_string(i) + " is not finite"};
      }
    }
    return {};
  }
};

/// `cloud` with `T_dst_src` applied to points and normals (fields are copied).
template <Scalar S>
PointCloud<S> transformed(const PointCloud<S>& cloud, const Isometry3<S>& T_dst_src) {
  PointCloud<S> out = cloud;
  for (auto& p : out.points) p = T_dst_src * p;
  for (auto& n : out.normals) n = T_dst_src.linear() * n;
  return out;
}

}  // namespace taxel
