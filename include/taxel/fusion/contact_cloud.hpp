// SPDX-License-Identifier: MIT
// ContactCloud: a compact cloud of fused contact points (Meier et al. 2011, Sec. II).
#pragma once

#include <algorithm>
#include <array>
#include <cmath>
#include <concepts>
#include <cstddef>
#include <cstdint>
#include <limits>
#include <optional>
#include <span>
#include <stdexcept>
#include <string>
#include <type_traits>
#include <utility>
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
  InsertStatus status =
      InsertStatus::rejected;                ///< Whether the contact was added, fused or rejected.
  index::PointId id = 0;                     ///< the added or fused point; 0 when rejected
  ContactDefect defect = ContactDefect::ok;  ///< the reason for a rejection
};

/// Counts of a batch insert.
struct BatchResult {
  std::size_t added = 0;     ///< Contacts that started a new point.
  std::size_t fused = 0;     ///< Contacts fused into an existing point.
  std::size_t rejected = 0;  ///< Invalid contacts, left out (the cloud unchanged).
};

/// Fuses a stream of contacts into a compact point cloud. Each valid contact is matched to the
/// nearest fused point within the association gate (`association_radius`, wider for a contact
/// whose noise across the surface is coarse: `gate`), through the index, and fused into it by
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
  /// The floating-point type of positions and covariances (float or double).
  using Scalar = typename F::Scalar;
  /// The fusion policy.
  using Fusion = F;
  /// The spatial index over the points.
  using Index = I;
  /// A point's state, as the policy keeps it.
  using State = typename F::State;

  /// Configuration of the cloud, its policy and its index.
  struct Config {
    /// Euclidean association gate [m]: a contact fuses into the nearest point within this
    /// distance. Default: one tactel pitch of a Weiss DSA matrix (3.4 mm).
    Scalar association_radius = Scalar(3.4e-3);
    /// The gate widens for a contact whose own noise across the surface is coarse: it fuses
    /// into the nearest point within max(association_radius, association_sigmas * sigma_n),
    /// sigma_n its standard deviation along its normal (sqrt(n' R n); without a normal, the
    /// square root of the covariance's smallest eigenvalue). Without this, a contact whose
    /// noise is comparable to the gate (a palm pad's 1.5 mm against a 6 mm gate) lands beyond
    /// every point now and then, 3-4 sigma off the surface, and starts a point there; that
    /// point then gathers the contacts on its side of the surface, a biased sample, and ends
    /// up a millimetre off while its covariance claims a tenth of that. At 6 sigma no
    /// Gaussian tail escapes (2e-9 per contact). Contacts finer than association_radius / 6
    /// along their normal are unaffected. 0 turns the widening off; finite and >= 0.
    Scalar association_sigmas = Scalar(6);
    typename F::Config fusion{};                     ///< the policy's configuration
    typename detail::index_config<I>::type index{};  ///< the index's configuration, if any
  };

  /// Throws std::invalid_argument when a field is out of range.
  explicit ContactCloud(const Config& config = {})
      : config_(checked(config)), policy_(config.fusion), index_(make_index(config)) {}

  /// Validates `contact`, then fuses it into the nearest point within the association gate
  /// (`gate`; if the policy merges and accepts it) or adds it as a new point.
  InsertResult insert(const Contact<Scalar>& contact) {
    const ContactDefect bad = defect(contact);
    if (bad != ContactDefect::ok) return {InsertStatus::rejected, 0, bad};
    if constexpr (F::kMerges) {
      // The nearest point within the radius is the nearest within any wider gate too, so the
      // wider query runs only when the radius holds none (the index serves the radius best).
      auto hit = index_.nearest_within(contact.position, config_.association_radius);
      if (!hit) [[unlikely]] {
        hit = nearest_within_gate(contact);
      }
      if (hit) {
        const index::PointId id = hit->id;
        Point& point = points_[id];
        // Fused in place, with a copy to put back when the update overflows (fusing into a
        // copy and writing it back cost Surfel about 3 % of its instructions per contact).
        const State before = point.state;
        if (policy_.fuse(point.state, contact, point.meta.observations)) {
          const Vec3<Scalar> mean = policy_.mean(point.state);
          if (!all_finite(mean) || !all_finite(policy_.covariance(point.state))) {
            // Only reachable with extreme magnitudes (overflow); keep the model intact.
            point.state = before;
            return {InsertStatus::rejected, 0, ContactDefect::overflow};
          }
          ++point.meta.observations;
          point.meta.last_time = contact.time;
          index_.move(id, mean);
          return {InsertStatus::fused, id, ContactDefect::ok};
        }
        // A refusing policy leaves the state as it was (FusionPolicy); a user's policy that
        // does not cannot change the point either.
        point.state = before;
      }
    }
    TAXEL_ASSERT(points_.size() < std::numeric_limits<index::PointId>::max(),
                 "ContactCloud: more than 2^32 - 1 points");
    State state = policy_.init(contact);
    if (!all_finite(policy_.mean(state)) || !all_finite(policy_.covariance(state))) {
      // A valid contact with extreme magnitudes (a variance of 1e-320 along the normal makes
      // Surfel's weight 1 / n'Rn infinite): keep the model intact, as for a fused contact.
      return {InsertStatus::rejected, 0, ContactDefect::overflow};
    }
    const auto id = static_cast<index::PointId>(points_.size());
    points_.push_back({state, {1, contact.time}});
    index_.insert(id, contact.position);
    return {InsertStatus::added, id, ContactDefect::ok};
  }

  /// Why insert would reject `contact` before fusing it (check_contact's defects, or a position
  /// beyond what the index separates exactly), or ContactDefect::ok. Only an overflow while
  /// fusing (extreme magnitudes) is found by insert alone. Lets a caller validate a batch
  /// before inserting any of it.
  [[nodiscard]] ContactDefect defect(const Contact<Scalar>& contact) const noexcept {
    const ContactDefect d = check_contact(contact);
    if (d != ContactDefect::ok) return d;
    if constexpr (requires(const I& ix) { ix.max_coordinate(); }) {
      if (!(contact.position.cwiseAbs().maxCoeff() <= index_.max_coordinate())) {
        return ContactDefect::out_of_range;
      }
    }
    return ContactDefect::ok;
  }

  /// The association gate of a valid `contact` [m]: association_radius, widened to
  /// association_sigmas standard deviations of the contact's noise across the surface when
  /// that is larger (see Config::association_sigmas).
  [[nodiscard]] Scalar gate(const Contact<Scalar>& contact) const noexcept {
    const Scalar r = config_.association_radius;
    const Scalar k2 = config_.association_sigmas * config_.association_sigmas;
    // The common case costs one comparison: no variance exceeds the trace.
    if (!(k2 * contact.covariance.trace() > r * r)) return r;
    const Scalar var = contact.normal ? contact.normal->dot(contact.covariance * *contact.normal)
                                      : eigenvalue_range(contact.covariance).first;
    return k2 * var > r * r ? std::sqrt(k2 * var) : r;
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
  /// The fusion policy (e.g. for Surfel's `normal(state(id))`).
  [[nodiscard]] const F& policy() const noexcept { return policy_; }

  /// Which points count as confident surface points (`to_point_cloud`, `confident`).
  struct PointFilter {
    /// Fewest contacts fused into a point. A point seeded by a single contact, however fine, may
    /// be a noise tail; 3 or more is a sensible floor for a cloud used downstream.
    std::uint32_t min_observations = 1;
    /// Largest standard deviation of the point's covariance, along any direction [m] (the
    /// square root of its largest eigenvalue); infinity keeps all.
    Scalar max_sigma = std::numeric_limits<Scalar>::infinity();
    /// Standard deviation along the point's best-determined direction [m] (the square root
    /// of its smallest eigenvalue): for a point on a surface, across the surface, the error
    /// that matters for shape. A point seeded by one coarse contact (a palm pad's 1.5 mm)
    /// fails `max_normal_sigma = 0.3e-3` until finer contacts or many coarse ones have
    /// confirmed it, while its sideways spread (which `max_sigma` bounds) may stay wide on
    /// a well-measured surface. Infinity keeps all.
    Scalar max_normal_sigma = std::numeric_limits<Scalar>::infinity();
  };

  /// True when point `id` passes `filter`. Throws std::invalid_argument for a NaN or negative
  /// max_sigma.
  [[nodiscard]] bool confident(index::PointId id, const PointFilter& filter) const {
    TAXEL_ASSERT(id < size(), "ContactCloud::confident: id out of range");
    check_filter(filter);
    return passes(points_[id], filter);
  }

  /// The points as a PointCloud, keeping those that pass `filter` (all by default), in id
  /// order. Fields: "observations"; the covariance [m^2] as "cov_xx", "cov_xy", "cov_xz",
  /// "cov_yy", "cov_yz", "cov_zz"; "last_time" [s]. Normals when the policy estimates them
  /// (Surfel: its fitted surface's normal at the point) and every kept point has one. Throws
  /// std::invalid_argument for a NaN or negative max_sigma.
  [[nodiscard]] PointCloud<Scalar> to_point_cloud(const PointFilter& filter = {}) const {
    check_filter(filter);
    PointCloud<Scalar> out;
    std::vector<Scalar> obs, time;
    std::array<std::vector<Scalar>, 6> cov;
    std::vector<Vec3<Scalar>> normals;
    constexpr bool kNormals = requires(const F& f, const State& st) {
      { f.normal(st) } -> std::convertible_to<Vec3<Scalar>>;
    };
    bool all_normals = kNormals;
    for (const Point& p : points_) {
      if (!passes(p, filter)) continue;
      out.points.push_back(policy_.mean(p.state));
      obs.push_back(static_cast<Scalar>(p.meta.observations));
      const Mat3<Scalar> c = policy_.covariance(p.state);
      const std::array<Scalar, 6> upper{c(0, 0), c(0, 1), c(0, 2), c(1, 1), c(1, 2), c(2, 2)};
      for (std::size_t k = 0; k < 6; ++k) cov[k].push_back(upper[k]);
      time.push_back(static_cast<Scalar>(p.meta.last_time));
      if constexpr (kNormals) {
        if (all_normals) {
          const Vec3<Scalar> n = policy_.normal(p.state);
          all_normals = n.squaredNorm() > Scalar(0.5);
          normals.push_back(n);
        }
      }
    }
    if (all_normals && !out.points.empty()) out.normals = std::move(normals);
    out.fields.push_back({"observations", std::move(obs)});
    constexpr std::array<const char*, 6> kCov{"cov_xx", "cov_xy", "cov_xz",
                                              "cov_yy", "cov_yz", "cov_zz"};
    for (std::size_t k = 0; k < 6; ++k) out.fields.push_back({kCov[k], std::move(cov[k])});
    out.fields.push_back({"last_time", std::move(time)});
    return out;
  }
  /// Appends a point with a state saved from a cloud of the same policy (`state(id)`,
  /// `observations(id)`, `last_time(id)`), as loading a saved cloud does; the index finds it
  /// at the state's mean. Throws std::invalid_argument for a state whose mean or covariance is
  /// not finite, no observations, or a mean beyond what the index separates.
  index::PointId restore(const State& state, std::uint32_t observations, double last_time) {
    const Vec3<Scalar> mean = policy_.mean(state);
    if (!all_finite(mean) || !all_finite(policy_.covariance(state)) || observations == 0) {
      throw std::invalid_argument(
          "ContactCloud::restore: a state needs a finite mean and covariance and at least one "
          "observation");
    }
    if constexpr (requires(const I& ix) { ix.max_coordinate(); }) {
      if (!(mean.cwiseAbs().maxCoeff() <= index_.max_coordinate())) {
        throw std::invalid_argument("ContactCloud::restore: the mean is beyond the index's range");
      }
    }
    TAXEL_ASSERT(points_.size() < std::numeric_limits<index::PointId>::max(),
                 "ContactCloud: more than 2^32 - 1 points");
    const auto id = static_cast<index::PointId>(points_.size());
    points_.push_back({state, {observations, last_time}});
    index_.insert(id, mean);
    return id;
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
    if (r > Scalar(1)) {  // no tactile contact is gated at a metre: a length in millimetres
      throw std::invalid_argument(
          "ContactCloud::Config::association_radius = " + std::to_string(r) +
          " m looks like millimetres; taxel uses metres (" + std::to_string(r) +
          " mm = " + std::to_string(r / Scalar(1000)) + ")");
    }
    const Scalar k = config.association_sigmas;
    if (!(k >= Scalar(0)) || !std::isfinite(k)) {
      throw std::invalid_argument(
          "ContactCloud::Config::association_sigmas must be finite and >= 0, got " +
          std::to_string(k));
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

  // The nearest point within the widened gate, when it is wider than the radius (out of line:
  // the common path, a point within the radius, stays short).
  [[gnu::noinline]] std::optional<index::Neighbor<Scalar>> nearest_within_gate(
      const Contact<Scalar>& contact) const {
    const Scalar g = gate(contact);
    const Scalar r = config_.association_radius;
    if (!(g > r)) return std::nullopt;
    // Twice the radius first: a narrower query reads fewer cells, and what it finds is the
    // nearest within the gate too.
    if (g > Scalar(2) * r) {
      if (auto hit = index_.nearest_within(contact.position, Scalar(2) * r)) return hit;
    }
    return index_.nearest_within(contact.position, g);
  }

  static void check_filter(const PointFilter& filter) {
    if (!(filter.max_sigma >= Scalar(0))) {
      throw std::invalid_argument("ContactCloud::PointFilter::max_sigma must be >= 0 [m], got " +
                                  std::to_string(filter.max_sigma));
    }
    if (!(filter.max_normal_sigma >= Scalar(0))) {
      throw std::invalid_argument(
          "ContactCloud::PointFilter::max_normal_sigma must be >= 0 [m], got " +
          std::to_string(filter.max_normal_sigma));
    }
  }
  bool passes(const Point& p, const PointFilter& filter) const {
    if (p.meta.observations < filter.min_observations) return false;
    constexpr Scalar kInf = std::numeric_limits<Scalar>::infinity();
    if (filter.max_sigma == kInf && filter.max_normal_sigma == kInf) return true;
    const auto [lo, hi] = eigenvalue_range(policy_.covariance(p.state));
    return hi <= filter.max_sigma * filter.max_sigma &&
           lo <= filter.max_normal_sigma * filter.max_normal_sigma;
  }
  // Smallest and largest eigenvalues of a symmetric 3x3 matrix, in closed form (the
  // trigonometric solution of the characteristic cubic; Smith, Comm. ACM 4(4), 1961).
  static std::pair<Scalar, Scalar> eigenvalue_range(const Mat3<Scalar>& a) {
    const Scalar p1 = a(0, 1) * a(0, 1) + a(0, 2) * a(0, 2) + a(1, 2) * a(1, 2);
    const Scalar q = a.trace() / Scalar(3);
    if (p1 == Scalar(0)) {
      return {std::min({a(0, 0), a(1, 1), a(2, 2)}), std::max({a(0, 0), a(1, 1), a(2, 2)})};
    }
    const Scalar p2 = (a(0, 0) - q) * (a(0, 0) - q) + (a(1, 1) - q) * (a(1, 1) - q) +
                      (a(2, 2) - q) * (a(2, 2) - q) + Scalar(2) * p1;
    const Scalar p = std::sqrt(p2 / Scalar(6));
    const Mat3<Scalar> b = (a - q * Mat3<Scalar>::Identity()) / p;
    const Scalar r = std::clamp(b.determinant() / Scalar(2), Scalar(-1), Scalar(1));
    const Scalar phi = std::acos(r) / Scalar(3);
    constexpr Scalar kThird = Scalar(2.0943951023931954923);  // 2 pi / 3
    return {q + Scalar(2) * p * std::cos(phi + kThird), q + Scalar(2) * p * std::cos(phi)};
  }
};

}  // namespace taxel::fusion
