// SPDX-License-Identifier: MIT
// KdTree: a static kd-tree over a fixed point set, on nanoflann 1.4.
#pragma once

#include <algorithm>
#include <cmath>
#include <cstddef>
#include <limits>
#include <memory>
#include <optional>
#include <stdexcept>
#include <utility>
#include <vector>

// nanoflann 1.4 leaves root_bbox uninitialised until built; GCC's -Wmaybe-uninitialized
// flags it inside nanoflann's own code.
#if defined(__GNUC__) && !defined(__clang__)
#pragma GCC diagnostic push
#pragma GCC diagnostic ignored "-Wmaybe-uninitialized"
#endif
#include <nanoflann.hpp>
#if defined(__GNUC__) && !defined(__clang__)
#pragma GCC diagnostic pop
#endif

#include "taxel/core/assert.hpp"
#include "taxel/core/point_cloud.hpp"
#include "taxel/index/concepts.hpp"

namespace taxel::index {
namespace detail {

// nanoflann only offers points with dist < worstDist(); reporting the next representable
// value above the bound lets points exactly at the bound (the radius, or a tie with the current
// best) reach the result set, which then breaks ties by id like every taxel index.
template <Scalar S>
S above(S bound) noexcept {
  return std::nextafter(bound, std::numeric_limits<S>::infinity());
}

// Result set: the closest point with squared distance <= bound, ties by id.
template <Scalar S, class IdMap>
class NearestWithinSet {
 public:
  using DistanceType = S;
  using IndexType = std::uint32_t;
  NearestWithinSet(S bound, const IdMap& ids) : best_{0, bound}, worst_(above(bound)), ids_(ids) {}
  bool full() const noexcept { return found_; }
  // Cached: nanoflann asks for it at every node, and nextafter is a libm call.
  S worstDist() const noexcept { return worst_; }
  bool addPoint(S d2, IndexType internal) {
    const Neighbor<S> n{ids_(internal), d2};
    if (n.squared_distance < best_.squared_distance ||
        (n.squared_distance == best_.squared_distance && (!found_ || n.id < best_.id))) {
      if (n.squared_distance != best_.squared_distance) worst_ = above(n.squared_distance);
      best_ = n;
      found_ = true;
    }
    return true;
  }
  std::optional<Neighbor<S>> result() const {
    return found_ ? std::optional<Neighbor<S>>(best_) : std::nullopt;
  }

 private:
  Neighbor<S> best_;
  S worst_;
  bool found_ = false;
  const IdMap& ids_;
};

// Result set: every point with squared distance <= bound.
template <Scalar S, class IdMap>
class WithinSet {
 public:
  using DistanceType = S;
  using IndexType = std::uint32_t;
  WithinSet(S bound, const IdMap& ids) : bound_(bound), worst_(above(bound)), ids_(ids) {}
  bool full() const noexcept { return true; }
  S worstDist() const noexcept { return worst_; }
  bool addPoint(S d2, IndexType internal) {
    if (d2 <= bound_) out.push_back({ids_(internal), d2});
    return true;
  }
  std::vector<Neighbor<S>> out;

 private:
  S bound_;
  S worst_;
  const IdMap& ids_;
};

// Result set: the k closest points by (distance, id), kept sorted (k is small).
template <Scalar S, class IdMap>
class KnnSet {
 public:
  using DistanceType = S;
  using IndexType = std::uint32_t;
  KnnSet(std::size_t k, const IdMap& ids) : k_(k), ids_(ids) { out.reserve(k); }
  bool full() const noexcept { return out.size() == k_; }
  S worstDist() const noexcept { return worst_; }
  bool addPoint(S d2, IndexType internal) {
    const Neighbor<S> n{ids_(internal), d2};
    if (full() && !closer(n, out.back())) return true;
    if (full()) out.pop_back();
    out.insert(std::upper_bound(out.begin(), out.end(), n, closer<S>), n);
    if (full()) worst_ = above(out.back().squared_distance);
    return true;
  }
  std::vector<Neighbor<S>> out;

 private:
  std::size_t k_;
  S worst_ = std::numeric_limits<S>::infinity();
  const IdMap& ids_;
};

// nanoflann dataset adaptor over a vector of points.
template <Scalar S>
struct PointsAdaptor {
  const std::vector<Vec3<S>>* points = nullptr;
  std::size_t kdtree_get_point_count() const { return points->size(); }
  S kdtree_get_pt(std::size_t i, std::size_t dim) const { return (*points)[i][int(dim)]; }
  template <class BBox>
  bool kdtree_get_bbox(BBox&) const {
    return false;
  }
};

struct IdentityIds {
  PointId operator()(std::uint32_t i) const noexcept { return i; }
};

}  // namespace detail

/// Static kd-tree (nanoflann 1.4) over a fixed set of points; point i has id i.
/// Build O(n log n); queries O(log n) expected. Exact, with taxel's tie order. Use it for
/// clouds that do not change (ICP targets, models); see DynamicKdTree for incremental use.
/// Const queries may run concurrently.
/// Immutable after construction: concurrent queries are safe.
template <Scalar S>
class KdTree {
 public:
  /// The floating-point type of positions and covariances (float or double).
  using Scalar = S;
  /// Build parameters.
  struct Config {
    std::size_t leaf_size = 10;  ///< maximum points per leaf, >= 1
  };

  /// Builds the tree over `points` (all finite; throws std::invalid_argument otherwise).
  explicit KdTree(std::vector<Vec3<S>> points, const Config& config = {})
      : impl_(std::make_unique<Impl>(std::move(points), config)) {}
  /// Builds the tree over the points of `cloud`.
  explicit KdTree(const PointCloud<S>& cloud, const Config& config = {})
      : KdTree(cloud.points, config) {}

  /// Number of points.
  [[nodiscard]] std::size_t size() const noexcept { return impl_->points.size(); }
  /// The point with id `id`.
  [[nodiscard]] const Vec3<S>& point(PointId id) const {
    TAXEL_ASSERT(id < size(), "KdTree::point: id out of range");
    return impl_->points[id];
  }
  /// All points, indexed by id.
  [[nodiscard]] const std::vector<Vec3<S>>& points() const noexcept { return impl_->points; }
  /// Approximate heap bytes held (points plus nanoflann's index and nodes).
  [[nodiscard]] std::size_t memory_bytes() const noexcept {
    return impl_->points.capacity() * sizeof(Vec3<S>) + impl_->tree.usedMemory(impl_->tree);
  }

  /// The closest point within distance r of q (ties by id), if any.
  [[nodiscard]] std::optional<Neighbor<S>> nearest_within(const Vec3<S>& q, S r) const {
    if (size() == 0 || !q.allFinite() || !(r >= S(0))) return std::nullopt;
    detail::NearestWithinSet<S, detail::IdentityIds> set(r * r, ids_);
    impl_->tree.findNeighbors(set, q.data(), nanoflann::SearchParams());
    return set.result();
  }
  /// The min(k, size()) closest points, ordered by `closer`.
  [[nodiscard]] std::vector<Neighbor<S>> knn(const Vec3<S>& q, std::size_t k) const {
    k = std::min(k, size());
    if (k == 0 || !q.allFinite()) return {};
    detail::KnnSet<S, detail::IdentityIds> set(k, ids_);
    impl_->tree.findNeighbors(set, q.data(), nanoflann::SearchParams());
    return std::move(set.out);
  }
  /// Every point within distance r of q, ordered by `closer`.
  [[nodiscard]] std::vector<Neighbor<S>> within(const Vec3<S>& q, S r) const {
    if (size() == 0 || !q.allFinite() || !(r >= S(0))) return {};
    detail::WithinSet<S, detail::IdentityIds> set(r * r, ids_);
    impl_->tree.findNeighbors(set, q.data(), nanoflann::SearchParams());
    std::sort(set.out.begin(), set.out.end(), closer<S>);
    return std::move(set.out);
  }

 private:
  using Adaptor = detail::PointsAdaptor<S>;
  using Tree = nanoflann::KDTreeSingleIndexAdaptor<
      nanoflann::L2_Simple_Adaptor<S, Adaptor, S, std::uint32_t>, Adaptor, 3, std::uint32_t>;

  struct Impl {
    Impl(std::vector<Vec3<S>> pts, const Config& config)
        : points(validated(std::move(pts), config)),
          adaptor{&points},
          tree(3, adaptor, nanoflann::KDTreeSingleIndexAdaptorParams(config.leaf_size)) {
      if (!points.empty()) tree.buildIndex();
    }
    static std::vector<Vec3<S>> validated(std::vector<Vec3<S>> pts, const Config& config) {
      if (config.leaf_size == 0) {
        throw std::invalid_argument("KdTree::Config::leaf_size must be >= 1");
      }
      if (pts.size() >= std::numeric_limits<std::uint32_t>::max()) {
        throw std::invalid_argument("KdTree: more than 2^32 - 1 points");
      }
      for (std::size_t i = 0; i < pts.size(); ++i) {
        if (!pts[i].allFinite()) {
          throw std::invalid_argument("KdTree: point " + std::to_string(i) + " is not finite");
        }
      }
      return pts;
    }
    std::vector<Vec3<S>> points;
    Adaptor adaptor;
    Tree tree;
  };

  std::unique_ptr<Impl> impl_;
  detail::IdentityIds ids_;
};

}  // namespace taxel::index
