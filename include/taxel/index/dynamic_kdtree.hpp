// SPDX-License-Identifier: MIT
// DynamicKdTree: an incremental kd-tree on nanoflann 1.4's dynamic adaptor.
#pragma once

#include <algorithm>
#include <cstddef>
#include <limits>
#include <memory>
#include <optional>
#include <stdexcept>
#include <vector>

#include "taxel/core/assert.hpp"
#include "taxel/index/concepts.hpp"
#include "taxel/index/kdtree.hpp"

namespace taxel::index {

/// Incremental exact spatial index on nanoflann 1.4's KDTreeSingleIndexDynamicAdaptor (a
/// logarithmic forest of static trees). It is the peer taxel's VoxelHash is measured against.
///
/// nanoflann 1.4 mishandles a removed index that is added again, so this class never reuses
/// one: every insert or move appends a fresh internal slot and removes the old one, and the
/// forest is rebuilt from the live points when dead slots outnumber them. Internal slots map
/// back to ids, so answers are exact and use taxel's tie order.
/// Complexity: insert/move O(log^2 n) amortised; queries O(log^2 n). Memory: see memory_bytes().
/// Not thread-safe for concurrent writes; concurrent const queries are safe.
template <Scalar S>
class DynamicKdTree {
 public:
  /// The floating-point type of positions and covariances (float or double).
  using Scalar = S;
  /// Build parameters.
  struct Config {
    std::size_t leaf_size = 10;  ///< maximum points per leaf, >= 1
  };

  /// An empty index. Throws std::invalid_argument for a bad configuration.
  explicit DynamicKdTree(const Config& config = {}) : config_(config) {
    if (config.leaf_size == 0) {
      throw std::invalid_argument("DynamicKdTree::Config::leaf_size must be >= 1");
    }
    rebuild();
  }

  /// Adds point `p` (finite) with a new `id`.
  void insert(PointId id, const Vec3<S>& p) {
    TAXEL_ASSERT(!contains(id), "DynamicKdTree::insert: id already stored");
    TAXEL_ASSERT(p.allFinite(), "DynamicKdTree::insert: point is not finite");
    if (id >= slot_of_.size()) slot_of_.resize(std::size_t{id} + 1, kNone);
    append(id, p);
    ++size_;
  }
  /// Moves stored point `id` to `p` (finite): the old slot is removed, a new one appended.
  void move(PointId id, const Vec3<S>& p) {
    TAXEL_ASSERT(contains(id), "DynamicKdTree::move: id not stored");
    TAXEL_ASSERT(p.allFinite(), "DynamicKdTree::move: point is not finite");
    impl_->tree.removePoint(slot_of_[id]);
    impl_->ids[slot_of_[id]] = kNone;
    append(id, p);
    maybe_compact();
  }
  /// Removes stored point `id`.
  void erase(PointId id) {
    TAXEL_ASSERT(contains(id), "DynamicKdTree::erase: id not stored");
    impl_->tree.removePoint(slot_of_[id]);
    impl_->ids[slot_of_[id]] = kNone;
    slot_of_[id] = kNone;
    --size_;
    maybe_compact();
  }
  /// Removes every point.
  void clear() {
    slot_of_.clear();
    size_ = 0;
    rebuild();
  }
  /// Reserves room for `n` points.
  void reserve(std::size_t n) {
    slot_of_.reserve(n);
    impl_->points.reserve(2 * n);
    impl_->ids.reserve(2 * n);
  }
  /// True when `id` is stored.
  [[nodiscard]] bool contains(PointId id) const noexcept {
    return id < slot_of_.size() && slot_of_[id] != kNone;
  }
  /// Number of stored points.
  [[nodiscard]] std::size_t size() const noexcept { return size_; }
  /// Approximate heap bytes held (slots, maps and nanoflann's trees).
  [[nodiscard]] std::size_t memory_bytes() const noexcept {
    std::size_t bytes = impl_->points.capacity() * sizeof(Vec3<S>) +
                        impl_->ids.capacity() * sizeof(PointId) +
                        slot_of_.capacity() * sizeof(PointId);
    for (const auto& t : impl_->tree.getAllIndices()) {
      bytes += t.vAcc.capacity() * sizeof(std::uint32_t) + t.pool.usedMemory;
    }
    // treeIndex (int per slot) and the removed-slot hash set (about 32 bytes per entry).
    return bytes + impl_->points.size() * (sizeof(int) + 32);
  }

  /// The closest point within distance r of q (ties by id), if any.
  [[nodiscard]] std::optional<Neighbor<S>> nearest_within(const Vec3<S>& q, S r) const {
    if (size_ == 0 || !q.allFinite() || !(r >= S(0))) return std::nullopt;
    detail::NearestWithinSet<S, IdOf> set(r * r, impl_->id_of);
    impl_->tree.findNeighbors(set, q.data(), nanoflann::SearchParams());
    return set.result();
  }
  /// The min(k, size()) closest points, ordered by `closer`.
  [[nodiscard]] std::vector<Neighbor<S>> knn(const Vec3<S>& q, std::size_t k) const {
    k = std::min(k, size_);
    if (k == 0 || !q.allFinite()) return {};
    detail::KnnSet<S, IdOf> set(k, impl_->id_of);
    impl_->tree.findNeighbors(set, q.data(), nanoflann::SearchParams());
    return std::move(set.out);
  }
  /// Every point within distance r of q, ordered by `closer`.
  [[nodiscard]] std::vector<Neighbor<S>> within(const Vec3<S>& q, S r) const {
    if (size_ == 0 || !q.allFinite() || !(r >= S(0))) return {};
    detail::WithinSet<S, IdOf> set(r * r, impl_->id_of);
    impl_->tree.findNeighbors(set, q.data(), nanoflann::SearchParams());
    std::sort(set.out.begin(), set.out.end(), closer<S>);
    return std::move(set.out);
  }

 private:
  static constexpr PointId kNone = std::numeric_limits<PointId>::max();
  using Adaptor = detail::PointsAdaptor<S>;
  using Tree = nanoflann::KDTreeSingleIndexDynamicAdaptor<
      nanoflann::L2_Simple_Adaptor<S, Adaptor, S, std::uint32_t>, Adaptor, 3, std::uint32_t>;

  struct IdOf {
    const std::vector<PointId>* ids;
    PointId operator()(std::uint32_t slot) const noexcept { return (*ids)[slot]; }
  };
  struct Impl {
    explicit Impl(const Config& config)
        : adaptor{&points},
          id_of{&ids},
          tree(3, adaptor, nanoflann::KDTreeSingleIndexAdaptorParams(config.leaf_size)) {}
    std::vector<Vec3<S>> points;  // by internal slot; dead slots keep their last coordinates
    std::vector<PointId> ids;     // id of each internal slot, kNone when dead
    Adaptor adaptor;
    IdOf id_of;
    Tree tree;
  };

  void append(PointId id, const Vec3<S>& p) {
    const auto slot = static_cast<std::uint32_t>(impl_->points.size());
    impl_->points.push_back(p);
    impl_->ids.push_back(id);
    slot_of_[id] = slot;
    impl_->tree.addPoints(slot, slot);
  }
  void maybe_compact() {
    if (impl_->points.size() > 2 * size_ + 1024) rebuild();
  }
  // A fresh forest over the live points, with slots renumbered densely.
  void rebuild() {
    auto fresh = std::make_unique<Impl>(config_);
    if (impl_) {
      fresh->points.reserve(size_);
      fresh->ids.reserve(size_);
      for (std::size_t slot = 0; slot < impl_->ids.size(); ++slot) {
        const PointId id = impl_->ids[slot];
        if (id == kNone) continue;
        slot_of_[id] = static_cast<std::uint32_t>(fresh->points.size());
        fresh->points.push_back(impl_->points[slot]);
        fresh->ids.push_back(id);
      }
      if (!fresh->points.empty()) {
        fresh->tree.addPoints(0, static_cast<std::uint32_t>(fresh->points.size() - 1));
      }
    }
    impl_ = std::move(fresh);
  }

  Config config_;
  std::unique_ptr<Impl> impl_;
  std::vector<PointId> slot_of_;
  std::size_t size_ = 0;
};

}  // namespace taxel::index
