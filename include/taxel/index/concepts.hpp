// SPDX-License-Identifier: MIT
// Concepts for spatial indexes, and the neighbour type every index returns.
#pragma once

#include <concepts>
#include <cstddef>
#include <cstdint>
#include <limits>
#include <optional>
#include <vector>

#include "taxel/core/types.hpp"

namespace taxel::index {

/// Identifier of a stored point. Indexes size per-id tables by the largest id, so ids are meant
/// to be dense (0, 1, 2, ...), as ContactCloud assigns them.
using PointId = std::uint32_t;

/// A point found by a query: its id and its squared Euclidean distance to the query [m^2].
template <Scalar S>
struct Neighbor {
  PointId id = 0;             ///< Id of the stored point.
  S squared_distance = S(0);  ///< Squared distance to the query [m^2].

  /// Equal ids and distances.
  friend bool operator==(const Neighbor&, const Neighbor&) = default;
};

/// The order of query answers in every index: by squared distance, ties by id.
template <Scalar S>
constexpr bool closer(const Neighbor<S>& a, const Neighbor<S>& b) noexcept {
  return a.squared_distance < b.squared_distance ||
         (a.squared_distance == b.squared_distance && a.id < b.id);
}

/// Squared distance as every index computes it: ((dx^2 + dy^2) + dz^2), in this order, so that
/// all indexes (and nanoflann's L2_Simple metric) produce bit-identical distances.
template <Scalar S>
constexpr S squared_distance(const Vec3<S>& a, const Vec3<S>& b) noexcept {
  const S dx = a.x() - b.x();
  const S dy = a.y() - b.y();
  const S dz = a.z() - b.z();
  return dx * dx + dy * dy + dz * dz;
}

/// A queryable set of 3-D points with ids. All answers are exact and ordered by `closer`;
/// "within r" means squared_distance <= r * r.
/// - `nearest_within(q, r)`: the closest point with distance <= r, or nothing.
/// - `knn(q, k)`: the min(k, size()) closest points.
/// - `within(q, r)`: every point with distance <= r.
template <class I>
concept SpatialIndex = requires(const I& index, const Vec3<typename I::Scalar>& q,
                                typename I::Scalar r, std::size_t k) {
  requires Scalar<typename I::Scalar>;
  { index.nearest_within(q, r) } -> std::same_as<std::optional<Neighbor<typename I::Scalar>>>;
  { index.knn(q, k) } -> std::same_as<std::vector<Neighbor<typename I::Scalar>>>;
  { index.within(q, r) } -> std::same_as<std::vector<Neighbor<typename I::Scalar>>>;
  { index.size() } -> std::convertible_to<std::size_t>;
  { index.memory_bytes() } -> std::convertible_to<std::size_t>;
};

/// A spatial index that can change point by point. `insert` takes an id not currently stored;
/// `move` and `erase` take a stored id (checked by TAXEL_ASSERT). After any sequence of
/// operations the answers equal those of a freshly built index over the stored points.
template <class I>
concept IncrementalIndex = SpatialIndex<I> &&
    requires(I& index, PointId id, const Vec3<typename I::Scalar>& p, std::size_t n) {
  index.insert(id, p);
  index.move(id, p);
  index.erase(id);
  index.clear();
  index.reserve(n);
  { index.contains(id) } -> std::same_as<bool>;
};

}  // namespace taxel::index
