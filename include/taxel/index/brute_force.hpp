// SPDX-License-Identifier: MIT
// BruteForce: a linear scan over all points; the reference every other index is tested against.
#pragma once

#include <algorithm>
#include <cstddef>
#include <optional>
#include <vector>

#include "taxel/core/assert.hpp"
#include "taxel/index/concepts.hpp"

namespace taxel::index {

/// Exact spatial index by linear scan. Every query is O(n); insert, move and erase are O(1).
/// Memory: 4 + 3 * sizeof(S) bytes per point plus 4 bytes per id value.
/// Not thread-safe for concurrent writes; concurrent const queries are safe.
template <Scalar S>
class BruteForce {
 public:
  /// The floating-point type of positions and covariances (float or double).
  using Scalar = S;
  /// BruteForce has nothing to configure.
  struct Config {};

  BruteForce() = default;
  /// BruteForce has nothing to configure.
  explicit BruteForce(const Config&) {}

  /// Adds point `p` with a new `id`.
  void insert(PointId id, const Vec3<S>& p) {
    TAXEL_ASSERT(!contains(id), "BruteForce::insert: id already stored");
    if (id >= slot_of_.size()) slot_of_.resize(std::size_t{id} + 1, kNone);
    slot_of_[id] = static_cast<PointId>(points_.size());
    points_.push_back(p);
    ids_.push_back(id);
  }
  /// Moves stored point `id` to `p`.
  void move(PointId id, const Vec3<S>& p) {
    TAXEL_ASSERT(contains(id), "BruteForce::move: id not stored");
    points_[slot_of_[id]] = p;
  }
  /// Removes stored point `id`.
  void erase(PointId id) {
    TAXEL_ASSERT(contains(id), "BruteForce::erase: id not stored");
    const PointId slot = slot_of_[id];
    points_[slot] = points_.back();
    ids_[slot] = ids_.back();
    slot_of_[ids_[slot]] = slot;
    points_.pop_back();
    ids_.pop_back();
    slot_of_[id] = kNone;
  }
  /// Removes every point.
  void clear() noexcept {
    points_.clear();
    ids_.clear();
    slot_of_.clear();
  }
  /// Reserves room for `n` points.
  void reserve(std::size_t n) {
    points_.reserve(n);
    ids_.reserve(n);
    slot_of_.reserve(n);
  }
  /// True when `id` is stored.
  [[nodiscard]] bool contains(PointId id) const noexcept {
    return id < slot_of_.size() && slot_of_[id] != kNone;
  }
  /// Number of stored points.
  [[nodiscard]] std::size_t size() const noexcept { return points_.size(); }
  /// Heap bytes held.
  [[nodiscard]] std::size_t memory_bytes() const noexcept {
    return points_.capacity() * sizeof(Vec3<S>) + ids_.capacity() * sizeof(PointId) +
           slot_of_.capacity() * sizeof(PointId);
  }

  /// The closest point within distance r of q (ties by id), if any. O(n). A point whose
  /// squared distance overflows (farther than about 1e154 in double) is never returned.
  [[nodiscard]] std::optional<Neighbor<S>> nearest_within(const Vec3<S>& q, S r) const {
    std::optional<Neighbor<S>> best;
    const S r2 = r * r;
    for (std::size_t i = 0; i < points_.size(); ++i) {
      const Neighbor<S> n{ids_[i], squared_distance(points_[i], q)};
      if (n.squared_distance <= r2 && n.squared_distance < std::numeric_limits<S>::infinity() &&
          (!best || closer(n, *best))) {
        best = n;
      }
    }
    return best;
  }
  /// The min(k, size()) closest points, ordered by `closer`. O(n log k).
  [[nodiscard]] std::vector<Neighbor<S>> knn(const Vec3<S>& q, std::size_t k) const {
    std::vector<Neighbor<S>> all = scan(q, std::numeric_limits<S>::infinity());
    const std::size_t m = std::min(k, all.size());
    std::partial_sort(all.begin(), all.begin() + static_cast<std::ptrdiff_t>(m), all.end(),
                      closer<S>);
    all.resize(m);
    return all;
  }
  /// Every point within distance r of q, ordered by `closer`. O(n + m log m).
  [[nodiscard]] std::vector<Neighbor<S>> within(const Vec3<S>& q, S r) const {
    std::vector<Neighbor<S>> out = scan(q, r * r);
    std::sort(out.begin(), out.end(), closer<S>);
    return out;
  }

 private:
  static constexpr PointId kNone = std::numeric_limits<PointId>::max();

  std::vector<Neighbor<S>> scan(const Vec3<S>& q, S r2) const {
    std::vector<Neighbor<S>> out;
    for (std::size_t i = 0; i < points_.size(); ++i) {
      const S d2 = squared_distance(points_[i], q);
      if (d2 <= r2 || r2 == std::numeric_limits<S>::infinity()) out.push_back({ids_[i], d2});
    }
    return out;
  }

  std::vector<Vec3<S>> points_;
  std::vector<PointId> ids_;
  std::vector<PointId> slot_of_;
};

}  // namespace taxel::index
