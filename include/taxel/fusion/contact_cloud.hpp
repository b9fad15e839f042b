// SPDX-License-Identifier: MIT
// ContactCloud: a compact cloud of fused contact points (Meier et al. 2011, Sec. II).
#pragma once

#include <concepts>
#include <cstddef>
#include <cstdint>
#include <limits>
#include <span>
#include <stdexcept>
#include <string>
#include <type_traits>
#include <vector>

#include "taxel/core/assert.hpp"
#include "taxel/core/contact.hpp"
#include "taxel/core/point_cloud.hpp"
#include "taxel/fusion/concepts.hpp"
#include "taxel/fusion/kalman.hpp"
#include "taxel/fusion/surfel.hpp"
#include "taxel/index/concepts.hpp"
#include "taxel/index/voxel_hash.hpp"

namespace taxel::fusion {

namespace detail {
/// An index's configuration type: `I::Config` when it has one, else an empty aggregate, so a
/// user's index needs no Config to plug into ContactCloud.
template <class I>
struct index_config {
  struct type {};
};
template <class I>
requires requires { typename I::Config; }
struct index_config<I> {
  using type = typename I::Config;
};
}  // namespace detail

/// What `ContactCloud::insert` did with a contact.
enum class InsertStatus : std::uint8_t {
  added,     ///< started a new point
  fused,     ///< merged into an existing point
  rejected,  ///< invalid contact (see `defect`); the cloud is unchanged
};

/// Outcome of one insert: the status, the point it concerns (added or fused) and, when
/// rejected, why.
struct InsertResult {
  InsertStatus status = InsertStatus::rejected;
  index::PointId id = 0;                     ///< the added or fused point; 0 when rejected
  ContactDefect defect = ContactDefect::ok;  ///< the reason for a rejection
};

/// Counts of a batch insert.
struct BatchResult {
  std::size_t added = 0;
  std::size_t fused = 0;
  std::size_t rejected = 0;
};

/// Fuses a stream of contacts into a compact point cloud. Each valid contact is matched to the
/// nearest fused point within `association_radius` (through the index) and fused into it by
/// the policy, or starts a new point; the index then follows the moved mean, so it stays
/// exact. Compose at compile time:
/// ```
/// using Cloud = ContactCloud<Kalman<double>, index::VoxelHash<double>>;
/// Cloud cloud({.association_radius = 2e-3});
/// ```
/// Point ids are dense (0 .. size() - 1, in order of creation) and stable until `clear`.
/// Memory per point: sizeof(State) + 16 bytes here, plus the index's share (see
/// `memory_bytes`). `insert` of a contact that fuses allocates nothing (with VoxelHash, when
/// the point stays in its cell, which is the common case; a cell change may grow a block pool).
/// Not thread-safe for writes.
template <FusionPolicy F = Surfel<double>,
          index::IncrementalIndex I = index::VoxelHash<typename F::Scalar>>
requires std::same_as<typename F::Scalar, typename I::Scalar>
class ContactCloud {
 public:
  using Scalar = typename F::Scalar;
  using Fusion = F;
  using Index = I;
  using State = typename F::State;

  /// Configuration of the cloud, its policy and its index.
  struct Config {
    /// Euclidean association gate [m]: a contact fuses into the nearest point within this
    /// distance. Default: one tactel pitch of a Weiss DSA matrix (3.4 mm).
    Scalar association_radius = Scalar(3.4e-3);
    typename F::Config fusion{};                     ///< the policy's configuration
    typename detail::index_config<I>::type index{};  ///< the index's configuration, if any
  };

  /// Throws std::invalid_argument when a field is out of range.
  explicit ContactCloud(const Config& config = {})
      : config_(checked(config)), policy_(config.fusion), index_(make_index(config)) {}

  /// Validates `contact`, then fuses it into the nearest point within the association radius
  /// (if the policy merges and accepts it) or adds it as a new point.
  InsertResult insert(const Contact<Scalar>& contact) {
    const ContactDefect defect = check_contact(contact);
    if (defect != ContactDefect::ok) return {InsertStatus::rejected, 0, defect};
    if constexpr (F::kMerges) {
      if (const auto hit = index_.nearest_within(contact.position, config_.association_radius)) {
        const index::PointId id = hit->id;
        Point& point = points_[id];
        State fused = point.state;
        if (policy_.fuse(fused, contact, point.meta.observations)) {
          const Vec3<Scalar> mean = policy_.mean(fused);
          if (!all_finite(mean) || !all_finite(policy_.covariance(fused))) {
            // Only reachable with extreme magnitudes (overflow); keep the model intact.
            return {InsertStatus::rejected, 0, ContactDefect::overflow};
          }
          point.state = fused;
          ++point.meta.observations;
          point.meta.last_time = contact.time;
          index_.move(id, mean);
          return {InsertStatus::fused, id, ContactDefect::ok};
        }
      }
    }
    TAXEL_ASSERT(points_.size() < std::numeric_limits<index::PointId>::max(),
                 "ContactCloud: more than 2^32 - 1 points");
    const auto id = static_cast<index::PointId>(points_.size());
    points_.push_back({policy_.init(contact), {1, contact.time}});
    index_.insert(id, contact.position);
    return {InsertStatus::added, id, ContactDefect::ok};
  }

  /// Inserts contacts in order; returns how many were added, fused and rejected.
  BatchResult insert(std::span<const Contact<Scalar>> contacts) {
    BatchResult r;
    for (const auto& c : contacts) {
      switch (insert(c).status) {
        case InsertStatus::added:
          ++r.added;
          break;
        case InsertStatus::fused:
          ++r.fused;
          break;
        case InsertStatus::rejected:
          ++r.rejected;
          break;
      }
    }
    return r;
  }

  /// Number of fused points.
  [[nodiscard]] std::size_t size() const noexcept { return points_.size(); }
  /// True when no point exists.
  [[nodiscard]] bool empty() const noexcept { return points_.empty(); }
  /// Mean of point `id` [m].
  [[nodiscard]] Vec3<Scalar> mean(index::PointId id) const {
    TAXEL_ASSERT(id < size(), "ContactCloud::mean: id out of range");
    return policy_.mean(points_[id].state);
  }
  /// Covariance of point `id` [m^2].
  [[nodiscard]] Mat3<Scalar> covariance(index::PointId id) const {
    TAXEL_ASSERT(id < size(), "ContactCloud::covariance: id out of range");
    return policy_.covariance(points_[id].state);
  }
  /// Number of contacts fused into point `id` (1 for a new point).
  [[nodiscard]] std::uint32_t observations(index::PointId id) const {
    TAXEL_ASSERT(id < size(), "ContactCloud::observations: id out of range");
    return points_[id].meta.observations;
  }
  /// Time of the last contact fused into point `id` [s].
  [[nodiscard]] double last_time(index::PointId id) const {
    TAXEL_ASSERT(id < size(), "ContactCloud::last_time: id out of range");
    return points_[id].meta.last_time;
  }
  /// The policy state of point `id`.
  [[nodiscard]] const State& state(index::PointId id) const {
    TAXEL_ASSERT(id < size(), "ContactCloud::state: id out of range");
    return points_[id].state;
  }
  /// The spatial index over the point means (for k-NN and radius queries).
  [[nodiscard]] const I& index() const noexcept { return index_; }
  /// The configuration in use.
  [[nodiscard]] const Config& config() const noexcept { return config_; }

  /// The points as a PointCloud with fields "observations", "covariance_trace" [m^2] and
  /// "last_time" [s].
  [[nodiscard]] PointCloud<Scalar> to_point_cloud() const {
    PointCloud<Scalar> out;
    out.points.reserve(size());
    std::vector<Scalar> obs, trace, time;
    obs.reserve(size());
    trace.reserve(size());
    time.reserve(size());
    for (std::size_t i = 0; i < size(); ++i) {
      out.points.push_back(policy_.mean(points_[i].state));
      obs.push_back(static_cast<Scalar>(points_[i].meta.observations));
      trace.push_back(policy_.covariance(points_[i].state).trace());
      time.push_back(static_cast<Scalar>(points_[i].meta.last_time));
    }
    out.fields.push_back({"observations", std::move(obs)});
    out.fields.push_back({"covariance_trace", std::move(trace)});
    out.fields.push_back({"last_time", std::move(time)});
    return out;
  }

  /// Removes every point.
  void clear() {
    points_.clear();
    index_.clear();
  }
  /// Prepares for `n` points without reallocation.
  void reserve(std::size_t n) {
    points_.reserve(n);
    index_.reserve(n);
  }
  /// Heap bytes held by the points and the index.
  [[nodiscard]] std::size_t memory_bytes() const noexcept {
    return points_.capacity() * sizeof(Point) + index_.memory_bytes();
  }

 private:
  struct Meta {
    std::uint32_t observations;
    double last_time;
  };

  static Config checked(const Config& config) {
    const Scalar r = config.association_radius;
    if (!(r > Scalar(0)) || !std::isfinite(r)) {
      throw std::invalid_argument(
          "ContactCloud::Config::association_radius must be finite and > 0 [m], got " +
          std::to_string(r));
    }
    return config;
  }
  // The index, from (radius, config), (config) or nothing, whichever it takes.
  static I make_index(const Config& config) {
    using IC = typename detail::index_config<I>::type;
    if constexpr (std::is_constructible_v<I, Scalar, const IC&>) {
      return I(config.association_radius, config.index);
    } else if constexpr (std::is_constructible_v<I, const IC&>) {
      return I(config.index);
    } else {
      return I();
    }
  }

  Config config_;
  F policy_;
  I index_;
  // A point's state and bookkeeping side by side: a fusion touches one record.
  struct Point {
    State state;
    Meta meta;
  };
  std::vector<Point> points_;
};

}  // namespace taxel::fusion
